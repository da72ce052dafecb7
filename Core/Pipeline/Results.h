// SDFCage — Core: the results of a run as one table of fields (name, kind, value, unit,
// description). Every way out reads the table: the VTK field data and the filters' getters by
// name, the CLI summary and its JSON report. Adding a result is one line in the table of
// Results.cxx (plus the member of the result struct it reads).
#pragma once

#include <string>
#include <vector>

namespace sdfcage
{

struct ActivePointAnalysis;
struct CageResult;
struct CageQualityResult;
struct OptimizeResult;

struct ResultField
{
  enum class Kind
  {
    Flag,    ///< yes / no: Integer 0 or 1; JSON true/false
    Integer, ///< a count or an index (-1 where stated)
    Real,
    Text
  };
  std::string Name; ///< as in the field data, the getters and the JSON report (CamelCase)
  Kind Type = Kind::Integer;
  long long Integer = 0;   ///< Flag and Integer
  double Real = 0.0;       ///< Real
  std::string Text;        ///< Text
  std::string Unit;        ///< "count", "s", "input units", "relative" (unit sphere), "degrees", "" (flags, text)
  std::string Description; ///< one line for a user

  /// Flag, Integer and Real as a number (0 for text).
  double number() const { return Type == Kind::Real ? Real : static_cast<double>(Integer); }
  /// Sets a Flag, Integer or Real from a number (text is left alone).
  void setNumber(double v);
  /// The value as text ("yes"/"no" for flags, %.6g for reals).
  std::string toString() const;
};

using ResultTable = std::vector<ResultField>;

/// Every result of a cage run (generateCage): outcome and verdicts, the envelope, the
/// simplification and the optional optimization, timings, what was done to the input and how its
/// inside was decided. The names are those of vtkSDFCageFilter's field data and getters and of the
/// CLI's JSON report. A default CageResult gives the table of a run that did not happen.
ResultTable cageResults(const CageResult& result);

/// The optimization's results (vtkCageOptimizeFilter; the cage filter's table has them too).
/// `measuredClearanceRelative` is r.MinimumClearance in unit-sphere units (`r` is in input
/// units when it comes from optimizeCageInInputUnits).
ResultTable optimizeResults(const OptimizeResult& r, double measuredClearanceRelative);

/// The active-point analysis alone (vtkActivePointFilter).
ResultTable activePointResults(const ActivePointAnalysis& a);

/// The judge's verdict and measures (vtkCageQualityFilter, `sdfcage --check`); relative lengths
/// are fractions of the input's bounding-box diagonal.
ResultTable qualityResults(const CageQualityResult& q);

/// The field called `name`, or nullptr.
const ResultField* findResult(const ResultTable& table, const std::string& name);

} // namespace sdfcage
