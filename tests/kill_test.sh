#!/usr/bin/env bash
# Nothing lost (issue #6): outputs of a successful run survive a run killed with SIGKILL at any
# moment byte for byte; a completed run replaces the whole set. After each kill every file must be
# byte for byte its old or its new version (never partial), and the set must be all old or all new
# unless the commit marker says the kill hit the final renames (then the next run warns).
# usage: kill_test.sh IMPACTDECK
set -u
bin=$1
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
[ "$bad" -eq 0 ] && [ "$kept" -ge 1 ] && echo "kill_test: 1 passed, 0 failed"
