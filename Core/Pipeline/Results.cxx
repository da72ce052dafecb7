#include "Pipeline/Results.h"

#include "Pipeline/CageGenerator.h"

namespace sdfcage
{

namespace
{
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
  ResultField f = integer(name, 0, unit, what);
  f.Type = ResultField::Kind::Real;
  f.Real = v;
  return f;
}
ResultField text(const char* name, const std::string& v, const char* what)
{
  ResultField f = integer(name, 0, "", what);
  f.Type = ResultField::Kind::Text;
  f.Text = v;
  return f;
}
} // namespace

std::vector<ResultField> inputResults(const CageResult& r)
{
  const MeshDefects& d = r.Defects;
  return {
    integer("MergedPoints", d.MergedPoints, "count", "coincident input points merged (split seams, duplicated positions)"),
    real("MergeTolerance", d.MergeTolerance, "input units", "distance under which points were merged"),
    integer("TriangulatedPolygons", d.TriangulatedPolygons, "count", "input polygons with more than 3 points split into triangles"),
    integer("DroppedDegenerateTriangles", d.DroppedDegenerateTriangles, "count", "zero-area triangles dropped"),
    integer("DroppedDuplicateTriangles", d.DroppedDuplicateTriangles, "count", "repeated triangles dropped"),
    integer("IgnoredCells", d.IgnoredCells, "count", "vertex and line cells ignored"),
    integer("InputBoundaryEdges", d.BoundaryEdges, "count", "edges of one triangle (holes, open borders)"),
    integer("InputNonManifoldEdges", d.NonManifoldEdges, "count", "edges of more than two triangles"),
    integer("InputNonManifoldVertices", d.NonManifoldVertices, "count", "vertices whose triangles form several fans"),
    integer("InputInconsistentEdges", d.InconsistentEdges, "count", "edges used twice in the same direction"),
    integer("InputComponents", d.Components, "count", "connected parts of the input"),
    integer("InputClosed", d.usable() ? 1 : 0, "", "1: a closed, consistently oriented 2-manifold"),
    integer("InputGenus", d.usable() ? d.Genus : -1, "", "genus of the input (-1: undefined, the input is not closed)"),
    text("SignMode", signModeName(r.SignUsed), "the inside rule used: flood, winding or unsigned"),
    text("SignReason", r.SignReason, "why that rule"),
    real("WindingTime", r.WindingSeconds, "s", "winding-number sign (part of DistanceFieldTime)"),
    real("IsoValueUsed", r.IsoValueUsed, "relative", "isovalue of the envelope the cage comes from (unit-sphere units)"),
    integer("EnvelopeWidenings", r.EnvelopeWidenings, "count", "envelopes rebuilt with twice the isovalue to reach the target (inputs without a defined topology only)"),
    text("WideningLog", r.WideningLog, "each envelope tried when widening: isovalue, parts, genus, vertices reached, time"),
  };
}

} // namespace sdfcage
