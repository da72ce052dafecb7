"""SDFCage: the "Cage Quality" proxy of the ParaView plugin under pvbatch.

Run: pvbatch TestCageQualityPlugin.py <path to SDFCage.so>
Judges the cage "SDF Cage" makes of a sphere (must enclose), a closed box around the sphere
(encloses), a box that cuts it and an open box (do not), through the proxy with two inputs.
"""
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

plugin = sys.argv[1]
failures = []


def check(condition, message):
    print(("ok:   " if condition else "FAIL: ") + message)
    if not condition:
        failures.append(message)


def field(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    if array is None:
        return None
    return array.GetValue(0)


LoadPlugin(plugin, remote=False, ns=globals())
check("CageQuality" in globals(), "the plugin defines CageQuality()")

sphere = Sphere(Radius=1.0, ThetaResolution=32, PhiResolution=32)

# --- the cage of SDF Cage ------------------------------------------------------------------------
cage = SDFCage(Input=sphere, IsoValue=0.04, TargetNumberOfVertices=100)
quality = CageQuality(Input=cage, Source=sphere)
check(abs(quality.HausdorffTolerance - 1e-4) < 1e-15, "HausdorffTolerance default 1e-4")
quality.UpdatePipeline()
out = servermanager.Fetch(quality)
check(out.GetNumberOfPoints() > 0, "the cage comes out (%d points)" % out.GetNumberOfPoints())
check(field(out, "Encloses") == 1, "the SDF cage encloses the sphere (%s)" % field(out, "QualityMessage"))
clearance = field(out, "MinimumClearance")
check(clearance is not None and clearance > 0, "MinimumClearance > 0 (%s)" % clearance)
sdf_clearance = servermanager.Fetch(cage).GetFieldData().GetArray("MeasuredClearance").GetValue(0)
check(abs(clearance - sdf_clearance) <= 1e-9 * sdf_clearance,
      "the quality filter measures the same exact clearance as SDF Cage (%g vs %g)" % (clearance, sdf_clearance))
dist = out.GetPointData().GetArray("DistanceToInput")
check(dist is not None and dist.GetRange()[0] >= clearance * (1 - 1e-12),
      "point DistanceToInput >= MinimumClearance")
for name in ("DistanceToInput", "MinimumAngle", "MIPSEnergy"):
    array = out.GetCellData().GetArray(name)
    check(array is not None and array.GetNumberOfTuples() == out.GetNumberOfCells(),
          "cell array %s on every cell" % name)
mips = out.GetCellData().GetArray("MIPSEnergy")
check(mips is not None and mips.GetRange()[0] >= 2.0 - 1e-9, "MIPS energy >= 2 (equilateral)")
for name in ("HausdorffCageToInput", "HausdorffInputToCage", "MeanDistanceCageToInput",
             "MeanDistanceCageToInputRelative", "MinimumClearanceRelative"):
    value = field(out, name)
    check(value is not None and value > 0, "%s = %s > 0" % (name, value))
check(field(out, "HausdorffCageToInput") >= dist.GetRange()[1] - 1e-12,
      "Hausdorff cage->input >= the largest point distance")
check(field(out, "CageGenus") == 0 and field(out, "InputGenus") == 0, "genus 0 and 0")
check(field(out, "SelfIntersections") == 0 and field(out, "InputIntersections") == 0
      and field(out, "InputVerticesOutside") == 0, "no intersections, no input vertex outside")

# --- hand-made boxes -----------------------------------------------------------------------------
def judge(box_side, merge):
    box = Box(XLength=box_side, YLength=box_side, ZLength=box_side)
    cage_input = Clean(Input=box) if merge else box
    q = CageQuality(Input=cage_input, Source=sphere)
    q.UpdatePipeline()
    return servermanager.Fetch(q)


good = judge(3.0, True)
check(field(good, "Encloses") == 1, "a closed box of side 3 encloses the unit sphere (%s)" % field(good, "QualityMessage"))
cuts = judge(1.6, True)
check(field(cuts, "Encloses") == 0, "a box of side 1.6 does not enclose")
check(field(cuts, "InputIntersections") > 0 and field(cuts, "InputVerticesOutside") > 0,
      "it intersects the sphere and leaves vertices outside")
check("intersects" in field(cuts, "QualityMessage"), "QualityMessage: %s" % field(cuts, "QualityMessage"))
opened = judge(3.0, False)  # the Box source's faces share no points: every edge is a boundary
check(field(opened, "Encloses") == 0, "an open box does not enclose")
check(field(opened, "CageGenus") == -1, "no genus for an open cage")
check("closed 2-manifold" in field(opened, "QualityMessage"), "QualityMessage: %s" % field(opened, "QualityMessage"))

if failures:
    print("%d failure(s)" % len(failures))
    sys.exit(1)
print("all checks passed")
