"""The compressed .vtu a sweep writes by default, read by meshio (Debian python3-meshio; meshio reads
VTK's UnstructuredGrid, not its PolyData): the points, one vertex cell per point and every
point-data array hold exactly the CSV's numbers (the CSV holds the shortest round-trip text of each
double, so equality is exact).
usage: meshio_reader_test.py DIR (written by sweep_files_fixture)"""
import csv
import os
import sys

try:
    import meshio
    import numpy as np
except ImportError as e:
    sys.exit(f"FAILED: meshio is missing ({e}): install the Debian package python3-meshio")

folder = sys.argv[1]
failures = 0
for name in ["ellipsoid", "cube"]:
    with open(os.path.join(folder, name + ".csv")) as f:
        table = list(csv.reader(line for line in f if not line.startswith("#")))
    head, body = table[0], table[1:]
    col = {h: i for i, h in enumerate(head)}
    n = len(body)

    def column(*names):
        return np.array([[float(r[col[c]]) for c in names] for r in body]).reshape(n, len(names)).squeeze()

    path = os.path.join(folder, name + ".vtu")
    problems = []
    try:
        mesh = meshio.read(path)
    except Exception as e:  # any reader error is the finding
        print(f"FAILED: {path}: meshio cannot read it: {e!r}")
        failures += 1
        continue
    if mesh.points.shape != (n, 3) or not np.array_equal(mesh.points, column("x_m", "y_m", "z_m")):
        problems.append(f"points {mesh.points.shape} differ from the CSV")
    blocks = [(c.type, len(c.data)) for c in mesh.cells]
    if blocks != [("vertex", n)] or not np.array_equal(mesh.cells[0].data.ravel(), np.arange(n)):
        problems.append(f"cells {blocks}: not one vertex per point")
    expected = {
        "max_force_N": ["max_force_N"], "force_ratio": ["force_ratio"], "reduced_mass_kg": ["reduced_mass_kg"],
        "restitution": ["restitution"], "residual_indentation_m": ["residual_indentation_m"],
        "effective_radius_m": ["effective_radius_m"], "target_radius_m": ["target_radius_m"],
        "contact_ellipse_axis_ratio": ["contact_ellipse_axis_ratio"], "sharp_feature": ["sharp_feature"],
        "normal": ["nx", "ny", "nz"],
    }
    if sorted(mesh.point_data) != sorted(list(expected) + ["flag"]):
        problems.append(f"arrays {sorted(mesh.point_data)}")
    for array, columns in expected.items():
        a = mesh.point_data.get(array)
        if a is None or not np.array_equal(np.asarray(a, dtype=float).reshape(column(*columns).shape), column(*columns)):
            problems.append(f"array {array} differs from the CSV")
    flag = mesh.point_data.get("flag")
    words = [r[col["flag"]] for r in body]
    if flag is None or any((int(flag[i]) == 0) != (words[i] == "") for i in range(n)):
        problems.append("array flag disagrees with the CSV's flag words")
    if abs(float(np.ravel(mesh.field_data.get("metres_per_length_unit", [0]))[0]) - 1.0) != 0:
        problems.append("field data metres_per_length_unit is not 1")
    if problems:
        failures += 1
        print(f"FAILED: {path}: " + "; ".join(problems))
    else:
        print(f"ok: {path}: {n} points, {len(expected) + 1} arrays equal to the CSV (meshio {meshio.__version__})")
sys.exit(1 if failures else 0)
