"""Reads impactdeck's ccx results series with VTK's own XML reader (python3-vtk9).

Usage: read_vtk_series.py DECK_DIR LENGTH_UNIT
VTK 9.1's Python has no .pvd reader (that is ParaView's), so the collection's DataSet entries
are parsed here and every .vtu it names is read by vtkXMLUnstructuredGridReader. Checks: more
than one time step, increasing times, each piece with the mesh, the point data and the units,
TimeValue equal to the .pvd's timestep; prints the number of steps and the largest PE.
"""
import sys
import xml.etree.ElementTree as ET

import vtk

deck, unit = sys.argv[1], sys.argv[2]
sets = ET.parse(deck + "/results.pvd").getroot().find("Collection").findall("DataSet")
times = [float(d.get("timestep")) for d in sets]
assert len(times) > 1, "one time step only"
assert all(b > a for a, b in zip(times, times[1:])), "times do not increase"
largest_pe, points = 0.0, None
for d, t in zip(sets, times):
    r = vtk.vtkXMLUnstructuredGridReader()
    r.SetFileName(deck + "/" + d.get("file"))
    r.Update()
    g = r.GetOutput()
    assert g.GetNumberOfPoints() > 0 and g.GetNumberOfCells() > 0, d.get("file")
    points = points or g.GetNumberOfPoints()
    assert g.GetNumberOfPoints() == points
    pd, fd = g.GetPointData(), g.GetFieldData()
    for name, comps in (("displacement", 3), ("stress", 6), ("von_mises", 1), ("equivalent_plastic_strain", 1)):
        a = pd.GetArray(name)
        assert a is not None and a.GetNumberOfComponents() == comps, name
    assert fd.GetAbstractArray("length_unit").GetValue(0) == unit
    assert abs(fd.GetArray("TimeValue").GetValue(0) - t) <= 1e-9 * t
    largest_pe = max(largest_pe, pd.GetArray("equivalent_plastic_strain").GetRange()[1])
print(len(times), largest_pe)
