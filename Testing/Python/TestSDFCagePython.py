"""SDFCage: the wrapped filter from /usr/bin/python3 (ParaView's VTK).

Run: PYTHONPATH=<build>/lib/python3/dist-packages /usr/bin/python3 TestSDFCagePython.py [scratch]
"""
import os
import sys
import tempfile

import vtk
import sdfcage


class Errors(object):
    """Collects VTK error events so that expected errors do not reach the output window."""

    def __init__(self, *objects):
        self.messages = []
        for obj in objects:
            obj.AddObserver("ErrorEvent", self)

    # VTK passes the message only to observers that declare the call data type
    CallDataType = vtk.VTK_STRING

    def __call__(self, caller, event, calldata=None):
        self.messages.append(str(calldata))


def check(condition, message):
    if not condition:
        raise AssertionError(message)
    print("ok:", message)


def sphere(radius=1.0, resolution=32):
    source = vtk.vtkSphereSource()
    source.SetRadius(radius)
    source.SetThetaResolution(resolution)
    source.SetPhiResolution(resolution)
    return source


def test_filter():
    source = sphere(2.0)
    f = sdfcage.vtkSDFCageFilter()
    check(f.GetIsoValue() == 0.01, "IsoValue default 0.01")
    f.SetInputConnection(source.GetOutputPort())
    f.SetIsoValue(0.04)  # coarse: keeps the dense distance image small
    f.GenerateDistanceFieldOn()
    errors = Errors(f, f.GetExecutive())
    f.Update()
    check(not errors.messages, "no errors: %s" % errors.messages)
    check(f.GetStatusString() == "Ok", "status Ok (%s %s)" % (f.GetStatusString(), f.GetLastErrorMessage()))
    check(f.GetEnclosureVerified(), "EnclosureVerified")
    cage = f.GetOutput(0)
    check(cage.GetNumberOfPoints() > 0 and cage.GetNumberOfPolys() > 0, "non-empty cage")
    dist = cage.GetPointData().GetArray("DistanceToInput")
    check(dist is not None, "DistanceToInput present")
    lo, hi = dist.GetRange()
    check(lo >= f.GetMeasuredClearance() * (1 - 1e-9),
          "min DistanceToInput %g >= MeasuredClearance %g" % (lo, f.GetMeasuredClearance()))
    check(abs(f.GetMeasuredClearance() - 2.0 * f.GetMeasuredClearanceRelative()) < 1e-6,
          "clearance in input units = 2 x relative")
    edges = vtk.vtkFeatureEdges()
    edges.SetInputData(cage)
    edges.BoundaryEdgesOn()
    edges.NonManifoldEdgesOn()
    edges.FeatureEdgesOff()
    edges.ManifoldEdgesOff()
    edges.Update()
    check(edges.GetOutput().GetNumberOfCells() == 0, "closed cage")
    fd = cage.GetFieldData()
    check(fd.GetAbstractArray("Status").GetValue(0) == "Ok", "field data Status")
    check(fd.GetArray("TotalTime").GetValue(0) > 0, "field data TotalTime")
    # every result of the filter's table, listed by name, is in the field data with its value
    names = [f.GetResultName(i) for i in range(f.GetNumberOfResults())]
    check(len(names) >= 50 and len(set(names)) == len(names), "%d results, unique names" % len(names))
    for name in names:
        a = fd.GetAbstractArray(name)
        if a is None:
            check(False, "field data has the result " + name)
        elif a.IsA("vtkStringArray"):
            check(a.GetValue(0) == f.GetResultText(name), "field data %s = GetResultText" % name)
        else:
            check(a.GetTuple1(0) == f.GetResultNumber(name), "field data %s = GetResultNumber" % name)
    check(f.GetResultNumber("VerticesReached") == f.GetVerticesReached(), "GetVerticesReached reads the table")
    image = f.GetOutputDataObject(2)
    check(image.IsA("vtkImageData") and image.GetNumberOfPoints() > 0, "distance field image")
    sd = image.GetPointData().GetArray("SignedDistance")
    check(sd is not None, "SignedDistance array")
    center = image.FindPoint(0.0, 0.0, 0.0)
    check(center >= 0 and sd.GetValue(center) < 0, "negative at the center")
    print("cage: %d points, clearance %g, %.3f s" % (cage.GetNumberOfPoints(),
                                                    f.GetMeasuredClearance(), f.GetTotalTime()))


def test_errors():
    # An open surface (a sphere cut in half by a clip) gets a cage: the inside comes from the
    # winding number, and the field data say so.
    plane = vtk.vtkPlane()
    plane.SetNormal(0, 0, 1)
    source = sphere()  # keep a reference: an output port does not keep its producer alive
    clip = vtk.vtkClipPolyData()
    clip.SetInputConnection(source.GetOutputPort())
    clip.SetClipFunction(plane)
    f = sdfcage.vtkSDFCageFilter()
    f.SetTargetNumberOfVertices(100)
    f.SetInputConnection(clip.GetOutputPort())
    errors = Errors(f, f.GetExecutive())
    f.Update()
    check(not errors.messages, "open input: no error")
    check(f.GetStatusString() == "Ok", "open input: status Ok (got %s)" % f.GetStatusString())
    check(f.GetEnclosureVerified(), "open input: enclosure verified")
    check(f.GetOutput(0).GetNumberOfPoints() == 100, "open input: 100 cage vertices")
    check(f.GetResultText("SignMode") == "winding", "open input: SignMode winding")
    check(f.GetResultNumber("InputBoundaryEdges") > 0, "open input: boundary edges reported")
    fd = f.GetOutput(0).GetFieldData()
    check(fd.GetAbstractArray("SignMode").GetValue(0) == "winding", "open input: field data SignMode")

    f.SetInputData(vtk.vtkPolyData())
    errors.messages = []
    f.Update()
    check(not errors.messages, "empty input: no error")
    check(f.GetStatusString() == "EmptyInput", "empty input: status EmptyInput")


def test_off(scratch):
    source = sphere(1.0, 12)
    source.SetOutputPointsPrecision(vtk.vtkAlgorithm.DOUBLE_PRECISION)
    source.Update()
    path = os.path.join(scratch, "python_roundtrip.off")
    w = sdfcage.vtkOFFWriter()
    w.SetInputConnection(source.GetOutputPort())
    w.SetFileName(path)
    check(w.Write() == 1, "OFF written")
    r = sdfcage.vtkOFFReader()
    r.SetFileName(path)
    r.Update()
    a, b = source.GetOutput(), r.GetOutput()
    check(a.GetNumberOfPoints() == b.GetNumberOfPoints(), "OFF points round trip")
    check(a.GetNumberOfPolys() == b.GetNumberOfPolys(), "OFF polygons round trip")
    check(all(a.GetPoint(i) == b.GetPoint(i) for i in range(a.GetNumberOfPoints())),
          "OFF coordinates exact")
    check(sdfcage.vtkOFFReader.CanReadFile(path) == 1, "CanReadFile")


def test_optimize():
    source = sphere(2.0, 24)
    cager = sdfcage.vtkSDFCageFilter()
    cager.SetInputConnection(source.GetOutputPort())
    cager.SetTargetNumberOfVertices(120)
    opt = sdfcage.vtkCageOptimizeFilter()
    opt.SetInputConnection(cager.GetOutputPort(0))
    opt.SetSourceConnection(source.GetOutputPort())
    opt.SetEnergyToSpacing()
    opt.SetTargetSpacing(0.05)
    opt.SetNumberOfIterations(2)
    errors = Errors(opt, opt.GetExecutive())
    opt.Update()
    check(opt.GetStatusString() == "Ok", "optimize: status Ok (%s)" % opt.GetLastErrorMessage())
    check(not errors.messages, "optimize: no errors")
    out = opt.GetOutput()
    check(out.GetNumberOfPoints() == 120, "optimize: same vertex count")
    check(opt.GetEnergyAfter() < opt.GetEnergyBefore(),
          "optimize: spacing energy lowered %g -> %g" % (opt.GetEnergyBefore(), opt.GetEnergyAfter()))
    check(opt.GetMeasuredClearanceRelative() >= opt.GetClearanceUsed() * (1 - 1e-9),
          "optimize: clearance kept")
    check(out.GetPointData().GetArray("DistanceToInput") is not None, "optimize: DistanceToInput")


if __name__ == "__main__":
    scratch = sys.argv[1] if len(sys.argv) > 1 else tempfile.mkdtemp()
    print("vtk", vtk.vtkVersion.GetVTKVersion(), "from", vtk.__file__)
    print("sdfcage", getattr(sdfcage, "__version__", "?"), "from", sdfcage.__file__)
    test_filter()
    test_errors()
    test_off(scratch)
    test_optimize()
    print("all Python tests passed")
