"""SDFCage under MPI: pvbatch on several ranks, every source and reader handing each rank a piece.

Run: mpiexec -np 2 pvbatch TestMPIPieces.py <SDFCage.so> <scratch dir> [data dir]
(with PYTHONPATH holding the `sdfcage` package). Each filter's result under MPI is compared with
a serial run of the same filter, made here on rank 0 with the plain VTK classes of the `sdfcage`
package (a plain Update() asks for the whole input, piece 0 of 1: it runs on this rank alone).
"""
import builtins
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

import sdfcage
from mpi_compare import Checker, same_surface, same_results, field_value, largest_point_offset, diagonal
from mpi_pieces import write_pieces_vtp, torus_mesh
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkFiltersCore import vtkAppendPolyData, vtkFlyingEdges3D
from vtkmodules.vtkCommonDataModel import vtkPolyData

plugin, scratch = sys.argv[1], sys.argv[2]
data_dir = sys.argv[3] if len(sys.argv) > 3 else ""
chk = Checker()

LoadPlugin(plugin, remote=False, ns=globals())
ranks = servermanager.ActiveConnection.GetNumberOfDataPartitions()
chk.check(ranks >= 2, "pvbatch runs on %d ranks" % ranks)

CAGE = dict(IsoValue=0.04, TargetNumberOfVertices=100)
RESULTS = ["Status", "EnclosureVerified", "VerticesReached", "TargetReached", "MergedPoints", "InputClosed",
           "InputGenus", "InputBoundaryEdges", "InputComponents", "SignMode", "EnvelopeGenus", "EnvelopeComponents",
           "MeasuredClearance", "NumberOfActivePoints"]


def serial_cage(mesh, generate_field=False, **params):
    f = sdfcage.vtkSDFCageFilter()
    f.SetInputData(mesh)
    f.SetIsoValue(params.get("IsoValue", 0.01))
    f.SetTargetNumberOfVertices(params.get("TargetNumberOfVertices", 500))
    f.SetGenerateDistanceField(1 if generate_field else 0)
    f.Update()
    return f


def sphere_mesh(**kw):
    s = vtkSphereSource()
    s.SetThetaResolution(kw.get("theta", 32))
    s.SetPhiResolution(kw.get("phi", 32))
    s.SetRadius(kw.get("radius", 0.5))
    s.SetCenter(kw.get("center", (0, 0, 0)))
    s.Update()
    return s.GetOutput()


# --- 1. a distributed source: Sphere -> SDF Cage ---------------------------------------------------
sphere = Sphere(ThetaResolution=32, PhiResolution=32)
sphere.UpdatePipeline()
whole = sphere_mesh()
chk.check(sphere.GetDataInformation().GetNumberOfPoints() > whole.GetNumberOfPoints(),
          "the Sphere source is split into pieces (%d points over the ranks, %d whole)"
          % (sphere.GetDataInformation().GetNumberOfPoints(), whole.GetNumberOfPoints()))
cage = SDFCage(Input=sphere, GenerateDistanceField=1, **CAGE)
cage.UpdatePipeline()
out = servermanager.Fetch(cage)
ref = serial_cage(whole, generate_field=True, **CAGE)
ref_out = ref.GetOutput(0)
chk.check(ref.GetStatusString() == "Ok" and ref_out.GetNumberOfPoints() == 100, "serial reference cage: Ok, 100 points")
same_surface(chk, "sphere cage", out, ref_out)
same_results(chk, "sphere cage", out, ref_out, RESULTS)
chk.check(cage.GetDataInformation().GetNumberOfPoints() == ref_out.GetNumberOfPoints(),
          "the cage is on one rank only (%d points over all ranks)" % cage.GetDataInformation().GetNumberOfPoints())
cage.UpdatePropertyInformation()
chk.check(cage.GetProperty("StatusInfo").GetElement(0) == "Ok", "information property StatusInfo Ok")
chk.check(cage.GetProperty("VerticesReachedInfo").GetElement(0) == 100, "information property VerticesReachedInfo 100")
# every rank reports process 0's results: a programmable filter on each rank turns the field data
# its (possibly empty) piece of the cage carries into one point per rank
probe = ProgrammableFilter(Input=cage, OutputDataSetType="vtkPolyData")
probe.Script = (
    "from vtkmodules.vtkCommonCore import vtkPoints, vtkIntArray\n"
    "from vtkmodules.vtkParallelCore import vtkMultiProcessController\n"
    "rank = vtkMultiProcessController.GetGlobalController().GetLocalProcessId()\n"
    "fd = self.GetInput().GetFieldData()\n"
    "out = self.GetOutput()\n"
    "pts = vtkPoints()\n"
    "pts.InsertNextPoint(rank, 0, 0)\n"
    "out.SetPoints(pts)\n"
    "for name in ('EnclosureVerified', 'VerticesReached'):\n"
    "    a = vtkIntArray()\n"
    "    a.SetName(name)\n"
    "    v = fd.GetArray(name)\n"
    "    a.InsertNextValue(int(v.GetValue(0)) if v is not None else -1)\n"
    "    out.GetPointData().AddArray(a)\n"
    "r = vtkIntArray()\n"
    "r.SetName('Rank')\n"
    "r.InsertNextValue(rank)\n"
    "out.GetPointData().AddArray(r)\n")
probe.UpdatePipeline()
po = servermanager.Fetch(probe)
per_rank = {int(po.GetPointData().GetArray("Rank").GetValue(i)): (int(po.GetPointData().GetArray("EnclosureVerified").GetValue(i)),
                                                                   int(po.GetPointData().GetArray("VerticesReached").GetValue(i)))
            for i in range(po.GetNumberOfPoints())}
# (paraview.simple's * import shadows all(): compare lists)
chk.check(sorted(per_rank) == list(range(ranks)) and [v for v in per_rank.values() if v != (1, 100)] == [],
          "every rank's piece carries the results (EnclosureVerified, VerticesReached by rank: %s)" % per_rank)
Delete(probe)
env_info = cage.GetDataInformation(1)
chk.check(env_info.GetNumberOfPoints() == ref.GetOutput(1).GetNumberOfPoints(),
          "envelope: %d points over all ranks, %d serial" % (env_info.GetNumberOfPoints(), ref.GetOutput(1).GetNumberOfPoints()))

# the distance field (an image on rank 0, empty images elsewhere): data information and a contour
ref_field = ref.GetOutputDataObject(2)
field_info = cage.GetDataInformation(2)
chk.check(tuple(field_info.GetExtent()) == tuple(ref_field.GetExtent()),
          "distance field extent %s, serial %s" % (tuple(field_info.GetExtent()), tuple(ref_field.GetExtent())))
chk.check(field_info.GetNumberOfPoints() == ref_field.GetNumberOfPoints(),
          "distance field: %d points over all ranks, %d serial" % (field_info.GetNumberOfPoints(), ref_field.GetNumberOfPoints()))
rng = field_info.GetPointDataInformation().GetArrayInformation("SignedDistance")
chk.check(rng is not None and abs(rng.GetComponentRange(0)[0] - ref_field.GetPointData().GetArray("SignedDistance").GetRange()[0]) < 1e-6,
          "distance field: SignedDistance range as serial")
contour = Contour(Input=OutputPort(cage, 2), ContourBy=["POINTS", "SignedDistance"], Isosurfaces=[0.0])
contour.UpdatePipeline()
fe = vtkFlyingEdges3D()
fe.SetInputData(ref_field)
fe.SetInputArrayToProcess(0, 0, 0, 0, "SignedDistance")
fe.SetValue(0, 0.0)
fe.Update()
chk.check(contour.GetDataInformation().GetNumberOfPoints() == fe.GetOutput().GetNumberOfPoints()
          and fe.GetOutput().GetNumberOfPoints() > 0,
          "a Contour of the distributed distance field: %d points, serial %d"
          % (contour.GetDataInformation().GetNumberOfPoints(), fe.GetOutput().GetNumberOfPoints()))
# a downstream change re-executes only the contour (every rank or none: no rank waits alone)
contour.Isosurfaces = [0.01]
contour.UpdatePipeline()
chk.check(contour.GetDataInformation().GetNumberOfPoints() > 0, "the contour updated again")

# --- 1b. nested levels (port 3, a multiblock with one block per level) ----------------------------
LEVELS = [120, 40]
nested = SDFCage(Input=sphere, NestedLevels=LEVELS, IsoValue=0.04)
nested.UpdatePipeline()
ref_nested = sdfcage.vtkSDFCageFilter()
ref_nested.SetInputData(whole)
ref_nested.SetIsoValue(0.04)
ref_nested.SetNumberOfNestedLevels(len(LEVELS))
for k, n in enumerate(LEVELS):
    ref_nested.SetNestedVertexCount(k, n)
ref_nested.Update()
ref_levels = ref_nested.GetOutputDataObject(3)
chk.check(ref_levels.GetNumberOfBlocks() == len(LEVELS) and
          [ref_levels.GetBlock(k).GetNumberOfPoints() for k in range(len(LEVELS))] == LEVELS,
          "serial reference: the levels have %s points" % LEVELS)
chk.check(nested.GetDataInformation(3).GetNumberOfPoints() == builtins.sum(LEVELS),
          "nested output: %d points over all ranks, %d serial"
          % (nested.GetDataInformation(3).GetNumberOfPoints(), builtins.sum(LEVELS)))
# the levels live on rank 0: Fetch(proxy, 0, idx=3) brings its multiblock whole (a plain Fetch of
# a composite output groups every rank's multiblock as one block per rank, ParaView's rule)
on_root = servermanager.Fetch(nested, 0, idx=3)
names = [on_root.GetMetaData(k).Get(on_root.NAME()) for k in range(on_root.GetNumberOfBlocks())]
chk.check(names == ["cage_%d" % n for n in LEVELS], "rank 0's nested output: blocks %s" % names)
for k, n in enumerate(LEVELS):
    same_surface(chk, "nested level cage_%d" % n, on_root.GetBlock(k), ref_levels.GetBlock(k))
grouped = servermanager.Fetch(nested, idx=3)
chk.check(grouped.GetNumberOfBlocks() == ranks and grouped.GetBlock(0).GetNumberOfPoints() == builtins.sum(LEVELS)
          and builtins.sum(grouped.GetBlock(r).GetNumberOfPoints() for r in range(1, ranks)) == 0,
          "a plain Fetch: one block per rank, rank 0's holding the %d points" % builtins.sum(LEVELS))
for n in LEVELS:
    level = MergeBlocks(Input=ExtractBlock(Input=OutputPort(nested, 3), Selectors=["/Root/cage_%d" % n]))
    level.UpdatePipeline()
    chk.check(level.GetDataInformation().GetNumberOfPoints() == n,
              "Extract Block cage_%d: %d points over all ranks" % (n, level.GetDataInformation().GetNumberOfPoints()))
    Delete(level)
# the quality filter on the whole nested output, the input mesh distributed too: each level judged
# against the level inside it on rank 0, as in a serial run
judge = CageQuality(Input=OutputPort(nested, 3), Source=sphere)
judge.UpdatePipeline()
judged = servermanager.Fetch(judge, 0)
serial_judge = sdfcage.vtkCageQualityFilter()
serial_judge.SetInputData(ref_levels)
serial_judge.SetSourceData(whole)
serial_judge.Update()
serial_judged = serial_judge.GetOutputDataObject(0)
for k, n in enumerate(LEVELS):
    got, want = judged.GetBlock(k), serial_judged.GetBlock(k)
    chk.check(got is not None and got.GetNumberOfPoints() == n and field_value(got, "Encloses") == 1
              and field_value(got, "JudgedAgainst") == field_value(want, "JudgedAgainst")
              and abs(field_value(got, "HausdorffCageToInput") - field_value(want, "HausdorffCageToInput"))
              <= 1e-9 * want.GetLength(),
              "quality of nested level cage_%d under MPI: encloses %s, judged against %s, as serial"
              % (n, field_value(got, "Encloses") if got else None, field_value(got, "JudgedAgainst") if got else None))
Delete(judge)
Delete(nested)

# --- 1c. cage deformation: each rank moves its own piece of the points -----------------------------
# An affine motion of the cage is reproduced exactly by mean value coordinates: every point of the
# distributed sphere must land where the same affine map puts it, on its own rank.
def affine(x, s, t):
    return [s[k] * x[k] + t[k] for k in range(3)]


moved = Transform(Input=cage)
moved.Transform.Scale = [1.2, 0.9, 1.1]
moved.Transform.Translate = [0.3, -0.1, 0.2]
deform = CageDeformation(Input=sphere, RestCage=cage, DeformedCage=moved, Coordinates="Mean Value")
deform.UpdatePipeline()
chk.check(deform.GetDataInformation().GetNumberOfPoints() == sphere.GetDataInformation().GetNumberOfPoints(),
          "deformation: as many points over the ranks as the distributed sphere (%d, %d)"
          % (deform.GetDataInformation().GetNumberOfPoints(), sphere.GetDataInformation().GetNumberOfPoints()))
pieces_in = servermanager.Fetch(sphere)
pieces_out = servermanager.Fetch(deform)
worst = 0.0
for i in range(pieces_in.GetNumberOfPoints()):
    want = affine(pieces_in.GetPoint(i), [1.2, 0.9, 1.1], [0.3, -0.1, 0.2])
    got = pieces_out.GetPoint(i)
    worst = builtins.max(worst, builtins.max(abs(got[k] - want[k]) for k in range(3)))
chk.check(pieces_out.GetNumberOfPoints() == pieces_in.GetNumberOfPoints() and worst < 1e-6,  # float points
          "deformation: every point of every piece moved by the cage's affine map (largest error %.3g)" % worst)
chk.check(field_value(pieces_out, "Status") == "Ok" and field_value(pieces_out, "PointsOutsideCage") == 0,
          "deformation: Ok, no point outside the rest cage (%s, %s)"
          % (field_value(pieces_out, "Status"), field_value(pieces_out, "PointsOutsideCage")))
chk.check(field_value(pieces_out, "WeightsRecomputed") == 1, "deformation: the weights computed once")
# moving the cage again re-applies with the same weights on every rank (the joined rest cage kept)
moved.Transform.Translate = [0.0, 0.4, 0.0]
deform.UpdatePipeline()
again = servermanager.Fetch(deform)
chk.check(field_value(again, "WeightsRecomputed") == 0,
          "deformation: the cage moved again, the weights kept under MPI (WeightsRecomputed %s)"
          % field_value(again, "WeightsRecomputed"))
Delete(deform)
Delete(moved)

# --- 2. the quality and optimize filters on distributed inputs ------------------------------------
quality = CageQuality(Input=cage, Source=sphere)
quality.UpdatePipeline()
q = servermanager.Fetch(quality)
ref_q = sdfcage.vtkCageQualityFilter()
ref_q.SetInputData(ref_out)
ref_q.SetSourceData(whole)
ref_q.Update()
same_surface(chk, "quality output", q, ref_q.GetOutput())
same_results(chk, "quality", q, ref_q.GetOutput(),
             ["Encloses", "MinimumClearance", "CageGenus", "InputGenus", "HausdorffCageToInput", "InputVerticesOutside"],
             relative=1e-6)

opt = CageOptimize(Input=cage, Source=sphere)
opt.UpdatePipeline()
o = servermanager.Fetch(opt)
ref_o = sdfcage.vtkCageOptimizeFilter()
ref_o.SetInputData(ref_out)
ref_o.SetSourceData(whole)
ref_o.Update()
same_surface(chk, "optimized cage", o, ref_o.GetOutput(), tolerance=1e-6)
same_results(chk, "optimize", o, ref_o.GetOutput(), ["Status", "NumberOfMoves", "NumberOfFlips", "EnergyAfter"],
             relative=1e-6)
opt.UpdatePropertyInformation()
chk.check(abs(opt.GetProperty("EnergyAfterInfo").GetElement(0) - ref_o.GetEnergyAfter()) <= 1e-6 * abs(ref_o.GetEnergyAfter()),
          "optimize: information property EnergyAfterInfo as serial")

# --- 3. active points on two distributed spheres a narrow gap apart -------------------------------
left = Sphere(Radius=1.0, Center=[-1.15, 0, 0], ThetaResolution=24, PhiResolution=24)
right = Sphere(Radius=1.0, Center=[1.15, 0, 0], ThetaResolution=24, PhiResolution=24)
pair = AppendGeometry(Input=[left, right])
ap = ActivePoints(Input=pair, ActiveRadius=0.2, GeodesicThreshold=0.5, GenerateDistanceFields=1)
ap.UpdatePipeline()
apo = servermanager.Fetch(ap)
app = vtkAppendPolyData()
app.AddInputData(sphere_mesh(radius=1.0, center=(-1.15, 0, 0), theta=24, phi=24))
app.AddInputData(sphere_mesh(radius=1.0, center=(1.15, 0, 0), theta=24, phi=24))
app.Update()
ref_ap = sdfcage.vtkActivePointFilter()
ref_ap.SetInputData(app.GetOutput())
ref_ap.SetActiveRadius(0.2)
ref_ap.SetGeodesicThreshold(0.5)
ref_ap.SetGenerateDistanceFields(1)
ref_ap.Update()
same_surface(chk, "active-point mesh", apo, ref_ap.GetOutput())
same_results(chk, "active points", apo, ref_ap.GetOutput(), ["Status", "NumberOfActivePoints"])
chk.check((field_value(apo, "NumberOfActivePoints") or 0) > 0, "active points found across the gap")
chk.check(tuple(ap.GetDataInformation(1).GetExtent()) == tuple(ref_ap.GetOutputDataObject(1).GetExtent()),
          "active-point fields: extent as serial")

# --- 4. a reader that splits its file into pieces -------------------------------------------------
meshes = [("torus", torus_mesh())]
bunny = os.path.join(data_dir, "bunny.off") if data_dir else ""
if bunny and os.path.exists(bunny):
    r = sdfcage.vtkOFFReader()
    r.SetFileName(bunny)
    r.Update()
    meshes.append(("bunny", r.GetOutput()))
else:
    print("skip: data folder absent, no bunny (the torus still runs)")
for name, mesh in meshes:
    path = os.path.join(scratch, "%s_4pieces.vtp" % name)
    write_pieces_vtp(mesh, path, 4)
    reader = XMLPolyDataReader(FileName=[path])
    reader.UpdatePipeline()
    chk.check(reader.GetDataInformation().GetNumberOfPoints() > mesh.GetNumberOfPoints(),
              "%s: the reader hands out pieces (%d points over the ranks, %d in the mesh)"
              % (name, reader.GetDataInformation().GetNumberOfPoints(), mesh.GetNumberOfPoints()))
    c = SDFCage(Input=reader, IsoValue=0.02, TargetNumberOfVertices=150)
    c.UpdatePipeline()
    co = servermanager.Fetch(c)
    rc = serial_cage(mesh, IsoValue=0.02, TargetNumberOfVertices=150)
    chk.check(rc.GetStatusString() == "Ok", "%s: serial reference Ok" % name)
    same_surface(chk, "%s cage from 4 pieces" % name, co, rc.GetOutput(0))
    # MergedPoints differs by design: each rank's piece holds two of the file's pieces, appended
    # by the reader with their seam points repeated (as a serial read of the file would), which
    # Core merges and counts; the seams between ranks are joined before (not counted).
    same_results(chk, "%s cage from 4 pieces" % name, co, rc.GetOutput(0), [r for r in RESULTS if r != "MergedPoints"])
    chk.check(0 < field_value(co, "MergedPoints") < reader.GetDataInformation().GetNumberOfPoints() - mesh.GetNumberOfPoints(),
              "%s: the seams inside each rank's piece merged by Core (%d), those between ranks before"
              % (name, field_value(co, "MergedPoints")))
    Delete(c)
    Delete(reader)

# --- 5. pieces with a layer of ghost cells (a programmable source on every rank) ---------------------
here = os.path.dirname(os.path.abspath(__file__))
ghosted = ProgrammableSource(OutputDataSetType="vtkPolyData")
ghosted.ScriptRequestInformation = (
    "from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm\n"
    "self.GetExecutive().GetOutputInformation(0).Set(vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)\n")
ghosted.Script = (
    "import sys\n"
    "sys.path.insert(0, %r)\n"
    "from mpi_pieces import piece_with_ghosts, torus_mesh\n"
    "from vtkmodules.vtkCommonExecutionModel import vtkStreamingDemandDrivenPipeline as SDDP\n"
    "info = self.GetOutputInformation(0)\n"
    "k, n = info.Get(SDDP.UPDATE_PIECE_NUMBER()), info.Get(SDDP.UPDATE_NUMBER_OF_PIECES())\n"
    "self.GetOutput().ShallowCopy(piece_with_ghosts(torus_mesh(), k, n))\n" % here)
ghosted.UpdatePipeline()
torus = torus_mesh()
chk.check(ghosted.GetDataInformation().GetNumberOfCells() > torus.GetNumberOfPolys(),
          "ghost pieces: %d cells over the ranks (ghost layers included), %d in the torus"
          % (ghosted.GetDataInformation().GetNumberOfCells(), torus.GetNumberOfPolys()))
gc = SDFCage(Input=ghosted, IsoValue=0.02, TargetNumberOfVertices=150)
gc.UpdatePipeline()
go = servermanager.Fetch(gc)
gref = serial_cage(torus, IsoValue=0.02, TargetNumberOfVertices=150)
same_surface(chk, "torus cage from ghosted pieces", go, gref.GetOutput(0))
# kept ghost cells would arrive as duplicated triangles (counted as dropped duplicates)
same_results(chk, "torus cage from ghosted pieces", go, gref.GetOutput(0), RESULTS + ["DroppedDuplicateTriangles"])

chk.finish()
