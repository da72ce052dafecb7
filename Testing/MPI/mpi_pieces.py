"""SDFCage MPI tests: meshes split into pieces (plain VTK).

write_pieces_vtp(mesh, path, n) writes one .vtp file holding n pieces of the mesh (consecutive
runs of cells, each piece with its own copy of the points it uses, as parallel writers make them),
which vtkXMLPolyDataReader / ParaView's XML PolyData reader hand out to the ranks.
"""
import math

from vtkmodules.util.vtkAlgorithm import VTKPythonAlgorithmBase
from vtkmodules.vtkCommonCore import vtkIdList, vtkPoints, vtkUnsignedCharArray
from vtkmodules.vtkCommonDataModel import vtkCellArray, vtkPolyData
from vtkmodules.vtkCommonExecutionModel import vtkAlgorithm, vtkStreamingDemandDrivenPipeline as SDDP
from vtkmodules.vtkIOXML import vtkXMLPolyDataWriter


def piece_of(mesh, k, n):
    """Cells [k*N/n, (k+1)*N/n) of the polygons of `mesh`, with the points they use (renumbered)."""
    polys = mesh.GetPolys()
    count = polys.GetNumberOfCells()
    first, last = k * count // n, (k + 1) * count // n
    out = vtkPolyData()
    points = vtkPoints()
    points.SetDataTypeToDouble()
    cells = vtkCellArray()
    index = {}
    ids = vtkIdList()
    for c in range(first, last):
        polys.GetCellAtId(c, ids)
        new = vtkIdList()
        for j in range(ids.GetNumberOfIds()):
            p = ids.GetId(j)
            if p not in index:
                index[p] = points.InsertNextPoint(mesh.GetPoint(p))
            new.InsertNextId(index[p])
        cells.InsertNextCell(new)
    out.SetPoints(points)
    out.SetPolys(cells)
    return out


def piece_with_ghosts(mesh, k, n):
    """Piece k of n as piece_of, plus one layer of ghost cells (the other pieces' cells that share
    a point with it), flagged as duplicated in the cell array vtkGhostType, as ghost-cell
    generators make them."""
    polys = mesh.GetPolys()
    count = polys.GetNumberOfCells()
    first, last = k * count // n, (k + 1) * count // n
    ids = vtkIdList()
    own_points = set()
    cells = []
    for c in range(count):
        polys.GetCellAtId(c, ids)
        cells.append([ids.GetId(j) for j in range(ids.GetNumberOfIds())])
    for c in range(first, last):
        own_points.update(cells[c])
    chosen = list(range(first, last)) + [c for c in range(count)
                                         if not first <= c < last and any(p in own_points for p in cells[c])]
    out = vtkPolyData()
    points = vtkPoints()
    points.SetDataTypeToDouble()
    polys_out = vtkCellArray()
    ghosts = vtkUnsignedCharArray()
    ghosts.SetName("vtkGhostType")
    index = {}
    for c in chosen:
        new = []
        for p in cells[c]:
            if p not in index:
                index[p] = points.InsertNextPoint(mesh.GetPoint(p))
            new.append(index[p])
        polys_out.InsertNextCell(len(new), new)
        ghosts.InsertNextValue(0 if first <= c < last else 1)  # 1: vtkDataSetAttributes::DUPLICATECELL
    out.SetPoints(points)
    out.SetPolys(polys_out)
    out.GetCellData().AddArray(ghosts)
    return out


class PieceSource(VTKPythonAlgorithmBase):
    """Serves piece k of n of a mesh when asked for it."""

    def __init__(self, mesh):
        VTKPythonAlgorithmBase.__init__(self, nInputPorts=0, nOutputPorts=1, outputType="vtkPolyData")
        self.mesh = mesh

    def RequestInformation(self, request, inInfo, outInfo):
        outInfo.GetInformationObject(0).Set(vtkAlgorithm.CAN_HANDLE_PIECE_REQUEST(), 1)
        return 1

    def RequestData(self, request, inInfo, outInfo):
        info = outInfo.GetInformationObject(0)
        k = info.Get(SDDP.UPDATE_PIECE_NUMBER())
        n = info.Get(SDDP.UPDATE_NUMBER_OF_PIECES())
        vtkPolyData.GetData(outInfo).ShallowCopy(piece_of(self.mesh, k, n))
        return 1


def write_pieces_vtp(mesh, path, n):
    source = PieceSource(mesh)
    writer = vtkXMLPolyDataWriter()
    writer.SetInputConnection(source.GetOutputPort())
    writer.SetFileName(path)
    writer.SetNumberOfPieces(n)
    writer.SetDataModeToBinary()
    if not writer.Write():
        raise RuntimeError("could not write " + path)


def torus_mesh(u=40, v=20, ring=1.0, tube=0.35):
    """A closed triangulated torus (genus 1): u x v quads split into triangles, indices wrapped
    around both seams (so no point is repeated)."""
    points = vtkPoints()
    points.SetDataTypeToDouble()
    for i in range(u):
        a = 2.0 * math.pi * i / u
        for j in range(v):
            b = 2.0 * math.pi * j / v
            r = ring + tube * math.cos(b)
            points.InsertNextPoint(r * math.cos(a), r * math.sin(a), tube * math.sin(b))
    cells = vtkCellArray()
    for i in range(u):
        for j in range(v):
            p00, p10 = i * v + j, ((i + 1) % u) * v + j
            p01, p11 = i * v + (j + 1) % v, ((i + 1) % u) * v + (j + 1) % v
            cells.InsertNextCell(3, (p00, p10, p11))
            cells.InsertNextCell(3, (p00, p11, p01))
    mesh = vtkPolyData()
    mesh.SetPoints(points)
    mesh.SetPolys(cells)
    return mesh
