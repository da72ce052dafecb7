#include "Envelope/ActivePointAnalysis.h"

#include "Pipeline/CageGenerator.h"
#include "Envelope/SDFIsosurface.h"
#include "Common/Progress.h"
#include "Common/Threads.h"
#include "Spatial/PointGrid.h"

#include <chrono>
#include <memory>

namespace sdfcage
{

ActivePointAnalysis analyzeActivePoints(
  const PolygonMesh& input, const ActivePointAnalysisOptions& options, Progress* progress)
{
  ActivePointAnalysis result;
  const auto start = std::chrono::steady_clock::now();
  auto elapsed = [&]() { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(); };
  const ThreadLimit threads(options.NumberOfThreads);
  const std::string bad = options.ActivePoints.validate();
  if (!bad.empty())
  {
    result.State = Status::InvalidInput;
    result.Message = "invalid active-point parameters: " + bad;
    return result;
  }
  progressStage(progress, "validating input", 0.0, 0.02);
  result.Defects = prepareMesh(input, result.Mesh, options.Validation);
  if (!result.Defects.usableAsInput())
  {
    const bool nothing =
      result.Defects.Empty && result.Defects.NonFinitePoints == 0 && result.Defects.InvalidPointIds == 0;
    result.State = nothing ? Status::EmptyInput : Status::InvalidInput;
    result.Message = result.Defects.inputErrorMessage();
    result.Mesh = TriangleMesh();
    return result;
  }
  if (!result.Defects.usable())
  {
    // the geodesic rule of §3.1 measures along a closed surface
    result.State = Status::InvalidInput;
    result.Message = "active points need a closed, consistently oriented 2-manifold input (the cage filter "
                     "cages any other input by its winding number, without active points): " +
      result.Defects.errorMessage();
    result.Mesh = TriangleMesh();
    return result;
  }
  const Normalization n = Normalization::fit(result.Mesh);
  const TriangleMesh unit = n.toUnit(result.Mesh);

  progressStage(progress, "active points", 0.02, options.GenerateFields ? 0.5 : 1.0);
  ActivePoints active = computeActivePoints(unit, options.ActivePoints, progress);
  if (active.Cancelled || progressCancelled(progress))
  {
    result.State = Status::Cancelled;
    result.Message = "cancelled";
    result.Mesh = TriangleMesh();
    return result;
  }
  const std::size_t np = result.Mesh.Points.size();
  result.Active.assign(active.Active.begin(), active.Active.begin() + np);
  result.GeodesicToActive.resize(np);
  result.Amplification.resize(np);
  for (std::size_t i = 0; i < np; ++i)
  {
    result.GeodesicToActive[i] = n.lengthToInput(active.GeodesicToActive[i]);
    result.Amplification[i] = active.phi(active.GeodesicToActive[i]);
  }
  // the rule per point: the gap-only samples' neighbourhoods (half a spacing, the resolution of
  // the sampling) in a hashed grid of cells of that size
  result.ActiveRule.assign(np, 0);
  {
    PointGrid gapSamples(0.5 * options.ActivePoints.sampleSpacing());
    for (int id : active.GapSamples)
      gapSamples.insert(active.Surface.Points[static_cast<std::size_t>(id)]);
    for (std::size_t i = 0; i < np; ++i)
    {
      if (!result.Active[i])
        continue;
      result.ActiveRule[i] = gapSamples.anyWithin(unit.Points[i]) ? 2 : 1;
      result.NumberOfGapRulePoints += result.ActiveRule[i] == 2 ? 1 : 0;
    }
  }
  result.NumberOfGapSamples = active.NumberOfGapSamples;
  result.NumberOfActivePoints = active.NumberOfActiveInputPoints;
  result.NumberOfActiveSamples = active.NumberOfActiveSamples;
  result.NumberOfSamples = active.NumberOfSamples;

  if (options.GenerateFields)
  {
    progressStage(progress, "distance fields", 0.5, 1.0);
    ScalarImage field, modified;
    std::string error;
    const TriangleMesh& mesh = active.empty() ? unit : active.Surface;
    if (!computeDisplayFields(mesh, options.IsoValue, 0.0, &active, field, active.empty() ? nullptr : &modified, error))
    {
      result.State = Status::Failed;
      result.Message = error;
      result.Mesh = TriangleMesh();
      return result;
    }
    if (progressCancelled(progress))
    {
      result.State = Status::Cancelled;
      result.Message = "cancelled";
      result.Mesh = TriangleMesh();
      return result;
    }
    result.SignedDistance = imageToInput(std::move(field), n);
    if (active.empty())
    {
      result.ModifiedSignedDistance = result.SignedDistance; // phi = 1 everywhere
    }
    else
    {
      result.ModifiedSignedDistance = imageToInput(std::move(modified), n);
    }
  }
  result.State = Status::Ok;
  result.Seconds = elapsed();
  progressUpdate(progress, 1.0);
  return result;
}

} // namespace sdfcage
