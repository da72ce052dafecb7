#include "SDFCageParallel.h"

#include "vtkAlgorithm.h"
#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDataSetAttributes.h"
#include "vtkExecutive.h"
#include "vtkType.h"
#include "vtkFieldData.h"
#include "vtkIdList.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkMultiProcessStream.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <unordered_map>

namespace sdfcage_vtk
{
namespace
{

// Points of different pieces closer than this fraction of the joined bounding box's diagonal (in
// each coordinate) are one point: far below Core's merge tolerance (1e-9), far above rounding.
constexpr double SeamTolerance = 1e-12;

vtkPolyData* InputOf(vtkInformationVector** inputVector, int port)
{
  return inputVector[port] && inputVector[port]->GetNumberOfInformationObjects() > 0
    ? vtkPolyData::GetData(inputVector[port], 0)
    : nullptr;
}

//------------------------------------------------------------------------------
// Seam points of different pieces: the same point computed by two processes may differ in the
// last bits (a sphere source's seam), so points of different pieces closer than a tolerance (in
// each coordinate) are one point. Bins of the tolerance's size; a point is looked for in its bin
// and the 26 around it.
class SeamPointMerger
{
public:
  explicit SeamPointMerger(double tolerance)
    : Tolerance(tolerance)
  {
  }

  /// The id of an earlier point of another piece within the tolerance, or -1.
  vtkIdType find(const double x[3], std::size_t piece, vtkPoints* points) const
  {
    const Bin b = this->binOf(x);
    for (int dx = -1; dx <= 1; ++dx)
    {
      for (int dy = -1; dy <= 1; ++dy)
      {
        for (int dz = -1; dz <= 1; ++dz)
        {
          auto range = this->Bins.equal_range(Bin{ b[0] + dx, b[1] + dy, b[2] + dz });
          for (auto it = range.first; it != range.second; ++it)
          {
            if (it->second.second == piece)
            {
              continue;
            }
            double y[3];
            points->GetPoint(it->second.first, y);
            if (std::abs(x[0] - y[0]) <= this->Tolerance && std::abs(x[1] - y[1]) <= this->Tolerance &&
              std::abs(x[2] - y[2]) <= this->Tolerance)
            {
              return it->second.first;
            }
          }
        }
      }
    }
    return -1;
  }

  void add(const double x[3], vtkIdType id, std::size_t piece)
  {
    this->Bins.emplace(this->binOf(x), std::make_pair(id, piece));
  }

private:
  using Bin = std::array<long long, 3>;
  struct BinHash
  {
    std::size_t operator()(const Bin& b) const
    {
      std::uint64_t h = 1469598103934665603ULL;
      for (long long v : b)
      {
        h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ULL;
        h ^= h >> 29;
      }
      return static_cast<std::size_t>(h);
    }
  };
  Bin binOf(const double x[3]) const
  {
    Bin b;
    for (int k = 0; k < 3; ++k)
    {
      b[static_cast<std::size_t>(k)] = this->Tolerance > 0
        ? static_cast<long long>(std::max(-4e18, std::min(4e18, std::floor(x[k] / this->Tolerance))))
        : 0;
    }
    return b;
  }

  double Tolerance;
  std::unordered_multimap<Bin, std::pair<vtkIdType, std::size_t>, BinHash> Bins;
};

//------------------------------------------------------------------------------
// Field data through a vtkMultiProcessStream: numeric arrays (values as doubles: exact for every
// integer below 2^53 and for floats and doubles) and string arrays; other arrays are skipped.
void WriteFieldData(vtkFieldData* fd, vtkMultiProcessStream& stream)
{
  std::vector<vtkAbstractArray*> arrays;
  for (int i = 0; fd && i < fd->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* a = fd->GetAbstractArray(i);
    if (a && a->GetName() && (vtkArrayDownCast<vtkDataArray>(a) || vtkArrayDownCast<vtkStringArray>(a)))
    {
      arrays.push_back(a);
    }
  }
  stream << static_cast<int>(arrays.size());
  for (vtkAbstractArray* a : arrays)
  {
    stream << std::string(a->GetName()) << a->GetDataType() << a->GetNumberOfComponents()
           << static_cast<vtkTypeInt64>(a->GetNumberOfValues());
    if (auto* s = vtkArrayDownCast<vtkStringArray>(a))
    {
      for (vtkIdType v = 0; v < s->GetNumberOfValues(); ++v)
      {
        stream << s->GetValue(v);
      }
    }
    else
    {
      auto* d = vtkArrayDownCast<vtkDataArray>(a);
      for (vtkIdType v = 0; v < d->GetNumberOfValues(); ++v)
      {
        stream << d->GetComponent(v / d->GetNumberOfComponents(), static_cast<int>(v % d->GetNumberOfComponents()));
      }
    }
  }
}

void ReadFieldData(vtkMultiProcessStream& stream, vtkFieldData* fd)
{
  int count = 0;
  stream >> count;
  for (int i = 0; i < count; ++i)
  {
    std::string name;
    int type = 0, components = 1;
    vtkTypeInt64 values = 0;
    stream >> name >> type >> components >> values;
    vtkSmartPointer<vtkAbstractArray> a = vtk::TakeSmartPointer(vtkAbstractArray::CreateArray(type));
    a->SetName(name.c_str());
    a->SetNumberOfComponents(components);
    a->SetNumberOfValues(static_cast<vtkIdType>(values));
    if (auto* s = vtkArrayDownCast<vtkStringArray>(a))
    {
      for (vtkIdType v = 0; v < values; ++v)
      {
        std::string text;
        stream >> text;
        s->SetValue(v, text);
      }
    }
    else
    {
      auto* d = vtkArrayDownCast<vtkDataArray>(a);
      for (vtkIdType v = 0; v < values; ++v)
      {
        double x = 0.0;
        stream >> x;
        d->SetComponent(v / components, static_cast<int>(v % components), x);
      }
    }
    fd->AddArray(a);
  }
}

//------------------------------------------------------------------------------
// An image's geometry and point arrays (names, types, components; no values).
void WriteImageLayout(vtkImageData* image, vtkMultiProcessStream& stream)
{
  double origin[3] = { 0, 0, 0 }, spacing[3] = { 1, 1, 1 };
  if (image)
  {
    image->GetOrigin(origin);
    image->GetSpacing(spacing);
  }
  stream << origin[0] << origin[1] << origin[2] << spacing[0] << spacing[1] << spacing[2];
  vtkPointData* pd = image ? image->GetPointData() : nullptr;
  const int n = pd ? pd->GetNumberOfArrays() : 0;
  stream << n;
  for (int i = 0; i < n; ++i)
  {
    vtkAbstractArray* a = pd->GetAbstractArray(i);
    stream << std::string(a->GetName() ? a->GetName() : "") << a->GetDataType() << a->GetNumberOfComponents()
           << (pd->GetScalars() == a);
  }
}

void ReadImageLayout(vtkMultiProcessStream& stream, vtkImageData* image)
{
  double origin[3], spacing[3];
  stream >> origin[0] >> origin[1] >> origin[2] >> spacing[0] >> spacing[1] >> spacing[2];
  int n = 0;
  stream >> n;
  if (image)
  {
    image->Initialize();
    image->SetExtent(0, -1, 0, -1, 0, -1);
    image->SetOrigin(origin);
    image->SetSpacing(spacing);
  }
  for (int i = 0; i < n; ++i)
  {
    std::string name;
    int type = 0, components = 1;
    bool scalars = false;
    stream >> name >> type >> components >> scalars;
    if (!image)
    {
      continue;
    }
    vtkSmartPointer<vtkAbstractArray> a = vtk::TakeSmartPointer(vtkAbstractArray::CreateArray(type));
    a->SetName(name.c_str());
    a->SetNumberOfComponents(components);
    auto* d = vtkArrayDownCast<vtkDataArray>(a);
    if (scalars && d)
    {
      image->GetPointData()->SetScalars(d);
    }
    else
    {
      image->GetPointData()->AddArray(a);
    }
  }
}

bool IsDuplicateGhost(vtkUnsignedCharArray* ghosts, vtkIdType cellId)
{
  return ghosts && (ghosts->GetValue(cellId) & vtkDataSetAttributes::DUPLICATECELL) != 0;
}

} // namespace

//------------------------------------------------------------------------------
void RequestSamePieceWithoutGhosts(vtkInformationVector** inputVector, int numberOfInputPorts,
  vtkInformationVector* outputVector, vtkInformation* request)
{
  int port =
    request && request->Has(vtkExecutive::FROM_OUTPUT_PORT()) ? request->Get(vtkExecutive::FROM_OUTPUT_PORT()) : 0;
  if (port < 0 || port >= outputVector->GetNumberOfInformationObjects())
  {
    port = 0;
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(port);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  const int piece =
    outInfo && outInfo->Has(SDDP::UPDATE_PIECE_NUMBER()) ? outInfo->Get(SDDP::UPDATE_PIECE_NUMBER()) : 0;
  const int pieces =
    outInfo && outInfo->Has(SDDP::UPDATE_NUMBER_OF_PIECES()) ? outInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES()) : 1;
  for (int p = 0; p < numberOfInputPorts; ++p)
  {
    for (int c = 0; inputVector[p] && c < inputVector[p]->GetNumberOfInformationObjects(); ++c)
    {
      vtkInformation* inInfo = inputVector[p]->GetInformationObject(c);
      inInfo->Set(SDDP::UPDATE_PIECE_NUMBER(), piece);
      inInfo->Set(SDDP::UPDATE_NUMBER_OF_PIECES(), pieces);
      inInfo->Set(SDDP::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
    }
  }
}

//------------------------------------------------------------------------------
vtkMultiProcessController* DistributingController(vtkInformationVector** inputVector)
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (!controller || controller->GetNumberOfProcesses() <= 1 || !inputVector[0] ||
    inputVector[0]->GetNumberOfInformationObjects() == 0)
  {
    return nullptr;
  }
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  using SDDP = vtkStreamingDemandDrivenPipeline;
  const int pieces = inInfo->Has(SDDP::UPDATE_NUMBER_OF_PIECES()) ? inInfo->Get(SDDP::UPDATE_NUMBER_OF_PIECES()) : 1;
  return pieces == controller->GetNumberOfProcesses() ? controller : nullptr;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkPolyData> JoinPieces(const std::vector<vtkPolyData*>& pieces, vtkIdType* mergedPoints)
{
  auto output = vtkSmartPointer<vtkPolyData>::New();
  std::vector<vtkPolyData*> used;
  vtkIdType totalPoints = 0;
  for (vtkPolyData* p : pieces)
  {
    if (p && (p->GetNumberOfPoints() > 0 || p->GetNumberOfCells() > 0))
    {
      used.push_back(p);
      totalPoints += p->GetNumberOfPoints();
    }
  }
  if (mergedPoints)
  {
    *mergedPoints = 0;
  }
  if (used.empty())
  {
    return output;
  }

  // the arrays every piece has (vtkGhostType is dropped from the joined surface)
  vtkDataSetAttributes::FieldList pointFields(static_cast<int>(used.size()));
  vtkDataSetAttributes::FieldList cellFields(static_cast<int>(used.size()));
  for (std::size_t i = 0; i < used.size(); ++i)
  {
    if (i == 0)
    {
      pointFields.InitializeFieldList(used[i]->GetPointData());
      cellFields.InitializeFieldList(used[i]->GetCellData());
    }
    else
    {
      pointFields.IntersectFieldList(used[i]->GetPointData());
      cellFields.IntersectFieldList(used[i]->GetCellData());
    }
  }

  // points: a point of a later piece within the seam tolerance of a point of an earlier piece is
  // that point
  double bounds[6] = { VTK_DOUBLE_MAX, VTK_DOUBLE_MIN, VTK_DOUBLE_MAX, VTK_DOUBLE_MIN, VTK_DOUBLE_MAX, VTK_DOUBLE_MIN };
  for (vtkPolyData* p : used)
  {
    if (p->GetNumberOfPoints() > 0)
    {
      const double* b = p->GetPoints()->GetBounds();
      for (int k = 0; k < 3; ++k)
      {
        bounds[2 * k] = std::min(bounds[2 * k], b[2 * k]);
        bounds[2 * k + 1] = std::max(bounds[2 * k + 1], b[2 * k + 1]);
      }
    }
  }
  double diagonal = 0.0;
  for (int k = 0; k < 3 && bounds[0] <= bounds[1]; ++k)
  {
    diagonal += (bounds[2 * k + 1] - bounds[2 * k]) * (bounds[2 * k + 1] - bounds[2 * k]);
  }
  SeamPointMerger merger(SeamTolerance * std::sqrt(diagonal));
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->Allocate(totalPoints);
  vtkPointData* outPD = output->GetPointData();
  outPD->CopyAllocate(pointFields, totalPoints);
  std::vector<std::vector<vtkIdType>> pointMap(used.size());
  vtkIdType merged = 0;
  for (std::size_t i = 0; i < used.size(); ++i)
  {
    vtkPolyData* piece = used[i];
    const vtkIdType n = piece->GetNumberOfPoints();
    pointMap[i].resize(static_cast<std::size_t>(n));
    double x[3];
    for (vtkIdType j = 0; j < n; ++j)
    {
      piece->GetPoint(j, x);
      const vtkIdType earlier = i > 0 ? merger.find(x, i, points) : -1;
      if (earlier >= 0)
      {
        pointMap[i][static_cast<std::size_t>(j)] = earlier;
        ++merged;
        continue;
      }
      const vtkIdType id = points->InsertNextPoint(x);
      pointMap[i][static_cast<std::size_t>(j)] = id;
      outPD->CopyData(pointFields, piece->GetPointData(), static_cast<int>(i), j, id);
      if (used.size() > 1)
      {
        merger.add(x, id, i);
      }
    }
  }
  output->SetPoints(points);
  outPD->RemoveArray(vtkDataSetAttributes::GhostArrayName());
  if (mergedPoints)
  {
    *mergedPoints = merged;
  }

  // cells, in vtkPolyData's order (verts, lines, polys, strips: cell ids follow it), without
  // duplicated ghost cells
  vtkCellData* outCD = output->GetCellData();
  vtkIdType totalCells = 0;
  for (vtkPolyData* p : used)
  {
    totalCells += p->GetNumberOfCells();
  }
  outCD->CopyAllocate(cellFields, totalCells);
  vtkIdType nextCell = 0;
  vtkNew<vtkIdList> ids;
  auto join = [&](vtkCellArray* (vtkPolyData::*get)(), vtkIdType (*offset)(vtkPolyData*)) {
    vtkNew<vtkCellArray> cells;
    for (std::size_t i = 0; i < used.size(); ++i)
    {
      vtkPolyData* piece = used[i];
      vtkCellArray* in = (piece->*get)();
      if (!in || in->GetNumberOfCells() == 0)
      {
        continue;
      }
      auto* ghosts =
        vtkArrayDownCast<vtkUnsignedCharArray>(piece->GetCellData()->GetArray(vtkDataSetAttributes::GhostArrayName()));
      const vtkIdType first = offset(piece);
      auto it = vtk::TakeSmartPointer(in->NewIterator());
      vtkIdType local = 0;
      for (it->GoToFirstCell(); !it->IsDoneWithTraversal(); it->GoToNextCell(), ++local)
      {
        const vtkIdType cellId = first + local;
        if (IsDuplicateGhost(ghosts, cellId))
        {
          continue;
        }
        it->GetCurrentCell(ids);
        for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
        {
          ids->SetId(k, pointMap[i][static_cast<std::size_t>(ids->GetId(k))]);
        }
        cells->InsertNextCell(ids);
        outCD->CopyData(cellFields, piece->GetCellData(), static_cast<int>(i), cellId, nextCell++);
      }
    }
    return cells;
  };
  // the cell ids of a vtkPolyData: verts first, then lines, polys, strips
  auto verts = join(&vtkPolyData::GetVerts, [](vtkPolyData*) -> vtkIdType { return 0; });
  auto lines = join(&vtkPolyData::GetLines, [](vtkPolyData* p) -> vtkIdType { return p->GetNumberOfVerts(); });
  auto polys = join(
    &vtkPolyData::GetPolys, [](vtkPolyData* p) -> vtkIdType { return p->GetNumberOfVerts() + p->GetNumberOfLines(); });
  auto strips = join(&vtkPolyData::GetStrips,
    [](vtkPolyData* p) -> vtkIdType { return p->GetNumberOfVerts() + p->GetNumberOfLines() + p->GetNumberOfPolys(); });
  output->SetVerts(verts);
  output->SetLines(lines);
  output->SetPolys(polys);
  output->SetStrips(strips);
  outCD->RemoveArray(vtkDataSetAttributes::GhostArrayName());
  output->GetFieldData()->ShallowCopy(used[0]->GetFieldData()); // e.g. the results a cage carries
  output->Squeeze();
  return output;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkPolyData> JoinOnProcessZero(vtkMultiProcessController* controller, vtkPolyData* piece)
{
  vtkNew<vtkPolyData> send;
  if (piece)
  {
    send->ShallowCopy(piece);
  }
  std::vector<vtkSmartPointer<vtkDataObject>> received;
  controller->Gather(send, received, 0);
  if (controller->GetLocalProcessId() != 0)
  {
    return nullptr;
  }
  std::vector<vtkPolyData*> pieces;
  for (const auto& object : received)
  {
    pieces.push_back(vtkPolyData::SafeDownCast(object));
  }
  return JoinPieces(pieces);
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkPolyData> JoinOnEveryProcess(vtkMultiProcessController* controller, vtkPolyData* piece)
{
  vtkSmartPointer<vtkPolyData> whole = JoinOnProcessZero(controller, piece);
  if (!whole)
  {
    whole = vtkSmartPointer<vtkPolyData>::New();
  }
  controller->Broadcast(whole, 0);
  return whole;
}

//------------------------------------------------------------------------------
int RunOnWholeSurface(vtkAlgorithm* self, vtkInformationVector** inputVector, vtkInformationVector* outputVector,
  const WholeSurfaceRun& run, const ExecuteFunction& execute, const AdoptFunction& adopt)
{
  const int ports = self->GetNumberOfInputPorts();
  vtkMultiProcessController* controller = DistributingController(inputVector);
  std::vector<vtkPolyData*> inputs(static_cast<std::size_t>(ports), nullptr);
  if (!controller)
  {
    for (int p = 0; p < ports; ++p)
    {
      inputs[static_cast<std::size_t>(p)] = InputOf(inputVector, p);
    }
    return execute(inputs);
  }

  // gather every port's pieces on process 0 (collective)
  const bool root = controller->GetLocalProcessId() == 0;
  std::vector<vtkSmartPointer<vtkPolyData>> whole(static_cast<std::size_t>(ports));
  for (int p = 0; p < ports; ++p)
  {
    vtkPolyData* piece = InputOf(inputVector, p);
    vtkSmartPointer<vtkPolyData> joined = JoinOnProcessZero(controller, piece);
    if (root && piece)
    {
      whole[static_cast<std::size_t>(p)] = joined;
      inputs[static_cast<std::size_t>(p)] = joined;
    }
  }

  int rc = 1;
  if (root)
  {
    rc = execute(inputs);
  }
  else
  {
    for (int o = 0; o < outputVector->GetNumberOfInformationObjects(); ++o)
    {
      if (vtkDataObject* out = vtkDataObject::GetData(outputVector, o))
      {
        out->Initialize();
      }
    }
  }

  // what every process reports: process 0's return code, results and image layout (collective)
  vtkMultiProcessStream stream;
  if (root)
  {
    stream << rc;
    vtkDataObject* carrier = vtkDataObject::GetData(outputVector, run.ResultsPort);
    WriteFieldData(carrier ? carrier->GetFieldData() : nullptr, stream);
    for (int port : run.ImagePorts)
    {
      WriteImageLayout(vtkImageData::GetData(outputVector, port), stream);
    }
  }
  controller->Broadcast(stream, 0);
  if (!root)
  {
    stream >> rc;
    vtkDataObject* carrier = vtkDataObject::GetData(outputVector, run.ResultsPort);
    vtkNew<vtkFieldData> fd;
    ReadFieldData(stream, fd);
    if (carrier)
    {
      carrier->GetFieldData()->ShallowCopy(fd);
    }
    for (int port : run.ImagePorts)
    {
      ReadImageLayout(stream, vtkImageData::GetData(outputVector, port));
    }
    if (adopt)
    {
      adopt(fd);
    }
  }
  return rc;
}

//------------------------------------------------------------------------------
void ReadResultArrays(vtkFieldData* fd, sdfcage::ResultTable& table)
{
  if (!fd)
  {
    return;
  }
  for (sdfcage::ResultField& f : table)
  {
    vtkAbstractArray* a = fd->GetAbstractArray(f.Name.c_str());
    if (!a || a->GetNumberOfValues() < 1)
    {
      continue;
    }
    if (f.Type == sdfcage::ResultField::Kind::Text)
    {
      f.Text = a->GetVariantValue(0).ToString();
    }
    else if (auto* d = vtkArrayDownCast<vtkDataArray>(a))
    {
      f.setNumber(d->GetComponent(0, 0));
    }
  }
}

//------------------------------------------------------------------------------
std::string FieldText(vtkFieldData* fd, const char* name)
{
  auto* s = fd ? vtkArrayDownCast<vtkStringArray>(fd->GetAbstractArray(name)) : nullptr;
  return s && s->GetNumberOfValues() > 0 ? s->GetValue(0) : std::string();
}

} // namespace sdfcage_vtk
