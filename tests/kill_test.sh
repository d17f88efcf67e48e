#!/usr/bin/env bash
# Nothing lost (issue #6): outputs of a successful run survive a run killed with SIGKILL at any
# moment byte for byte; a completed run replaces the whole set. After each kill every file must be
# byte for byte its old or its new version (never partial), and the set must be all old or all new
# unless the commit marker says the kill hit the final renames (then the next run warns).
# Then a kill made certain to land inside the final renames, and a kill during the ccx run.
# usage: kill_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src_dir=${2:-$(dirname "$0")/..}
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
make_scene() {  # make_scene SPEED FILE: 40 impacts, fine tables, so that writing takes a while
  {
    printf 'length_unit = "mm"\n[materials.steel]\nyoungs_modulus_Pa = 2.05e11\npoisson_ratio = 0.3\ndensity_kg_m3 = 7850\n'
    printf '[[bodies]]\nname = "t"\nshape = "ellipsoid"\nsemi_axes = [2000, 500, 500]\nmaterial = "steel"\n'
    printf '[[bodies]]\nname = "b"\nshape = "sphere"\nradius = 50\nmaterial = "steel"\n'
    for i in $(seq 1 40); do
      x=$(awk -v i="$i" 'BEGIN { printf "%.6f", -1900 + 95 * i }')
      y=$(awk -v x="$x" 'BEGIN { printf "%.6f", 500 * sqrt(1 - (x / 2000)^2) }')
      printf '[[impacts]]\nname = "i%02d"\ntarget = "t"\nimpactor = "b"\npoint = [%s, %s, 0]\napproach_speed_m_s = %s\nrestitution = 0.5\n' "$i" "$x" "$y" "$1"
    done
    printf '[outputs]\nforce_table_csv = "f.csv"\nforce_table_impulse_tolerance = 1e-8\n'
  } >"$2"
}
make_scene 1 "$tmp/a.toml"
make_scene 2 "$tmp/b.toml"
out="$tmp/out"; mkdir -p "$out"
sum() { (cd "$out" && ls -A | sort | xargs sha256sum | sha256sum | cut -c1-16); }
"$bin" run "$tmp/b.toml" --out "$out" >/dev/null 2>&1 || { echo "FAILED: run B"; exit 1; }
new=$(sum)
start=$(date +%s%N)
"$bin" run "$tmp/a.toml" --out "$out" >/dev/null 2>&1 || { echo "FAILED: run A"; exit 1; }
dur_ms=$(( ($(date +%s%N) - start) / 1000000 ))
old=$(sum)
[ "$old" != "$new" ] || { echo "FAILED: runs A and B wrote the same bytes"; exit 1; }
fsum() { (cd "$out" && sha256sum "$1" | cut -c1-16); }
declare -A oldf newf
for f in $(cd "$out" && ls); do oldf[$f]=$(fsum "$f"); done
"$bin" run "$tmp/b.toml" --out "$out" >/dev/null 2>&1
for f in $(cd "$out" && ls); do newf[$f]=$(fsum "$f"); done
"$bin" run "$tmp/a.toml" --out "$out" >/dev/null 2>&1
kept=0; replaced=0; bad=0; marked=0
for k in $(seq 1 20); do
  delay_ms=$(( (k * dur_ms) / 21 ))
  "$bin" run "$tmp/b.toml" --out "$out" >/dev/null 2>&1 &
  pid=$!
  sleep "$(awk -v d="$delay_ms" 'BEGIN { printf "%.3f", d / 1000 }')"
  kill -9 "$pid" 2>/dev/null
  wait "$pid" 2>/dev/null
  now=$(cd "$out" && ls -A | grep -v '^\.' | sort | xargs sha256sum | sha256sum | cut -c1-16)
  for f in $(cd "$out" && ls); do
    h=$(fsum "$f")
    if [ "$h" != "${oldf[$f]}" ] && [ "$h" != "${newf[$f]}" ]; then
      bad=$((bad+1)); echo "FAILED: kill after ${delay_ms} ms left a partial $f"
    fi
  done
  if [ "$now" = "$old" ]; then kept=$((kept+1));
  elif [ "$now" = "$new" ]; then replaced=$((replaced+1));
  elif [ -e "$out/.impactdeck-commit" ]; then
    marked=$((marked+1))
    "$bin" run "$tmp/a.toml" --out "$out" 2>&1 | grep -q "killed while replacing" ||
      { bad=$((bad+1)); echo "FAILED: the next run did not warn about the interrupted commit"; }
  else bad=$((bad+1)); echo "FAILED: kill after ${delay_ms} ms left a mixed set without the commit marker"; fi
  rm -f "$out"/.*.tmp-* "$out/.impactdeck-commit" 2>/dev/null   # the killed run's leftovers
  "$bin" run "$tmp/a.toml" --out "$out" >/dev/null 2>&1   # back to the old set
done
echo "kill_test: run takes ${dur_ms} ms; 20 kills: ${kept} left the old set, ${replaced} the new set, ${marked} a marked mixed set, ${bad} broken"

# 2. A kill inside the rename phase, made certain: IMPACTDECK_TEST_COMMIT_DELAY_MS (a test seam of
# common/run_transaction.cpp) sleeps after each rename; run B is killed once its journal exists.
# The next run into the folder, even one that writes nothing, finishes B's renames from its
# staging folder (all of B, never a mix) and says so.
printf 'length_unit = "mm"\n[materials.s]\nyoungs_modulus_Pa = 2e11\npoisson_ratio = 0.3\ndensity_kg_m3 = 7850\n[[bodies]]\nname = "a"\nshape = "sphere"\nradius = 10\nmaterial = "s"\n[[bodies]]\nname = "b"\nshape = "sphere"\nradius = 10\nmaterial = "s"\nvelocity_m_s = [-1, 0, 0]\n[[impacts]]\ntarget = "a"\nimpactor = "b"\npoint = [10, 0, 0]\n' >"$tmp/none.toml"
"$bin" run "$tmp/a.toml" --out "$out" >/dev/null 2>&1
IMPACTDECK_TEST_COMMIT_DELAY_MS=100 "$bin" run "$tmp/b.toml" --out "$out" >/dev/null 2>&1 &
pid=$!
for _ in $(seq 1 600); do [ -e "$out/.impactdeck-commit" ] && break; sleep 0.02; done
sleep 0.35
kill -9 "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
journal=no; [ -e "$out/.impactdeck-commit" ] && journal=yes
mixed=$(cd "$out" && ls -A | grep -v '^\.' | sort | xargs sha256sum | sha256sum | cut -c1-16)
[ "$journal" = yes ] || { bad=$((bad+1)); echo "FAILED: the kill inside the renames left no journal"; }
[ "$mixed" != "$old" ] && [ "$mixed" != "$new" ] || { bad=$((bad+1)); echo "FAILED: the kill did not land inside the renames"; }
# (41: the 40 force tables and report.html)
"$bin" run "$tmp/none.toml" --out "$out" >"$tmp/none.out" 2>&1
# 40 tables, their 40 JSON sidecars and the report page
grep -q "killed while replacing its 81 outputs" "$tmp/none.out" || { bad=$((bad+1)); echo "FAILED: the next run did not report the interrupted commit"; }
[ "$(cd "$out" && ls -A | grep -v '^\.' | sort | xargs sha256sum | sha256sum | cut -c1-16)" = "$new" ] ||
  { bad=$((bad+1)); echo "FAILED: the interrupted commit was not finished into run B's complete set"; }
[ -z "$(cd "$out" && ls -A | grep '^\.')" ] || { bad=$((bad+1)); echo "FAILED: leftovers after recovery: $(ls -A "$out" | grep '^\.')"; }

# 3. A kill while ccx runs: ccx (in its own process group, PR_SET_PDEATHSIG) dies with impactdeck,
# nothing is visible in --out, and the next run removes the dead run's staging folder.
if command -v ccx >/dev/null; then
  fem="$tmp/fem"; mkdir -p "$fem"
  sed -e 's/^end_time_s = .*/end_time_s = 2e-2/' -e 's/^time_step_s = .*/time_step_s = 2e-6/' \
    "$src_dir/samples/eccentric_fem.toml" >"$tmp/fem.toml"
  "$bin" run "$tmp/fem.toml" --out "$fem" >/dev/null 2>&1 &
  pid=$!
  ccx_pid=""
  for _ in $(seq 1 1200); do ccx_pid=$(pgrep -P "$pid" | head -n 1); [ -n "$ccx_pid" ] && break; sleep 0.05; done
  if [ -z "$ccx_pid" ]; then bad=$((bad+1)); echo "FAILED: ccx never started"; fi
  sleep 0.3
  kill -9 "$pid" 2>/dev/null; wait "$pid" 2>/dev/null
  gone=no
  for _ in $(seq 1 100); do kill -0 "$ccx_pid" 2>/dev/null || { gone=yes; break; }; sleep 0.02; done
  [ "$gone" = yes ] || { bad=$((bad+1)); echo "FAILED: ccx ($ccx_pid) outlived the killed run"; kill -9 "$ccx_pid"; }
  [ -z "$(ls "$fem")" ] || { bad=$((bad+1)); echo "FAILED: the killed FEM run left visible files: $(ls "$fem")"; }
  ls -A "$fem" | grep -q '^\.impactdeck-stage-' || { bad=$((bad+1)); echo "FAILED: no staging folder of the killed run (did the kill land before ccx?)"; }
  "$bin" run "$tmp/none.toml" --out "$fem" >"$tmp/none2.out" 2>&1
  grep -q "removed 1 staging folder" "$tmp/none2.out" || { bad=$((bad+1)); echo "FAILED: the next run did not remove the stale staging folder"; }
  [ -z "$(ls -A "$fem")" ] || { bad=$((bad+1)); echo "FAILED: leftovers after the next run: $(ls -A "$fem")"; }
  echo "kill_test: ccx ($ccx_pid) died with the killed run: $gone"
fi
echo "kill_test: kill inside the renames left a journal: $journal; finished into run B's set by the next run"
[ "$bad" -eq 0 ] && [ "$kept" -ge 1 ] && echo "kill_test: 1 passed, 0 failed"
