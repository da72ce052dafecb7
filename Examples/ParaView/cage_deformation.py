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
import argparse
import builtins
import os
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_PLUGIN = os.path.join(HERE, "..", "..", "build", "lib", "paraview-5.11", "plugins",
                              "SDFCage", "SDFCage.so")

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


def field(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    return None if array is None else array.GetValue(0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", help="closed surface mesh (default: a stretched sphere)")
    parser.add_argument("--plugin", default=os.environ.get("SDFCAGE_PLUGIN", DEFAULT_PLUGIN),
                        help="path of SDFCage.so (default: the build tree's, or $SDFCAGE_PLUGIN)")
    parser.add_argument("-n", "--vertices", type=int, default=500, help="cage vertices (500)")
    parser.add_argument("--angle", type=float, default=70.0, help="bend angle in degrees (70)")
    parser.add_argument("--screenshot", default="cage_deformation.png", help="PNG to write")
    args = parser.parse_args()

    if not os.path.isfile(args.plugin):
        print("error: plugin not found: %s (build the project or pass --plugin)" % args.plugin)
        return 2
    LoadPlugin(args.plugin, remote=False, ns=globals())

    if args.mesh:
        if args.mesh.lower().endswith(".off"):
            mesh = OFFMeshReader(FileName=args.mesh)
        else:
            mesh = OpenDataFile(args.mesh)
        if mesh is None:
            print("error: cannot open %s" % args.mesh)
            return 2
        mesh = ExtractSurface(Input=mesh)  # any dataset -> polydata
    else:
        sphere = Sphere(Radius=0.5, ThetaResolution=48, PhiResolution=96)
        mesh = Transform(Input=sphere)
        mesh.Transform.Scale = [0.6, 2.0, 0.6]
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
        data = servermanager.Fetch(deform)
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
    bounds = servermanager.Fetch(cage).GetBounds()
    shift = 1.25 * builtins.max(bounds[1] - bounds[0], bounds[3] - bounds[2])

    def moved(source, k):
        t = Transform(Input=source)
        t.Transform.Translate = [k * shift, 0.0, 0.0]
        return t

    view = CreateView("RenderView")
    view.ViewSize = [1800, 800]
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 0
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    panels = [(mesh, cage, "rest: the mesh in its %d-vertex cage" % args.vertices),
              (results["Mean Value"][0], bent, "mean value coordinates"),
              (results["Green"][0], bent, "Green coordinates")]
    labels = []
    for k, (surface, wire, label) in enumerate(panels):
        s = Show(moved(surface, k), view)
        s.ColorArrayName = ["POINTS", ""]
        s.DiffuseColor = [0.78, 0.74, 0.68]
        s.Specular = 0.3
        w = Show(moved(wire, k), view)
        w.SetRepresentationType("Wireframe")
        w.ColorArrayName = ["POINTS", ""]
        w.AmbientColor = [0.15, 0.35, 0.75]
        w.DiffuseColor = [0.15, 0.35, 0.75]
        w.Opacity = 0.35
        labels.append(Text(Text=label))
    # parallel projection framing the three panels (each panel's centre known: labels above them)
    width, height = 2.0 * shift + (bounds[1] - bounds[0]), bounds[3] - bounds[2]
    aspect = 1800.0 / 800.0
    scale = builtins.max(0.62 * height, 0.53 * width / aspect)
    centre = [shift + 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]) + 0.04 * height,
              0.5 * (bounds[4] + bounds[5])]
    Render(view)  # the first render resets the camera: set ours after it
    view.CameraParallelProjection = 1
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0], centre[1], centre[2] + 10.0 * width]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraParallelScale = scale
    for k, label in enumerate(labels):
        t = Show(label, view)
        t.WindowLocation = "Any Location"
        t.Justification = "Center"
        t.Position = [0.5 + (k - 1) * shift / (2.0 * scale * aspect) - 0.1, 0.9]
        t.FontSize = 22
        t.Color = [0.1, 0.1, 0.1]
    Render(view)
    SaveScreenshot(args.screenshot, view, ImageResolution=[1800, 800])
    print("screenshot     : %s" % args.screenshot)
    Delete(view)
    del view
    return 0 if outside == 0 else 1


if __name__ == "__main__":
    sys.exit(main())
