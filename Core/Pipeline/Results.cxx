#include "Pipeline/Results.h"

#include "Envelope/ActivePointAnalysis.h"
#include "Pipeline/CageGenerator.h"
#include "Quality/CageQuality.h"

#include <cstdio>

namespace sdfcage
{

void ResultField::setNumber(double v)
{
  switch (Type)
  {
    case Kind::Flag:
      Integer = v != 0.0 ? 1 : 0;
      break;
    case Kind::Integer:
      Integer = static_cast<long long>(v);
      break;
    case Kind::Real:
      Real = v;
      break;
    case Kind::Text:
      break;
  }
}

std::string ResultField::toString() const
{
  switch (Type)
  {
    case Kind::Flag:
      return Integer ? "yes" : "no";
    case Kind::Integer:
      return std::to_string(Integer);
    case Kind::Real:
    {
      char buffer[32];
      std::snprintf(buffer, sizeof(buffer), "%.6g", Real);
      return buffer;
    }
    case Kind::Text:
      break;
  }
  return Text;
}

const ResultField* findResult(const ResultTable& table, const std::string& name)
{
  for (const ResultField& f : table)
  {
    if (f.Name == name)
      return &f;
  }
  return nullptr;
}

namespace
{
// One row of a table: name, value, unit, description.
ResultField flag(const char* name, bool v, const char* what)
{
  ResultField f;
  f.Name = name;
  f.Type = ResultField::Kind::Flag;
  f.Integer = v ? 1 : 0;
  f.Description = what;
  return f;
}
ResultField integer(const char* name, long long v, const char* unit, const char* what)
{
  ResultField f;
  f.Name = name;
  f.Type = ResultField::Kind::Integer;
  f.Integer = v;
  f.Unit = unit;
  f.Description = what;
  return f;
}
ResultField real(const char* name, double v, const char* unit, const char* what)
{
  ResultField f;
  f.Name = name;
  f.Type = ResultField::Kind::Real;
  f.Real = v;
  f.Unit = unit;
  f.Description = what;
  return f;
}
ResultField text(const char* name, const std::string& v, const char* what)
{
  ResultField f;
  f.Name = name;
  f.Type = ResultField::Kind::Text;
  f.Text = v;
  f.Description = what;
  return f;
}

void append(ResultTable& table, ResultTable rows)
{
  table.insert(table.end(), rows.begin(), rows.end());
}

// The optimization's statistics, shared by the cage run and the optimization filter.
ResultTable optimizationStatistics(const OptimizeResult& o)
{
  return {
    real("EnergyBefore", o.EnergyBefore, "", "optimization energy E_quality of the simplified cage"),
    real("EnergyAfter", o.EnergyAfter, "", "optimization energy E_quality of the optimized cage"),
    real("MinimumAngleBefore", o.MinimumAngleBefore, "degrees", "smallest triangle angle before the optimization"),
    real("MinimumAngleAfter", o.MinimumAngleAfter, "degrees", "smallest triangle angle after the optimization"),
    real("SmallAnglesBefore", 100 * o.SmallAnglesBefore, "percent",
      "triangle angles below the target minimum angle (MIPS, 15 degrees by default) before the optimization"),
    real("SmallAnglesAfter", 100 * o.SmallAnglesAfter, "percent", "the same after the optimization"),
    real("HausdorffBefore", o.HausdorffBefore, "relative",
      "one-sided Hausdorff distance cage -> input before the optimization (unit sphere, branch and bound)"),
    real("HausdorffAfter", o.HausdorffAfter, "relative", "the same after the optimization"),
    real("SpacingBandBefore", 100 * o.SpacingBandBefore, "percent",
      "spacing energy: area of the cage at TargetSpacing +- 20% from the input, before the optimization"),
    real("SpacingBandAfter", 100 * o.SpacingBandAfter, "percent", "the same after the optimization"),
    real("SpacingCloserAfter", 100 * o.SpacingCloserAfter, "percent",
      "spacing energy: area of the optimized cage closer than 0.8 TargetSpacing to the input"),
    real("SpacingFartherAfter", 100 * o.SpacingFartherAfter, "percent",
      "spacing energy: area of the optimized cage farther than 1.2 TargetSpacing from the input"),
    real("OptimizationPartRoom", o.PartClearanceUsed, "relative",
      "distance the optimization kept between the cage's parts: as the simplified cage had them (nested levels; "
      "0: none)"),
    integer("NumberOfMoves", o.Moves, "count", "accepted vertex relocations"),
    integer("NumberOfFlips", o.Flips, "count", "accepted edge flips"),
    integer("NumberOfCollapses", o.Collapses, "count",
      "needle collapses, each paired with an edge split elsewhere (the vertex count stays exact)"),
    integer("NumberOfSweeps", o.Sweeps, "count", "sweeps run (relocation, flips and, MIPS, needle repair)"),
    flag("Reverted", o.Reverted, "the optimized cage failed its verification: the given cage was kept"),
    real("OptimizationTime", o.Seconds, "s", "optimization, verification included"),
  };
}
} // namespace

ResultTable cageResults(const CageResult& r)
{
  const MeshDefects& d = r.Defects;
  const SimplifyResult& s = r.Simplification;
  ResultTable t = {
    // the verdict
    flag(
      "EnclosureVerified", r.EnclosureVerified, "the cage strictly encloses the input with the clearance (verified)"),
    real("MeasuredClearance", r.MinimumClearance, "input units",
      "minimum distance between the cage and the input (exact)"),
    real("MeasuredClearanceRelative", r.MinimumClearanceRelative, "relative",
      "the same, for the input scaled into the unit sphere"),
    integer("VerticesReached", r.VerticesReached, "count", "vertices of the cage"),
    flag("TargetReached", r.TargetReached,
      "the cage has the number of vertices asked for (or no simplification was asked)"),
    text("StopReason", r.StopReason, "why the simplification stopped before the target (empty when it reached it)"),
    // the envelope (paper 3.1)
    integer("RemovedPockets", r.RemovedPockets, "count", "trapped air pockets (inner envelope components) removed"),
    integer("EnvelopeGenus", r.EnvelopeGenus, "", "genus of the envelope"),
    integer("EnvelopeComponents", r.EnvelopeComponents, "count", "connected parts of the envelope"),
    real("VoxelSizeUsed", r.VoxelSizeUsed, "relative", "voxel size of the distance grid, after any refinement"),
    real("AmplificationAlphaUsed", r.AlphaUsed, "",
      "amplification alpha of the kept envelope (0 without active points; lowered where the requested one "
      "would put the envelope within the clearance)"),
    real("AdaptivityUsed", r.AdaptivityUsed, "",
      "isosurface adaptivity of the kept envelope (1 from a topology repair round, lower after a failed extraction)"),
    flag("InputWasFlipped", d.FlippedOrientation, "the input was inward-oriented and was flipped"),
    integer("NumberOfActivePoints", static_cast<long long>(r.NumberOfActivePoints), "count",
      "input points found active (nearly touching another part)"),
    integer("NumberOfActiveSamples", static_cast<long long>(r.NumberOfActiveSamples), "count",
      "samples of the active set A on the surface"),
    text("TopologyWarning", r.TopologyWarning, "set when the envelope's genus or components differ from the input's"),
    // the simplification (paper 3.2)
    integer("Collapses", s.Collapses, "count", "edge collapses performed"),
    integer("CollapsesRejectedByClearance", s.RejectedInput, "count",
      "candidate collapses vetoed by the clearance to the input"),
    integer("CollapsesRejectedBySelfIntersection", s.RejectedSelf, "count",
      "... by a self-intersection or the self clearance"),
    integer("CollapsesRejectedByTopology", s.RejectedTopology, "count", "... by the link condition"),
    integer("CollapsesRejectedByShape", s.RejectedShape, "count", "... by a flip or a needle"),
    integer("RelocatedPlacements", s.Relocated, "count", "infeasible placements replaced by a feasible one"),
    integer("Relaxations", r.Relaxations, "count",
      "MIPS relaxation sweeps of a stalled simplification (each followed by more simplification)"),
    integer("VerticesBeforeRelaxation", r.VerticesBeforeRelaxation, "count",
      "vertices where the simplification stalled above the target before it was relaxed (0: it did not, or relaxation "
      "is off)"),
    real("RelaxationTime", r.RelaxationSeconds, "s", "the relaxation sweeps (part of SimplificationTime)"),
    real("PartClearanceUsed", s.PartClearanceUsed, "relative",
      "room kept between the cage's parts for the next nested level (0: none asked or one part)"),
    // the optional optimization (paper 3.3)
    flag("Optimized", r.Optimized, "the optimization ran and its result is the cage"),
  };
  append(t, optimizationStatistics(r.Optimization));
  append(t,
    {
      // timings
      real("ValidationTime", r.ValidationSeconds, "s", "input validation and repair"),
      real("DistanceFieldTime", r.DistanceFieldSeconds, "s", "distance field (sign and amplification included)"),
      real("ActivePointTime", r.ActivePointSeconds, "s", "active points and their geodesic distances"),
      real("AmplificationTime", r.AmplificationSeconds, "s",
        "amplified field phi xi on the grid (part of DistanceFieldTime)"),
      real("IsosurfaceTime", r.IsosurfaceSeconds, "s", "isosurface extraction"),
      real("VerificationTime", r.VerificationSeconds, "s", "envelope verification"),
      real("SimplificationTime", r.SimplificationSeconds, "s", "constrained simplification"),
      real("CageVerificationTime", r.CageVerificationSeconds, "s", "independent verification of the cage"),
      real("TotalTime", r.TotalSeconds, "s", "the whole run"),
      // what was done to the input, and how its inside was decided
      integer(
        "MergedPoints", d.MergedPoints, "count", "coincident input points merged (split seams, duplicated positions)"),
      real("MergeTolerance", d.MergeTolerance, "input units", "distance under which points were merged"),
      integer("TriangulatedPolygons", d.TriangulatedPolygons, "count",
        "input polygons with more than 3 points split into triangles"),
      integer("DroppedDegenerateTriangles", d.DroppedDegenerateTriangles, "count", "zero-area triangles dropped"),
      integer("DroppedDuplicateTriangles", d.DroppedDuplicateTriangles, "count", "repeated triangles dropped"),
      integer("IgnoredCells", d.IgnoredCells, "count", "vertex and line cells ignored"),
      integer("InputBoundaryEdges", d.BoundaryEdges, "count", "edges of one triangle (holes, open borders)"),
      integer("InputNonManifoldEdges", d.NonManifoldEdges, "count", "edges of more than two triangles"),
      integer("InputNonManifoldVertices", d.NonManifoldVertices, "count", "vertices whose triangles form several fans"),
      integer("InputInconsistentEdges", d.InconsistentEdges, "count", "edges used twice in the same direction"),
      integer("InputComponents", d.Components, "count", "connected parts of the input"),
      integer("InputClosed", d.usable() ? 1 : 0, "", "1: a closed, consistently oriented 2-manifold"),
      integer(
        "InputGenus", d.usable() ? d.Genus : -1, "", "genus of the input (-1: undefined, the input is not closed)"),
      text("SignMode", r.SignReason.empty() ? std::string() : std::string(signModeName(r.SignUsed)),
        "the inside rule used: flood, winding or unsigned (empty when not decided)"),
      text("SignReason", r.SignReason, "why that rule"),
      real("WindingTime", r.WindingSeconds, "s", "winding-number sign (part of DistanceFieldTime)"),
      real(
        "IsoValueUsed", r.IsoValueUsed, "relative", "isovalue of the envelope the cage comes from (unit-sphere units)"),
      integer("EnvelopeWidenings", r.EnvelopeWidenings, "count",
        "envelopes rebuilt with twice the isovalue to reach the target (inputs without a defined topology only)"),
      text("WideningLog", r.WideningLog,
        "each envelope tried when widening (coarse probes first): isovalue, parts, genus, vertices reached, time"),
      integer("EnvelopeProbes", r.EnvelopeProbes, "count",
        "coarse-grid probes of the envelope's parts and genus run to choose the isovalue"),
      integer("IsoValuesSkipped", r.IsoValuesSkipped, "count",
        "isovalues the probes ruled out (too many parts and handles for the target; counted in EnvelopeWidenings)"),
      real("ProbeTime", r.ProbeSeconds, "s", "the coarse-grid probes"),
      integer("EnvelopeAttempts", r.EnvelopeAttempts, "count", "envelopes built on the requested grid"),
      integer("FieldTriangles", r.FieldTriangles, "count",
        "triangles the envelope's distance field came from (fewer than the input's: a clustered proxy)"),
      integer("TopologyRepairs", r.TopologyRepairs, "count",
        "envelopes rebuilt (gap rule, stronger amplification, finer grid) to keep the input's topology"),
      text("TopologyRepairLog", r.TopologyRepairLog, "what each topology repair round did and found"),
      real("ClearanceUsed", r.ClearanceUsedRelative, "relative",
        "clearance every cage triangle keeps (unit-sphere units; lowered by the topology repair only when automatic)"),
    });
  return t;
}

ResultTable optimizeResults(const OptimizeResult& o, double measuredClearanceRelative)
{
  ResultTable t = optimizationStatistics(o);
  append(t,
    {
      real("MeasuredClearance", o.MinimumClearance, "input units",
        "minimum distance between the optimized cage and the input (exact)"),
      real("MeasuredClearanceRelative", measuredClearanceRelative, "relative",
        "the same, for the input scaled into the unit sphere"),
      real("ClearanceUsed", o.ClearanceUsed, "relative", "the clearance enforced"),
    });
  return t;
}

ResultTable activePointResults(const ActivePointAnalysis& a)
{
  return {
    integer("NumberOfActivePoints", static_cast<long long>(a.NumberOfActivePoints), "count",
      "input points found active (nearly touching another part)"),
    integer("NumberOfActiveSamples", static_cast<long long>(a.NumberOfActiveSamples), "count",
      "samples of the active set A on the surface"),
    integer("NumberOfSamples", static_cast<long long>(a.NumberOfSamples), "count", "samples of the surface"),
    integer("NumberOfGapSamples", static_cast<long long>(a.NumberOfGapSamples), "count",
      "active samples only the facing-gap rule found (GapRatio > 0; a topology repair round uses 3)"),
    integer("NumberOfGapRulePoints", static_cast<long long>(a.NumberOfGapRulePoints), "count",
      "input points active by the facing-gap rule (ActiveRule 2)"),
    real("ActivePointTime", a.Seconds, "s", "the whole analysis"),
  };
}

ResultTable qualityResults(const CageQualityResult& q)
{
  const double diagonal = q.Diagonal > 0 ? q.Diagonal : 1.0;
  return {
    flag("Encloses", q.Encloses, "the cage strictly encloses the input"),
    real("MinimumClearance", q.MinimumClearance, "input units",
      "exact minimum distance between the surfaces (0 if they touch)"),
    real("MinimumClearanceRelative", q.MinimumClearance / diagonal, "diagonal",
      "the same, as a fraction of the input's bounding-box diagonal"),
    real("HausdorffCageToInput", q.HausdorffCageToInput, "input units",
      "largest distance from the cage surface to the input (value reached)"),
    real("HausdorffCageToInputRelative", q.HausdorffCageToInput / diagonal, "diagonal",
      "the same, as a fraction of the diagonal"),
    real("HausdorffCageToInputBound", q.HausdorffCageToInputBound, "input units",
      "certified upper bound of HausdorffCageToInput"),
    real("HausdorffInputToCage", q.HausdorffInputToCage, "input units",
      "largest distance from the input surface to the cage (value reached)"),
    real("HausdorffInputToCageRelative", q.HausdorffInputToCage / diagonal, "diagonal",
      "the same, as a fraction of the diagonal"),
    real("HausdorffInputToCageBound", q.HausdorffInputToCageBound, "input units",
      "certified upper bound of HausdorffInputToCage"),
    real("MeanDistanceCageToInput", q.MeanDistanceCageToInput, "input units",
      "area-weighted mean distance from the cage surface to the input"),
    real("MeanDistanceCageToInputRelative", q.MeanDistanceCageToInput / diagonal, "diagonal",
      "the same, as a fraction of the diagonal"),
    integer("SelfIntersections", q.SelfIntersections, "count", "intersecting pairs of non-adjacent cage triangles"),
    integer("InputIntersections", q.InputIntersections, "count", "intersecting or touching cage/input triangle pairs"),
    integer("InputVerticesOutside", q.InputVerticesOutside, "count", "input vertices not strictly inside the cage"),
    integer("CageGenus", q.CageGenus, "", "genus of the cage (-1: not a closed 2-manifold)"),
    integer("InputGenus", q.InputGenus, "", "genus of the input (-1: not a closed 2-manifold)"),
    real("QualityTime", q.Seconds, "s", "the evaluation"),
    text("QualityMessage", q.Message, "why the cage does not enclose, or what could not be evaluated"),
  };
}

} // namespace sdfcage
