#!/usr/bin/env bash
# End-to-end checks of `impactdeck mesh-ellipsoid` and `impactdeck inspect`: exit codes, the JSON
# keys of docs/geometry.md, one-line errors.  usage: cli_geometry_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$(dirname "$0")/check_lib.sh"

"$bin" mesh-ellipsoid 30 20 10 --subdivisions 5 -o "$tmp/e.stl" >/dev/null
check "mesh-ellipsoid exit 0" test $? -eq 0
check "binary STL size 84 + 50*20480" test "$(stat -c %s "$tmp/e.stl")" -eq $((84 + 50 * 20480))
"$bin" inspect "$tmp/e.stl" --length-unit mm --density-kg-m3 7850 --at 30,0,0 --at 10,10,5 --json >"$tmp/e.json" 2>"$tmp/e.err"
check "inspect exit 0" test $? -eq 0
python3 - "$tmp/e.json" <<'PY' || { echo "FAILED: inspect JSON"; fails=$((fails+1)); }
import json, math, sys
d = json.load(open(sys.argv[1]))
top = ["triangles", "vertices", "shells", "closed", "outward_oriented", "self_intersections", "volume_m3",
       "area_m2", "mass_kg", "center_of_mass_m", "inertia_kg_m2", "principal_moments_kg_m2", "principal_axes"]
per = ["surface_point_m", "normal", "principal_curvatures_1_per_m", "principal_directions", "sharp_feature",
       "curvature_error_estimate_1_per_m"]
missing = [k for k in top if k not in d] + [k for p in d["points"] for k in per if k not in p]
assert not missing, missing
assert d["triangles"] == 20480 and d["closed"] and d["outward_oriented"] and d["self_intersections"] == 0
V = 4 / 3 * math.pi * 0.03 * 0.02 * 0.01
assert abs(d["volume_m3"] - V) / V < 1e-3, d["volume_m3"]
assert abs(d["mass_kg"] - 7850 * V) / (7850 * V) < 1e-3
k1, k2 = d["points"][0]["principal_curvatures_1_per_m"]   # x tip: 30/10^2 mm^-1 and 30/20^2
assert abs(k1 - 300) / 300 < 0.02 and abs(k2 - 75) / 75 < 0.02, (k1, k2)
assert len(d["points"]) == 2 and not d["points"][0]["sharp_feature"]
def walk(x):
    if isinstance(x, float): assert math.isfinite(x)
    elif isinstance(x, dict): [walk(v) for v in x.values()]
    elif isinstance(x, list): [walk(v) for v in x]
walk(d)
assert d["stages_run"] == ["mesh_load", "mesh_validation", "mass_properties", "curvature_index"], d["stages_run"]
assert d["stages_skipped"] == [] and set(d["stage_times_s"]) == set(d["stages_run"])
PY
passes=$((passes+1))
# Without --at no surface index is built; the report is the same otherwise.
"$bin" inspect "$tmp/e.stl" --length-unit mm --density-kg-m3 7850 --json >"$tmp/n.json" 2>/dev/null
check "inspect without --at exit 0" test $? -eq 0
check "no surface index without --at" python3 - "$tmp/e.json" "$tmp/n.json" <<'PY'
import json, sys
a, b = (json.load(open(f)) for f in sys.argv[1:3])
assert b["stages_run"] == ["mesh_load", "mesh_validation", "mass_properties", "sharp_edges"], b["stages_run"]
assert b["stages_skipped"] == ["curvature_index"], b["stages_skipped"]
for k in ["volume_m3", "inertia_kg_m2", "sharp_edges", "mean_edge_length_m", "validation", "self_intersections"]:
    assert a[k] == b[k], k
assert b["points"] == []
PY
"$bin" inspect "$tmp/e.stl" --length-unit mm >"$tmp/h.txt" 2>&1
check "readable report" grep -q "principal moments" "$tmp/h.txt"

# Errors: exit 3, one line naming the file.
"$bin" inspect "$src/tests/data/open_cube.off" --length-unit mm 2>"$tmp/o.err" >/dev/null
check "open mesh exit 3" test $? -eq 3
check "open mesh message" grep -q "open_cube.off: mass properties: the surface is open (4 boundary edges)" "$tmp/o.err"
check "one line" test "$(wc -l <"$tmp/o.err")" -eq 1
"$bin" inspect "$src/tests/data/open_cube.off" --length-unit mm --accept-approximate --json >"$tmp/a.json" 2>/dev/null
check "accepted approximation exit 0" test $? -eq 0
check "marked approximate" grep -q '"mass_properties_approximate": true' "$tmp/a.json"
"$bin" inspect "$src/tests/data/inverted_cube.off" --length-unit mm 2>"$tmp/i.err" >/dev/null
check "inverted exit 3" test $? -eq 3
"$bin" inspect "$src/tests/data/inverted_cube.off" --length-unit mm --repair --json >"$tmp/r.json" 2>/dev/null
check "repair exit 0" test $? -eq 0
check "repairs listed" grep -q "oriented every shell" "$tmp/r.json"
"$bin" inspect "$src/tests/data/testpoints.obj" --length-unit mm 2>"$tmp/p.err" >/dev/null
check "points-only exit 3" test $? -eq 3
"$bin" inspect "$src/tests/data/empty.obj" --length-unit mm 2>"$tmp/z.err" >/dev/null
check "empty exit 3" test $? -eq 3
check "empty message" grep -q "empty.obj: file: is empty (0 bytes)" "$tmp/z.err"
"$bin" inspect "$src/tests/data/cube.off" --length-unit mm --at 1,1,0 --json >"$tmp/c.json" 2>/dev/null
check "sharp edge reported" python3 -c "import json,sys; p=json.load(open('$tmp/c.json'))['points'][0]; sys.exit(0 if p['sharp_feature'] and p['principal_curvatures_1_per_m'] is None else 1)"
"$bin" inspect "$tmp/e.stl" >/dev/null 2>&1; check "missing --length-unit exit 2" test $? -eq 2
"$bin" inspect "$tmp/e.stl" --length-unit furlong >/dev/null 2>&1; check "bad unit exit 2" test $? -eq 2
"$bin" inspect "$tmp/e.stl" --length-unit mm --density-kg-m3 1 --mass-kg 1 >/dev/null 2>&1; check "density xor mass exit 2" test $? -eq 2
"$bin" mesh-ellipsoid 1 -1 1 -o "$tmp/x.stl" 2>/dev/null >/dev/null; check "negative axis exit 3" test $? -eq 3

finish cli_geometry_test
