#!/usr/bin/env bash
# Issue 32 item 2: one unit system per deck folder ([outputs.fem] deck_units, docs/fem.md "Units").
# The drop sample is a cm scene: its deck folder is mm-t-s by default (never a cm-based mass unit),
# and every file in it states that system; SI on request. Checked through ccx: the mass ccx builds
# from the scaled density card is the mesh's, the stresses of the SI and mm-t-s decks agree, and
# the .vtu displacements are the .frd's in the same unit. `files_written` (run --json) lists every
# file the run wrote.
# usage: deck_units_test.sh IMPACTDECK SOURCE_DIR
set -u
bin=$1; src=$2
. "$(dirname "$0")/check_lib.sh"
scene="$src/samples/drop_test.toml"
command -v ccx >/dev/null || { echo "deck_units: ccx not installed: skipped"; exit 77; }

for sys in default SI; do
  set_arg=(); [ "$sys" = SI ] && set_arg=(--set 'outputs.fem.deck_units="SI"')
  "$bin" run "$scene" --json --out "$tmp/$sys" "${set_arg[@]}" >"$tmp/$sys.json" 2>"$tmp/$sys.err"
  rc=$?
  check "$sys: run exit 0 (got $rc: $(tail -3 "$tmp/$sys.err"))" test $rc -eq 0
done

# Every file of the mm-t-s folder states mm-t-s (and the SI folder SI), each in its own way; a
# file the table does not know fails the test, so a new file must say how it states its units.
/usr/bin/python3 - "$tmp" <<'PY' || { echo "FAILED: every file states the deck's system"; fails=$((fails+1)); }
import json, os, re, sys, glob
import vtk
tmp = sys.argv[1]
for run, system, length, stress in (("default", "mm-t-s", "mm", "MPa"), ("SI", "SI", "m", "Pa")):
    d = glob.glob(os.path.join(tmp, run, "fem_*"))
    assert len(d) == 1, d
    d = d[0]
    text = lambda f: open(os.path.join(d, f), encoding="latin-1").read()
    def vtu_fields(f):
        r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(os.path.join(d, f)); r.Update()
        fd = r.GetOutput().GetFieldData()
        s = lambda name: fd.GetAbstractArray(name).GetValue(0)
        return s("unit_system"), s("length_unit"), s("stress_unit"), fd.GetArray("metres_per_length_unit").GetValue(0)
    def vtu(f):
        assert vtu_fields(f) == (system, length, stress, {"mm": 1e-3, "m": 1.0}[length]), (f, vtu_fields(f))
    def header(f):  # the decks' header comment
        assert re.search(r"Units: %s, N, s, .*system %s\)" % (length, re.escape(system)), text(f)), f
    def msh(f):  # the $Comments section
        assert re.search(r"\$Comments\nimpactdeck: node coordinates in %s; deck unit system %s: " % (length, re.escape(system)), text(f)), f
    statements = {
        "mesh.geo": lambda f: re.search(r"the mesh is saved in %s " % length, text(f)) or sys.exit(f),
        "mesh.msh": msh, "mesh_v22.msh": msh,
        # Gmsh's input of mesh.geo, in the deck's length unit like the script.
        "mesh_part.stl": lambda f: text(f).startswith("solid part coordinates in %s (the deck's length unit)\n" % length) or sys.exit(f),
        "mesh.inp": header, "impact.inp": header, "impact.comm": header,
        "mesh.med": lambda f: (b"impactdeck target body, " + system.encode()) in open(os.path.join(d, f), "rb").read() or sys.exit(f),
        "impact.export": lambda f: True,  # file names and CPUs: no quantity with a unit
        "force.csv": lambda f: text(f).startswith("time_s,force_N") or sys.exit(f + ": " + text(f)[:40]),
        "force.csv.json": lambda f: [c["unit"] for c in json.loads(text(f))["columns"]] == ["s", "N"] or sys.exit(f),
        "mesh_quality.json": lambda f: True,  # JSON: SI, the unit in every key's name (docs/cli.md)
        "deck.json": lambda f: (json.loads(text(f))["deck_units"], json.loads(text(f))["length_unit"], json.loads(text(f))["stress_unit"]) == (system, length, stress) or sys.exit(f),
        "impact.dat": lambda f: True, "impact.frd": lambda f: True,  # ccx's own, from the deck's numbers
        "impact.sta": lambda f: True, "impact.cvg": lambda f: True, "impact.12d": lambda f: True,
        "impact.log": lambda f: True,
        "von_mises_history.csv": lambda f: text(f).startswith("time_s,LOAD_von_mises_%s\n" % stress) or sys.exit(f),
        "von_mises_history.csv.json": lambda f: json.loads(text(f))["metadata"]["unit_system"] == system or sys.exit(f),
        "von_mises_peak.vtu": vtu,
        "von_mises_peak.msh": lambda f: text(f).count(", positions in %s (%s)\"" % (length, system)) == 4 or sys.exit(f),
        "von_mises.svg": lambda f: re.search(r"LOAD at \([^)]*\) %s \(contact node\)" % length, text(f)) or sys.exit(f),
        "results.pvd": lambda f: ("unit system %s: lengths and displacements in %s, stresses in %s" % (system, length, stress)) in text(f) or sys.exit(f),
    }
    names = sorted(os.listdir(d))
    for f in names:
        if re.fullmatch(r"results_\d{4}\.vtu", f):
            vtu(f)
            continue
        assert f in statements, "no unit statement known for " + f
        statements[f](f)
    print("%s: %d files state %s" % (run, len(names), system))
PY

# The .inp is in mm for mm-t-s (m for SI), and its density card in t/mm^3 (kg/m^3): ccx's total
# mass (EMAS, kg after the deck's mass unit) is the mesh's own sum of rho V_e. ccx prints it with
# 7 significant digits (E13.6 in ccx 2.20), the .inp's numbers have 12: 1e-6 relative covers both.
python3 - "$tmp" <<'PY' || { echo "FAILED: coordinates and mass in the deck's units"; fails=$((fails+1)); }
import json, sys, glob, os
tmp = sys.argv[1]
kMassRoundOff = 1e-6
for run, per_m, per_kg_m3 in (("default", 1e3, 1e-12), ("SI", 1.0, 1.0)):
    d = glob.glob(os.path.join(tmp, run, "fem_*"))[0]
    deck = json.load(open(os.path.join(d, "deck.json")))
    nodes = {}
    blk = None
    for l in open(os.path.join(d, "mesh.inp")):
        if l.startswith("*"): blk = l.split(",")[0].strip(); continue
        if blk == "*NODE":
            f = [float(v) for v in l.split(",")]; nodes[int(f[0])] = f[1:]
    p = nodes[deck["load_node"]]
    q = [x * per_m for x in deck["load_node_point_m"]]
    assert max(abs(a - b) for a, b in zip(p, q)) <= 1e-9 * max(abs(v) for v in q), (run, p, q)
    inp = open(os.path.join(d, "impact.inp")).read().split("*DENSITY\n")[1].split("\n")[0]
    rho = float(inp.rstrip(","))
    want = deck["density_kg_m3"] * per_kg_m3
    assert abs(rho - want) <= 1e-12 * want, (run, rho, want)
    c = json.load(open(os.path.join(tmp, run + ".json")))["impacts"][0]["fem"]["check"]
    err = abs(c["solver_mass_kg"] - c["fe_mass_kg"]) / c["fe_mass_kg"]
    assert err <= kMassRoundOff, (run, c["solver_mass_kg"], c["fe_mass_kg"])
    print("%s: load node at %s, density card %.6g, ccx mass %.9g kg vs mesh %.9g kg (%.2g)"
          % (run, p, rho, c["solver_mass_kg"], c["fe_mass_kg"], err))
PY

# The same impact in SI and in mm-t-s: the same stresses (Pa after conversion) and momentum. ccx's
# .frd prints 6 significant digits (1.23456E+02) and both decks' increments are alike: 1e-5.
python3 - "$tmp/default.json" "$tmp/SI.json" <<'PY' || { echo "FAILED: SI and mm-t-s give the same stresses"; fails=$((fails+1)); }
import json, sys
kFrdDigits = 1e-5
a, b = (json.load(open(p))["impacts"][0]["fem"]["check"] for p in sys.argv[1:])
va, vb = (c["stress"]["verdict"]["governing"]["max_von_mises_Pa"] for c in (a, b))
assert abs(va - vb) <= kFrdDigits * va, (va, vb)
for pa, pb in zip(a["stress"]["probes"], b["stress"]["probes"]):
    assert abs(pa["max_von_mises_Pa"] - pb["max_von_mises_Pa"]) <= kFrdDigits * pa["max_von_mises_Pa"], (pa, pb)
assert abs(a["linear_momentum_relative_error"] - b["linear_momentum_relative_error"]) <= kFrdDigits
print("peak von Mises %.9g Pa (mm-t-s) and %.9g Pa (SI)" % (va, vb))
PY

# The displacements of the .vtu files are the .frd's, in the unit of the positions (ParaView's
# Warp By Vector at scale 1 is the deformed shape): von_mises_peak.vtu at the governing peak's time,
# and every results_NNNN.vtu at its time. The .vtu writes 9 significant digits of the .frd's 6.
/usr/bin/python3 - "$tmp" <<'PY' || { echo "FAILED: .vtu displacements are the .frd's"; fails=$((fails+1)); }
import glob, json, os, sys, re
import vtk
from vtk.util.numpy_support import vtk_to_numpy
tmp = sys.argv[1]
kVtuDigits = 1e-8
for run, length in (("default", "mm"), ("SI", "m")):
    d = glob.glob(os.path.join(tmp, run, "fem_*"))[0]
    frames = {}  # time -> {node: (ux, uy, uz)} of the .frd's DISP blocks
    t = None; disp = False
    for l in open(os.path.join(d, "impact.frd")):
        if l.startswith("  100C"): t = float(l[12:24]); continue
        if l.startswith(" -4"): disp = l.startswith(" -4  DISP"); continue
        if l.startswith(" -3"): disp = False; continue
        if disp and l.startswith(" -1"):
            frames.setdefault(t, {})[int(l[3:13])] = [float(l[13 + 12 * k:25 + 12 * k]) for k in range(3)]
    def read(f):
        r = vtk.vtkXMLUnstructuredGridReader(); r.SetFileName(os.path.join(d, f)); r.Update(); return r.GetOutput()
    def compare(grid, name, time):
        u = vtk_to_numpy(grid.GetPointData().GetArray(name))
        ref = frames[time]
        scale = max(max(abs(x) for x in v) for v in ref.values())
        assert scale > 0
        worst = max(abs(u[n - 1][k] - ref[n][k]) for n in ref for k in range(3))
        assert worst <= kVtuDigits * scale, (run, name, time, worst, scale)
        return scale
    c = json.load(open(os.path.join(tmp, run + ".json")))["impacts"][0]["fem"]["check"]["stress"]
    peak = c["peak_field_time_s"]
    tp = min(frames, key=lambda x: abs(x - peak))
    scale = compare(read("von_mises_peak.vtu"), "displacement_at_peak_" + length, tp)
    pvd = open(os.path.join(d, "results.pvd")).read()
    pieces = re.findall(r'timestep="([^"]+)" group="" part="0" file="([^"]+)"', pvd)
    assert len(pieces) >= 2
    for time, f in pieces:
        compare(read(f), "displacement", min(frames, key=lambda x: abs(x - float(time))))
    print("%s: displacements of von_mises_peak.vtu and %d frames equal the .frd's (largest %.4g %s at the peak)"
          % (run, len(pieces), scale, length))
PY

# The part's STL and mesh.geo are in the deck's length unit: the STL's bounding box is mesh.inp's
# (the mesh's boundary lies on the part: kOnPart of its size, the remeshed surface's chordal
# error), and Gmsh meshes the script (a copy, outside the output folder) into a mesh of the same
# part in that unit, within kGeoTets of mesh.msh's tetrahedron count (Gmsh's tolerances are not all
# relative: the script in m is not the run's mesh in mm element for element; docs/fem.md).
/usr/bin/python3 - "$tmp" <<'PY' || { echo "FAILED: the part STL and mesh.geo in the deck's unit"; fails=$((fails+1)); }
import glob, os, re, shutil, subprocess, sys
tmp = sys.argv[1]
kOnPart, kGeoTets = 0.01, 0.10
def bbox(points):
    return [min(p[k] for p in points) for k in range(3)], [max(p[k] for p in points) for k in range(3)]
def msh_tets_and_box(f):
    text = open(f).read()
    nodes = text.split("$Nodes\n")[1].split("$EndNodes")[0].split("\n")
    pts = [[float(v) for v in l.split()[1:4]] for l in nodes[1:] if len(l.split()) == 4]
    elems = text.split("$Elements\n")[1].split("$EndElements")[0].split("\n")
    tets = sum(1 for l in elems[1:] if len(l.split()) > 1 and l.split()[1] == "4")
    return tets, bbox(pts)
for run in ("default", "SI"):
    d = glob.glob(os.path.join(tmp, run, "fem_*"))[0]
    stl = [[float(v) for v in l.split()[1:]] for l in open(os.path.join(d, "mesh_part.stl")) if l.strip().startswith("vertex")]
    lo, hi = bbox(stl)
    size = max(b - a for a, b in zip(lo, hi))
    tets, (mlo, mhi) = msh_tets_and_box(os.path.join(d, "mesh_v22.msh"))
    assert max(abs(a - b) for a, b in zip(lo + hi, mlo + mhi)) <= kOnPart * size, (run, lo, hi, mlo, mhi)
    work = os.path.join(tmp, run + "_geo")
    os.makedirs(work)
    for f in ("mesh.geo", "mesh_part.stl"): shutil.copy(os.path.join(d, f), work)
    r = subprocess.run(["gmsh", "-nopopup", "-3", "-format", "msh22", "-o", "geo.msh", "mesh.geo"], cwd=work, capture_output=True, text=True)
    assert r.returncode == 0, r.stdout[-500:] + r.stderr[-500:]
    gtets, (glo, ghi) = msh_tets_and_box(os.path.join(work, "geo.msh"))
    assert abs(gtets - tets) <= kGeoTets * tets, (run, gtets, tets)
    assert max(abs(a - b) for a, b in zip(glo + ghi, mlo + mhi)) <= kOnPart * size, (run, glo, ghi, mlo, mhi)
    print("%s: mesh_part.stl spans %.6g (deck unit), mesh.geo meshes %d tets (mesh.msh %d)" % (run, size, gtets, tets))
PY

# The report's stress picture is drawn in the deck's frame: its axes are the deck's, in its length
# unit, and its caption says so.
for pair in "default mm" "SI m"; do
  set -- $pair
  check "$1: the stress picture names the deck's axes in $2" grep -q "deck axes x y z ($2)" "$tmp/$1/report.html"
  check "$1: its caption names the deck's frame" grep -q "in the deck&#39;s frame (the target&#39;s own axes x y z, as in mesh.inp, lengths in $2)" "$tmp/$1/report.html"
done

# files_written lists every file the run wrote, once.
python3 - "$tmp" <<'PY' || { echo "FAILED: files_written is complete"; fails=$((fails+1)); }
import json, os, sys
tmp = sys.argv[1]
for run in ("default", "SI"):
    listed = json.load(open(os.path.join(tmp, run + ".json")))["files_written"]
    assert len(listed) == len(set(listed)), [f for f in listed if listed.count(f) > 1]
    out = os.path.join(tmp, run)
    found = sorted(os.path.relpath(os.path.join(r, f), out) for r, _, fs in os.walk(out) for f in fs)
    rel = sorted(os.path.relpath(f, out) for f in listed)
    assert rel == found, ("not listed: %s; listed, not there: %s" % (sorted(set(found) - set(rel)), sorted(set(rel) - set(found))))
    print("%s: files_written names all %d files" % (run, len(found)))
PY
finish deck_units
