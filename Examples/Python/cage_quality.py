"""SDFCage example with plain VTK (the wrapped module `sdfcage`, no ParaView application).

    PYTHONPATH=build/lib/python3/dist-packages /usr/bin/python3 Examples/Python/cage_quality.py \\
        [MESH.off|.obj|.ply|.stl|.vtp] [-n N] [--iso C] [--screenshot FILE.png]

Builds the cage of MESH (or of a sphere) with vtkSDFCageFilter, judges it with
vtkCageQualityFilter, prints the verdicts and renders offscreen: the input (grey, translucent)
under the cage coloured by DistanceToInput (translucent, with its edges). Rendering needs an X
server: on a machine without a display run it under `xvfb-run -a`.
"""
import argparse
import sys

import vtk  # noqa: F401  (ParaView's VTK under /usr/bin/python3; load it before sdfcage)
import sdfcage
from vtkmodules.vtkFiltersCore import vtkTriangleFilter
from vtkmodules.vtkFiltersSources import vtkSphereSource
from vtkmodules.vtkIOGeometry import vtkOBJReader, vtkSTLReader
from vtkmodules.vtkIOImage import vtkPNGWriter
from vtkmodules.vtkIOPLY import vtkPLYReader
from vtkmodules.vtkIOXML import vtkXMLPolyDataReader
from vtkmodules.vtkRenderingAnnotation import vtkScalarBarActor
from vtkmodules.vtkRenderingCore import (vtkActor, vtkPolyDataMapper, vtkRenderer,
                                         vtkRenderWindow, vtkWindowToImageFilter)
import vtkmodules.vtkRenderingOpenGL2  # noqa: F401  (the rendering backend)
import vtkmodules.vtkRenderingFreeType  # noqa: F401  (text of the scalar bar)

READERS = {".off": sdfcage.vtkOFFReader, ".obj": vtkOBJReader, ".ply": vtkPLYReader,
           ".stl": vtkSTLReader, ".vtp": vtkXMLPolyDataReader}


def mesh_source(path):
    if not path:
        sphere = vtkSphereSource()
        sphere.SetThetaResolution(48)
        sphere.SetPhiResolution(48)
        return sphere
    extension = path[path.rfind("."):].lower()
    if extension not in READERS:
        raise SystemExit("error: unknown extension %s (%s)" % (extension, " ".join(READERS)))
    reader = READERS[extension]()
    reader.SetFileName(path)
    triangles = vtkTriangleFilter()  # strips and polygons -> triangles, normals dropped
    triangles.SetInputConnection(reader.GetOutputPort())
    return triangles


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("mesh", nargs="?", help="closed surface mesh (default: a sphere)")
    parser.add_argument("-n", "--vertices", type=int, default=200, help="cage vertices (200)")
    parser.add_argument("--iso", type=float, default=0.02, help="isovalue, relative (0.02)")
    parser.add_argument("--screenshot", default="cage_quality_vtk.png", help="PNG to write")
    args = parser.parse_args()

    source = mesh_source(args.mesh)
    source.Update()
    mesh = source.GetOutput()
    if mesh.GetNumberOfCells() == 0:
        print("error: %s has no cells" % (args.mesh or "the sphere"))
        return 2

    cage = sdfcage.vtkSDFCageFilter()
    cage.SetInputData(mesh)
    cage.SetTargetNumberOfVertices(args.vertices)
    cage.SetIsoValue(args.iso)

    quality = sdfcage.vtkCageQualityFilter()
    quality.SetInputConnection(cage.GetOutputPort(0))
    quality.SetSourceData(mesh)
    quality.Update()
    if cage.GetStatusString() != "Ok":
        print("error: no cage: %s" % cage.GetLastErrorMessage())
        return 1

    result = quality.GetOutput()
    print("cage           : %d points, %d triangles" % (result.GetNumberOfPoints(), result.GetNumberOfCells()))
    print("encloses       : %s %s" % ("yes" if quality.GetEncloses() else "NO", quality.GetQualityMessage()))
    print("clearance      : %.6g (%.3g of the diagonal)" % (quality.GetMinimumClearance(),
                                                          quality.GetMinimumClearanceRelative()))
    print("Hausdorff      : cage->input %.6g, input->cage %.6g" % (quality.GetHausdorffCageToInput(),
                                                                  quality.GetHausdorffInputToCage()))
    print("mean distance  : %.6g" % quality.GetMeanDistanceCageToInput())
    print("genus          : cage %d, input %d" % (quality.GetCageGenus(), quality.GetInputGenus()))
    print("quality time   : %.3f s" % quality.GetQualityTime())

    # --- picture -------------------------------------------------------------------------------
    renderer = vtkRenderer()
    renderer.SetBackground(1.0, 1.0, 1.0)
    mesh_mapper = vtkPolyDataMapper()
    mesh_mapper.SetInputData(mesh)
    mesh_mapper.ScalarVisibilityOff()
    mesh_actor = vtkActor()
    mesh_actor.SetMapper(mesh_mapper)
    mesh_actor.GetProperty().SetColor(0.75, 0.75, 0.75)
    mesh_actor.GetProperty().SetOpacity(0.5)
    renderer.AddActor(mesh_actor)

    distance = result.GetPointData().GetArray("DistanceToInput")
    cage_mapper = vtkPolyDataMapper()
    cage_mapper.SetInputData(result)
    cage_mapper.SetScalarModeToUsePointFieldData()
    cage_mapper.SelectColorArray("DistanceToInput")
    cage_mapper.SetScalarRange(distance.GetRange())
    cage_mapper.GetLookupTable().SetHueRange(0.667, 0.0)  # blue (close) to red (far)
    cage_actor = vtkActor()
    cage_actor.SetMapper(cage_mapper)
    cage_actor.GetProperty().SetOpacity(0.45)
    cage_actor.GetProperty().EdgeVisibilityOn()
    cage_actor.GetProperty().SetEdgeColor(0.1, 0.1, 0.4)
    renderer.AddActor(cage_actor)

    bar = vtkScalarBarActor()
    bar.SetLookupTable(cage_mapper.GetLookupTable())
    bar.SetTitle("DistanceToInput")
    bar.GetTitleTextProperty().SetColor(0, 0, 0)
    bar.GetLabelTextProperty().SetColor(0, 0, 0)
    renderer.AddActor2D(bar)

    window = vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(1200, 800)
    window.AddRenderer(renderer)
    renderer.ResetCamera()
    window.Render()
    grab = vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtkPNGWriter()
    writer.SetFileName(args.screenshot)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    window.Finalize()
    print("screenshot     : %s" % args.screenshot)
    return 0 if quality.GetEncloses() else 1


if __name__ == "__main__":
    sys.exit(main())
