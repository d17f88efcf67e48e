#!/usr/bin/env bash
# End-to-end checks of the impactdeck CLI: exit codes, JSON keys, files written, errors.
# usage: cli_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
tmp=$(mktemp -d); trap 'rm -rf "$tmp"' EXIT
fails=0; passes=0
check() {  # check NAME CONDITION...
  local name=$1; shift
  if "$@"; then passes=$((passes+1)); else echo "FAILED: $name"; fails=$((fails+1)); fi
}

# 1. The paper sample: exit 0, JSON with the contract keys, CSV written into --out.
"$bin" run "$src/samples/paper_table2.toml" --json --out "$tmp/out" >"$tmp/p.json" 2>"$tmp/p.err"
check "paper sample exit 0" test $? -eq 0
check "paper CSV written" test -s "$tmp/out/force_table2.csv"
python3 - "$tmp/p.json" <<'PY' || { echo "FAILED: JSON keys"; fails=$((fails+1)); }
import json, math, sys
d = json.load(open(sys.argv[1]))
keys = ["reduced_mass_kg", "effective_radius_m", "effective_modulus_Pa", "hertz_constant_N_per_m1_5",
        "approach_velocity_m_s", "energy_flux_density", "restitution", "max_indentation_m",
        "max_force_N", "compression_time_s", "contact_time_s", "impulse_compression_Ns",
        "impulse_total_Ns"]
i = d["impacts"][0]
missing = [k for k in keys if k not in i]
missing += [k for k in ["impulse_relative_error", "energy_relative_error", "passed"] if k not in i["checks"]]
for who in ("target", "impactor"):
    missing += [who + "." + k for k in ["delta_velocity_m_s", "delta_angular_velocity_rad_s"] if k not in i[who]]
missing += [k for k in ["stages_run", "stages_skipped"] if k not in d]
assert not missing, missing
assert i["checks"]["passed"] and i["checks"]["impulse_relative_error"] < 1e-6 and i["checks"]["energy_relative_error"] < 1e-6
def walk(x):
    if isinstance(x, float): assert math.isfinite(x)
    elif isinstance(x, dict): [walk(v) for v in x.values()]
    elif isinstance(x, list): [walk(v) for v in x]
walk(d)
assert "force_table" in d["stages_run"] and "fem_mesh" in d["stages_skipped"]
PY
passes=$((passes+1))
check "paper warns about ln Phi on stderr" grep -q "outside the validity range" "$tmp/p.err"

# 2. Human-readable summary.
"$bin" run "$src/samples/two_spheres.toml" --out "$tmp/out2" >"$tmp/s.txt" 2>&1
check "two spheres exit 0" test $? -eq 0
check "summary mentions max force" grep -q "max force" "$tmp/s.txt"

# 3. Usage errors: exit 2.
"$bin" >/dev/null 2>&1; check "no subcommand exit 2" test $? -eq 2
"$bin" run >/dev/null 2>&1; check "missing scene exit 2" test $? -eq 2
"$bin" run x.toml --bogus >/dev/null 2>&1; check "unknown flag exit 2" test $? -eq 2
"$bin" --help >/dev/null 2>&1; check "--help exit 0" test $? -eq 0

# 4. Invalid input: exit 3, one line naming file, line and key; no output file.
sed 's/youngs_modulus_Pa = 2.05e11/youngs_modulus_Pa = -2.05e11/' "$src/samples/paper_table2.toml" >"$tmp/bad.toml"
"$bin" run "$tmp/bad.toml" --out "$tmp/out3" >"$tmp/bad.out" 2>"$tmp/bad.err"
check "negative modulus exit 3" test $? -eq 3
check "message names the key" grep -q "bad.toml: line 17, key 'materials.steel.youngs_modulus_Pa': must be > 0" "$tmp/bad.err"
check "message is one line" test "$(wc -l <"$tmp/bad.err")" -eq 1
check "no output written" test ! -e "$tmp/out3/force_table2.csv"
"$bin" run "$tmp/does-not-exist.toml" >/dev/null 2>&1; check "missing file exit 3" test $? -eq 3

# 5. A failing self-check: exit 4 and no output file (threshold set impossibly low).
sed 's/^restitution_range_policy = "warn"/restitution_range_policy = "warn"\n[checks]\nimpulse_relative = 1e-300/' \
  "$src/samples/paper_table2.toml" >"$tmp/strict.toml"
"$bin" run "$tmp/strict.toml" --out "$tmp/out4" >/dev/null 2>"$tmp/strict.err"
rc=$?
check "failed check exit 4 (got $rc)" test $rc -eq 4
check "failed check writes nothing" test ! -e "$tmp/out4/force_table2.csv"

echo "cli_end_to_end: $passes passed, $fails failed"
test $fails -eq 0
