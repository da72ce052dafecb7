"""SDFCage: the "Cage Deformation" proxy of the ParaView plugin under pvbatch.

Run: pvbatch TestCageDeformationPlugin.py <path to SDFCage.so>
The cage SDF Cage makes of a sphere deforms that sphere, through the proxy with three inputs: the
deformed cage comes from a Transform (a similarity: both coordinates follow it) and from Warp By
Vector after a Calculator (a bend: the two differ, both finite); moving the cage again keeps the
weights.
"""
import math
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
    return None if array is None else array.GetValue(0)


def coordinates(data):
    return [data.GetPoint(i) for i in range(data.GetNumberOfPoints())]


LoadPlugin(plugin, remote=False, ns=globals())
check("CageDeformation" in globals(), "the plugin defines CageDeformation()")

sphere = Sphere(Radius=1.0, ThetaResolution=24, PhiResolution=24)
cage = SDFCage(Input=sphere, IsoValue=0.04, TargetNumberOfVertices=100)
moved = Transform(Input=cage)
moved.Transform.Rotate = [0.0, 0.0, 30.0]
moved.Transform.Scale = [1.5, 1.5, 1.5]
moved.Transform.Translate = [2.0, 0.0, 0.0]

original = coordinates(servermanager.Fetch(sphere))
c, s = math.cos(math.radians(30.0)), math.sin(math.radians(30.0))
expected = [(2.0 + 1.5 * (c * x - s * y), 1.5 * (s * x + c * y), 1.5 * z) for x, y, z in original]

for kind in ("Mean Value", "Green"):
    deform = CageDeformation(Input=sphere, RestCage=cage, DeformedCage=moved)
    check(deform.Coordinates == "Mean Value", "Coordinates default Mean Value")
    deform.Coordinates = kind
    deform.UpdatePipeline()
    out = servermanager.Fetch(deform)
    check(field(out, "Status") == "Ok", "%s: status Ok (%s)" % (kind, field(out, "LastErrorMessage")))
    check(out.GetNumberOfPoints() == len(original) and out.GetNumberOfCells() > 0,
          "%s: the sphere comes out deformed (%d points)" % (kind, out.GetNumberOfPoints()))
    err = max(max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(coordinates(out), expected))
    # ParaView's sources and Transform give float points: single precision is the limit
    check(err < 1e-5, "%s: the cage's similarity is reproduced (%.2g)" % (kind, err))
    check(field(out, "PointsOutsideCage") == 0, "%s: no point outside the cage of SDF Cage" % kind)
    check(field(out, "WeightsRecomputed") == 1, "%s: weights computed" % kind)

    moved.Transform.Rotate = [0.0, 0.0, 45.0]
    deform.UpdatePipeline()
    out = servermanager.Fetch(deform)
    check(field(out, "WeightsRecomputed") == 0, "%s: moving the cage keeps the weights" % kind)
    moved.Transform.Rotate = [0.0, 0.0, 30.0]

# a bend made by Calculator + Warp By Vector: the two coordinates differ
calc = Calculator(Input=cage, Function="coordsX*coordsX*jHat*0.5", ResultArrayName="d")
bent = WarpByVector(Input=calc, Vectors=["POINTS", "d"])
results = {}
for kind in ("Mean Value", "Green"):
    deform = CageDeformation(Input=sphere, RestCage=cage, DeformedCage=bent, Coordinates=kind)
    deform.UpdatePipeline()
    out = servermanager.Fetch(deform)
    pts = coordinates(out)
    check(len(pts) == len(original) and all(all(math.isfinite(v) for v in p) for p in pts),
          "%s: bent output finite" % kind)
    results[kind] = pts
diff = max(max(abs(a - b) for a, b in zip(p, q)) for p, q in zip(results["Mean Value"], results["Green"]))
check(diff > 1e-3, "Green and mean value differ on a bend (%.3g)" % diff)

if failures:
    print("%d failure(s)" % len(failures))
    sys.exit(1)
print("all Cage Deformation plugin tests passed")
