#!/usr/bin/env bash
# The installed package: `cmake --install` of this build into a temporary prefix, then the
# consumer project (tests/consumer) configured with find_package(impactdeck) against it, built and
# run; the installed `impactdeck` command finds its Gmsh plugins beside itself. Then the same with
# a collision-core-only build (IMPACTDECK_CORE_ONLY=ON) of the sources.
#   consumer_test.sh BUILD_DIR SOURCE_DIR
set -u
build=$(cd "$1" && pwd)
src=$(cd "$2" && pwd)
. "$src/tests/check_lib.sh"

export CCACHE_BASEDIR=$src

# Full package, from this build.
cmake --install "$build" --prefix "$tmp/full" > "$tmp/install_full.log" 2>&1
check "install (full)" test $? -eq 0
check "package config installed" test -f "$tmp/full/lib/cmake/impactdeck/impactdeckConfig.cmake"
check "version file installed" test -f "$tmp/full/lib/cmake/impactdeck/impactdeckConfigVersion.cmake"
check "public header installed" test -f "$tmp/full/include/impactdeck/collision/impact.hpp"
check "generated version header installed" test -f "$tmp/full/include/impactdeck/common/version.hpp"
check "plugins beside the command" test -f "$tmp/full/bin/libimpactdeck_gmsh_cad.so" -a -f "$tmp/full/bin/libimpactdeck_gmsh_mesher.so"
check "man page installed" test -s "$tmp/full/share/man/man1/impactdeck.1"
check "bash completion installed" bash -c ". '$tmp/full/share/bash-completion/completions/impactdeck' && complete -p impactdeck"
# Stripped by default (IMPACTDECK_INSTALL_STRIP, issue 32): no symbol tables or debug sections in
# the command, the plugins and the Python module, no debug sections in the static libraries (their
# symbols stay: the consumer below links them); the build tree keeps its debug information.
unstripped() { readelf -S -W "$1" | grep -q -E '\.symtab|\.debug_info'; }
for f in "$tmp/full/bin/impactdeck" "$tmp/full/bin/"lib*.so $(find "$tmp/full/lib" -name 'impactdeck*.so'); do
  check "installed stripped: ${f#$tmp/full/}" bash -c "! readelf -S -W '$f' | grep -q -E '\.symtab|\.debug_info'"
done
for f in "$tmp/full/lib/"libimpactdeck_*.a; do
  check "installed without debug sections: ${f#$tmp/full/}" bash -c "! readelf -S -W '$f' | grep -q '\.debug_info'"
done
check "the build tree's command keeps its debug information" unstripped "$build/cli/impactdeck"
cmake -S "$src/tests/consumer" -B "$tmp/cfull" -G Ninja -DCMAKE_PREFIX_PATH="$tmp/full" > "$tmp/cfull.log" 2>&1
check "consumer configures against the full package" test $? -eq 0
cmake --build "$tmp/cfull" > "$tmp/cfull_build.log" 2>&1
check "consumer builds (full)" test $? -eq 0
"$tmp/cfull/consumer_core" > "$tmp/core_run.txt" 2>&1
check "consumer_core runs (F_max = closed form)" test $? -eq 0
IMPACTDECK_GMSH_CAD_PLUGIN="$tmp/full/bin/libimpactdeck_gmsh_cad.so" \
  "$tmp/cfull/consumer_full" "$src/tests/data/cad/screw.step" > "$tmp/full_run.txt" 2>&1
check "consumer_full runs a scene and reads a STEP part with the installed plugin" test $? -eq 0
check "consumer_full printed the STEP volume" grep -q "cad volume_m3 3.788" "$tmp/full_run.txt"
# The installed command, moved away from the build tree's plugin paths: plugins beside it.
"$tmp/full/bin/impactdeck" inspect "$src/tests/data/cad/screw.step" --length-unit mm --json > "$tmp/inspect.json" 2> "$tmp/inspect.err"
check "installed impactdeck reads a STEP part (plugin beside it)" test $? -eq 0
check "installed impactdeck found the installed plugin" grep -q '"format": "step"' "$tmp/inspect.json"

# Collision core only: no CGAL, Gmsh, MED, assimp.
cmake -S "$src" -B "$tmp/core-build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DIMPACTDECK_CORE_ONLY=ON \
  > "$tmp/core_configure.log" 2>&1
check "core-only configures" test $? -eq 0
check "core-only needs no CGAL, Gmsh, MED or assimp" bash -c "! grep -q -i -E 'cgal|gmsh|medC|assimp' '$tmp/core-build/CMakeCache.txt'"
cmake --build "$tmp/core-build" -j 2 > "$tmp/core_build.log" 2>&1
check "core-only builds" test $? -eq 0
cmake --install "$tmp/core-build" --prefix "$tmp/core" > "$tmp/install_core.log" 2>&1
check "install (core only)" test $? -eq 0
check "core-only installs no geometry" test ! -e "$tmp/core/include/impactdeck/geometry"
cmake -S "$src/tests/consumer" -B "$tmp/ccore" -G Ninja -DCMAKE_PREFIX_PATH="$tmp/core" -DCONSUMER_FULL=OFF \
  > "$tmp/ccore.log" 2>&1
check "consumer configures against the core-only package" test $? -eq 0
cmake --build "$tmp/ccore" > "$tmp/ccore_build.log" 2>&1
check "consumer builds (core only)" test $? -eq 0
"$tmp/ccore/consumer_core" > "$tmp/core_only_run.txt" 2>&1
check "consumer_core runs against the core-only package" test $? -eq 0
cmake -S "$src/tests/consumer" -B "$tmp/ccore_full" -G Ninja -DCMAKE_PREFIX_PATH="$tmp/core" -DCONSUMER_FULL=ON \
  > "$tmp/ccore_full.log" 2>&1
check "asking the core-only package for geometry fails" test $? -ne 0
finish consumer_test
