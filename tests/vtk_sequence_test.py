"""The VTK series of a drop sequence read by VTK's own reader (Debian python3-vtk9): every frame the
.pvd names is a valid PolyData with the part's triangles, the times never decrease, and no frame
lies below the floor (z = 0) by more than the contact search's tolerance.
usage: vtk_sequence_test.py OUT_DIR (a run of samples/drop_sequence.toml)"""
import os
import sys
import xml.etree.ElementTree as ET

import vtk

out = sys.argv[1]
pvd = os.path.join(out, "sequence_drop.pvd")
sets = ET.parse(pvd).getroot().find("Collection").findall("DataSet")
assert 2 <= len(sets) <= 120, len(sets)
times = [float(d.get("timestep")) for d in sets]
assert times == sorted(times) and times[0] == 0.0, times[:5]
cells = None
for d in sets:
    r = vtk.vtkXMLPolyDataReader()
    r.SetFileName(os.path.join(out, d.get("file")))
    r.Update()
    o = r.GetOutput()
    assert o.GetNumberOfCells() > 0
    cells = cells or o.GetNumberOfCells()
    assert o.GetNumberOfCells() == cells
    zmin = o.GetBounds()[4]
    assert zmin > -1e-6, (d.get("file"), zmin)  # cm: the part is ~1 cm across
print("ok", len(sets), "frames of", cells, "triangles")
