"""What the SDFCage ParaView examples share: their command line (MESH, --plugin, --screenshot),
loading the plugin, opening a mesh as polydata, reading a result from field data, and a white
render view whose panels stand side by side under a parallel camera, each with a label above it.

Imported by the scripts beside it (they put this folder on sys.path first), under pvpython or
pvbatch. Not an example itself.
"""
import argparse
import builtins
import os

from paraview import servermanager
from paraview import simple

HERE = os.path.dirname(os.path.abspath(__file__))
DEFAULT_PLUGIN = os.path.join(HERE, "..", "..", "build", "lib", "paraview-5.11", "plugins",
                              "SDFCage", "SDFCage.so")


def parser(doc, mesh_help, screenshot):
    """An argument parser with MESH, --plugin and --screenshot; the script adds its own options."""
    p = argparse.ArgumentParser(description=doc.splitlines()[0])
    p.add_argument("mesh", nargs="?", help=mesh_help)
    p.add_argument("--plugin", default=os.environ.get("SDFCAGE_PLUGIN", DEFAULT_PLUGIN),
                   help="path of SDFCage.so (default: the build tree's, or $SDFCAGE_PLUGIN)")
    p.add_argument("--screenshot", default=screenshot, help="PNG to write")
    return p


def load_plugin(path, ns):
    """Loads SDFCage.so into paraview.simple and the script's namespace `ns`; False (with a
    message) when the file is not there."""
    if not os.path.isfile(path):
        print("error: plugin not found: %s (build the project or pass --plugin)" % path)
        return False
    simple.LoadPlugin(path, remote=False, ns=ns)
    return True


def open_surface(path):
    """MESH as polydata: through ParaView's readers (.off through the plugin's, which registers its
    extension: LoadPlugin puts the plugin's functions into the script's namespace, not into
    paraview.simple), then Extract Surface. None (with a message) when ParaView cannot open it."""
    reader = simple.OpenDataFile(path)
    if reader is None:
        print("error: cannot open %s" % path)
        return None
    return simple.ExtractSurface(Input=reader)


def open_input(args, ns, default):
    """Loads the plugin (args.plugin) into `ns`, then opens args.mesh, or makes `default()` when no
    mesh was given: the input as a pipeline proxy, or None (with a message) on failure."""
    if not load_plugin(args.plugin, ns):
        return None
    return open_surface(args.mesh) if args.mesh else default()


def field(data, name):
    """The first value of field-data array `name`, or None."""
    array = data.GetFieldData().GetAbstractArray(name)
    return None if array is None else array.GetValue(0)


def white_view(width, height):
    """A render view on a white background without the orientation axes."""
    view = simple.CreateView("RenderView")
    view.ViewSize = [width, height]
    view.Background = [1.0, 1.0, 1.0]
    view.OrientationAxesVisibility = 0
    try:
        view.UseColorPaletteForBackground = 0
    except AttributeError:  # older ParaView: the background is used as set
        pass
    return view


def translated(source, dx):
    """`source` moved by dx along x (a Transform filter)."""
    t = simple.Transform(Input=source)
    t.Transform.Translate = [dx, 0.0, 0.0]
    return t


def show_in_cage(view, surface, cage, dx, opacity, line_width=1.0):
    """Shows `surface` (beige, shaded) inside `cage` (blue edges), both moved by dx along x."""
    s = simple.Show(translated(surface, dx), view)
    s.ColorArrayName = ["POINTS", ""]
    s.DiffuseColor = [0.78, 0.74, 0.68]
    s.Specular = 0.3
    w = simple.Show(translated(cage, dx), view)
    w.SetRepresentationType("Wireframe")
    w.ColorArrayName = ["POINTS", ""]
    w.AmbientColor = [0.15, 0.35, 0.75]
    w.DiffuseColor = [0.15, 0.35, 0.75]
    w.LineWidth = line_width
    w.Opacity = opacity


def frame_and_save(view, bounds, shift, labels, size, screenshot, fill=(0.62, 0.55), lift=0.05,
                   label_dx=0.15, font=20):
    """Frames len(labels) panels of one object with `bounds`, panel k moved by k*shift along x,
    under a parallel camera looking down -z; puts labels[k] above panel k and saves `size`
    (width, height) pixels to `screenshot`."""
    n = len(labels)
    width, height = (n - 1) * shift + (bounds[1] - bounds[0]), bounds[3] - bounds[2]
    aspect = float(size[0]) / size[1]
    scale = builtins.max(fill[0] * height, fill[1] * width / aspect)
    centre = [0.5 * (n - 1) * shift + 0.5 * (bounds[0] + bounds[1]),
              0.5 * (bounds[2] + bounds[3]) + lift * height, 0.5 * (bounds[4] + bounds[5])]
    simple.Render(view)  # the first render resets the camera: set ours after it
    view.CameraParallelProjection = 1
    view.CameraFocalPoint = centre
    view.CameraPosition = [centre[0], centre[1], centre[2] + 10.0 * width]
    view.CameraViewUp = [0.0, 1.0, 0.0]
    view.CameraParallelScale = scale
    for k, label in enumerate(labels):
        t = simple.Show(simple.Text(Text=label), view)
        t.WindowLocation = "Any Location"
        t.Justification = "Center"
        t.Position = [0.5 + (k - 0.5 * (n - 1)) * shift / (2.0 * scale * aspect) - label_dx, 0.9]
        t.FontSize = font
        t.Color = [0.1, 0.1, 0.1]
    simple.Render(view)
    simple.SaveScreenshot(screenshot, view, ImageResolution=list(size))
    print("screenshot     : %s" % screenshot)


def fetch(proxy):
    """The proxy's output data on this process (servermanager.Fetch)."""
    return servermanager.Fetch(proxy)
