"""SDFCage example for pvpython / pvbatch: bend a mesh by moving its cage, with mean value and
with Green coordinates, side by side.

    pvpython Examples/ParaView/cage_deformation.py [MESH] [--plugin SDFCage.so] [-n N]
                                 [--angle DEGREES] [--screenshot FILE.png]

Loads the SDFCage plugin, opens MESH (any format ParaView reads, plus .off) or, without MESH, a
capsule-like sphere stretched along y, builds its cage with "SDF Cage" (N vertices, default
500), bends the cage (a Programmable Filter moves its vertices: everything above 40% of the
height bends sideways by ANGLE degrees, default 70, around a horizontal axis, as a beam bends),
and deforms the mesh with "Cage Deformation" twice: mean value and Green coordinates. Prints the
weight and apply times and saves a picture: the mesh in its rest cage, the mean value result
and the Green result, each with its cage as a wireframe. Rendering needs an X server: on a
machine without a display run it under `xvfb-run -a`.

    xvfb-run -a pvpython Examples/ParaView/cage_deformation.py ../shared/data/armadillo.obj \\
        --screenshot docs/deformation.png
"""
import builtins
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paraview.simple import *  # noqa: E402,F401,F403
import sdfcage_example as ex  # noqa: E402

field = ex.field

# The Programmable Filter's script: bends the cage's points (runs where the data is).
BEND_SCRIPT = """
import numpy as np
from vtkmodules.vtkCommonCore import vtkPoints
from vtkmodules.util.numpy_support import vtk_to_numpy, numpy_to_vtk
inp = self.GetPolyDataInput()
out = self.GetPolyDataOutput()
out.ShallowCopy(inp)
p = vtk_to_numpy(inp.GetPoints().GetData()).astype(float)
lo, hi = p.min(axis=0), p.max(axis=0)
height = hi[1] - lo[1]
y0 = lo[1] + 0.4 * height            # the bend starts here
cx = 0.5 * (lo[0] + hi[0])
angle = np.radians({angle})
R = (hi[1] - y0) / angle             # radius of the bend of the axis x = cx
h = np.maximum(p[:, 1] - y0, 0.0)    # height above the start
t = h / R
d = p[:, 0] - cx                     # offset across the axis
q = p.copy()
q[:, 0] = np.where(h > 0, cx + R - (R - d) * np.cos(t), p[:, 0])
q[:, 1] = np.where(h > 0, y0 + (R - d) * np.sin(t), p[:, 1])
points = vtkPoints()
points.SetData(numpy_to_vtk(np.ascontiguousarray(q), deep=1))
out.SetPoints(points)
"""



def main():
    parser = ex.parser(__doc__, "closed surface mesh (default: a stretched sphere)", "cage_deformation.png")
    parser.add_argument("-n", "--vertices", type=int, default=500, help="cage vertices (500)")
    parser.add_argument("--angle", type=float, default=70.0, help="bend angle in degrees (70)")
    args = parser.parse_args()

    def default():
        stretched = Transform(Input=Sphere(Radius=0.5, ThetaResolution=48, PhiResolution=96))
        stretched.Transform.Scale = [0.6, 2.0, 0.6]
        return stretched

    mesh = ex.open_input(args, globals(), default)
    if mesh is None:
        return 2
    mesh = Clean(Input=mesh)  # OBJ readers split points along seams: merge them (the cage does too)
    mesh = GenerateSurfaceNormals(Input=mesh, Splitting=0)  # smooth shading, no split points

    cage = SDFCage(Input=mesh, TargetNumberOfVertices=args.vertices)
    bent = ProgrammableFilter(Input=cage)
    bent.OutputDataSetType = "vtkPolyData"
    bent.Script = BEND_SCRIPT.replace("{angle}", repr(args.angle))
    results = {}
    for kind in ("Mean Value", "Green"):
        deform = CageDeformation(Input=mesh, RestCage=cage, DeformedCage=bent, Coordinates=kind)
        deform.UpdatePipeline()
        data = ex.fetch(deform)
        if data.GetNumberOfPoints() == 0:
            print("error: %s: %s" % (kind, field(data, "LastErrorMessage")))
            return 1
        results[kind] = (deform, data)
        print("%-14s : %d points, weights %.2f s, apply %.1f ms, %d outside the cage, %d on it" % (
            kind, data.GetNumberOfPoints(), field(data, "WeightTime"), 1e3 * field(data, "ApplyTime"),
            field(data, "PointsOutsideCage"), field(data, "PointsOnCage")))
    outside = builtins.sum(field(d, "PointsOutsideCage") + field(d, "PointsOnCage") for _, d in results.values())
    print("encloses       : %s (points outside or on the rest cage: %d)" % ("yes" if outside == 0 else "NO", outside))

    # three panels side by side: rest, mean value, Green (each with its cage)
    bounds = ex.fetch(cage).GetBounds()
    shift = 1.25 * builtins.max(bounds[1] - bounds[0], bounds[3] - bounds[2])

    view = ex.white_view(1800, 800)
    panels = [(mesh, cage, "rest: the mesh in its %d-vertex cage" % args.vertices),
              (results["Mean Value"][0], bent, "mean value coordinates"),
              (results["Green"][0], bent, "Green coordinates")]
    for k, (surface, wire, _) in enumerate(panels):
        ex.show_in_cage(view, surface, wire, k * shift, opacity=0.35)
    labels = [label for _, _, label in panels]
    ex.frame_and_save(view, bounds, shift, labels, (1800, 800), args.screenshot, fill=(0.62, 0.53), lift=0.04,
                      label_dx=0.1, font=22)
    Delete(view)
    del view
    return 0 if outside == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
