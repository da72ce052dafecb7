"""SDFCage: vtkCageDeformationFilter from /usr/bin/python3 (ParaView's VTK).

Cage = a coarse sphere, input = a finer sphere inside it (and an unstructured grid); the
deformed cage comes from vtkTransformFilter / vtkWarpVector, as a user would make it.

Run: PYTHONPATH=<build>/lib/python3/dist-packages /usr/bin/python3 TestCageDeformationPython.py
"""
import math

import numpy as np
import vtk
from vtk.util.numpy_support import vtk_to_numpy

import sdfcage


class Events(object):
    """Collects VTK error or warning events so that expected ones do not reach the output window."""

    CallDataType = vtk.VTK_STRING

    def __init__(self, event, *objects):
        self.messages = []
        for obj in objects:
            obj.AddObserver(event, self)

    def __call__(self, caller, event, calldata=None):
        self.messages.append(str(calldata))


def check(condition, message):
    if not condition:
        raise AssertionError(message)
    print("ok:", message)


def sphere(radius, resolution):
    s = vtk.vtkSphereSource()
    s.SetRadius(radius)
    s.SetThetaResolution(resolution)
    s.SetPhiResolution(resolution)
    s.SetOutputPointsPrecision(vtk.vtkAlgorithm.DOUBLE_PRECISION)  # the output keeps the input's type
    s.Update()
    return s


def points(data):
    return vtk_to_numpy(data.GetPoints().GetData()).astype(float)


def transform(source, matrix, translation):
    t = vtk.vtkTransform()
    m = vtk.vtkMatrix4x4()
    for i in range(3):
        for j in range(3):
            m.SetElement(i, j, matrix[i][j])
        m.SetElement(i, 3, translation[i])
    t.SetMatrix(m)
    f = vtk.vtkTransformFilter()
    f.SetTransform(t)
    f.SetOutputPointsPrecision(vtk.vtkAlgorithm.DOUBLE_PRECISION)
    f.SetInputConnection(source.GetOutputPort())
    f.Update()
    return f, t


def test_reproduction_and_maps():
    cage = sphere(1.0, 12)  # 12 x 12: 132 points, a closed triangle mesh
    mesh = sphere(0.6, 24)
    x = points(mesh.GetOutput())
    diag = 2.0 * math.sqrt(3.0)
    for kind in ("MeanValue", "Green"):
        f = sdfcage.vtkCageDeformationFilter()
        getattr(f, "SetCoordinatesTo" + kind)()
        f.SetInputConnection(mesh.GetOutputPort())
        f.SetRestCageConnection(cage.GetOutputPort())
        f.SetDeformedCageConnection(cage.GetOutputPort())
        errors = Events("ErrorEvent", f, f.GetExecutive())
        f.Update()
        check(not errors.messages and f.GetStatusString() == "Ok", "%s: rest = deformed runs" % kind)
        out = f.GetOutput()
        check(out.IsA("vtkPolyData") and out.GetNumberOfCells() == mesh.GetOutput().GetNumberOfCells(),
              "%s: the output is the input's type and cells" % kind)
        err = np.abs(points(out) - x).max()
        check(err < 1e-9 * diag, "%s: rest = deformed reproduces the input (%.2g)" % (kind, err))
        check(f.GetWeightsRecomputed() and f.GetNumberOfPointsOutside() == 0, "%s: weights computed, none outside" % kind)
        check(f.GetReproductionError() < 1e-9, "%s: ReproductionError %.2g" % (kind, f.GetReproductionError()))
        loc = out.GetPointData().GetArray("CageLocation")
        check(loc is not None and vtk_to_numpy(loc).max() == 0, "%s: CageLocation all inside" % kind)
        check(out.GetFieldData().GetAbstractArray("CageCoordinates").GetValue(0) == kind,
              "%s: field data CageCoordinates" % kind)

        # the deformed cage from a transform: MVC reproduces an affine map, Green a similarity
        if kind == "MeanValue":
            a = [[1.3, 0.4, -0.2], [0.1, 0.7, 0.5], [-0.3, 0.2, 1.6]]
        else:
            c, s = math.cos(0.6), math.sin(0.6)
            a = [[1.5 * c, -1.5 * s, 0.0], [1.5 * s, 1.5 * c, 0.0], [0.0, 0.0, 1.5]]
        t = [0.5, -1.0, 2.0]
        moved, _ = transform(cage, a, t)
        f.SetDeformedCageConnection(moved.GetOutputPort())
        f.Update()
        check(not f.GetWeightsRecomputed(), "%s: moving the cage keeps the weights" % kind)
        expected = x @ np.array(a).T + np.array(t)
        err = np.abs(points(f.GetOutput()) - expected).max()
        check(err < 1e-9 * diag, "%s: the cage's %s map is reproduced (%.2g)" %
              (kind, "affine" if kind == "MeanValue" else "similarity", err))
        check(f.GetApplyTime() < 1.0, "%s: apply took %.4f s" % (kind, f.GetApplyTime()))

        # changing the input recomputes the weights
        mesh.SetRadius(0.5)
        mesh.Update()
        f.Update()
        check(f.GetWeightsRecomputed(), "%s: a modified input recomputes the weights" % kind)
        mesh.SetRadius(0.6)
        mesh.Update()


def test_single_precision():
    cage = sphere(1.0, 12)
    mesh = sphere(0.6, 24)
    x = points(mesh.GetOutput())
    c, s = math.cos(0.6), math.sin(0.6)
    a = [[1.5 * c, -1.5 * s, 0.0], [1.5 * s, 1.5 * c, 0.0], [0.0, 0.0, 1.5]]
    moved, _ = transform(cage, a, [0.5, -1.0, 2.0])
    expected = x @ np.array(a).T + np.array([0.5, -1.0, 2.0])
    for kind in ("MeanValue", "Green"):
        f = sdfcage.vtkCageDeformationFilter()
        getattr(f, "SetCoordinatesTo" + kind)()
        check(not f.GetSinglePrecisionWeights(), "%s: SinglePrecisionWeights off by default" % kind)
        f.SinglePrecisionWeightsOn()
        f.SetInputConnection(mesh.GetOutputPort())
        f.SetRestCageConnection(cage.GetOutputPort())
        f.SetDeformedCageConnection(cage.GetOutputPort())
        f.Update()
        err = np.abs(points(f.GetOutput()) - x).max()
        check(err < 1e-12, "%s single: rest = deformed still reproduces the input (%.2g)" % (kind, err))
        f.SetDeformedCageConnection(moved.GetOutputPort())
        f.Update()
        check(not f.GetWeightsRecomputed(), "%s single: moving the cage keeps the weights" % kind)
        err = np.abs(points(f.GetOutput()) - expected).max()
        check(err < 1e-5, "%s single: a similarity to %.2g" % (kind, err))
        f.SinglePrecisionWeightsOff()
        f.Update()
        check(f.GetWeightsRecomputed(), "%s: switching the precision recomputes the weights" % kind)


def test_green_is_not_mvc_and_finite():
    cage = sphere(1.0, 12)
    mesh = sphere(0.8, 24)
    # bend: warp the cage with a displacement that grows along x
    calc = vtk.vtkArrayCalculator()
    calc.SetInputConnection(cage.GetOutputPort())
    calc.AddCoordinateScalarVariable("x", 0)
    calc.SetFunction("(x*x)*jHat*0.6")
    calc.SetResultArrayName("d")
    warp = vtk.vtkWarpVector()
    warp.SetInputConnection(calc.GetOutputPort())
    warp.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, "d")
    warp.Update()
    results = {}
    for kind in ("MeanValue", "Green"):
        f = sdfcage.vtkCageDeformationFilter()
        getattr(f, "SetCoordinatesTo" + kind)()
        f.SetInputConnection(mesh.GetOutputPort())
        f.SetRestCageConnection(cage.GetOutputPort())
        f.SetDeformedCageConnection(warp.GetOutputPort())
        f.Update()
        out = points(f.GetOutput())
        check(np.isfinite(out).all(), "%s: bent output finite" % kind)
        results[kind] = out
    diff = np.abs(results["Green"] - results["MeanValue"]).max()
    check(diff > 1e-3, "Green and mean value differ on a bend (%.3g)" % diff)


def test_unstructured_grid_and_outside_points():
    cage = sphere(1.0, 12)
    # a few points, two of them outside the cage, as a vtkUnstructuredGrid of vertices
    pts = vtk.vtkPoints()
    coords = [(0, 0, 0), (0.3, 0.2, -0.1), (1.5, 0, 0), (0, -3, 1)]
    grid = vtk.vtkUnstructuredGrid()
    for p in coords:
        grid.InsertNextCell(vtk.VTK_VERTEX, 1, [pts.InsertNextPoint(p)])
    grid.SetPoints(pts)
    moved, _ = transform(cage, [[2, 0, 0], [0, 1, 0], [0, 0, 1]], [0, 0, 0])
    for kind in ("MeanValue", "Green"):
        f = sdfcage.vtkCageDeformationFilter()
        getattr(f, "SetCoordinatesTo" + kind)()
        f.SetInputData(0, grid)
        f.SetInputData(1, cage.GetOutput())
        f.SetInputData(2, moved.GetOutput())
        warnings = Events("WarningEvent", f)
        f.Update()
        out = f.GetOutput()
        check(out.IsA("vtkUnstructuredGrid"), "%s: an unstructured grid stays one" % kind)
        check(f.GetNumberOfPointsOutside() == 2, "%s: 2 points outside counted" % kind)
        check(any("outside the rest cage" in m for m in warnings.messages), "%s: warning given" % kind)
        loc = vtk_to_numpy(out.GetPointData().GetArray("CageLocation"))
        check(list(loc) == [0, 0, 1, 1], "%s: CageLocation %s" % (kind, list(loc)))
        # outside points follow the (affine) stretch by mean value coordinates, in both modes
        got = points(out)
        check(np.abs(got[2:] - np.array(coords[2:]) * [2, 1, 1]).max() < 1e-9,
              "%s: outside points follow an affine cage motion" % kind)


def test_errors():
    cage = sphere(1.0, 12)
    other = sphere(1.0, 10)
    mesh = sphere(0.5, 12)
    f = sdfcage.vtkCageDeformationFilter()
    f.SetInputConnection(mesh.GetOutputPort())
    f.SetRestCageConnection(cage.GetOutputPort())
    f.SetDeformedCageConnection(other.GetOutputPort())
    errors = Events("ErrorEvent", f, f.GetExecutive())
    f.Update()
    check(f.GetStatusString() == "InvalidInput" and f.GetOutput().GetNumberOfPoints() == 0,
          "another connectivity: InvalidInput, empty output")
    check(any("same points and triangles" in m for m in errors.messages), "another connectivity: error says why")

    # an open rest cage
    plane = vtk.vtkPlane()
    plane.SetNormal(0, 0, 1)
    clip = vtk.vtkClipPolyData()
    clip.SetInputConnection(cage.GetOutputPort())
    clip.SetClipFunction(plane)
    f.SetRestCageConnection(clip.GetOutputPort())
    f.SetDeformedCageConnection(clip.GetOutputPort())
    errors.messages = []
    f.Update()
    check(f.GetStatusString() == "InvalidInput" and any("boundary edge" in m for m in errors.messages),
          "open rest cage: InvalidInput, error names the boundary edges")

    # quads: triangulate first
    cube = vtk.vtkCubeSource()
    f.SetRestCageConnection(cube.GetOutputPort())
    f.SetDeformedCageConnection(cube.GetOutputPort())
    errors.messages = []
    f.Update()
    check(any("not triangles" in m for m in errors.messages), "quad cage: error asks to triangulate")

    # missing or empty inputs are not errors
    g = sdfcage.vtkCageDeformationFilter()
    g.SetInputData(0, vtk.vtkPolyData())
    g.SetInputData(1, cage.GetOutput())
    g.SetInputData(2, cage.GetOutput())
    errors = Events("ErrorEvent", g, g.GetExecutive())
    g.Update()
    check(not errors.messages and g.GetStatusString() == "EmptyInput", "empty input: EmptyInput, no error")


if __name__ == "__main__":
    test_reproduction_and_maps()
    test_single_precision()
    test_green_is_not_mvc_and_finite()
    test_unstructured_grid_and_outside_points()
    test_errors()
    print("all cage deformation tests passed")
