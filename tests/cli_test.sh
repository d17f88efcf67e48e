#!/usr/bin/env bash
# End-to-end checks of the impactdeck CLI: exit codes, JSON keys, files written, errors.
# usage: cli_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$(dirname "$0")/check_lib.sh"

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

# 2b. The bottle drop sample (issue 12): OCCT's bottle (a B-rep) dropped tilted on a floor, first
# contact on the bottle's lowest point. Checked: the contact lies on the risen floor with the
# floor's normal, both self-checks pass, the jump of the bottle is upwards, the plastic law runs, and
# the validity block flags this hit (a 2.5 mm fillet) with warnings.
"$bin" run "$src/samples/drop_bottle.toml" --json --out "$tmp/drop" >"$tmp/drop.json" 2>"$tmp/drop.err"
check "drop-test sample exit 0" test $? -eq 0
check "drop-test force table written" test -s "$tmp/drop/force_drop.csv"
python3 - "$tmp/drop.json" "$tmp/drop.err" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
i = j["impacts"][0]
assert i["contact_mode"] == "first-contact", i["contact_mode"]
# The floor (z = 0) travels along the relative velocity (-0.3, 0, 3.13)/|v| until it touches the
# bottle where it hangs: the contact lies at the floor's risen height.
rise = i["travel_m"] * 3.13 / (0.3 ** 2 + 3.13 ** 2) ** 0.5
assert abs(i["contact_point_m"][2] - rise) < 1e-9, (i["contact_point_m"], rise)
assert abs(i["contact_normal"][2] + 1) < 1e-12, i["contact_normal"]
assert i["checks"]["passed"]
assert i["target"]["delta_velocity_m_s"][2] > 0
# The steel yields far below this speed: "auto" runs Jackson - Green's law with Sneddon's unloading,
# which leaves a dent and its own restitution (docs/plastic.md); the fillet is small against the
# contact (validity flagged).
assert i["contact_law"] == "jackson-green-sneddon" and i["contact_law_requested"] == "auto", i["contact_law"]
assert i["approach_velocity_m_s"] > 100 * i["yield_velocity_m_s"], i["yield_velocity_m_s"]
assert i["residual_indentation_m"] > 0 and 0 < i["restitution"] < 1, (i["residual_indentation_m"], i["restitution"])
assert not i["validity"]["ok"] and i["validity"]["contact_law"] == "jackson-green-sneddon", i["validity"]
assert "validity of the jackson-green-sneddon law" in open(sys.argv[2]).read()
PY
check "drop-test JSON: first contact on the floor, checks, validity flagged" test $? -eq 0

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

# 5. A failing self-check: exit 4, and the outputs published as its evidence (threshold set
# impossibly low; tests/cli_evidence_test.sh has the rest).
sed 's/^restitution_range_policy = "warn"/restitution_range_policy = "warn"\n[checks]\nimpulse_relative = 1e-30/' \
  "$src/samples/paper_table2.toml" >"$tmp/strict.toml"
"$bin" run "$tmp/strict.toml" --out "$tmp/out4" >"$tmp/strict.out" 2>"$tmp/strict.err"
rc=$?
check "failed check exit 4 (got $rc)" test $rc -eq 4
check "failed check publishes the evidence" test -s "$tmp/out4/force_table2.csv" -a -s "$tmp/out4/report.html"
check "failed check: the report says FAILED first" grep -q "^FAILED: " <(sed -n 2p "$tmp/strict.out")

# 6. Sweep: files, JSON summary, quiet progress, errors.
# The files of earlier versions, one flag away (--format csv,vtp,pos,svg,png).
"$bin" sweep "$src/samples/fig4_sweep.toml" --out "$tmp/sw" --json --quiet --format csv,vtp,pos,svg,png --no-png >"$tmp/sw.json" 2>"$tmp/sw.err"
check "sweep exit 0" test $? -eq 0
for f in sweep_fig4.csv sweep_fig4.pos sweep_fig4.vtp sweep_fig4.svg; do
  check "sweep wrote $f" test -s "$tmp/sw/$f"
done
check "sweep --no-png writes no PNG" test ! -e "$tmp/sw/sweep_fig4.png"
# By default: the compressed VTK file and the picture's SVG, nothing else.
"$bin" sweep "$src/samples/fig4_sweep.toml" --out "$tmp/swd" --quiet >/dev/null 2>&1
check "sweep default exit 0" test $? -eq 0
check "sweep writes the .vtu and the .svg by default" test "$(ls "$tmp/swd" | tr '\n' ' ')" = "sweep_fig4.svg sweep_fig4.vtu "
check "sweep's default .vtu is zlib-compressed" grep -q 'compressor="vtkZLibDataCompressor"' "$tmp/swd/sweep_fig4.vtu"
# --format: an unknown name, an empty list or an empty name exit 3 with one line naming the flag and
# the formats known, and nothing written (not even the folder).
for bad in "csv,stl" "" "vtu,,csv"; do
  "$bin" sweep "$src/samples/fig4_sweep.toml" --out "$tmp/swbad" --quiet --format "$bad" >/dev/null 2>"$tmp/swbad.err"
  rc=$?
  check "sweep --format '$bad' exit 3 (got $rc)" test $rc -eq 3
  check "sweep --format '$bad': one line naming the flag and the formats" \
    test "$(wc -l <"$tmp/swbad.err")" -eq 1 -a -n "$(grep -- "--format" "$tmp/swbad.err" | grep "csv, vtp, pos, svg, png, vtu or all")"
  check "sweep --format '$bad': nothing written" test ! -e "$tmp/swbad"
done
"$bin" sweep "$src/samples/fig4_sweep.toml" --out "$tmp/swf" --quiet --formats png,csv >/dev/null 2>&1
check "sweep --formats png,csv exit 0" test $? -eq 0
check "sweep --formats writes what it lists" test "$(ls "$tmp/swf" | tr '\n' ' ')" = "sweep_fig4.csv sweep_fig4.csv.json sweep_fig4.png "
"$bin" sweep "$src/samples/fig4_sweep.toml" --out "$tmp/swg" --quiet --formats csv,stl >/dev/null 2>"$tmp/swg.err"
check "sweep --formats with an unknown name exit 2" test $? -eq 2
check "sweep --formats names it" grep -q "'stl' is not one of csv, vtp, pos, svg, png" "$tmp/swg.err"
check "sweep stderr silent (not a tty)" test ! -s "$tmp/sw.err"
python3 - "$tmp/sw.json" <<'PY' || { echo "FAILED: sweep JSON"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
assert d["points"] == 390, d["points"]
assert 0 < d["force_ratio"] <= 1
assert d["min"]["max_force_N"] <= d["max"]["max_force_N"]
assert abs(d["min"]["max_force_N"] / d["max"]["max_force_N"] - d["force_ratio"]) < 1e-12
# The stages that ran, in order, with their wall times (an analytic target: no mesh stages).
assert d["stages_run"] == ["scene", "cloud", "sweep", "write_outputs"], d["stages_run"]
assert set(d["stage_times_s"]) == set(d["stages_run"]) and all(t >= 0 for t in d["stage_times_s"].values())
assert d["stage_times_s"]["sweep"] >= d["seconds"] * 0.5
assert [f.rsplit("/", 1)[1] for f in d["files_written"]] == ["sweep_fig4.csv", "sweep_fig4.csv.json", "sweep_fig4.pos", "sweep_fig4.vtp", "sweep_fig4.svg"], d["files_written"]
PY

# 5b. A sweep with Thornton's plastic law on a real part (issue 30): CGAL's aluminium handle of
# samples/drop_test.toml hit by the floor at 300 points; maps of F_max, restitution and the dent,
# and the law's F(t) curves.
"$bin" sweep "$src/samples/drop_test.toml" --set 'impacts[0].contact_law="thornton"' --cloud uniform --count 300 \
  --curves --curve-samples 21 --format csv,pos --quiet --json --out "$tmp/swt" >"$tmp/swt.json" 2>"$tmp/swt.err"
rc=$?
check "thornton sweep on a real part exit 0 (got $rc: $(tail -1 "$tmp/swt.err"))" test $rc -eq 0
python3 - "$tmp/swt.json" "$tmp/swt" <<'PY' || { echo "FAILED: thornton sweep"; fails=$((fails+1)); }
import csv, json, sys
d = json.load(open(sys.argv[1]))
assert d["contact_law"] == "thornton", d["contact_law"]
rows = [r for r in csv.DictReader(l for l in open(sys.argv[2] + "/sweep_drop.csv") if not l.startswith("#"))]
ok = [r for r in rows if r["flag"] == ""]
assert len(rows) == 300 and ok, (len(rows), len(ok))
# Every valid point: 0 < R <= 1 and a dent >= 0; where the hit is beyond V_y the part dents and rebounds less.
for r in ok:
    R, dent = float(r["restitution"]), float(r["residual_indentation_m"])
    assert 0 < R <= 1 and dent >= 0, r
    assert (dent > 0) == (R < 1), r
assert any(float(r["residual_indentation_m"]) > 0 for r in ok)
views = [l for l in open(sys.argv[2] + "/sweep_drop.pos") if l.startswith("View")]
assert any('"restitution"' in v for v in views) and any('"residual_indentation_m"' in v for v in views), views
assert json.load(open(sys.argv[2] + "/sweep_drop.csv.json"))["metadata"]["contact_law"] == "thornton"
curves = [l for l in open(sys.argv[2] + "/sweep_drop_curves.csv") if not l.startswith("#")]
assert len(curves) == 1 + 21 * len(ok), len(curves)
PY
passes=$((passes+1))
"$bin" sweep "$src/samples/fig4_sweep.toml" --impact nope --out "$tmp/sw2" >/dev/null 2>"$tmp/sw2.err"
check "sweep unknown impact exit 3" test $? -eq 3
check "sweep error names the impact" grep -q "no impact named 'nope'" "$tmp/sw2.err"
"$bin" sweep "$src/samples/fig4_sweep.toml" --cloud bogus >/dev/null 2>&1
check "sweep bad --cloud exit 2" test $? -eq 2

# 7. Study table1: JSON rows g, columns mu; the paper preset meets the acceptance figures.
"$bin" study table1 --preset paper --json --quiet --no-png --out "$tmp/t1" >"$tmp/t1.json"
check "table1 exit 0" test $? -eq 0
check "table1 wrote csv, md, svg" test -s "$tmp/t1/table1.csv" -a -s "$tmp/t1/table1.md" -a -s "$tmp/t1/table1_heatmap.svg"
python3 - "$tmp/t1.json" <<'PY' || { echo "FAILED: table1 JSON"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
g, mu, r = d["geometric_ratios"], d["mass_ratios"], d["collision_force_ratio"]
assert len(g) == 9 and len(mu) == 9 and len(r) == 9 and all(len(row) == 9 for row in r)
assert g[0] == 1e-4 and g[-1] == 1e4
assert d["agreement"]["mean_abs_delta"] <= 0.002 and d["agreement"]["max_abs_delta"] <= 0.005
assert r[8][0] < 0.3 and r[0][8] > 0.99   # rows g: g = 1e4 is curvature-dominated; g = 1e-4, mu = 1e4 ~ 1
PY
passes=$((passes+1))
"$bin" study table1 --preset nope >/dev/null 2>"$tmp/t1b.err"
check "unknown preset exit 3" test $? -eq 3
"$bin" study table1 --mass-ratios 1,abc >/dev/null 2>&1
check "bad list exit 2" test $? -eq 2

# 8. Study table1 on a scene's own target and impactor: the JSON keys, no paper comparison.
"$bin" study table1 --scene "$src/samples/fig4_sweep.toml" --geometric-ratios 1,4 --mass-ratios 0.1,10 \
  --json --quiet --no-png --out "$tmp/t1s" >"$tmp/t1s.json"
check "table1 --scene exit 0" test $? -eq 0
check "table1 --scene wrote csv, md, svg" test -s "$tmp/t1s/table1.csv" -a -s "$tmp/t1s/table1.md" -a -s "$tmp/t1s/table1_heatmap.svg"
check "table1 --scene says there is no paper comparison" grep -q "No comparison with the paper" "$tmp/t1s/table1.md"
python3 - "$tmp/t1s.json" <<'PY' || { echo "FAILED: table1 --scene JSON"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
g, mu, r = d["geometric_ratios"], d["mass_ratios"], d["collision_force_ratio"]
assert g == [1, 4] and mu == [0.1, 10] and len(r) == 2 and all(len(row) == 2 for row in r)
assert all(0 < x <= 1 for row in r for x in row)
assert "delta" not in d and "paper_comparison" in d
assert d["scene"]["stretch_axis"] == "x" and d["scene"]["impact"] == "fig4" and d["sharp_points"] == [0, 0]
PY
passes=$((passes+1))

# 9. Sweep over a cube's vertices and faces: corners flagged, counted, left out.
"$bin" sweep "$src/tests/data/bad/scenes/mesh_sharp_edge.toml" --cloud uniform --count 100 --json --quiet --format csv,vtu \
  --out "$tmp/sh" >"$tmp/sh.json"
check "sweep on a cube exit 0" test $? -eq 0
python3 - "$tmp/sh.json" "$tmp/sh/sweep_impact1.csv" <<'PY' || { echo "FAILED: sweep on a cube"; fails=$((fails+1)); }
import json, sys
d = json.load(open(sys.argv[1]))
assert d["sharp_points"] == 0 and d["points"] == 100
rows = [l for l in open(sys.argv[2]) if not l.startswith("#")]
head = rows[0].strip().split(",")
assert head[-3:] == ["contact_ellipse_axis_ratio", "sharp_feature", "flag"], head[-3:]
assert all(l.rstrip("\n").endswith(",0,") for l in rows[1:])
assert d["flagged_points"] == 0 and d["flag_counts"]["sharp"] == 0
PY
passes=$((passes+1))
"$bin" sweep "$src/tests/data/bad/scenes/mesh_sharp_edge.toml" --cloud vertices --quiet --no-png --out "$tmp/sh2" \
  >/dev/null 2>"$tmp/sh2.err"
check "sweep with every point on a corner exit 3" test $? -eq 3
check "sweep names the sharp points" grep -q "all 8 points of the cloud are flagged (8 sharp)" "$tmp/sh2.err"

finish cli_end_to_end
