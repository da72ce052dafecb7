"""SDFCage example for pvpython / pvbatch: build the cage of a mesh and look at its quality.

    pvpython Examples/ParaView/cage_quality.py [MESH] [--plugin SDFCage.so] [-n N]
                                               [--iso C] [--screenshot FILE.png]

Loads the SDFCage plugin, opens MESH (any format ParaView reads, plus .off) or, without MESH,
uses a sphere, builds the cage with "SDF Cage", judges it with "Cage Quality", prints the
verdicts, and saves a screenshot: the input (grey, translucent) under the cage coloured by its
DistanceToInput (translucent, with its edges). Rendering needs an X server: on a machine without
a display run it under `xvfb-run -a`.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paraview.simple import *  # noqa: E402,F401,F403
import sdfcage_example as ex  # noqa: E402


def main():
    parser = ex.parser(__doc__, "closed surface mesh (default: a sphere)", "cage_quality.png")
    parser.add_argument("-n", "--vertices", type=int, default=200, help="cage vertices (200)")
    parser.add_argument("--iso", type=float, default=0.02, help="isovalue, relative (0.02)")
    args = parser.parse_args()
    mesh = ex.open_input(args, globals(), lambda: Sphere(Radius=1.0, ThetaResolution=48, PhiResolution=48))
    if mesh is None:
        return 2

    cage = SDFCage(Input=mesh, TargetNumberOfVertices=args.vertices, IsoValue=args.iso)
    quality = CageQuality(Input=cage, Source=mesh)
    quality.UpdatePipeline()

    data = ex.fetch(quality)

    def value(name):
        return ex.field(data, name)

    if data.GetNumberOfPoints() == 0:
        print("error: no cage: %s" % (ex.field(ex.fetch(cage), "LastErrorMessage") or "unknown reason"))
        return 1
    print("cage           : %d points, %d triangles" % (data.GetNumberOfPoints(), data.GetNumberOfCells()))
    print("encloses       : %s %s" % ("yes" if value("Encloses") == 1 else "NO", value("QualityMessage")))
    print("clearance      : %.6g (%.3g of the diagonal)" % (value("MinimumClearance"),
                                                          value("MinimumClearanceRelative")))
    print("Hausdorff      : cage->input %.6g, input->cage %.6g" % (value("HausdorffCageToInput"),
                                                                  value("HausdorffInputToCage")))
    print("mean distance  : %.6g" % value("MeanDistanceCageToInput"))
    print("genus          : cage %d, input %d" % (value("CageGenus"), value("InputGenus")))

    view = ex.white_view(1200, 800)
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
