// SDFCage — the command-line program: a surface mesh (or the built-in shape) -> its cage.
//
//   sdfcage [INPUT] [-o OUT] [-n N | -n N1,N2,...] [--iso C] [--voxel H] [--clearance D] [--adaptivity A]
//           [--refinements N] [--sign auto|flood|winding|unsigned] [--no-active-points] [--active-radius R] [--geodesic-threshold L]
//           [--alpha A] [--beta B] [--optimize none|mips|spacing] [--spacing H] [--iterations K]
//           [--hausdorff-factor F] [--target-angle DEG] [--sweeps K]
//           [--report FILE.json] [--screenshot FILE.png] [--threads N] [--quiet] [--verbose]
//           [--help] [--version]
//   sdfcage --check INPUT CAGE [--report FILE.json] [--quiet]
//
// Exit codes: 0 cage written and enclosure verified; 1 enclosure could not be verified;
// 2 bad command line or unusable input; 3 could not write an output, render, or other failure;
// 130 interrupted (Ctrl-C).
#include "CLIAllocator.h"
#include "CLICheck.h"
#include "CLIMeshIO.h"
#include "CLIMessages.h"
#include "CLIMultiBlock.h"
#include "CLIReport.h"
#include "CLIScreenshot.h"

#include "Envelope/Envelope.h"      // sdfcage::EnvelopeOptions: what "0 = automatic" resolves to
#include "Pipeline/CageGenerator.h" // sdfcage::CageResult, for the names of the result table
#include "Pipeline/NestedCages.h"   // sdfcage::parseNestedCounts, sortNestedCounts

#include <vtkSDFCageFilter.h>

#include <vtkAbstractArray.h>
#include <vtkCommand.h>
#include <vtkCompositeDataSet.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkInformation.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkStringArray.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkVersion.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <filesystem>
#include <future>
#include <iostream>
#include <new>
#include <string>
#include <vector>

#include <unistd.h> // isatty

#ifndef SDFCAGE_VERSION
#define SDFCAGE_VERSION "unknown"
#endif

namespace
{

using namespace sdfcage_cli;

enum ExitCode
{
  ExitOk = 0,
  ExitNotVerified = 1,
  ExitUnusable = 2, // bad command line or unusable input
  ExitFailure = 3,  // could not write, could not render, internal error
  ExitInterrupted = 130
};

const char* const Program = "sdfcage";

void printUsage(std::ostream& os)
{
  os << "Usage: sdfcage [INPUT] [options]\n"
        "       sdfcage --check INPUT CAGE [--report FILE.json] [--quiet]\n"
        "\n"
        "Builds a cage (a coarse closed mesh that strictly encloses the input) from an SDF\n"
        "envelope, simplified to N vertices, and verifies it. INPUT is a surface mesh file\n"
        "(closed or not: open scans, soups of parts, quads and polygons are repaired and caged)\n"
        "("
     << supportedExtensions()
     << ").\n"
        "Without INPUT the built-in shape (a torus beside a sphere) is used.\n"
        "\n"
        "Options (lengths are relative: the input is scaled into the unit sphere):\n"
        "  -o, --output FILE       cage file; format from the extension ("
     << supportedExtensions()
     << ")\n"
        "                          default: <input stem>_cage.vtp (builtin_cage.vtp) in the\n"
        "                          current folder\n"
        "  -n, --vertices N        vertices of the cage, default 500; 0 = no simplification\n"
        "                          (the cage is the dense verified envelope)\n"
        "  -n, --vertices N1,N2,...\n"
        "                          nested cages (paper 4, Fig. 9): one cage per count, each\n"
        "                          strictly enclosing the finer ones and the input; one file per\n"
        "                          level named by its count (-n 1000,300 -o cage.off writes\n"
        "                          cage_1000.off and cage_300.off), or all levels in one .vtm or\n"
        "                          .vtpc file\n"
        "      --iso C             isovalue of the envelope, default 0.01\n"
        "      --voxel H           voxel size of the distance grid, default 0 = automatic (C/2)\n"
        "      --clearance D       clearance every cage triangle keeps from the input,\n"
        "                          default 0 = automatic (C/4)\n"
        "      --adaptivity A      isosurface adaptivity in [0, 1]: 0 uniform triangles, larger\n"
        "                          merges flat regions (fewer triangles); default 0.3\n"
        "      --refinements N     times the grid may be refined if verification fails, default 2\n"
        "      --relaxations N     a simplification that stalls above the target: relax the cage\n"
        "                          so far (one MIPS sweep, guarantees kept) and go on, up to N\n"
        "                          times, default 4; 0 = off\n"
        "      --widenings N       inputs without a defined topology (open, soups) whose target is\n"
        "                          not reached: rebuild the envelope at twice the isovalue up to N\n"
        "                          times and keep the closest cage, default 3; 0 = off\n"
        "      --choose-iso-first  with --widenings and the automatic voxel size, an input of more\n"
        "                          parts than the target can carry apart (4 vertices each) has its\n"
        "                          isovalue chosen first by probes on grids twice as coarse, so that\n"
        "                          envelopes that cannot reach the target are not built (default\n"
        "                          on; --no-choose-iso-first: every widening built in turn)\n"
        "      --topology-repairs N\n"
        "                          a closed input whose envelope fuses nearly touching parts\n"
        "                          (another genus or number of parts): rebuild it up to N times,\n"
        "                          each stronger (gap rule, amplification, finer grid, lower\n"
        "                          automatic clearance), default 2; 0 = off\n"
        "      --require-topology  exit 1 and write no cage if the cage's genus or number of parts\n"
        "                          still differs from the closed input's (default: a warning)\n"
        "      --coarse-first      with the automatic voxel size, try the grid twice as coarse\n"
        "                          first: a closed input without active points is tried on it and\n"
        "                          kept only if verified with the input's genus and parts, else\n"
        "                          a grid between (voxel 2C/3) and then the C/2 grid follow\n"
        "                          (default on; --no-coarse-first: off)\n"
        "      --memory-limit MB   memory budget of the envelope (distance grid, isosurface,\n"
        "                          verification), estimated before each grid is built: over it the\n"
        "                          run stops with the need named (exit 3); default 0 = automatic\n"
        "                          (three quarters of the physical memory)\n"
        "      --sign S            how the inside of the input is decided: auto (default: flood for\n"
        "                          a closed, consistently oriented mesh, winding otherwise), flood,\n"
        "                          winding (generalized winding number: holes bridged, sheets\n"
        "                          wrapped on both sides) or unsigned (every sheet wrapped)\n"
        "      --no-active-points  plain offset envelope: no active points, no amplified SDF\n"
        "                          (nearly touching parts may fuse)\n"
        "      --active-radius R   active points: another surface point closer than R in space,\n"
        "                          default 0.025 ...\n"
        "      --geodesic-threshold L\n"
        "                          ... but farther than L along the surface, default 0.15\n"
        "      --alpha A           amplification of the SDF at active points (> 1), default 3\n"
        "      --beta B            decay of the amplification, default 8\n"
        "      --optimize E        optimize the cage (paper 3.3): none (default), mips (well-shaped\n"
        "                          triangles) or spacing (the cage at distance H from the input)\n"
        "      --spacing H         target distance of --optimize spacing, default 0.05\n"
        "      --iterations K      optimization rounds (of up to --sweeps sweeps), default 1\n"
        "      --hausdorff-factor F\n"
        "                          mips: no change may move the cage farther from the input than F\n"
        "                          times the plain cage's one-sided Hausdorff distance; 0 = no bound,\n"
        "                          else >= 1; default 1.4\n"
        "      --target-angle DEG  mips: the smallest triangle angle aimed at (needles below it are\n"
        "                          repaired by flips and collapses); 0 = no repair; default 15\n"
        "      --sweeps K          sweeps per round (relocation, flips, needle repair); a round ends\n"
        "                          earlier once no angle is below the target; default 12\n"
        "      --report FILE.json  write the results as JSON\n"
        "      --screenshot FILE.png\n"
        "                          render input and cage offscreen to a PNG (needs an X server:\n"
        "                          on a headless machine run under `xvfb-run -a`)\n"
        "      --threads N         worker threads, default 0 = all cores\n"
        "  -q, --quiet             no progress bar, no summary (errors are still printed)\n"
        "  -v, --verbose           after the summary, every result with its unit and meaning\n"
        "  -h, --help              this help\n"
        "      --version           program and library versions\n"
        "\n"
        "--check INPUT CAGE judges any cage (from any program) against its input: distances\n"
        "(clearance, Hausdorff both ways, mean), self-intersections, intersections with the\n"
        "input, input vertices outside, genus, and the exact verdict: does CAGE strictly\n"
        "enclose INPUT? Exit codes: 0 it encloses, 1 it does not, 2 a file cannot be used.\n"
        "\n"
        "Exit codes: 0 cage written and enclosure verified; 1 enclosure not verified;\n"
        "2 bad command line, unusable input (missing file, unknown format, no triangle,\n"
        "NaN coordinates, ...) or an output path that cannot be written (checked before any\n"
        "computing); 3 an output could not be written or rendered after the run, the memory\n"
        "budget was exceeded, or another failure; 130 interrupted.\n";
}

struct Options
{
  std::string Input; ///< "" = built-in shape
  std::string Output;
  std::string Report;
  std::string Screenshot;
  double IsoValue = 0.01;
  double VoxelSize = 0.0;
  double Clearance = 0.0;
  double Adaptivity = -1.0; ///< -1 = the filter's default
  int Vertices = -1;        ///< -1 = the filter's default
  std::vector<int> Nested;  ///< -n N1,N2,...: nested levels, sorted finest first (empty: one cage)
  int Refinements = -1;     ///< -1 = the filter's default
  int Widenings = -1;       ///< -1 = the filter's default
  int Relaxations = -1;     ///< -1 = the filter's default
  int TopologyRepairs = -1; ///< -1 = the filter's default
  bool RequireTopology = false;
  int CoarseFirst = -1; ///< -1 = the filter's default
  int ChooseIsoValueFirst = -1; ///< -1 = the filter's default
  double MemoryLimit = 0.0; ///< MiB, 0 = automatic (3/4 of the physical memory)
  bool NoActivePoints = false;
  double ActiveRadius = -1.0;      ///< -1 = the filter's default
  double GeodesicThreshold = -1.0; ///< -1 = the filter's default
  double Alpha = -1.0;             ///< -1 = the filter's default
  double Beta = -1.0;              ///< -1 = the filter's default
  std::string Optimize = "none";   ///< none, mips or spacing
  std::string Sign = "auto";       ///< auto, flood, winding or unsigned
  double Spacing = -1.0;           ///< -1 = the filter's default
  int Iterations = -1;             ///< -1 = the filter's default
  double HausdorffFactor = -1.0;   ///< -1 = the filter's default
  double TargetAngle = -1.0;       ///< -1 = the filter's default
  int Sweeps = -1;                 ///< -1 = the filter's default
  int Threads = 0;
  bool Quiet = false;
  bool Verbose = false; ///< every result after the summary
  bool Help = false;
  bool Version = false;
  bool Check = false; ///< --check INPUT CAGE
  std::string Cage;   ///< the cage of --check
};

/// Thrown for a bad command line; main() prints the message and the usage, exit code 2.
struct UsageError
{
  std::string Message;
};

double parseDouble(const std::string& option, const std::string& text, double lo, double hi)
{
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || !end || *end != '\0' || !(v >= lo && v <= hi))
  {
    char range[96];
    std::snprintf(range, sizeof(range), "a number in [%g, %g]", lo, hi);
    throw UsageError{ option + " expects " + range + ", got '" + text + "'" };
  }
  return v;
}

int parseInt(const std::string& option, const std::string& text, int lo, int hi)
{
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || !end || *end != '\0' || v < lo || v > hi)
  {
    throw UsageError{ option + " expects an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) +
      "], got '" + text + "'" };
  }
  return static_cast<int>(v);
}

/// Walks the command line one argument at a time: an option (`-n 5`, `--iso 0.02`,
/// `--iso=0.02`) with its value, or a positional (a file; everything after `--`).
class ArgumentCursor
{
public:
  ArgumentCursor(int argc, char* argv[])
    : Argc(argc)
    , Argv(argv)
  {
  }

  /// Moves to the next argument; false at the end.
  bool next()
  {
    if (++this->Index >= this->Argc)
    {
      return false;
    }
    this->Name = this->Argv[this->Index];
    this->Value.clear();
    this->HasInlineValue = false;
    this->Positional = this->PositionalOnly || this->Name.empty() || this->Name[0] != '-' || this->Name == "-";
    if (this->Positional)
    {
      if (this->Name.empty())
      {
        throw UsageError{ "empty input file name" };
      }
      return true;
    }
    if (this->Name == "--")
    {
      this->PositionalOnly = true;
      return this->next();
    }
    if (this->Name.compare(0, 2, "--") == 0) // --name=value
    {
      const std::size_t eq = this->Name.find('=');
      if (eq != std::string::npos)
      {
        this->Value = this->Name.substr(eq + 1);
        this->Name = this->Name.substr(0, eq);
        this->HasInlineValue = true;
      }
    }
    return true;
  }

  bool positional() const { return this->Positional; }
  /// The option's name (without "=value"), or the positional argument.
  const std::string& name() const { return this->Name; }

  /// The option's value: after "=", or the next argument.
  std::string value()
  {
    if (this->HasInlineValue)
    {
      return this->Value;
    }
    if (this->Index + 1 >= this->Argc)
    {
      throw UsageError{ "option " + this->Name + " needs a value" };
    }
    return this->Argv[++this->Index];
  }

  /// For a switch: "--quiet=1" is an error.
  void noValue() const
  {
    if (this->HasInlineValue)
    {
      throw UsageError{ "option " + this->Name + " takes no value" };
    }
  }

  double number(double lo, double hi) { return parseDouble(this->Name, this->value(), lo, hi); }
  int integer(int lo, int hi) { return parseInt(this->Name, this->value(), lo, hi); }

private:
  int Argc;
  char** Argv;
  int Index = 0;
  std::string Name;
  std::string Value;
  bool HasInlineValue = false;
  bool Positional = false;
  bool PositionalOnly = false;
};

/// The options of every mode: --check, --help, --version, --quiet, --report. False if `a` is not
/// one of them.
bool parseCommonOption(ArgumentCursor& a, Options& o)
{
  const std::string& arg = a.name();
  if (arg == "--check")
  {
    a.noValue();
    o.Check = true;
  }
  else if (arg == "-h" || arg == "--help")
  {
    a.noValue();
    o.Help = true;
  }
  else if (arg == "--version")
  {
    a.noValue();
    o.Version = true;
  }
  else if (arg == "-q" || arg == "--quiet")
  {
    a.noValue();
    o.Quiet = true;
  }
  else if (arg == "--report")
  {
    o.Report = a.value();
    if (o.Report.empty())
    {
      throw UsageError{ "option --report needs a file name" };
    }
  }
  else
  {
    return false;
  }
  return true;
}

/// The options of building a cage (the ranges are the filter's). False if `a` is not one of them.
bool parseBuildOption(ArgumentCursor& a, Options& o, vtkSDFCageFilter* limits)
{
  const std::string& arg = a.name();
  if (arg == "-o" || arg == "--output")
  {
    o.Output = a.value();
    if (o.Output.empty())
    {
      throw UsageError{ "option " + arg + " needs a file name" };
    }
  }
  else if (arg == "--screenshot")
  {
    o.Screenshot = a.value();
    if (lowerExtension(o.Screenshot) != ".png")
    {
      throw UsageError{ "--screenshot writes PNG: the file name must end in .png, got '" + o.Screenshot + "'" };
    }
  }
  else if (arg == "--iso")
    o.IsoValue = a.number(limits->GetIsoValueMinValue(), limits->GetIsoValueMaxValue());
  else if (arg == "--voxel")
    o.VoxelSize = a.number(limits->GetVoxelSizeMinValue(), limits->GetVoxelSizeMaxValue());
  else if (arg == "--clearance")
    o.Clearance = a.number(limits->GetMinimumClearanceMinValue(), limits->GetMinimumClearanceMaxValue());
  else if (arg == "-n" || arg == "--vertices")
  {
    const std::string value = a.value();
    if (value.find(',') == std::string::npos)
    {
      o.Vertices = parseInt(
        arg, value, limits->GetTargetNumberOfVerticesMinValue(), limits->GetTargetNumberOfVerticesMaxValue());
      o.Nested.clear();
    }
    else
    {
      std::vector<int> counts;
      std::string why = sdfcage::parseNestedCounts(value, counts);
      if (why.empty())
        why = sdfcage::sortNestedCounts(counts);
      if (!why.empty())
        throw UsageError{ arg + ": " + why };
      o.Nested = counts;
    }
  }
  else if (arg == "--adaptivity")
    o.Adaptivity = a.number(limits->GetAdaptivityMinValue(), limits->GetAdaptivityMaxValue());
  else if (arg == "--refinements")
    o.Refinements = a.integer(limits->GetMaximumRefinementsMinValue(), limits->GetMaximumRefinementsMaxValue());
  else if (arg == "--memory-limit")
    o.MemoryLimit = a.number(limits->GetMemoryLimitMinValue(), limits->GetMemoryLimitMaxValue());
  else if (arg == "--relaxations")
    o.Relaxations = a.integer(limits->GetMaximumRelaxationsMinValue(), limits->GetMaximumRelaxationsMaxValue());
  else if (arg == "--widenings")
    o.Widenings =
      a.integer(limits->GetMaximumEnvelopeWideningsMinValue(), limits->GetMaximumEnvelopeWideningsMaxValue());
  else if (arg == "--topology-repairs")
    o.TopologyRepairs =
      a.integer(limits->GetMaximumTopologyRepairsMinValue(), limits->GetMaximumTopologyRepairsMaxValue());
  else if (arg == "--require-topology")
    o.RequireTopology = true;
  else if (arg == "--coarse-first")
    o.CoarseFirst = 1;
  else if (arg == "--no-coarse-first")
    o.CoarseFirst = 0;
  else if (arg == "--choose-iso-first")
    o.ChooseIsoValueFirst = 1;
  else if (arg == "--no-choose-iso-first")
    o.ChooseIsoValueFirst = 0;
  else if (arg == "--no-active-points")
    o.NoActivePoints = true;
  else if (arg == "--active-radius")
    o.ActiveRadius = a.number(limits->GetActiveRadiusMinValue(), limits->GetActiveRadiusMaxValue());
  else if (arg == "--geodesic-threshold")
    o.GeodesicThreshold = a.number(limits->GetGeodesicThresholdMinValue(), limits->GetGeodesicThresholdMaxValue());
  else if (arg == "--alpha")
    o.Alpha = a.number(limits->GetAmplificationAlphaMinValue(), limits->GetAmplificationAlphaMaxValue());
  else if (arg == "--beta")
    o.Beta = a.number(limits->GetAmplificationBetaMinValue(), limits->GetAmplificationBetaMaxValue());
  else if (arg == "--sign")
  {
    o.Sign = a.value();
    if (o.Sign != "auto" && o.Sign != "flood" && o.Sign != "winding" && o.Sign != "unsigned")
    {
      throw UsageError{ "--sign expects auto, flood, winding or unsigned, got '" + o.Sign + "'" };
    }
  }
  else if (arg == "--optimize")
  {
    o.Optimize = a.value();
    if (o.Optimize != "none" && o.Optimize != "mips" && o.Optimize != "spacing")
    {
      throw UsageError{ "--optimize expects none, mips or spacing, got '" + o.Optimize + "'" };
    }
  }
  else if (arg == "--spacing")
    o.Spacing = a.number(limits->GetTargetSpacingMinValue(), limits->GetTargetSpacingMaxValue());
  else if (arg == "--iterations")
    o.Iterations = a.integer(limits->GetNumberOfIterationsMinValue(), limits->GetNumberOfIterationsMaxValue());
  else if (arg == "--hausdorff-factor")
  {
    o.HausdorffFactor = a.number(limits->GetHausdorffFactorMinValue(), limits->GetHausdorffFactorMaxValue());
    if (o.HausdorffFactor > 0 && o.HausdorffFactor < 1)
    {
      throw UsageError{ "--hausdorff-factor expects 0 (no bound) or a factor >= 1" };
    }
  }
  else if (arg == "--target-angle")
    o.TargetAngle = a.number(limits->GetTargetMinimumAngleMinValue(), limits->GetTargetMinimumAngleMaxValue());
  else if (arg == "--sweeps")
    o.Sweeps = a.integer(limits->GetMaximumSweepsMinValue(), limits->GetMaximumSweepsMaxValue());
  else if (arg == "--threads")
    o.Threads = a.integer(limits->GetNumberOfThreadsMinValue(), limits->GetNumberOfThreadsMaxValue());
  else if (arg == "-v" || arg == "--verbose")
  {
    a.noValue();
    o.Verbose = true;
  }
  else
  {
    return false;
  }
  return true;
}

void checkSupported(const std::string& file, const char* verb)
{
  if (!isSupportedExtension(file))
  {
    throw UsageError{ std::string("cannot ") + verb + " '" + file + "': unknown extension '" + lowerExtension(file) +
      "' (supported: " + supportedExtensions() + ")" };
  }
}

/// --check INPUT CAGE: two files, and no option of building a cage.
void finishCheckOptions(
  Options& o, const std::vector<std::string>& positionals, const std::vector<std::string>& buildOptions)
{
  if (positionals.size() != 2)
  {
    throw UsageError{ "--check needs two files, INPUT and CAGE (got " + std::to_string(positionals.size()) + ")" };
  }
  if (!buildOptions.empty())
  {
    throw UsageError{ "--check takes only --report and --quiet; '" + buildOptions.front() +
      "' is an option for building a cage" };
  }
  o.Input = positionals[0];
  o.Cage = positionals[1];
  for (const std::string& file : positionals)
  {
    checkSupported(file, "read");
  }
}

/// Building a cage: at most one input (none: the built-in shape), known formats, the default
/// output name.
void finishBuildOptions(Options& o, const std::vector<std::string>& positionals)
{
  if (positionals.size() > 1)
  {
    throw UsageError{ "more than one input given ('" + positionals[0] + "' and '" + positionals[1] +
      "'): sdfcage reads one mesh (to judge a cage: sdfcage --check INPUT CAGE)" };
  }
  if (!positionals.empty())
  {
    o.Input = positionals[0];
  }
  if (!o.Input.empty())
  {
    checkSupported(o.Input, "read");
  }
  if (!o.Output.empty() && isMultiBlockExtension(o.Output))
  {
    if (o.Nested.empty())
    {
      throw UsageError{ "'" + o.Output + "': a " + lowerExtension(o.Output) +
        " file holds nested cages: give several vertex counts (e.g. -n 2000,500,100), or write one cage as " +
        supportedExtensions() };
    }
  }
  else if (!o.Output.empty())
  {
    checkSupported(o.Output, "write");
  }
  if (o.Output.empty())
  {
    const std::string stem = o.Input.empty() ? std::string("builtin") : std::filesystem::path(o.Input).stem().string();
    o.Output = stem + "_cage.vtp";
  }
}

/// The files of a nested run: one per level for single-mesh formats, the stem suffixed with the
/// level's count (cage.off -> cage_1000.off); for .vtm/.vtpc the one file, for every level.
std::vector<std::string> levelFiles(const Options& o)
{
  std::vector<std::string> files;
  for (int count : o.Nested)
  {
    if (isMultiBlockExtension(o.Output))
    {
      files.push_back(o.Output);
      continue;
    }
    const std::filesystem::path p(o.Output);
    std::filesystem::path named = p.parent_path() / (p.stem().string() + "_" + std::to_string(count) + p.extension().string());
    files.push_back(named.string());
  }
  return files;
}

Options parseOptions(int argc, char* argv[], vtkSDFCageFilter* limits)
{
  Options o;
  std::vector<std::string> positionals;
  std::vector<std::string> buildOptions; // options that only make sense when building a cage
  ArgumentCursor a(argc, argv);
  while (a.next())
  {
    if (a.positional())
    {
      positionals.push_back(a.name());
    }
    else if (!parseCommonOption(a, o))
    {
      buildOptions.push_back(a.name());
      if (!parseBuildOption(a, o, limits))
      {
        throw UsageError{ "unknown option '" + a.name() + "'" };
      }
    }
  }
  if (o.Check && !o.Help && !o.Version)
  {
    finishCheckOptions(o, positionals, buildOptions);
  }
  else
  {
    finishBuildOptions(o, positionals);
  }
  return o;
}

// --- Ctrl-C: the first one cancels the filter cleanly, a second one kills --------------------
volatile std::sig_atomic_t InterruptRequested = 0;

extern "C" void onInterrupt(int)
{
  InterruptRequested = 1;
  std::signal(SIGINT, SIG_DFL);
}

// --- progress bar on a terminal --------------------------------------------------------------
class ProgressBar : public vtkCommand
{
public:
  static ProgressBar* New() { return new ProgressBar; }

  bool Enabled = false;

  void Execute(vtkObject* caller, unsigned long, void* callData) override
  {
    vtkAlgorithm* algorithm = vtkAlgorithm::SafeDownCast(caller);
    if (InterruptRequested && algorithm)
    {
      algorithm->SetAbortExecute(1);
    }
    if (!this->Enabled || !callData)
    {
      return;
    }
    const double fraction = *static_cast<double*>(callData);
    const int percent = static_cast<int>(fraction * 100.0 + 0.5);
    const char* text = algorithm ? algorithm->GetProgressText() : nullptr;
    const std::string stage = (text && *text) ? text : "building the cage";
    if (percent == this->LastPercent && stage == this->LastStage)
    {
      return;
    }
    this->LastPercent = percent;
    this->LastStage = stage;
    this->draw(fraction, percent, stage);
  }

  /// Shows a step that reports no progress of its own (reading, writing, rendering).
  void step(const std::string& stage, double fraction)
  {
    if (this->Enabled)
    {
      this->LastStage = stage;
      this->LastPercent = static_cast<int>(fraction * 100.0 + 0.5);
      this->draw(fraction, this->LastPercent, stage);
    }
  }

  /// Ends the bar's line (if anything was drawn).
  void finish()
  {
    if (this->Drawn)
    {
      std::fputc('\n', stderr);
      std::fflush(stderr);
      this->Drawn = false;
    }
  }

private:
  void draw(double fraction, int percent, const std::string& stage)
  {
    constexpr int width = 30;
    const int filled = std::max(0, std::min(width, static_cast<int>(fraction * width + 0.5)));
    std::string bar(static_cast<std::size_t>(filled), '#');
    bar.append(static_cast<std::size_t>(width - filled), '.');
    std::string label = stage.substr(0, 40);
    label.resize(40, ' '); // overwrite a longer previous stage name
    std::fprintf(stderr, "\r[%s] %3d%%  %s", bar.c_str(), percent, label.c_str());
    std::fflush(stderr);
    this->Drawn = true;
  }

  int LastPercent = -1;
  std::string LastStage;
  bool Drawn = false;
};

void printError(const std::string& message)
{
  std::cerr << Program << ": error: " << message << "\n";
}

/// Prints collected VTK warnings (unless quiet) and clears them.
void flushWarnings(MessageCollector* messages, bool quiet, ProgressBar* bar)
{
  if (!quiet && !messages->warnings().empty())
  {
    bar->finish(); // warnings go on lines of their own
    for (const std::string& w : messages->warnings())
    {
      std::cerr << Program << ": warning: " << w << "\n";
    }
  }
  messages->clear();
}

std::string shortNumber(double v)
{
  char buffer[32];
  std::snprintf(buffer, sizeof(buffer), "%.3g", v);
  return buffer;
}

/// Writes the report (if asked) and returns the exit code.
int finish(const Options& o, RunReport& r, int code)
{
  r.ExitCode = code;
  if (!o.Report.empty())
  {
    std::string error;
    if (!writeJsonReport(r, o.Report, error))
    {
      printError(error);
      return code == ExitOk ? ExitFailure : code;
    }
  }
  return code;
}

using Clock = std::chrono::steady_clock;

double since(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// What was asked, before anything runs.
RunReport startReport(const Options& o)
{
  RunReport r;
  r.InputFile = o.Input.empty() ? "builtin" : o.Input;
  r.ReportFile = o.Report;
  r.IsoValue = o.IsoValue;
  r.VoxelSize = o.VoxelSize;
  r.MinimumClearance = o.Clearance;
  r.NumberOfThreads = o.Threads;
  sdfcage::EnvelopeOptions resolved;
  resolved.IsoValue = o.IsoValue;
  resolved.MinimumClearance = o.Clearance;
  r.MinimumClearanceUsed = resolved.clearance();
  return r;
}

/// --- read: the mesh file, or the built-in shape. Null (with the status in `r`) when the file
/// cannot be read.
vtkSmartPointer<vtkPolyData> readInput(
  const Options& o, RunReport& r, ProgressBar* progress, MessageCollector* messages)
{
  const Clock::time_point start = Clock::now();
  vtkSmartPointer<vtkPolyData> input;
  if (o.Input.empty())
  {
    input = builtinShape();
  }
  else
  {
    progress->step("reading " + std::filesystem::path(o.Input).filename().string(), 0.0);
    // Read on a worker thread so that a Ctrl-C answers at once even inside a reader that does
    // not poll for it (VTK's OBJ reader): reading writes nothing, so the reader can simply be
    // abandoned; the readers that can stop (ours, and VTK's that poll AbortExecute) do.
    std::string error;
    auto reading = std::async(std::launch::async,
      [&o, &error] { return readMesh(o.Input, error, [] { return InterruptRequested != 0; }); });
    while (reading.wait_for(std::chrono::milliseconds(20)) != std::future_status::ready)
    {
      if (InterruptRequested)
      {
        progress->finish();
        printError("interrupted");
        r.Status = "Cancelled";
        r.ErrorMessage = "interrupted";
        finish(o, r, ExitInterrupted);
        std::fflush(stdout);
        std::fflush(stderr);
        std::_Exit(ExitInterrupted); // the reader thread is abandoned with the process
      }
    }
    input = reading.get();
    if (!input)
    {
      progress->finish();
      if (InterruptRequested)
      {
        return nullptr; // run() reports the interruption
      }
      printError(error);
      r.Status = "UnreadableInput";
      r.ErrorMessage = error;
      return nullptr;
    }
  }
  r.ReadTime = since(start);
  r.InputPoints = input->GetNumberOfPoints();
  r.InputCells = input->GetNumberOfPolys() + input->GetNumberOfStrips();
  r.InputTriangles = triangleCount(input);
  flushWarnings(messages, o.Quiet, progress);
  return input;
}

/// --- options: the command line on the filter (unset values keep the filter's defaults); the
/// values used go to the report.
void configureFilter(vtkSDFCageFilter* filter, const Options& o, RunReport& r)
{
  filter->SetIsoValue(o.IsoValue);
  filter->SetVoxelSize(o.VoxelSize);
  filter->SetMinimumClearance(o.Clearance);
  if (o.Vertices >= 0)
    filter->SetTargetNumberOfVertices(o.Vertices);
  filter->SetNumberOfNestedLevels(static_cast<int>(o.Nested.size()));
  for (std::size_t k = 0; k < o.Nested.size(); ++k)
    filter->SetNestedVertexCount(static_cast<int>(k), o.Nested[k]);
  if (o.Adaptivity >= 0)
    filter->SetAdaptivity(o.Adaptivity);
  if (o.Refinements >= 0)
    filter->SetMaximumRefinements(o.Refinements);
  if (o.Widenings >= 0)
    filter->SetMaximumEnvelopeWidenings(o.Widenings);
  if (o.Relaxations >= 0)
    filter->SetMaximumRelaxations(o.Relaxations);
  if (o.TopologyRepairs >= 0)
    filter->SetMaximumTopologyRepairs(o.TopologyRepairs);
  filter->SetRequireTopology(o.RequireTopology ? 1 : 0);
  if (o.CoarseFirst >= 0)
    filter->SetCoarseFirst(o.CoarseFirst);
  if (o.ChooseIsoValueFirst >= 0)
    filter->SetChooseIsoValueFirst(o.ChooseIsoValueFirst);
  filter->SetMemoryLimit(o.MemoryLimit);
  filter->SetUseActivePoints(o.NoActivePoints ? 0 : 1);
  if (o.ActiveRadius >= 0)
    filter->SetActiveRadius(o.ActiveRadius);
  if (o.GeodesicThreshold >= 0)
    filter->SetGeodesicThreshold(o.GeodesicThreshold);
  if (o.Alpha >= 0)
    filter->SetAmplificationAlpha(o.Alpha);
  if (o.Beta >= 0)
    filter->SetAmplificationBeta(o.Beta);
  filter->SetOptimize(o.Optimize != "none");
  if (o.Optimize == "spacing")
    filter->SetEnergyToSpacing();
  else
    filter->SetEnergyToMIPS();
  if (o.Spacing >= 0)
    filter->SetTargetSpacing(o.Spacing);
  if (o.Iterations >= 0)
    filter->SetNumberOfIterations(o.Iterations);
  if (o.HausdorffFactor >= 0)
    filter->SetHausdorffFactor(o.HausdorffFactor);
  if (o.TargetAngle >= 0)
    filter->SetTargetMinimumAngle(o.TargetAngle);
  if (o.Sweeps >= 0)
    filter->SetMaximumSweeps(o.Sweeps);
  filter->SetNumberOfThreads(o.Threads);
  filter->SetSignMode(o.Sign == "flood" ? 1 : o.Sign == "winding" ? 2 : o.Sign == "unsigned" ? 3 : 0);

  r.UseActivePoints = filter->GetUseActivePoints() != 0;
  r.CoarseFirst = filter->GetCoarseFirst() != 0;
  r.ChooseIsoValueFirst = filter->GetChooseIsoValueFirst() != 0;
  r.ActiveRadius = filter->GetActiveRadius();
  r.GeodesicThreshold = filter->GetGeodesicThreshold();
  r.AmplificationAlpha = filter->GetAmplificationAlpha();
  r.AmplificationBeta = filter->GetAmplificationBeta();
  r.Optimize = o.Optimize;
  r.TargetSpacing = filter->GetTargetSpacing();
  r.NumberOfIterations = filter->GetNumberOfIterations();
  r.HausdorffFactor = filter->GetHausdorffFactor();
  r.TargetMinimumAngle = filter->GetTargetMinimumAngle();
  r.MaximumSweeps = filter->GetMaximumSweeps();
  r.Adaptivity = filter->GetAdaptivity();
  r.TargetNumberOfVertices = o.Nested.empty() ? filter->GetTargetNumberOfVertices() : o.Nested.front();
  r.NestedCounts = o.Nested;
  r.MaximumRefinements = filter->GetMaximumRefinements();
  r.Sign = o.Sign;
}

/// --- run: the filter, with the progress bar; a Ctrl-C (handler installed by run()) cancels it
/// cleanly at its next progress report.
void runFilter(vtkSDFCageFilter* filter, ProgressBar* progress)
{
  filter->AddObserver(vtkCommand::ProgressEvent, progress);
  filter->Update();
}

/// An interruption before or between the steps: exit code 130, nothing written.
int interrupted(const Options& o, RunReport& r, ProgressBar* progress)
{
  progress->finish();
  printError("interrupted");
  r.Status = "Cancelled";
  r.ErrorMessage = "interrupted";
  return finish(o, r, ExitInterrupted);
}

/// Every file the run will write can be written: checked before anything is read or computed.
bool checkOutputs(const Options& o, RunReport& r)
{
  std::vector<std::string> paths = o.Nested.empty() ? std::vector<std::string>{ o.Output } : levelFiles(o);
  paths.push_back(o.Report);
  paths.push_back(o.Screenshot);
  for (const std::string* path = paths.data(); path != paths.data() + paths.size(); ++path)
  {
    std::string error;
    if (!path->empty() && !checkWritable(*path, error))
    {
      printError(error);
      r.Status = "UnwritableOutput";
      r.ErrorMessage = error;
      return false;
    }
  }
  return true;
}

/// --- results: the filter's status and every result of its table (by name), the mesh sizes.
void collectResults(vtkSDFCageFilter* filter, RunReport& r)
{
  vtkPolyData* cage = filter->GetOutput(0);
  vtkPolyData* envelope = vtkPolyData::SafeDownCast(filter->GetOutputDataObject(1));
  r.FilterRan = true;
  r.Status = filter->GetStatusString();
  r.ErrorMessage = filter->GetLastErrorMessage();
  for (sdfcage::ResultField& f : r.Results)
  {
    if (f.Type == sdfcage::ResultField::Kind::Text)
      f.Text = filter->GetResultText(f.Name.c_str());
    else
      f.setNumber(filter->GetResultNumber(f.Name.c_str()));
  }
  r.CagePoints = cage ? cage->GetNumberOfPoints() : 0;
  r.CageTriangles = cage ? triangleCount(cage) : 0;
  r.EnvelopePoints = envelope ? envelope->GetNumberOfPoints() : 0;
  r.EnvelopeTriangles = envelope ? triangleCount(envelope) : 0;

  // nested levels: one block each, its results in its field data
  r.Levels.clear();
  auto* levels = vtkMultiBlockDataSet::SafeDownCast(filter->GetOutputDataObject(3));
  for (unsigned int b = 0; levels && b < levels->GetNumberOfBlocks() && b < r.NestedCounts.size(); ++b)
  {
    LevelReport l;
    l.Count = r.NestedCounts[b];
    l.Name = "cage_" + std::to_string(l.Count);
    l.Results = levelResultFields();
    vtkPolyData* block = vtkPolyData::SafeDownCast(levels->GetBlock(b));
    vtkFieldData* fd = block ? block->GetFieldData() : nullptr;
    auto* status = fd ? vtkStringArray::SafeDownCast(fd->GetAbstractArray("Status")) : nullptr;
    l.Status = status && status->GetNumberOfValues() > 0 ? status->GetValue(0) : std::string("NotBuilt");
    l.Points = block ? block->GetNumberOfPoints() : 0;
    l.Triangles = block ? triangleCount(block) : 0;
    for (sdfcage::ResultField& f : l.Results)
    {
      vtkAbstractArray* a = fd ? fd->GetAbstractArray(f.Name.c_str()) : nullptr;
      if (!a || a->GetNumberOfValues() < 1)
        continue;
      if (auto* s = vtkStringArray::SafeDownCast(a))
        f.Text = s->GetValue(0);
      else if (auto* d = vtkDataArray::SafeDownCast(a))
        f.setNumber(d->GetComponent(0, 0));
    }
    r.Levels.push_back(l);
  }
}

/// Every level of a nested run was built and re-verified against the level inside it and the
/// input.
bool levelsVerified(const RunReport& r)
{
  if (r.Levels.size() != r.NestedCounts.size())
    return false;
  for (const LevelReport& l : r.Levels)
  {
    const sdfcage::ResultField* inside = sdfcage::findResult(l.Results, "VerifiedAgainstInside");
    const sdfcage::ResultField* input = sdfcage::findResult(l.Results, "VerifiedAgainstInput");
    if (l.Status != "Ok" || l.Triangles == 0 || !inside || !inside->Integer || !input || !input->Integer)
      return false;
  }
  return true;
}

/// Prints VTK's warnings of the run (unless quiet) and returns its errors. The filter reports
/// its errors through GetLastErrorMessage(): VTK's copy of them is not printed again.
std::vector<std::string> takeFilterMessages(MessageCollector* messages, bool quiet, ProgressBar* progress)
{
  if (!quiet && !messages->warnings().empty())
  {
    progress->finish(); // warnings go on lines of their own
    for (const std::string& w : messages->warnings())
    {
      std::cerr << Program << ": warning: " << w << "\n";
    }
  }
  const std::vector<std::string> errors = messages->errors();
  messages->clear();
  return errors;
}

/// The outcomes that end the run before writing anything: interrupted, unusable input, a
/// failure of the filter. -1 when the run goes on.
int stopCode(const Options& o, RunReport& r, const std::vector<std::string>& filterErrors)
{
  if (InterruptRequested || r.Status == "Cancelled")
  {
    printError("interrupted");
    r.ErrorMessage = r.ErrorMessage.empty() ? "interrupted" : r.ErrorMessage;
    return ExitInterrupted;
  }
  if (r.Status == "InvalidInput" || r.Status == "EmptyInput")
  {
    const std::string why = !r.ErrorMessage.empty() ? r.ErrorMessage
      : r.Status == "EmptyInput"                    ? std::string("the input has no triangles")
                                                    : std::string("the input is not usable");
    printError((o.Input.empty() ? std::string("the built-in shape") : "'" + o.Input + "'") + ": " + why);
    r.ErrorMessage = why;
    return ExitUnusable;
  }
  if (r.Status != "Ok" && r.Status != "VerificationFailed" && r.Status != "TopologyChanged")
  {
    std::string why = r.ErrorMessage;
    if (why.empty())
    {
      why = !filterErrors.empty() ? filterErrors.front() : "the cage filter failed (status '" + r.Status + "')";
    }
    printError(why);
    r.ErrorMessage = why;
    return ExitFailure;
  }
  return -1;
}

/// STL stores coordinates as 32-bit floats (PLY is written with doubles). Rounding moves every point of the cage by at
/// most the largest vertex move, so the verified clearance survives when that move is a small
/// part of it (at most a tenth); far from the origin (1e12 away, say) it is not: then nothing
/// is written and the message says which formats keep doubles.
bool fitsSinglePrecision(vtkPolyData* cage, const std::string& path, double clearance, std::string& error)
{
  const std::string ext = lowerExtension(path);
  if (ext != ".stl")
  {
    return true;
  }
  double largest = 0.0;
  for (vtkIdType i = 0; i < cage->GetNumberOfPoints(); ++i)
  {
    double p[3];
    cage->GetPoint(i, p);
    double moved = 0.0;
    for (double c : p)
    {
      const double d = c - static_cast<double>(static_cast<float>(c));
      moved += d * d;
    }
    largest = std::max(largest, std::sqrt(moved));
  }
  if (!(largest <= 0.1 * clearance))
  {
    error = "cannot write '" + path + "': single precision (" + ext +
      " stores 32-bit floats) would move the cage by up to " + shortNumber(largest) +
      ", more than a tenth of its clearance " + shortNumber(clearance) +
      " (input far from the origin?): write .vtp, .vtk, .off, .obj or .ply, which keep doubles";
    return false;
  }
  return true;
}

/// --- write: the cage file. False (with the status in `r`) when it cannot be written.
bool writeCage(vtkPolyData* cage, const Options& o, RunReport& r, ProgressBar* progress)
{
  const Clock::time_point start = Clock::now();
  progress->step("writing " + std::filesystem::path(o.Output).filename().string(), 1.0);
  std::string error;
  if (!fitsSinglePrecision(cage, o.Output, r.number("MeasuredClearance"), error) ||
    !writeMesh(cage, o.Output, error))
  {
    progress->finish();
    printError(error);
    r.Status = "WriteFailed";
    r.ErrorMessage = error;
    return false;
  }
  r.WriteTime = since(start);
  r.OutputFile = o.Output;
  return true;
}

/// --- write, nested: one file per level (or one multi-block file). False (with the status in
/// `r`) when one cannot be written.
bool writeLevels(vtkSDFCageFilter* filter, const Options& o, RunReport& r, ProgressBar* progress)
{
  const Clock::time_point start = Clock::now();
  auto* levels = vtkMultiBlockDataSet::SafeDownCast(filter->GetOutputDataObject(3));
  const std::vector<std::string> files = levelFiles(o);
  std::string error;
  auto failed = [&]() {
    progress->finish();
    printError(error);
    r.Status = "WriteFailed";
    r.ErrorMessage = error;
    return false;
  };
  if (!levels || levels->GetNumberOfBlocks() != files.size())
  {
    error = "the nested levels are missing from the filter's output";
    return failed();
  }
  if (isMultiBlockExtension(o.Output))
  {
    progress->step("writing " + std::filesystem::path(o.Output).filename().string(), 1.0);
    if (!writeMultiBlock(levels, o.Output, error))
      return failed();
  }
  else
  {
    for (unsigned int b = 0; b < levels->GetNumberOfBlocks(); ++b)
    {
      vtkPolyData* block = vtkPolyData::SafeDownCast(levels->GetBlock(b));
      progress->step("writing " + std::filesystem::path(files[b]).filename().string(), 1.0);
      const sdfcage::ResultField* clearance = sdfcage::findResult(r.Levels[b].Results, "ClearanceToInside");
      if (!block || !fitsSinglePrecision(block, files[b], clearance ? clearance->Real : 0.0, error) ||
        !writeMesh(block, files[b], error))
        return failed();
    }
  }
  for (std::size_t k = 0; k < r.Levels.size() && k < files.size(); ++k)
    r.Levels[k].File = files[k];
  r.WriteTime = since(start);
  r.OutputFile = isMultiBlockExtension(o.Output) ? o.Output : std::string();
  return true;
}

/// --- picture: input and cage (or the unverified envelope, to inspect it) as a PNG. Returns
/// the exit code, made ExitFailure when rendering fails on an otherwise good run.
int writePicture(vtkPolyData* input, vtkPolyData* shown, bool verified, const Options& o, RunReport& r,
  ProgressBar* progress, MessageCollector* messages, int code)
{
  std::string title = std::string("SDFCage: ") +
    (o.Input.empty() ? std::string("built-in shape") : std::filesystem::path(o.Input).filename().string()) +
    (verified ? " and its cage (" : " and its UNVERIFIED envelope (") +
    std::to_string(shown ? triangleCount(shown) : 0) + " triangles, clearance " +
    shortNumber(r.number("MeasuredClearanceRelative")) + " relative)";
  progress->step("rendering " + std::filesystem::path(o.Screenshot).filename().string(), 1.0);
  std::string error;
  if (messages)
  {
    messages->clear(); // what VTK says while rendering is reported below
  }
  bool pictured = writeScreenshot(input, shown, title, o.Screenshot, error);
  if (pictured && messages && !messages->errors().empty())
  {
    pictured = false; // VTK reported an error while rendering or writing
    error = "cannot write the screenshot '" + o.Screenshot + "': " + messages->errors().front();
  }
  if (!pictured)
  {
    progress->finish();
    printError(error);
    if (code == ExitOk)
    {
      r.Status = "ScreenshotFailed";
      r.ErrorMessage = error;
      code = ExitFailure;
    }
  }
  else
  {
    r.ScreenshotFile = o.Screenshot;
  }
  flushWarnings(messages, o.Quiet, progress);
  return code;
}

/// One cage: read -> options -> run -> results -> write -> picture -> summary and report.
int run(const Options& o, MessageCollector* messages)
{
  RunReport r = startReport(o);
  if (!o.Screenshot.empty())
  {
    // fail before the long computation, not after it
    std::string error;
    if (!canRender(error))
    {
      printError(error);
      r.Status = "RenderingUnavailable";
      r.ErrorMessage = error;
      return finish(o, r, ExitFailure);
    }
  }
  if (!checkOutputs(o, r))
  {
    // the report itself may be what cannot be written: finish() then says so too
    return finish(o, r, ExitUnusable);
  }
  vtkNew<ProgressBar> progress;
  progress->Enabled = !o.Quiet && isatty(STDERR_FILENO);

  vtkSmartPointer<vtkPolyData> input = readInput(o, r, progress, messages);
  if (InterruptRequested)
  {
    return interrupted(o, r, progress);
  }
  if (!input)
  {
    return finish(o, r, ExitUnusable);
  }
  vtkNew<vtkSDFCageFilter> filter;
  filter->SetInputData(input);
  configureFilter(filter, o, r);
  if (InterruptRequested)
  {
    return interrupted(o, r, progress);
  }
  runFilter(filter, progress);
  collectResults(filter, r);
  const std::vector<std::string> filterErrors = takeFilterMessages(messages, o.Quiet, progress);
  if (r.Status != "Ok" || !r.flag("EnclosureVerified"))
  {
    progress->finish();
  }
  const int stop = stopCode(o, r, filterErrors);
  if (stop >= 0)
  {
    return finish(o, r, stop);
  }

  int code = ExitOk;
  vtkPolyData* cage = filter->GetOutput(0);
  const bool verified = r.Status == "Ok" && r.flag("EnclosureVerified") && r.CageTriangles > 0 &&
    (o.Nested.empty() || levelsVerified(r));
  if (!verified)
  {
    code = ExitNotVerified;
    const std::string why = r.ErrorMessage.empty() ? "the enclosure could not be verified" : r.ErrorMessage;
    printError(why + " (no cage written)");
    r.ErrorMessage = why;
  }
  else if (o.Nested.empty() ? !writeCage(cage, o, r, progress) : !writeLevels(filter, o, r, progress))
  {
    return finish(o, r, ExitFailure);
  }
  if (!o.Screenshot.empty())
  {
    vtkPolyData* envelope = vtkPolyData::SafeDownCast(filter->GetOutputDataObject(1));
    code = writePicture(input, verified ? cage : envelope, verified, o, r, progress, messages, code);
  }

  progress->finish();
  if (!o.Quiet)
  {
    printSummary(std::cout, r);
    if (o.Verbose)
    {
      printResults(std::cout, r.Results);
    }
    std::cout.flush();
  }
  return finish(o, r, code);
}

} // namespace

int main(int argc, char* argv[])
{
  // before any thread: fewer page faults for the pipeline's buffers (CLIAllocator.cxx)
  sdfcage_cli::tuneAllocator();
  // Ctrl-C from here on: the first one stops the run cleanly (checked while reading, at every
  // progress report of the filter and between the steps; exit code 130), a second one kills.
  std::signal(SIGINT, onInterrupt);
  try
  {
    MessageCollector* messages = MessageCollector::install();
    Options options;
    try
    {
      vtkNew<vtkSDFCageFilter> limits; // the parameter ranges come from the filter
      options = parseOptions(argc, argv, limits);
    }
    catch (const UsageError& e)
    {
      printError(e.Message);
      std::cerr << "\n";
      printUsage(std::cerr);
      return ExitUnusable;
    }
    if (options.Help)
    {
      printUsage(std::cout);
      return ExitOk;
    }
    if (options.Version)
    {
      std::cout << "sdfcage " << SDFCAGE_VERSION << " (VTK " << vtkVersion::GetVTKVersion()
                << (renderingAvailable() ? ", with rendering" : ", without rendering") << ")\n";
      return ExitOk;
    }
    if (options.Check)
    {
      return runCheck(options.Input, options.Cage, options.Report, options.Quiet, messages);
    }
    return run(options, messages);
  }
  catch (const std::bad_alloc&)
  {
    printError("out of memory (try a larger --voxel)");
    return ExitFailure;
  }
  catch (const std::exception& e)
  {
    printError(std::string("internal error: ") + e.what());
    return ExitFailure;
  }
  catch (...)
  {
    printError("internal error (unknown exception)");
    return ExitFailure;
  }
}
