// SDFCage — Core: results as one table (name, value, unit, description), so that a result
// travels to the VTK field data, the filter's generic getters, the CLI summary and the JSON
// report by one line here. The input-repair and inside-rule results of "any mesh in" use it;
// the first wave's results still have their own getters and copies.
#pragma once

#include <string>
#include <vector>

namespace sdfcage
{

struct CageResult;

struct ResultField
{
  enum class Kind
  {
    Integer,
    Real,
    Text
  };
  std::string Name;        ///< as in the field data and the JSON report (CamelCase)
  Kind Type = Kind::Integer;
  long long Integer = 0;
  double Real = 0.0;
  std::string Text;
  std::string Unit;        ///< "count", "s", "input units", "" for flags and text
  std::string Description; ///< one line for a user

  double number() const { return Type == Kind::Real ? Real : static_cast<double>(Integer); }
};

/// What was done to the input and how its inside was decided: merged points, triangulated
/// polygons, dropped triangles, boundary / non-manifold / inconsistent edges, components,
/// closedness, genus (-1 when undefined), the inside rule used and why.
std::vector<ResultField> inputResults(const CageResult& result);

} // namespace sdfcage
