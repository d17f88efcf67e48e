"""The binary VTK files of a sweep, read by VTK's own XML readers (vtkXMLPolyDataReader and
vtkXMLUnstructuredGridReader, what ParaView and pyvista use; Debian python3-vtk9), hold exactly the
CSV's numbers: every point-data array, the points and the vertex cells, in the raw .vtp with UInt32
and UInt64 block sizes, the zlib-compressed .vtp and the compressed .vtu (a sweep's default file).
usage: vtk_reader_test.py DIR (written by sweep_files_fixture)"""
import csv
import os
import sys

try:
    from vtkmodules.vtkIOXML import vtkXMLPolyDataReader, vtkXMLUnstructuredGridReader
    from vtkmodules.vtkCommonCore import vtkLogger
except ImportError as e:
    sys.exit(f"FAILED: VTK's Python modules are missing ({e}): install the Debian package python3-vtk9")

vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
folder = sys.argv[1]
failures = 0


def rows(path):
    with open(path) as f:
        lines = [line for line in f if not line.startswith("#")]
    table = list(csv.reader(lines))
    return table[0], table[1:]


for name in ["ellipsoid", "cube"]:
    head, body = rows(os.path.join(folder, name + ".csv"))
    col = {h: i for i, h in enumerate(head)}
    # CSV column(s) of each VTP array; the CSV holds the shortest round-trip text of each double.
    expected = {
        "max_force_N": ["max_force_N"], "force_ratio": ["force_ratio"], "reduced_mass_kg": ["reduced_mass_kg"],
        "restitution": ["restitution"], "residual_indentation_m": ["residual_indentation_m"],
        "effective_radius_m": ["effective_radius_m"], "target_radius_m": ["target_radius_m"],
        "contact_ellipse_axis_ratio": ["contact_ellipse_axis_ratio"], "sharp_feature": ["sharp_feature"],
        "normal": ["nx", "ny", "nz"],
    }
    for header in ["_u32.vtp", "_u64.vtp", "_zlib.vtp", ".vtu"]:
        path = os.path.join(folder, name + header)
        reader = vtkXMLUnstructuredGridReader() if header == ".vtu" else vtkXMLPolyDataReader()
        reader.SetFileName(path)
        reader.Update()
        pd = reader.GetOutput()
        problems = []
        if reader.GetErrorCode() != 0:
            problems.append(f"reader error code {reader.GetErrorCode()}")
        n = len(body)
        cells = pd.GetNumberOfCells() if header == ".vtu" else pd.GetNumberOfVerts()
        if pd.GetNumberOfPoints() != n or cells != n:
            problems.append(f"{pd.GetNumberOfPoints()} points, {cells} cells, CSV has {n} rows")
        data = pd.GetPointData()
        names = sorted(data.GetArrayName(i) for i in range(data.GetNumberOfArrays()))
        if names != sorted(list(expected) + ["flag"]):
            problems.append(f"arrays {names}")
        for array, columns in expected.items():
            a = data.GetArray(array)
            if a is None or a.GetNumberOfTuples() != n or a.GetNumberOfComponents() != len(columns):
                problems.append(f"array {array}: missing or wrong shape")
                continue
            bad = [i for i in range(n) if list(a.GetTuple(i)) != [float(body[i][col[c]]) for c in columns]]
            if bad:
                problems.append(f"array {array}: {len(bad)} points differ from the CSV, first {bad[0]}")
        # flag: collision::ContactFlag's number, 0 where the CSV's flag word is empty, 1 for "sharp".
        fl = data.GetArray("flag")
        if fl is None or fl.GetNumberOfTuples() != n:
            problems.append("array flag: missing or wrong shape")
        else:
            words = [body[i][col["flag"]] for i in range(n)]
            bad = [i for i in range(n) if (fl.GetValue(i) == 0) != (words[i] == "")
                   or (fl.GetValue(i) == 1) != (words[i] == "sharp")]
            if bad:
                problems.append(f"array flag: {len(bad)} points disagree with the CSV's flag words, first {bad[0]}")
        points = pd.GetPoints()
        bad = [i for i in range(n)
               if points is None or list(points.GetPoint(i)) != [float(body[i][col[c]]) for c in ["x_m", "y_m", "z_m"]]]
        if bad:
            problems.append(f"points: {len(bad)} differ from the CSV")
        verts = pd.GetCells() if header == ".vtu" else pd.GetVerts()
        cells = [verts.GetOffsetsArray().GetValue(i) for i in range(n + 1)] if verts else []
        ids = [verts.GetConnectivityArray().GetValue(i) for i in range(n)] if verts else []
        if cells != list(range(n + 1)) or ids != list(range(n)):
            problems.append("vertex cells are not one per point")
        if header == ".vtu" and any(pd.GetCellType(i) != 1 for i in range(n)):  # VTK_VERTEX
            problems.append("cells that are not vertices")
        sharp = sum(float(r[col["sharp_feature"]]) for r in body)
        if (name == "cube") != (sharp > 0):
            problems.append(f"{sharp} sharp points")
        if problems:
            failures += 1
            print(f"FAILED: {path}: " + "; ".join(problems))
        else:
            print(f"ok: {path}: {n} points, {len(expected)} arrays equal to the CSV")

sys.exit(1 if failures else 0)
