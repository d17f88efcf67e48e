#!/usr/bin/env bash
# Concurrent runs into one --out (issue 14): each stages into its own folder and publishes under
# flock(2), so both succeed and never corrupt each other: two FEM runs with ccx into one folder
# (they used to crash ccx with signal 11 and leave .fem_*.old-PID folders), then ten pairs of
# plain runs racing on the same file names.
# usage: concurrency_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$(dirname "$0")/check_lib.sh"
out="$tmp/out"

# 1. Two FEM runs with ccx at once (the eccentric sample, shortened): both exit 0, the deck that
# stays is complete and its results pass the momentum check again, nothing else is left.
sed -e 's/^end_time_s = .*/end_time_s = 5e-4/' "$src/samples/eccentric_fem.toml" >"$tmp/fem.toml"
"$bin" run "$tmp/fem.toml" --out "$out" >"$tmp/a.out" 2>"$tmp/a.err" &
a=$!
"$bin" run "$tmp/fem.toml" --out "$out" >"$tmp/b.out" 2>"$tmp/b.err" &
b=$!
wait "$a"; ra=$?
wait "$b"; rb=$?
check "first FEM run exit 0 (got $ra: $(tail -2 "$tmp/a.err"))" test "$ra" -eq 0
check "second FEM run exit 0 (got $rb: $(tail -2 "$tmp/b.err"))" test "$rb" -eq 0
check "one deck folder and the report, nothing else: $(ls -A "$out" | tr '\n' ' ')" test "$(ls -A "$out" | tr '\n' ' ')" = "fem_eccentric report.html "
check "the deck holds ccx's results" test -s "$out/fem_eccentric/impact.dat" -a -s "$out/fem_eccentric/deck.json"
"$bin" fem-check "$out/fem_eccentric" --no-run >/dev/null 2>"$tmp/check.err"
check "the published deck's results pass the momentum check ($(cat "$tmp/check.err"))" test $? -eq 0

# 2. Ten pairs of runs writing the same force table: each file is one run's, whole.
plain="$tmp/plain"
for i in $(seq 1 10); do
  "$bin" run "$src/samples/two_spheres.toml" --out "$plain" >/dev/null 2>"$tmp/p1.err" &
  p1=$!
  "$bin" run "$src/samples/two_spheres.toml" --out "$plain" >/dev/null 2>"$tmp/p2.err" &
  p2=$!
  wait "$p1"; r1=$?
  wait "$p2"; r2=$?
  if [ "$r1" -ne 0 ] || [ "$r2" -ne 0 ]; then
    # What the failing run said (one of ten pairs failed once in a sanitizer CI run, exit 3 0,
    # with its stderr thrown away; not reproduced in 590 tries since).
    echo "FAILED: pair $i exit $r1 $r2: $(grep -h 'error' "$tmp/p1.err" "$tmp/p2.err" | head -2)"
    fails=$((fails+1))
  fi
done
check "only the force table, its sidecar and the report are left: $(ls -A "$plain" | tr '\n' ' ')" \
  test "$(ls -A "$plain" | tr '\n' ' ')" = "force_two_spheres.csv force_two_spheres.csv.json report.html "
"$bin" run "$src/samples/two_spheres.toml" --out "$tmp/alone" >/dev/null 2>&1
check "the raced file equals a lone run's byte for byte" cmp -s "$plain/force_two_spheres.csv" "$tmp/alone/force_two_spheres.csv"
finish concurrency_test
