"""SDFCage: the ParaView plugin under pvbatch.

Run: pvbatch TestSDFCagePlugin.py <path to SDFCage.so> <scratch dir> [data dir]
Loads the plugin, runs the "SDF Cage" proxy on a Sphere source, fetches the outputs, and checks
the OFF reader/writer proxies.
"""
import os
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

plugin, scratch = sys.argv[1], sys.argv[2]
data_dir = sys.argv[3] if len(sys.argv) > 3 else ""
failures = []


def check(condition, message):
    print(("ok:   " if condition else "FAIL: ") + message)
    if not condition:
        failures.append(message)


LoadPlugin(plugin, remote=False, ns=globals())
check("SDFCage" in globals(), "the plugin defines SDFCage()")
check("OFFMeshReader" in globals(), "the plugin defines OFFMeshReader()")

# --- the filter ------------------------------------------------------------------------------
sphere = Sphere(Radius=2.0, ThetaResolution=32, PhiResolution=32)
cage = SDFCage(Input=sphere)
check(cage.IsoValue == 0.01, "IsoValue default 0.01")
cage.IsoValue = 0.04  # coarse: keeps the dense distance image small
cage.GenerateDistanceField = 1
cage.UpdatePipeline()

out = servermanager.Fetch(cage)
check(out is not None and out.IsA("vtkPolyData"), "port 0 fetches a vtkPolyData")
check(out.GetNumberOfPoints() > 0 and out.GetNumberOfPolys() > 0,
      "non-empty cage (%d points)" % out.GetNumberOfPoints())
dist = out.GetPointData().GetArray("DistanceToInput")
check(dist is not None, "DistanceToInput on the cage")
status = out.GetFieldData().GetAbstractArray("Status")
check(status is not None and status.GetValue(0) == "Ok", "field data Status = Ok")
clearance = out.GetFieldData().GetArray("MeasuredClearance").GetValue(0)
if dist is not None:
    check(dist.GetRange()[0] >= clearance * (1 - 1e-9), "DistanceToInput >= MeasuredClearance")
check(out.GetFieldData().GetArray("EnclosureVerified").GetValue(0) == 1, "EnclosureVerified")

envelope = servermanager.Fetch(cage, idx=1)
check(envelope.GetNumberOfPoints() > 0, "port 1 (Envelope) is not empty")
field = servermanager.Fetch(cage, idx=2)
check(field.IsA("vtkImageData") and field.GetNumberOfPoints() > 0,
      "port 2 (Distance Field) is a non-empty vtkImageData")
check(field.GetPointData().GetArray("SignedDistance") is not None, "SignedDistance array")

cage.UpdatePropertyInformation()
check(cage.GetProperty("StatusInfo").GetElement(0) == "Ok", "information property StatusInfo")
check(cage.GetProperty("TotalTimeInfo").GetElement(0) > 0, "information property TotalTimeInfo")

info = cage.GetDataInformation(0)
check(info.GetNumberOfPoints() == out.GetNumberOfPoints(), "data information agrees with Fetch")

# --- active points: the Active Points proxy and the cage's properties ---------------------------
# Two unit spheres 0.3 apart (0.3 / 2.15 = 0.14 in unit-sphere units): with Active Radius 0.2 the
# facing caps become active, nothing else.
left = Sphere(Radius=1.0, Center=[-1.15, 0, 0], ThetaResolution=48, PhiResolution=48)
right = Sphere(Radius=1.0, Center=[1.15, 0, 0], ThetaResolution=48, PhiResolution=48)
pair = AppendGeometry(Input=[left, right])
check("ActivePoints" in globals(), "the plugin defines ActivePoints()")
ap = ActivePoints(Input=pair)
check(abs(ap.ActiveRadius - 0.025) < 1e-12 and abs(ap.GeodesicThreshold - 0.15) < 1e-12,
      "Active Points defaults r 0.025, l 0.15")
ap.ActiveRadius = 0.2
ap.GeodesicThreshold = 0.5
ap.GenerateDistanceFields = 1
ap.UpdatePipeline()
apo = servermanager.Fetch(ap)
arr = apo.GetPointData().GetArray("ActivePoint")
check(arr is not None, "ActivePoint array on the mesh")
check(apo.GetPointData().GetArray("GeodesicDistanceToActive") is not None, "GeodesicDistanceToActive array")
check(apo.GetPointData().GetArray("Amplification") is not None, "Amplification array")
if arr is not None:
    n_active = sum(int(arr.GetValue(i)) for i in range(arr.GetNumberOfTuples()))
    facing = all(abs(apo.GetPoint(i)[0]) < 0.6 for i in range(arr.GetNumberOfTuples()) if arr.GetValue(i))
    print("active points:", n_active)
    check(n_active > 0, "the facing caps have active points")
    check(facing, "only points near the gap are active")
ap.UpdatePropertyInformation()
check(ap.GetProperty("NumberOfActivePointsInfo").GetElement(0) > 0, "information NumberOfActivePointsInfo")
apf = servermanager.Fetch(ap, idx=1)
check(apf.IsA("vtkImageData") and apf.GetPointData().GetArray("ModifiedSignedDistance") is not None,
      "output 1 has ModifiedSignedDistance")
check(cage.UseActivePoints == 1, "SDF Cage: Use Active Points on by default")
fresh = ActivePoints(Input=pair)
for name in ("ActiveRadius", "GeodesicThreshold", "AmplificationAlpha", "AmplificationBeta"):
    check(abs(getattr(cage, name) - getattr(fresh, name)) < 1e-12,
          "SDF Cage and Active Points share the default %s" % name)
Delete(fresh)

# --- an open input (a sheet): a cage around it, the inside rule in the field data ---------------
plane = Plane(XResolution=4, YResolution=4)  # an open sheet: 16 boundary edges
sheet_cage = SDFCage(Input=plane, TargetNumberOfVertices=60)
check(sheet_cage.SignMode == "Auto", "SignMode default Auto (got %s)" % sheet_cage.SignMode)
check(sheet_cage.ChooseIsoValueFirst == 1,
      "ChooseIsoValueFirst default on (got %s)" % sheet_cage.ChooseIsoValueFirst)
sheet_cage.UpdatePipeline()
sheet_out = servermanager.Fetch(sheet_cage)
check(sheet_out.GetNumberOfPoints() == 60, "open sheet: a 60-vertex cage (got %d)" % sheet_out.GetNumberOfPoints())
sheet_cage.UpdatePropertyInformation()
check(sheet_cage.GetProperty("StatusInfo").GetElement(0) == "Ok", "open sheet: Ok")
sign = sheet_out.GetFieldData().GetAbstractArray("SignMode")
check(sign is not None and sign.GetValue(0) == "winding", "open sheet: SignMode winding in the field data")
edges = sheet_out.GetFieldData().GetArray("InputBoundaryEdges")
check(edges is not None and edges.GetValue(0) == 16, "open sheet: 16 boundary edges reported")

# --- ParaView's own OBJ reader on a closed, textured OBJ: the seams come in split -----------------
# Every face corner has its own texture coordinate, so the reader makes a separate point for each
# corner (a closed sphere arrives as a soup of triangles); the filter merges them back.
src = servermanager.Fetch(Sphere(Radius=1.0, ThetaResolution=16, PhiResolution=12))
obj_path = os.path.join(scratch, "textured_sphere.obj")
with open(obj_path, "w") as obj:
    for i in range(src.GetNumberOfPoints()):
        obj.write("v %.17g %.17g %.17g\n" % src.GetPoint(i))
    corner = 0
    faces = []
    for c in range(src.GetNumberOfCells()):
        ids = src.GetCell(c).GetPointIds()
        f = []
        for k in range(ids.GetNumberOfIds()):
            corner += 1
            obj.write("vt %.6f %.6f\n" % ((corner % 97) / 97.0, (corner % 89) / 89.0))
            f.append("%d/%d" % (ids.GetId(k) + 1, corner))
        faces.append("f " + " ".join(f) + "\n")
    obj.writelines(faces)
reader = OpenDataFile(obj_path)
read = servermanager.Fetch(reader)
check(read.GetNumberOfPoints() > src.GetNumberOfPoints(),
      "ParaView's OBJ reader splits the seams (%d points for %d)" % (read.GetNumberOfPoints(), src.GetNumberOfPoints()))
obj_cage = SDFCage(Input=reader, TargetNumberOfVertices=100)
obj_cage.UpdatePipeline()
obj_out = servermanager.Fetch(obj_cage)
fd = obj_out.GetFieldData()
check(obj_out.GetNumberOfPoints() == 100, "textured OBJ: a 100-vertex cage (got %d)" % obj_out.GetNumberOfPoints())
check(fd.GetArray("EnclosureVerified").GetValue(0) == 1, "textured OBJ: enclosure verified")
check(fd.GetArray("MergedPoints").GetValue(0) == read.GetNumberOfPoints() - src.GetNumberOfPoints(),
      "textured OBJ: the split points are merged back (%g)" % fd.GetArray("MergedPoints").GetValue(0))
check(fd.GetAbstractArray("SignMode").GetValue(0) == "flood", "textured OBJ: closed again, so the flood-fill path")

# --- the Cage Optimize filter (two inputs: the cage and the source mesh) ------------------------
check("CageOptimize" in globals() or "CageOptimizeFilter" in globals(), "the plugin defines CageOptimize()")
opt = CageOptimize(Input=cage, Source=sphere)
check(opt.Energy == "MIPS", "Energy default MIPS (got %s)" % opt.Energy)
check(abs(opt.TargetSpacing - 0.05) < 1e-12, "TargetSpacing default 0.05")
check(opt.NumberOfIterations == 1 and opt.EdgeFlips == 1, "one iteration with edge flips by default")
check(abs(opt.HausdorffFactor - 1.4) < 1e-12 and abs(opt.TargetMinimumAngle - 15) < 1e-12 and
      opt.MaximumSweeps == 12, "MIPS defaults: Hausdorff factor 1.4, target angle 15, 12 sweeps")
# the MIPS options reach the filter: one sweep, and the share of small angles measured at 45 deg
opt.MaximumSweeps = 1
opt.TargetMinimumAngle = 45
opt.UpdatePipeline()
fd = servermanager.Fetch(opt).GetFieldData()
check(fd.GetArray("NumberOfSweeps").GetValue(0) == 1, "Maximum Sweeps 1: one sweep run")
small45 = fd.GetArray("SmallAnglesBefore").GetValue(0)
opt.TargetMinimumAngle = 15
opt.UpdatePipeline()
small15 = servermanager.Fetch(opt).GetFieldData().GetArray("SmallAnglesBefore").GetValue(0)
check(small45 > small15, "Target Minimum Angle reaches the filter (%g%% below 45 > %g%% below 15)" % (small45, small15))
opt.MaximumSweeps = 12
for energy in ("MIPS", "Spacing"):
    opt.Energy = energy
    opt.TargetSpacing = 0.1
    opt.UpdatePipeline()
    oo = servermanager.Fetch(opt)
    check(oo.GetNumberOfPoints() == out.GetNumberOfPoints(), "%s: same vertex count" % energy)
    fd = oo.GetFieldData()
    ostatus = fd.GetAbstractArray("Status")
    check(ostatus is not None and ostatus.GetValue(0) == "Ok", "%s: status Ok" % energy)
    before = fd.GetArray("EnergyBefore").GetValue(0)
    after = fd.GetArray("EnergyAfter").GetValue(0)
    check(after < before, "%s: energy lowered %g -> %g" % (energy, before, after))
    od = oo.GetPointData().GetArray("DistanceToInput")
    check(od is not None and od.GetRange()[0] >= fd.GetArray("MeasuredClearance").GetValue(0) * (1 - 1e-9),
          "%s: DistanceToInput >= MeasuredClearance" % energy)
    opt.UpdatePropertyInformation()
    check(opt.GetProperty("EnergyAfterInfo").GetElement(0) == after, "%s: information property EnergyAfterInfo" % energy)

# the optional step of SDF Cage
cage2 = SDFCage(Input=sphere, IsoValue=0.04, Optimize=1, Energy="Spacing", TargetSpacing=0.1)
cage2.UpdatePipeline()
o2 = servermanager.Fetch(cage2)
check(o2.GetFieldData().GetAbstractArray("Status").GetValue(0) == "Ok", "SDF Cage with Optimize: Ok")
check(o2.GetFieldData().GetArray("EnergyAfter").GetValue(0) < o2.GetFieldData().GetArray("EnergyBefore").GetValue(0),
      "SDF Cage with Optimize: energy lowered")

# --- nested cages: the Nested Levels list and the Nested Cages output (port 3) ------------------
nested = SDFCage(Input=sphere, IsoValue=0.04, NestedLevels=[30, 90])
check(list(SDFCage(Input=sphere).NestedLevels) == [], "Nested Levels is empty by default")
nested.UpdatePipeline()
levels = servermanager.Fetch(nested, idx=3)
check(levels is not None and levels.IsA("vtkMultiBlockDataSet") and levels.GetNumberOfBlocks() == 2,
      "Nested Cages fetches a vtkMultiBlockDataSet with one block per level")
if levels is not None and levels.IsA("vtkMultiBlockDataSet") and levels.GetNumberOfBlocks() == 2:
    for b, n in enumerate((90, 30)):
        name = levels.GetMetaData(b).Get(levels.NAME())
        block = levels.GetBlock(b)
        verified = block.GetFieldData().GetArray("VerifiedAgainstInside")
        check(name == "cage_%d" % n and block.GetNumberOfPoints() == n
              and verified is not None and verified.GetValue(0) == 1,
              "level %d: %s, %d points, verified against the level inside" % (b, name, block.GetNumberOfPoints()))
check(servermanager.Fetch(nested).GetNumberOfPoints() == 90, "the Cage output is the finest level")
one_level = servermanager.Fetch(cage, idx=3)
check(one_level.GetNumberOfBlocks() == 0, "without Nested Levels the Nested Cages output is empty")
Delete(nested)

# --- OFF writer and reader proxies -------------------------------------------------------------
path = os.path.join(scratch, "pv_sphere.off")
if os.path.exists(path):
    os.remove(path)
SaveData(path, proxy=cage)
check(os.path.exists(path), "SaveData wrote %s through the OFF writer" % path)
reader = OpenDataFile(path)
check(reader is not None and reader.GetXMLName() == "OFFMeshReader",
      "OpenDataFile picks the OFF Mesh Reader for .off (%s)" % (reader.GetXMLName() if reader else None))
if reader is not None:
    back = servermanager.Fetch(reader)
    check(back.GetNumberOfPoints() == out.GetNumberOfPoints()
          and back.GetNumberOfPolys() == out.GetNumberOfPolys(), "the cage reads back identically")

# --- the memory budget: a 1 MiB limit stops the run before its grid, with the need named ----------
check(cage.MemoryLimit == 0, "MemoryLimit default 0 (automatic)")
tight = SDFCage(Input=Sphere(ThetaResolution=32, PhiResolution=32), MemoryLimit=1)
from vtkmodules.vtkCommonCore import vtkLogger  # noqa: E402
verbosity = vtkLogger.GetCurrentVerbosityCutoff()
vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)  # the failure is reported as a VTK error: expected here
tight_out = servermanager.Fetch(tight)
vtkLogger.SetStderrVerbosity(verbosity)
tight_status = tight_out.GetFieldData().GetAbstractArray("Status")
tight_msg = tight_out.GetFieldData().GetAbstractArray("LastErrorMessage")
check(tight_out.GetNumberOfPoints() == 0 and tight_status is not None and tight_status.GetValue(0) == "Failed",
      "MemoryLimit 1 MiB: no cage, status Failed (%s)" % (tight_status.GetValue(0) if tight_status else None))
check(tight_msg is not None and "memory limit of 1 MiB" in tight_msg.GetValue(0),
      "MemoryLimit 1 MiB: the message names the need and the limit (%s)" % (tight_msg.GetValue(0) if tight_msg else None))
Delete(tight)

knight = os.path.join(data_dir, "decimated-knight.off") if data_dir else ""
if knight and os.path.exists(knight):
    k = OFFMeshReader(FileName=knight)
    kc = SDFCage(Input=k)
    kd = servermanager.Fetch(kc)
    check(kd.GetNumberOfPoints() > 0, "the knight from the data folder gets a cage")
else:
    print("skip: data folder absent, no knight")

if failures:
    print("%d failure(s)" % len(failures))
    sys.exit(1)
print("plugin test passed")
