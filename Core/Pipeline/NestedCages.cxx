#include "Pipeline/NestedCages.h"

#include "Common/Progress.h"
#include "Mesh/Validation.h"
#include "Quality/Verification.h"
#include "Spatial/Geometry.h"
#include "Spatial/TriangleTree.h"

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <sstream>
#include <thread>

namespace sdfcage
{

namespace
{
double seconds(std::chrono::steady_clock::time_point t0)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

/// One level's share [Begin, End] of the caller's progress. Reports from the thread that built
/// it are forwarded with the stage named after the level ("level 2 of 3 (500 vertices):
/// simplifying"); reports from worker threads are not (the parent's stage name is only ever
/// written by that thread), cancellation is read from the parent on every thread.
class LevelProgress final : public Progress
{
public:
  LevelProgress(Progress* parent, std::string prefix, double begin, double end)
    : Parent(parent)
    , Prefix(std::move(prefix))
    , Begin(begin)
    , End(end)
    , Owner(std::this_thread::get_id())
  {
  }

protected:
  void report(double overall, const std::string& stage) override
  {
    if (!this->Parent || std::this_thread::get_id() != this->Owner)
      return;
    if (stage != this->LastStage)
    {
      this->LastStage = stage;
      const std::string name = this->Prefix + stage;
      this->Parent->beginStage(name.c_str(), this->Begin, this->End);
    }
    this->Parent->update(overall);
  }
  bool pollCancel() override { return progressCancelled(this->Parent); }

private:
  Progress* Parent;
  std::string Prefix;
  double Begin;
  double End;
  std::thread::id Owner;
  std::string LastStage;
};

int componentsOf(const TriangleMesh& mesh)
{
  std::vector<int> component;
  return triangleComponents(mesh, component);
}

} // namespace

std::string sortNestedCounts(std::vector<int>& counts)
{
  if (counts.empty())
    return "no vertex count given";
  std::vector<int> sorted = counts;
  std::sort(sorted.begin(), sorted.end(), std::greater<int>());
  if (sorted.back() < 1)
    return "every vertex count of nested cages must be at least 1, got " + std::to_string(sorted.back());
  for (std::size_t i = 1; i < sorted.size(); ++i)
  {
    if (sorted[i] == sorted[i - 1])
      return "the vertex count " + std::to_string(sorted[i]) +
        " is given twice: nested cages need distinct counts, one per level";
  }
  counts = std::move(sorted);
  return std::string();
}

std::string parseNestedCounts(const std::string& text, std::vector<int>& counts)
{
  std::vector<int> out;
  std::size_t at = 0;
  while (true)
  {
    const std::size_t comma = text.find(',', at);
    std::string item = text.substr(at, comma == std::string::npos ? std::string::npos : comma - at);
    item.erase(0, item.find_first_not_of(" \t"));
    item.erase(item.find_last_not_of(" \t") + 1);
    char* end = nullptr;
    errno = 0;
    const long long v = item.empty() ? 0 : std::strtoll(item.c_str(), &end, 10);
    if (item.empty() || !end || *end != '\0' || errno != 0 || v < INT_MIN || v > INT_MAX)
    {
      return "expected a vertex count or a comma-separated list of them (e.g. 2000,500,100), got '" + text + "'";
    }
    out.push_back(static_cast<int>(v));
    if (comma == std::string::npos)
      break;
    at = comma + 1;
  }
  counts = std::move(out);
  return std::string();
}

NestedCageResult generateNestedCages(
  const PolygonMesh& input, std::vector<int> counts, const CageOptions& options, Progress* progress)
{
  const auto start = std::chrono::steady_clock::now();
  NestedCageResult nested;
  const std::string bad = sortNestedCounts(counts);
  if (!bad.empty())
  {
    nested.State = Status::InvalidInput;
    nested.Message = bad;
    return nested;
  }
  nested.Counts = counts;
  const std::size_t L = counts.size();

  // the input in its own coordinates, as the pipeline prepares it: the referee of every level
  TriangleMesh inputMesh;
  const MeshDefects defects = prepareMesh(input, inputMesh, options.Validation);
  const bool inputClosed = defects.usable();
  const int inputGenus = inputClosed ? genus(inputMesh) : -1;
  const int inputComponents = componentsOf(inputMesh);

  double inputClearance = 0.0; // level 0's clearance in input units: what every level keeps
  for (std::size_t k = 0; k < L; ++k)
  {
    const auto t0 = std::chrono::steady_clock::now();
    std::ostringstream prefix;
    prefix << "level " << (k + 1) << " of " << L << " (" << counts[k] << " vertices): ";
    LevelProgress levelProgress(progress, prefix.str(), static_cast<double>(k) / L, static_cast<double>(k + 1) / L);

    CageOptions levelOptions = options;
    levelOptions.TargetNumberOfVertices = counts[k];
    // Room between this level's parts for the next one (SimplifyOptions::PartClearance, as far as
    // this level's envelope leaves room): the next envelope lies the isovalue c out from each
    // part (closer only at active points), so parts less than 2c apart fuse in it, and its grid
    // resolves the gap between the two offsets only when that is at least a voxel h wide: parts
    // closer than 2c + h may fuse. h is the requested voxel, not the coarse grid the next level
    // tries first: a coarse envelope that fuses parts fails the topology check and the level
    // falls back to the requested grid, which must resolve the gap. (2c + h) x 1.1: 10% for the
    // next level's normalization. (It
    // was 2.2c until session 51: with the envelope's inside midpoints lifted, the spacing
    // variant's 100-vertex level below kept its parts 0.029 apart, 2.2c of the next level's
    // units, and the 40-vertex level's envelope on the c/2 grid fused them: genus 1, one part.)
    // Without it the simplifier lets
    // parts come as close as the self clearance (c / 16). Measured with two spheres 0.08 apart,
    // levels 400, 100, 40: the 100-vertex level's parts 0.0135 apart without, 0.036 with; the
    // 40-vertex level fused (96 vertices, one part) without, two parts and 40 vertices with.
    // With the room, the levels take the coarse grid first and the mended envelopes like any
    // run (before it they kept the requested grid without mending: the mended envelopes' cages
    // bulged differently and the built-in shape's 60-vertex level of core.NestedCages fused its
    // parts); bunny's 2000/500/100 levels 5.1 -> 2.7 s.
    if (k + 1 < L)
      levelOptions.Simplify.PartClearance =
        1.1 * (2.0 * levelOptions.Envelope.IsoValue + levelOptions.Envelope.voxelSize());
    NestedLevel level;
    level.TargetNumberOfVertices = counts[k];
    if (k == 0)
    {
      level.Result = generateCage(input, levelOptions, &levelProgress);
    }
    else
    {
      // the paper's procedure: the whole method again, on the cage of the level inside
      levelOptions.Envelope.Sign = SignMode::Auto; // a cage is closed and oriented: flood fill
      levelOptions.Envelope.KeepDistanceField = false;
      // Active points only where the input has nearly touching parts (level 0 found some): a
      // coarse cage has no such parts of its own, but its long edges fool the geodesic test
      // (measured: 5 spurious active points on a 60-vertex cage of a cube, whose envelope then
      // grew from 7k to 115k points and stalled the simplification at 1105 of 20 vertices).
      levelOptions.Envelope.UseActivePoints =
        options.Envelope.UseActivePoints && nested.Levels[0].Result.NumberOfActivePoints > 0;
      level.Result =
        generateCage(PolygonMesh::fromTriangles(nested.Levels[k - 1].Result.Cage), levelOptions, &levelProgress);
    }
    const CageResult& r = level.Result;
    if (r.State != Status::Ok)
    {
      // a cancel, an error: the finished levels are kept (each is valid and verified)
      nested.State = r.State;
      std::ostringstream msg;
      msg << "level " << (k + 1) << " (" << counts[k] << " vertices)" << (k > 0 ? ", built on the level inside it" : "")
          << ": " << (r.Message.empty() ? std::string("no reason given") : r.Message);
      nested.Message =
        r.State == Status::Cancelled ? "cancelled; " + std::to_string(k) + " level(s) finished" : msg.str();
      if (k == 0 && r.State != Status::Cancelled)
      {
        nested.Message = r.Message;                // the input's own error, as a single run gives it
        nested.Levels.push_back(std::move(level)); // its defects and envelope, for the caller to report
      }
      nested.TotalSeconds = seconds(start);
      return nested;
    }

    // independent re-verification in the input's coordinates; rounding of the unit-sphere
    // mapping is far below a millionth of the clearance
    constexpr double rounding = 1.0 - 1e-6;
    const double levelClearance = r.Normalize.lengthToInput(r.ClearanceUsedRelative) * rounding;
    if (k == 0)
      inputClearance = levelClearance;
    std::string why;
    if (k == 0)
    {
      // the pipeline's own final check (verifyEnclosure on the input, exact minimum) is this one
      level.VerifiedAgainstInput = level.VerifiedAgainstInside = r.EnclosureVerified;
      level.ClearanceToInput = level.ClearanceToInside = r.MinimumClearance;
      if (!r.EnclosureVerified)
        level.VerificationMessage = "against the input: not verified";
    }
    else
    {
      const TriangleMesh& inside = nested.Levels[k - 1].Result.Cage;
      level.VerifiedAgainstInside =
        verifyEnclosure(inside, r.Cage, levelClearance, level.ClearanceToInside, why, nullptr, &levelProgress);
      if (!why.empty())
        level.VerificationMessage = "against the level inside: " + why;
      why.clear();
      level.VerifiedAgainstInput =
        verifyEnclosure(inputMesh, r.Cage, inputClearance, level.ClearanceToInput, why, nullptr, &levelProgress);
      if (!why.empty())
        level.VerificationMessage +=
          (level.VerificationMessage.empty() ? "" : "; ") + std::string("against the input: ") + why;
    }
    level.CageGenus = genus(r.Cage);
    level.CageComponents = componentsOf(r.Cage);
    level.TopologyKept = inputClosed && level.CageGenus == inputGenus && level.CageComponents == inputComponents;
    if (k > 0 && level.CageComponents < nested.Levels[k - 1].CageComponents)
    {
      // parts fused: say whether any enclosing cage could have kept them apart. Each part of this
      // level keeps the clearance from the level inside, and two parts keep the self clearance
      // from each other, so parts of the level inside closer than twice the clearance plus the
      // self clearance cannot stay apart, whatever the vertex count.
      const double clearance = r.Normalize.lengthToInput(r.ClearanceUsedRelative);
      const double needed = 2.0 * clearance + clearance / 4;
      const double gap = distanceBetweenParts(nested.Levels[k - 1].Result.Cage, needed);
      if (gap < needed)
      {
        std::ostringstream why;
        why << "the parts of the level inside are " << gap << " apart (input units), less than twice the clearance "
            << "plus the self clearance (" << needed
            << "): no cage enclosing it with the clearance can keep them apart, whatever its vertex count";
        level.Result.TopologyWarning += (level.Result.TopologyWarning.empty() ? "" : "; ") + why.str();
      }
    }
    level.Seconds = seconds(t0);
    const bool verified = level.VerifiedAgainstInside && level.VerifiedAgainstInput;
    const bool cancelled = progressCancelled(progress);
    nested.Levels.push_back(std::move(level));
    if (!verified && !cancelled)
    {
      nested.State = Status::VerificationFailed;
      nested.Message = "level " + std::to_string(k + 1) + " (" + std::to_string(counts[k]) +
        " vertices) failed its re-verification " + nested.Levels.back().VerificationMessage;
      nested.TotalSeconds = seconds(start);
      return nested;
    }
    if (cancelled)
    {
      nested.Levels.pop_back(); // a verification cut short proves nothing
      nested.State = Status::Cancelled;
      nested.Message = "cancelled; " + std::to_string(k) + " level(s) finished";
      nested.TotalSeconds = seconds(start);
      return nested;
    }
  }
  nested.State = Status::Ok;
  nested.TotalSeconds = seconds(start);
  progressUpdate(progress, 1.0);
  return nested;
}

ResultTable nestedLevelResults(const NestedLevel& level, int index)
{
  auto make = [](const char* name, ResultField::Kind kind, const char* unit, const char* what) {
    ResultField f;
    f.Name = name;
    f.Type = kind;
    f.Unit = unit;
    f.Description = what;
    return f;
  };
  using K = ResultField::Kind;
  ResultTable t;
  t.push_back(make("Level", K::Integer, "count", "position in the hierarchy, 0 the finest"));
  t.back().Integer = index;
  t.push_back(make("TargetNumberOfVertices", K::Integer, "count", "vertex count asked for this level"));
  t.back().Integer = level.TargetNumberOfVertices;
  t.push_back(make("VerifiedAgainstInside", K::Flag, "",
    "this cage strictly encloses the level inside it (the input for the finest) with the clearance (re-verified)"));
  t.back().Integer = level.VerifiedAgainstInside ? 1 : 0;
  t.push_back(make("ClearanceToInside", K::Real, "input units", "exact minimum distance to the level inside it"));
  t.back().Real = level.ClearanceToInside;
  t.push_back(make("VerifiedAgainstInput", K::Flag, "",
    "this cage strictly encloses the input with the finest level's clearance (re-verified)"));
  t.back().Integer = level.VerifiedAgainstInput ? 1 : 0;
  t.push_back(make("ClearanceToInput", K::Real, "input units", "exact minimum distance to the input"));
  t.back().Real = level.ClearanceToInput;
  t.push_back(make("CageGenus", K::Integer, "count", "genus of this cage"));
  t.back().Integer = level.CageGenus;
  t.push_back(make("CageComponents", K::Integer, "count", "parts of this cage"));
  t.back().Integer = level.CageComponents;
  t.push_back(make("TopologyKept", K::Flag, "", "genus and parts equal to the (closed) input's"));
  t.back().Integer = level.TopologyKept ? 1 : 0;
  t.push_back(make("LevelTime", K::Real, "s", "this level's run and re-verification"));
  t.back().Real = level.Seconds;
  return t;
}

} // namespace sdfcage
