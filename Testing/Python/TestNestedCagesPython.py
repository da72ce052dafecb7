"""SDFCage: nested cages from Python (vtkSDFCageFilter's NestedVertexCounts and its fourth output,
a vtkMultiBlockDataSet with one block per level), judged level by level with vtkCageQualityFilter.

Run: PYTHONPATH=<build>/lib/python3/dist-packages /usr/bin/python3 TestNestedCagesPython.py
"""
import sys

import vtk
import sdfcage


class Errors(object):
    """Collects VTK error events so that expected errors do not reach the output window."""

    def __init__(self, *objects):
        self.messages = []
        for obj in objects:
            obj.AddObserver("ErrorEvent", self)

    CallDataType = vtk.VTK_STRING

    def __call__(self, caller, event, calldata=None):
        self.messages.append(str(calldata))


def check(condition, message):
    if not condition:
        raise AssertionError(message)
    print("ok:", message)


def field(block, name):
    a = block.GetFieldData().GetAbstractArray(name)
    if a is None:
        return None
    return a.GetValue(0)


def two_spheres():
    """Two spheres well apart (two parts: the levels must keep them apart)."""
    append = vtk.vtkAppendPolyData()
    for center in ((0.0, 0.0, 0.0), (3.0, 0.0, 0.0)):
        s = vtk.vtkSphereSource()
        s.SetCenter(*center)
        s.SetThetaResolution(24)
        s.SetPhiResolution(24)
        append.AddInputConnection(s.GetOutputPort())
    append.Update()
    return append.GetOutput()


def judge(cage, inside):
    q = sdfcage.vtkCageQualityFilter()
    q.SetInputData(cage)
    q.SetSourceData(inside)
    q.Update()
    return q


def test_levels():
    mesh = two_spheres()
    f = sdfcage.vtkSDFCageFilter()
    f.SetInputData(mesh)
    f.SetIsoValue(0.02)
    f.SetNumberOfNestedLevels(3)
    for i, n in enumerate((40, 160, 80)):  # any order: the levels come out finest first
        f.SetNestedVertexCount(i, n)
    check(f.GetNumberOfNestedLevels() == 3 and f.GetNestedVertexCount(1) == 160, "the counts are stored")
    errors = Errors(f, f.GetExecutive())
    f.Update()
    check(not errors.messages, "no errors (%d)" % len(errors.messages))
    check(f.GetStatusString() == "Ok", "status Ok (%s %s)" % (f.GetStatusString(), f.GetLastErrorMessage()))
    finest = f.GetOutput(0)
    check(finest.GetNumberOfPoints() == 160, "port 0 is the finest level (%d points)" % finest.GetNumberOfPoints())
    levels = f.GetOutputDataObject(3)
    check(levels.IsA("vtkMultiBlockDataSet"), "port 3 is a vtkMultiBlockDataSet")
    check(levels.GetNumberOfBlocks() == 3, "one block per level")
    inside = mesh
    previous_to_input = 0.0
    for b, n in enumerate((160, 80, 40)):
        block = levels.GetBlock(b)
        name = levels.GetMetaData(b).Get(vtk.vtkCompositeDataSet.NAME())
        check(name == "cage_%d" % n, "block %d is named %s" % (b, name))
        check(block.GetNumberOfPoints() == n, "%s has exactly %d points" % (name, block.GetNumberOfPoints()))
        check(field(block, "Status") == "Ok", "%s status Ok" % name)
        check(field(block, "Level") == b, "%s Level %s" % (name, field(block, "Level")))
        check(field(block, "VerifiedAgainstInside") == 1 and field(block, "VerifiedAgainstInput") == 1,
              "%s verified against the level inside and the input" % name)
        check(field(block, "TopologyKept") == 1 and field(block, "CageComponents") == 2,
              "%s keeps the two parts apart" % name)
        check(block.GetPointData().GetArray("DistanceToInput") is not None, "%s has DistanceToInput" % name)
        # the quality filter judges the level against the one inside it
        q = judge(block, inside)
        check(q.GetEncloses(), "%s encloses the level inside it (%s)" % (name, q.GetQualityMessage()))
        clearance = field(block, "ClearanceToInside")
        check(abs(q.GetMinimumClearance() - clearance) <= 1e-6 * clearance,
              "%s: the judge's clearance %g == ClearanceToInside %g" % (name, q.GetMinimumClearance(), clearance))
        to_input = judge(block, mesh)
        check(to_input.GetEncloses(), "%s encloses the input" % name)
        check(to_input.GetMinimumClearance() > previous_to_input,
              "%s lies farther out than the finer level (%g > %g)" % (
                  name, to_input.GetMinimumClearance(), previous_to_input))
        previous_to_input = to_input.GetMinimumClearance()
        inside = block

    # the quality filter on the whole port 3: every level against the next one in, in one go
    q = sdfcage.vtkCageQualityFilter()
    q.SetInputConnection(f.GetOutputPort(3))
    q.SetSourceData(mesh)
    q.Update()
    judged = q.GetOutputDataObject(0)
    check(judged.IsA("vtkMultiBlockDataSet") and judged.GetNumberOfBlocks() == 3,
          "the quality filter gives the three levels back")
    check(q.GetEncloses(), "every level encloses the next one in (%s)" % q.GetQualityMessage())
    for b, against in enumerate(("input", "cage_160", "cage_80")):
        block = judged.GetBlock(b)
        name = judged.GetMetaData(b).Get(vtk.vtkCompositeDataSet.NAME())
        check(field(block, "JudgedAgainst") == against, "%s judged against %s" % (name, against))
        clearance = field(levels.GetBlock(b), "ClearanceToInside")
        check(field(block, "Encloses") == 1 and
              abs(field(block, "MinimumClearance") - clearance) <= 1e-6 * clearance,
              "%s: its clearance to the level inside, %g" % (name, clearance))

    # back to one cage: port 0 as before, port 3 empty
    f.SetNumberOfNestedLevels(0)
    f.SetTargetNumberOfVertices(100)
    f.Update()
    check(f.GetStatusString() == "Ok" and f.GetOutput(0).GetNumberOfPoints() == 100,
          "without nested counts: one cage of TargetNumberOfVertices")
    check(f.GetOutputDataObject(3).GetNumberOfBlocks() == 0, "without nested counts: port 3 empty")


def test_bad_counts():
    f = sdfcage.vtkSDFCageFilter()
    f.SetInputData(two_spheres())
    f.SetNumberOfNestedLevels(2)
    f.SetNestedVertexCount(0, 100)
    f.SetNestedVertexCount(1, 100)
    errors = Errors(f, f.GetExecutive())
    f.Update()
    check(f.GetStatusString() == "InvalidInput", "duplicate counts: status %s" % f.GetStatusString())
    check(any("given twice" in m for m in errors.messages), "duplicate counts: the error says so")
    check(f.GetOutput(0).GetNumberOfPoints() == 0, "duplicate counts: empty cage")
    check(f.GetOutputDataObject(3).GetNumberOfBlocks() == 0, "duplicate counts: no levels")
    f.SetNestedVertexCount(1, 0)
    errors.messages = []
    f.Update()
    check(any("at least 1" in m for m in errors.messages), "a zero count is rejected with its reason")


if __name__ == "__main__":
    test_levels()
    test_bad_counts()
    print("all nested-cage checks passed")
    sys.exit(0)
