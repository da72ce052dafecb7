"""SDFCage example for pvpython / pvbatch: build the cage of a mesh and look at its quality.

    pvpython Examples/ParaView/cage_quality.py [MESH] [--plugin SDFCage.so] [-n N]
                                               [--iso C] [--screenshot FILE.png]

Loads the SDFCage plugin, opens MESH (any format ParaView reads, plus .off) or, without MESH,
uses a sphere, builds the cage with "SDF Cage", judges it with "Cage Quality", prints the
verdicts, and saves a screenshot: the input (grey, translucent) under the cage coloured by its
DistanceToInput (translucent, with its edges). Rendering needs an X server: on a machine without
a display run it under `xvfb-run -a`.
"""
import argparse
import os
import sys

from paraview.simple import *  # noqa: F401,F403
from paraview import servermanager

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_PLUGIN = os.path.join(HERE, "..", "..", "build", "lib", "paraview-5.11", "plugins",
                              "SDFCage", "SDFCage.so")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", help="closed surface mesh (default: a sphere)")
    parser.add_argument("--plugin", default=os.environ.get("SDFCAGE_PLUGIN", DEFAULT_PLUGIN),
                        help="path of SDFCage.so (default: the build tree's, or $SDFCAGE_PLUGIN)")
    parser.add_argument("-n", "--vertices", type=int, default=200, help="cage vertices (200)")
    parser.add_argument("--iso", type=float, default=0.02, help="isovalue, relative (0.02)")
    parser.add_argument("--screenshot", default="cage_quality.png", help="PNG to write")
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
        mesh = Sphere(Radius=1.0, ThetaResolution=48, PhiResolution=48)

    cage = SDFCage(Input=mesh, TargetNumberOfVertices=args.vertices, IsoValue=args.iso)
    quality = CageQuality(Input=cage, Source=mesh)
    quality.UpdatePipeline()

    data = servermanager.Fetch(quality)
    fd = data.GetFieldData()

    def value(name):
        array = fd.GetAbstractArray(name)
        return None if array is None else array.GetValue(0)

    if data.GetNumberOfPoints() == 0:
        status = servermanager.Fetch(cage).GetFieldData().GetAbstractArray("LastErrorMessage")
        print("error: no cage: %s" % (status.GetValue(0) if status else "unknown reason"))
        return 1
    print("cage           : %d points, %d triangles" % (data.GetNumberOfPoints(), data.GetNumberOfCells()))
    print("encloses       : %s %s" % ("yes" if value("Encloses") == 1 else "NO", value("QualityMessage")))
    print("clearance      : %.6g (%.3g of the diagonal)" % (value("MinimumClearance"),
                                                          value("MinimumClearanceRelative")))
    print("Hausdorff      : cage->input %.6g, input->cage %.6g" % (value("HausdorffCageToInput"),
                                                                  value("HausdorffInputToCage")))
    print("mean distance  : %.6g" % value("MeanDistanceCageToInput"))
    print("genus          : cage %d, input %d" % (value("CageGenus"), value("InputGenus")))

    view = CreateView("RenderView")
    view.ViewSize = [1200, 800]
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 0
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:
        pass
    meshDisplay = Show(mesh, view)
    meshDisplay.DiffuseColor = [0.75, 0.75, 0.75]
    meshDisplay.Opacity = 0.5
    meshDisplay.ColorArrayName = ["POINTS", ""]
    cageDisplay = Show(quality, view)
    cageDisplay.SetRepresentationType("Surface With Edges")
    ColorBy(cageDisplay, ("POINTS", "DistanceToInput"))
    cageDisplay.RescaleTransferFunctionToDataRange(True, False)
    cageDisplay.SetScalarBarVisibility(view, True)
    cageDisplay.Opacity = 0.45
    view.ResetCamera()
    Render(view)
    SaveScreenshot(args.screenshot, view, ImageResolution=[1200, 800])
    print("screenshot     : %s" % args.screenshot)
    # release the OpenGL context while the X connection is still there (under Xvfb, tearing
    # it down at interpreter exit fails with GLXBadContext)
    Delete(view)
    del view
    return 0 if value("Encloses") == 1 else 1


if __name__ == "__main__":
    sys.exit(main())
