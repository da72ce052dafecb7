"""SDFCage example for pvpython / pvbatch: a plain cage next to the same cage optimized with the
MIPS energy at the defaults (no angle below 15 degrees, still tight).

    pvpython Examples/ParaView/optimized_cage.py [MESH] [--plugin SDFCage.so] [-n N]
                                 [--screenshot FILE.png]

Loads the SDFCage plugin, opens MESH (any format ParaView reads, plus .off; default: a sphere),
builds its cage with "SDF Cage" (N vertices, default 500), optimizes it with "Cage Optimize" (Energy MIPS,
every other property at its default), prints the smallest angle and the one-sided Hausdorff
distance cage -> input before and after, and saves a picture: the mesh inside the plain cage
and inside the optimized cage, each cage drawn as its edges. Rendering needs an X server: on a
machine without a display run it under `xvfb-run -a`.

    xvfb-run -a pvpython Examples/ParaView/optimized_cage.py ../shared/data/bunny.off \\
        --screenshot docs/optimized.png
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


def field(data, name):
    array = data.GetFieldData().GetAbstractArray(name)
    return None if array is None else array.GetValue(0)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", help="closed surface mesh (default: a sphere)")
    parser.add_argument("--plugin", default=os.environ.get("SDFCAGE_PLUGIN", DEFAULT_PLUGIN),
                        help="path of SDFCage.so (default: the build tree's, or $SDFCAGE_PLUGIN)")
    parser.add_argument("-n", "--vertices", type=int, default=500, help="cage vertices (500)")
    parser.add_argument("--screenshot", default="optimized_cage.png", help="PNG to write")
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
        mesh = ExtractSurface(Input=mesh)
    else:
        mesh = Sphere(Radius=0.5, ThetaResolution=48, PhiResolution=48)
    mesh = Clean(Input=mesh)
    mesh = GenerateSurfaceNormals(Input=mesh, Splitting=0)

    cage = SDFCage(Input=mesh, TargetNumberOfVertices=args.vertices)
    optimized = CageOptimize(Input=cage, Source=mesh, Energy="MIPS")
    optimized.UpdatePipeline()
    data = servermanager.Fetch(optimized)
    if data.GetNumberOfPoints() == 0:
        print("error: %s" % field(data, "LastErrorMessage"))
        return 1
    plain = servermanager.Fetch(cage)
    print("vertices       : %d plain, %d optimized" % (plain.GetNumberOfPoints(), data.GetNumberOfPoints()))
    print("min angle      : %.2f -> %.2f degrees" % (field(data, "MinimumAngleBefore"),
                                                     field(data, "MinimumAngleAfter")))
    print("angles < 15    : %.2f%% -> %.2f%%" % (field(data, "SmallAnglesBefore"), field(data, "SmallAnglesAfter")))
    print("Hausdorff      : %.5f -> %.5f (cage -> input, unit sphere)" % (field(data, "HausdorffBefore"),
                                                                          field(data, "HausdorffAfter")))
    print("time           : %.1f s, reverted: %s" % (field(data, "OptimizationTime"),
                                                     "yes" if field(data, "Reverted") else "no"))

    bounds = plain.GetBounds()
    shift = 1.2 * (bounds[1] - bounds[0])

    def moved(source, k):
        t = Transform(Input=source)
        t.Transform.Translate = [k * shift, 0.0, 0.0]
        return t

    view = CreateView("RenderView")
    view.ViewSize = [1600, 800]
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 0
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    panels = [(cage, "plain cage: min angle %.1f deg, Hausdorff %.4f" % (
                   field(data, "MinimumAngleBefore"), field(data, "HausdorffBefore"))),
              (optimized, "--optimize mips: min angle %.1f deg, Hausdorff %.4f" % (
                   field(data, "MinimumAngleAfter"), field(data, "HausdorffAfter")))]
    labels = []
    for k, (wire, label) in enumerate(panels):
        s = Show(moved(mesh, k), view)
        s.ColorArrayName = ["POINTS", ""]
        s.DiffuseColor = [0.78, 0.74, 0.68]
        s.Specular = 0.3
        w = Show(moved(wire, k), view)
        w.SetRepresentationType("Wireframe")
        w.ColorArrayName = ["POINTS", ""]
        w.AmbientColor = [0.15, 0.35, 0.75]
        w.DiffuseColor = [0.15, 0.35, 0.75]
        w.LineWidth = 1.5
        w.Opacity = 0.6
        labels.append(Text(Text=label))
    width, height = shift + (bounds[1] - bounds[0]), bounds[3] - bounds[2]
    aspect = 1600.0 / 800.0
    scale = builtins.max(0.62 * height, 0.55 * width / aspect)
    centre = [0.5 * shift + 0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]) + 0.05 * height,
              0.5 * (bounds[4] + bounds[5])]
    Render(view)
    view.CameraParallelProjection = 1
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0], centre[1], centre[2] + 10.0 * width]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraParallelScale = scale
    for k, label in enumerate(labels):
        t = Show(label, view)
        t.WindowLocation = "Any Location"
        t.Justification = "Center"
        t.Position = [0.5 + (k - 0.5) * shift / (2.0 * scale * aspect) - 0.15, 0.9]
        t.FontSize = 20
        t.Color = [0.1, 0.1, 0.1]
    Render(view)
    SaveScreenshot(args.screenshot, view, ImageResolution=[1600, 800])
    print("screenshot     : %s" % args.screenshot)
    Delete(view)
    del view
    ok = field(data, "MinimumAngleAfter") > field(data, "MinimumAngleBefore") and not field(data, "Reverted")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
