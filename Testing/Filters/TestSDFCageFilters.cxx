// SDFCage — driver of the C++ filter tests: SDFCageFiltersTests <case> <scratch dir> [data dir]
#include "SDFCageTestUtilities.h"

#include "vtkFeatureEdges.h"
#include "vtkPolyData.h"
#include "vtkSphereSource.h"
#include "vtkTriangleFilter.h"

#include <cstring>
#include <functional>
#include <map>

namespace sdfcage_test
{

vtkIdType CountOpenEdges(vtkPolyData* mesh)
{
  vtkNew<vtkFeatureEdges> edges;
  edges->SetInputData(mesh);
  edges->BoundaryEdgesOn();
  edges->NonManifoldEdgesOn();
  edges->FeatureEdgesOff();
  edges->ManifoldEdgesOff();
  edges->Update();
  return edges->GetOutput()->GetNumberOfCells();
}

vtkSmartPointer<vtkPolyData> MakeSphere(double radius, int resolution)
{
  vtkNew<vtkSphereSource> sphere;
  sphere->SetRadius(radius);
  sphere->SetThetaResolution(resolution);
  sphere->SetPhiResolution(resolution);
  vtkNew<vtkTriangleFilter> triangles;
  triangles->SetInputConnection(sphere->GetOutputPort());
  triangles->Update();
  vtkSmartPointer<vtkPolyData> result = vtkSmartPointer<vtkPolyData>::New();
  result->ShallowCopy(triangles->GetOutput());
  return result;
}

} // namespace sdfcage_test

int main(int argc, char* argv[])
{
  using namespace sdfcage_test;
  const std::map<std::string, std::function<int(const Context&)>> cases = {
    { "Sphere", TestSphere },
    { "OptimizeFilter", TestOptimizeFilter },
    { "OptimizeTightOptions", TestOptimizeTightOptions },
    { "OptimizeKeepsPartsApart", TestOptimizeKeepsPartsApart },
    { "BuiltinShape", TestBuiltinShape },
    { "OpenInput", TestOpenInput },
    { "ChooseIsoValueFirst", TestChooseIsoValueFirst },
    { "NoSurface", TestNoSurface },
    { "EmptyInput", TestEmptyInput },
    { "Abort", TestAbort },
    { "DistanceField", TestDistanceField },
    { "Parameters", TestParameters },
    { "DataKnight", TestDataKnight },
    { "DataBunnyOFF", TestDataBunnyOFF },
    { "OFFRoundTrip", TestOFFRoundTrip },
    { "OFFVariants", TestOFFVariants },
    { "OFFMalformed", TestOFFMalformed },
    { "ActivePointsBuiltin", TestActivePointsBuiltin },
    { "ActivePointsErrors", TestActivePointsErrors },
  };
  if (argc < 3 || cases.find(argv[1]) == cases.end())
  {
    std::cerr << "usage: " << argv[0] << " <case> <scratch dir> [data dir]\ncases:";
    for (const auto& c : cases)
    {
      std::cerr << " " << c.first;
    }
    std::cerr << "\n";
    return 2;
  }
  Context context;
  context.Scratch = argv[2];
  context.DataDir = argc > 3 ? argv[3] : "";
  return cases.at(argv[1])(context);
}
