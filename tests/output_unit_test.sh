#!/usr/bin/env bash
# Issue 18 item 4: one length unit across the outputs. The sweep map (.vtp, .pos, CSV) and the FEM
# deck (.msh, .inp, MED, .geo) of the same scene overlay exactly, in the scene's unit by default
# and in the unit --output-length-unit asks for: checked in ParaView's terms (VTK's own readers:
# every sweep point on the deck mesh's boundary surface, same bounding box), in Gmsh's (the gmsh
# command merging the deck's .msh and the sweep's .pos, printing both bounding boxes) and in the
# files' own words (header comments, FieldData, CSV column names, deck.json, JSON keys). The deck
# follows the output unit when it is mm or m; an inch run's deck is mm-t-s (never an inch-based mass
# unit, docs/fem.md "Units"), its mesh then scaled to inches to overlay the sweep. Then the
# solver's side: the same ccx result with the decks in mm-t-s and in SI.
# usage: output_unit_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$(dirname "$0")/check_lib.sh"
scene="$src/tests/data/overlay/box_overlay.toml"

# Refused: an unknown unit is bad input (exit 3), one line, nothing written.
"$bin" run "$scene" --output-length-unit furlong --out "$tmp/bad" >/dev/null 2>"$tmp/bad.err"
check "unknown unit: exit 3" test $? -eq 3
check "unknown unit: one line naming scene and option" \
  grep -q "box_overlay.toml: --output-length-unit: 'furlong' is not a length unit" "$tmp/bad.err"
check "unknown unit: nothing written" test ! -e "$tmp/bad"
"$bin" sweep "$scene" --output-length-unit MM --out "$tmp/bad2" --quiet >/dev/null 2>"$tmp/bad2.err"
check "sweep unknown unit: exit 3" test $? -eq 3
check "sweep unknown unit: nothing written" test ! -e "$tmp/bad2"

for unit in default m in; do
  flag=(); [ "$unit" != default ] && flag=(--output-length-unit "$unit")
  expect=$([ "$unit" = default ] && echo mm || echo "$unit")
  deck_unit=$([ "$expect" = m ] && echo m || echo mm)
  o="$tmp/$unit"
  "$bin" run "$scene" --json --out "$o" "${flag[@]}" >"$o.run.json" 2>"$o.err"
  check "$unit: run exit 0" test $? -eq 0
  "$bin" sweep "$scene" --cloud uniform --count 300 --quiet --json --format csv,vtp,pos,svg --out "$o" "${flag[@]}" \
    >"$o.sweep.json" 2>>"$o.err"
  check "$unit: sweep (uniform) exit 0" test $? -eq 0
  "$bin" sweep "$scene" --cloud vertices --prefix corners --quiet --formats csv,vtp,pos --out "$o" "${flag[@]}" \
    >/dev/null 2>>"$o.err"
  check "$unit: sweep (vertices) exit 0" test $? -eq 0

  # The files' own words.
  python3 - "$o" "$expect" "$deck_unit" <<'PY' || { echo "FAILED: $unit: units stated"; fails=$((fails+1)); }
import json, sys, re
o, su, u = sys.argv[1], sys.argv[2], sys.argv[3]
metres = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254}[u]
run = json.load(open(o + ".run.json")); sw = json.load(open(o + ".sweep.json"))
assert run["output_length_unit"] == su and run["length_unit"] == "mm", run["output_length_unit"]
assert sw["output_length_unit"] == su
deck = json.load(open(o + "/fem_hit/deck.json"))
assert deck["length_unit"] == u, deck["length_unit"]
assert deck["deck_units"] == {"mm": "mm-t-s", "m": "SI"}[u], deck["deck_units"]
for f in ["impact.inp", "impact.comm"]:
    t = open(o + "/fem_hit/" + f).read()
    assert re.search(r"Units: %s, N, s, " % re.escape(u), t), f
assert ("mesh of the target body (%s)" % u) in open(o + "/fem_hit/mesh.inp").read()
geo = open(o + "/fem_hit/mesh.geo").read()
# A mesh part's script is in the deck's length unit, that of the STL it merges (docs/fem.md).
m = re.search(r"^Mesh.ScalingFactor = ([^;]+);", geo, re.M)
assert m and float(m.group(1)) == 1.0 and ("this script is in %s;" % u) in geo, geo[:400]
assert open(o + "/fem_hit/mesh_part.stl").readline() == "solid part coordinates in %s (the deck's length unit)\n" % u
csv = [l for l in open(o + "/sweep_hit.csv") if not l.startswith("#")]
assert csv[0].startswith("index,x_%s,y_%s,z_%s," % (su, su, su)), csv[0]
head = "".join(l for l in open(o + "/sweep_hit.pos") if l.startswith("//"))
assert ("coordinates in %s" % su) in head, head
PY

  # ParaView's side: VTK reads the sweep's .vtp and the deck's mesh (its nodes and tetrahedra
  # from mesh_v22.msh, its boundary surface by vtkDataSetSurfaceFilter); every sweep point lies on
  # that surface to round-off, and the corner sweep spans the mesh's bounding box.
  /usr/bin/python3 - "$o" "$expect" "$deck_unit" <<'PY' || { echo "FAILED: $unit: VTK overlay"; fails=$((fails+1)); }
import sys, math
import vtk
o, u, du = sys.argv[1], sys.argv[2], sys.argv[3]
metres = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "in": 0.0254}[u]
to_sweep = {"m": 1.0, "mm": 1e-3}[du] / metres  # deck unit -> the sweep's
def read_msh22(path):
    lines = open(path).read().split("\n"); i = 0; nodes = {}; tets = []
    while i < len(lines):
        if lines[i] == "$Nodes":
            n = int(lines[i + 1])
            for k in range(n):
                t, x, y, z = lines[i + 2 + k].split()
                nodes[int(t)] = (float(x) * to_sweep, float(y) * to_sweep, float(z) * to_sweep)
            i += n + 2
        elif lines[i] == "$Elements":
            n = int(lines[i + 1])
            for k in range(n):
                f = lines[i + 2 + k].split()
                if f[1] == "4": tets.append([int(v) for v in f[3 + int(f[2]):]])
            i += n + 2
        i += 1
    return nodes, tets
nodes, tets = read_msh22(o + "/fem_hit/mesh_v22.msh")
ids = sorted(nodes); index = {t: k for k, t in enumerate(ids)}
pts = vtk.vtkPoints(); pts.SetDataTypeToDouble()
for t in ids: pts.InsertNextPoint(*nodes[t])
grid = vtk.vtkUnstructuredGrid(); grid.SetPoints(pts)
for t in tets:
    cell = vtk.vtkIdList()
    for v in t: cell.InsertNextId(index[v])
    grid.InsertNextCell(vtk.VTK_TETRA, cell)
surf = vtk.vtkDataSetSurfaceFilter(); surf.SetInputData(grid); surf.Update()
surface = surf.GetOutput()
assert surface.GetNumberOfCells() > 0
loc = vtk.vtkStaticCellLocator(); loc.SetDataSet(surface); loc.BuildLocator()
bounds = surface.GetBounds()
size = max(bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4])
# The box is 200 x 100 x 60 mm: its size in the output unit.
assert abs(size - 0.2 / metres) <= 1e-9 * size, (size, u)
def read_vtp(path):
    r = vtk.vtkXMLPolyDataReader(); r.SetFileName(path); r.Update(); return r.GetOutput()
sweep = read_vtp(o + "/sweep_hit.vtp")
fd = sweep.GetFieldData().GetArray("metres_per_length_unit")
assert fd is not None and fd.GetValue(0) == metres, "FieldData metres_per_length_unit"
worst = 0.0
cp = [0.0] * 3; cid = vtk.reference(0); sub = vtk.reference(0); d2 = vtk.reference(0.0)
for i in range(sweep.GetNumberOfPoints()):
    loc.FindClosestPoint(sweep.GetPoint(i), cp, cid, sub, d2)
    worst = max(worst, math.sqrt(d2.get()))
# Round-off: the part's coordinates pass through a rotation to the world and back, and Gmsh's
# mm, scaled on save; 1e-9 of the size is 10^6 times the double's resolution and 10^-6 of an
# element.
assert sweep.GetNumberOfPoints() >= 200 and worst <= 1e-9 * size, (worst, size)
corners = read_vtp(o + "/corners.vtp").GetBounds()
assert max(abs(a - b) for a, b in zip(corners, bounds)) <= 1e-9 * size, (corners, bounds)
# The CalculiX mesh holds the same nodes as the .msh (same unit).
inp = {}
blk = None
for l in open(o + "/fem_hit/mesh.inp"):
    if l.startswith("*"): blk = l.split(",")[0].strip(); continue
    if blk == "*NODE":
        f = [float(v) for v in l.split(",")]; inp[int(f[0])] = [v * to_sweep for v in f[1:]]
# (numbered apart: ccx's nodes follow the tetrahedra's index, Gmsh's its tags; each .inp node is
# matched to its nearest .msh node, one to one: sorting the two lists pairs them wrongly when two
# nodes mirror each other and their x differ only in digits the .inp's 12 do not keep)
assert len(inp) == len(nodes)
mpts = vtk.vtkPoints(); mpts.SetDataTypeToDouble()
for t in ids: mpts.InsertNextPoint(*nodes[t])
mset = vtk.vtkPolyData(); mset.SetPoints(mpts)
near = vtk.vtkKdTreePointLocator(); near.SetDataSet(mset); near.BuildLocator()
matched = set(); diff = 0.0
for q in inp.values():
    k = near.FindClosestPoint(q)
    matched.add(k)
    diff = max(diff, max(abs(a - b) for a, b in zip(q, nodes[ids[k]])))
assert len(matched) == len(nodes), (len(matched), len(nodes))
assert diff <= 1e-9 * size, diff
print("%s: %d sweep points, farthest from the deck surface %.3g (size %.4g %s); corners' box matches to %.3g"
      % (u, sweep.GetNumberOfPoints(), worst, size, u,
         max(abs(a - b) for a, b in zip(corners, bounds))))
PY

  # Gmsh's side: the gmsh command merges the deck's mesh and the sweep's view and prints both
  # bounding boxes (the view's from its own coordinates).
  cat > "$o/overlay.geo" <<GEO
Merge "fem_hit/mesh.msh";
Printf("mesh %.17g %.17g %.17g %.17g %.17g %.17g", General.MinX, General.MaxX, General.MinY, General.MaxY, General.MinZ, General.MaxZ);
Merge "corners.pos";
Printf("view %.17g %.17g %.17g %.17g %.17g %.17g", View[0].MinX, View[0].MaxX, View[0].MinY, View[0].MaxY, View[0].MinZ, View[0].MaxZ);
GEO
  (cd "$o" && gmsh -nopopup -parse_and_exit overlay.geo) >"$o/gmsh.out" 2>&1
  check "$unit: gmsh merges both" test $? -eq 0
  python3 - "$o/gmsh.out" "$expect" "$deck_unit" <<'PY' || { echo "FAILED: $unit: Gmsh overlay"; cat "$o/gmsh.out"; fails=$((fails+1)); }
import re, sys
t = open(sys.argv[1]).read()
metres = {"m": 1.0, "mm": 1e-3, "in": 0.0254}
to_sweep = metres[sys.argv[3]] / metres[sys.argv[2]]  # deck unit -> the sweep's
m = [float(v) * to_sweep for v in re.search(r"mesh (\S+) (\S+) (\S+) (\S+) (\S+) (\S+)", t).groups()]
v = [float(x) for x in re.search(r"view (\S+) (\S+) (\S+) (\S+) (\S+) (\S+)", t).groups()]
size = max(m[1] - m[0], m[3] - m[2], m[5] - m[4])
assert size > 0 and max(abs(a - b) for a, b in zip(m, v)) <= 1e-9 * size, (m, v)
PY
done

# The same mesh in every unit: the nodes in m are the nodes in mm / 1000; the inch run's deck is
# mm-t-s, the default's nodes.
python3 - "$tmp" <<'PY' || { echo "FAILED: the units agree"; fails=$((fails+1)); }
import sys
def nodes(p):
    t = open(p).read().split("$Nodes\n")[1].split("$EndNodes")[0].split("\n")[1:]
    return [[float(v) for v in l.split()[1:]] for l in t if l.strip()]
mm, m, inch = (nodes(sys.argv[1] + "/%s/fem_hit/mesh_v22.msh" % u) for u in ("default", "m", "in"))
assert len(mm) == len(m) == len(inch)
err = max(max(abs(a / 1000 - b), abs(a - c) / 1000) for p, q, r in zip(mm, m, inch) for a, b, c in zip(p, q, r))
assert err <= 1e-12, err
PY
# The solver sees one consistent unit system whatever the length: the drop sample (a cm scene)
# through ccx with its decks in mm-t-s (the default for a cm scene) and in SI (output unit m)
# gives the same momentum and stresses (ccx's .frd prints 6 significant digits: 1e-5).
if command -v ccx >/dev/null; then
  for u in default m; do
    flag=(); [ "$u" != default ] && flag=(--output-length-unit "$u")
    "$bin" run "$src/samples/drop_test.toml" --json --out "$tmp/drop_$u" "${flag[@]}" >"$tmp/drop_$u.json" 2>/dev/null
    check "drop sample with decks in $u: exit 0" test $? -eq 0
  done
  python3 - "$tmp/drop_default.json" "$tmp/drop_m.json" <<'PY' || { echo "FAILED: the deck's unit changes the FEM result"; fails=$((fails+1)); }
import json, sys
a, b = (json.load(open(p))["impacts"][0]["fem"]["check"] for p in sys.argv[1:])
assert json.load(open(sys.argv[1]))["output_length_unit"] == "cm"
va, vb = (c["stress"]["verdict"]["governing"]["max_von_mises_Pa"] for c in (a, b))
assert a["passed"] and b["passed"]
assert abs(va - vb) <= 1e-5 * va, (va, vb)
assert abs(a["linear_momentum_relative_error"] - b["linear_momentum_relative_error"]) <= 1e-5, (a, b)
assert [json.load(open(p))["impacts"][0]["fem"]["check"]["stress"]["files"][0] for p in sys.argv[1:]]
print("drop sample: peak von Mises %.9g Pa (mm-t-s deck) and %.9g Pa (SI deck)" % (va, vb))
PY
fi
finish output_length_unit
