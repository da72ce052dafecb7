"""SDFCage example for pvpython / pvbatch: nested cages (paper section 4, Fig. 9), each level
judged against the level inside it with "Cage Quality", and a picture.

    pvpython Examples/ParaView/nested_cages.py [MESH] [--plugin SDFCage.so] [-n 2000,500,100]
                                               [--screenshot FILE.png]

Loads the SDFCage plugin, opens MESH (any format ParaView reads, plus .off) or, without MESH, a
sphere beside a torus, and runs "SDF Cage" with "Nested Levels" set to the counts. Its "Nested
Cages" output holds one block per level (cage_2000, cage_500, cage_100), finest first. Each level
is taken out with "Extract Block" (+ "Merge Blocks" and "Extract Surface": a polydata) and judged
by "Cage Quality" against the level inside it (the input for the finest). Prints one line per
level and saves a picture: one panel per level (the level as a wireframe around the level
inside it), and a cut through the input and every level, which shows them nested. Rendering
needs an X server: on a machine without a display run it under `xvfb-run -a`.

    xvfb-run -a pvpython Examples/ParaView/nested_cages.py ../shared/data/bunny.off \\
        --screenshot docs/nested.png
"""
import builtins
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from paraview.simple import *  # noqa: E402,F401,F403
import sdfcage_example as ex  # noqa: E402

field = ex.field

# inner to outer: warm to cool
COLORS = [[0.85, 0.33, 0.10], [0.20, 0.55, 0.25], [0.15, 0.35, 0.75], [0.45, 0.25, 0.60]]



def main():
    parser = ex.parser(__doc__, "closed surface mesh (default: a sphere beside a torus)", "nested_cages.png")
    parser.add_argument("-n", "--vertices", default="2000,500,100",
                        help="vertex counts of the levels, comma-separated (2000,500,100)")
    args = parser.parse_args()
    counts = sorted((int(v) for v in args.vertices.split(",")), reverse=True)

    def default():
        sphere = Sphere(Radius=0.5, Center=[-1.1, 0.0, 0.0], ThetaResolution=48, PhiResolution=48)
        torus = Superquadric(Toroidal=1, Thickness=0.35, Size=0.5, Center=[0.6, 0.0, 0.0],
                             ThetaResolution=64, PhiResolution=32)
        return ExtractSurface(Input=AppendDatasets(Input=[sphere, ExtractSurface(Input=torus)]))

    mesh = ex.open_input(args, globals(), default)
    if mesh is None:
        return 2
    mesh = Clean(Input=mesh)  # OBJ/STL readers split points: merge them (the cage does too)
    mesh = GenerateSurfaceNormals(Input=mesh, Splitting=0)

    cage = SDFCage(Input=mesh, NestedLevels=counts)
    cage.UpdatePipeline()
    finest = ex.fetch(cage)
    status = field(finest, "Status")
    if status != "Ok":
        print("error: SDF Cage: %s: %s" % (status, field(finest, "LastErrorMessage")))
        return 1
    nested = OutputPort(cage, 3)

    # every level as a polydata, judged against the one inside it
    levels = []
    inside = mesh
    ok = True
    for n in counts:
        block = ExtractBlock(Input=nested, Selectors=["/Root/cage_%d" % n])
        level = ExtractSurface(Input=MergeBlocks(Input=block))
        judge = CageQuality(Input=level, Source=inside)
        judge.UpdatePipeline()
        q = ex.fetch(judge)
        levels.append(level)
        inside = level
        encloses = field(q, "Encloses") == 1
        ok = ok and encloses and q.GetNumberOfPoints() == n
        print("cage_%-6d : %d points, encloses the level inside it: %s, clearance %.4g, "
              "Hausdorff to it %.4g (%.2f%% of the diagonal)" % (
                  n, q.GetNumberOfPoints(), "yes" if encloses else "NO", field(q, "MinimumClearance"),
                  field(q, "HausdorffCageToInput"), 100.0 * field(q, "HausdorffCageToInputRelative")))
    print("encloses       : %s" % ("yes" if ok else "NO"))

    # panels: the input and each level around the level inside it, then a cut through all
    bounds = ex.fetch(levels[-1]).GetBounds()
    size = [bounds[1] - bounds[0], bounds[3] - bounds[2], bounds[5] - bounds[4]]
    shift = 1.15 * builtins.max(size[0], size[2])
    centre = [0.5 * (bounds[0] + bounds[1]), 0.5 * (bounds[2] + bounds[3]), 0.5 * (bounds[4] + bounds[5])]
    panels = len(counts) + 1
    width_px, height_px = 520 * panels, 520

    view = ex.white_view(width_px, height_px)

    def moved(source, k):
        return ex.translated(source, k * shift)

    def solid(source, k, color, opacity=1.0):
        d = Show(moved(source, k), view)
        d.ColorArrayName = ["POINTS", ""]
        d.DiffuseColor = color
        d.Specular = 0.2
        d.Opacity = opacity
        return d

    def wire(source, k, color):
        d = Show(moved(source, k), view)
        d.SetRepresentationType("Wireframe")
        d.ColorArrayName = ["POINTS", ""]
        d.AmbientColor = color
        d.DiffuseColor = color
        d.LineWidth = 1.0
        return d

    grey = [0.78, 0.74, 0.68]
    labels = []
    for k, n in enumerate(counts):
        solid(mesh if k == 0 else levels[k - 1], k, grey if k == 0 else COLORS[(k - 1) % len(COLORS)],
              1.0 if k == 0 else 0.55)
        wire(levels[k], k, COLORS[k % len(COLORS)])
        labels.append("cage_%d around %s" % (n, "the input" if k == 0 else "cage_%d" % counts[k - 1]))
    # the cut: a plane through the centre, normal to the view's depth axis (z)
    k = len(counts)
    for i, source in enumerate([mesh] + levels):
        cut = Slice(Input=source)
        cut.SliceType = "Plane"
        cut.SliceType.Origin = centre
        cut.SliceType.Normal = [0.0, 0.0, 1.0]
        d = Show(moved(cut, k), view)
        d.ColorArrayName = ["POINTS", ""]
        d.AmbientColor = [0.2, 0.2, 0.2] if i == 0 else COLORS[(i - 1) % len(COLORS)]
        d.DiffuseColor = d.AmbientColor
        d.LineWidth = 2.0
    labels.append("a cut through all levels")

    ex.frame_and_save(view, bounds, shift, labels, (width_px, height_px), args.screenshot,
                      fill=(0.62, 0.52), lift=-0.04, label_dx=0.09, font=18)
    Delete(view)
    del view
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
