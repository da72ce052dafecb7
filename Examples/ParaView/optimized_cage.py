"""SDFCage example for pvpython / pvbatch: a plain cage next to the same cage optimized with the
MIPS energy at the defaults (no angle below 15 degrees, still tight).

    pvpython Examples/ParaView/optimized_cage.py [MESH] [--plugin SDFCage.so] [-n N]
                                 [--screenshot FILE.png]

Loads the SDFCage plugin, opens MESH (any format ParaView reads, plus .off; default: a sphere),
builds its cage with "SDF Cage" (N vertices, default 500), optimizes it with "Cage Optimize"
(Energy MIPS, every other property at its default), prints the smallest angle and the one-sided
Hausdorff distance cage -> input before and after and the verdict of "Cage Quality" on the
optimized cage, and saves a picture: the mesh inside the plain cage and inside the optimized
cage, each cage drawn as its edges. Rendering needs an X server: on a
machine without a display run it under `xvfb-run -a`.

    xvfb-run -a pvpython Examples/ParaView/optimized_cage.py ../shared/data/bunny.off \\
        --screenshot docs/optimized.png
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paraview.simple import *  # noqa: E402,F401,F403
import sdfcage_example as ex  # noqa: E402

field = ex.field


def main():
    parser = ex.parser(__doc__, "closed surface mesh (default: a sphere)", "optimized_cage.png")
    parser.add_argument("-n", "--vertices", type=int, default=500, help="cage vertices (500)")
    args = parser.parse_args()
    mesh = ex.open_input(args, globals(), lambda: Sphere(Radius=0.5, ThetaResolution=48, PhiResolution=48))
    if mesh is None:
        return 2
    mesh = Clean(Input=mesh)
    mesh = GenerateSurfaceNormals(Input=mesh, Splitting=0)

    cage = SDFCage(Input=mesh, TargetNumberOfVertices=args.vertices)
    optimized = CageOptimize(Input=cage, Source=mesh, Energy="MIPS")
    optimized.UpdatePipeline()
    data = ex.fetch(optimized)
    if data.GetNumberOfPoints() == 0:
        print("error: %s" % field(data, "LastErrorMessage"))
        return 1
    plain = ex.fetch(cage)
    print("vertices       : %d plain, %d optimized" % (plain.GetNumberOfPoints(), data.GetNumberOfPoints()))
    print("min angle      : %.2f -> %.2f degrees" % (field(data, "MinimumAngleBefore"),
                                                     field(data, "MinimumAngleAfter")))
    print("angles < 15    : %.2f%% -> %.2f%%" % (field(data, "SmallAnglesBefore"), field(data, "SmallAnglesAfter")))
    print("Hausdorff      : %.5f -> %.5f (cage -> input, unit sphere)" % (field(data, "HausdorffBefore"),
                                                                          field(data, "HausdorffAfter")))
    print("time           : %.1f s, reverted: %s" % (field(data, "OptimizationTime"),
                                                     "yes" if field(data, "Reverted") else "no"))
    judged = ex.fetch(CageQuality(Input=optimized, Source=mesh))  # the exact verdict, independent of the optimizer
    encloses = field(judged, "Encloses") == 1
    print("encloses       : %s %s" % ("yes" if encloses else "NO", field(judged, "QualityMessage")))

    bounds = plain.GetBounds()
    shift = 1.2 * (bounds[1] - bounds[0])

    view = ex.white_view(1600, 800)
    panels = [(cage, "plain cage: min angle %.1f deg, Hausdorff %.4f" % (
                   field(data, "MinimumAngleBefore"), field(data, "HausdorffBefore"))),
              (optimized, "--optimize mips: min angle %.1f deg, Hausdorff %.4f" % (
                   field(data, "MinimumAngleAfter"), field(data, "HausdorffAfter")))]
    for k, (wire, _) in enumerate(panels):
        ex.show_in_cage(view, mesh, wire, k * shift, opacity=0.6, line_width=1.5)
    labels = [label for _, label in panels]
    ex.frame_and_save(view, bounds, shift, labels, (1600, 800), args.screenshot)
    Delete(view)
    del view
    ok = encloses and field(data, "MinimumAngleAfter") > field(data, "MinimumAngleBefore") \
        and not field(data, "Reverted")
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
