// Cancel latency of vtkSDFCageFilter: from the abort request to the return of Update(), per
// stage, and what the cancelled run outputs.
//
// The abort is requested the way ParaView's Cancel button and the sdfcage program's Ctrl-C do it:
// a flag set asynchronously (here by a timer thread) that a ProgressEvent observer turns into
// SetAbortExecute(1). So the latency includes the time until the filter next fires a progress
// event, and then until Core's next cancel check answers. One uninterrupted run first gives the
// stages (the filter's progress texts) and how long each lasts; then, for each stage and each k of
// K, a run requests the abort (k + 0.5)/K of that stage's duration after the stage first starts
// (so the tries follow the stages even when the machine's load changes the timings; a stage that
// comes back, like the optimization's sweeps, is tried at its first occurrence). The stage of a try
// is the progress text at the moment of the request.
//
// After each cancelled run the cage output must be empty or a cage that the exact checker
// (CGAL, Testing/Exact) finds closed, 2-manifold, self-intersection free and enclosing the input:
// a broken one makes the program exit with 1. A benchmark (prints figures), not a timed test.
//
//   sdfcage_cancel_benchmark [MESH] [--per-stage K] [--threads T] [--vertices V] [--iso C]
//                            [--optimize] [--builtin] [--no-check] [--only TEXT]...
//   (default MESH: SDFCAGE_DATA_DIR/armadillo_midsub4x.obj, K = 3; --only: tries in the stages
//   whose progress text contains TEXT only, e.g. --only validating --only "active points")
#include "vtkSDFCageFilter.h"

#include "MeshIO.h"
#include "ExactCheck.h"
#include "Mesh/Shapes.h"

#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

namespace
{
using Clock = std::chrono::steady_clock;

double since(Clock::time_point t0, Clock::time_point t1 = Clock::now())
{
  return std::chrono::duration<double>(t1 - t0).count();
}

vtkSmartPointer<vtkPolyData> toPolyData(const sdfcage::PolygonMesh& mesh)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(mesh.Points.size()));
  for (std::size_t i = 0; i < mesh.Points.size(); ++i)
    points->SetPoint(static_cast<vtkIdType>(i), mesh.Points[i].data());
  vtkNew<vtkCellArray> polys;
  for (std::size_t c = 0; c < mesh.numberOfCells(); ++c)
  {
    polys->InsertNextCell(static_cast<int>(mesh.Offsets[c + 1] - mesh.Offsets[c]));
    for (std::int64_t k = mesh.Offsets[c]; k < mesh.Offsets[c + 1]; ++k)
      polys->InsertCellPoint(static_cast<vtkIdType>(mesh.Connectivity[k]));
  }
  auto out = vtkSmartPointer<vtkPolyData>::New();
  out->SetPoints(points);
  out->SetPolys(polys);
  return out;
}

sdfcage::TriangleMesh toTriangles(vtkPolyData* pd)
{
  sdfcage::TriangleMesh m;
  for (vtkIdType i = 0; i < pd->GetNumberOfPoints(); ++i)
  {
    double p[3];
    pd->GetPoint(i, p);
    m.Points.emplace_back(p[0], p[1], p[2]);
  }
  vtkNew<vtkIdList> ids;
  vtkCellArray* polys = pd->GetPolys();
  for (polys->InitTraversal(); polys->GetNextCell(ids);)
  {
    for (vtkIdType k = 1; k + 1 < ids->GetNumberOfIds(); ++k)
      m.Triangles.push_back(
        { static_cast<int>(ids->GetId(0)), static_cast<int>(ids->GetId(k)), static_cast<int>(ids->GetId(k + 1)) });
  }
  return m;
}

struct Options
{
  std::string Mesh = std::string(SDFCAGE_DATA_DIR) + "/armadillo_midsub4x.obj";
  bool Builtin = false;
  int PerStage = 3;
  int Threads = 0;
  int Vertices = -1;
  double IsoValue = -1.0;
  bool Optimize = false;
  bool Check = true;
  std::vector<std::string> Only; ///< tries only in the stages whose text contains one of these
};

/// What one run saw: the progress texts with their times, and (for a cancelled run) the time of
/// the request.
struct RunRecord
{
  Clock::time_point Start;
  std::mutex Lock;
  std::vector<std::pair<double, std::string>> Texts; ///< (seconds since start, progress text)
  std::atomic<bool> AbortRequested{ false };
  std::string TriggerStage; ///< the abort is requested Delay seconds after this text shows
  double StageSeen = -1.0;  ///< when it showed (under Lock)
  std::condition_variable* Wake = nullptr;
  double RequestedAt = -1.0;
  int Events = 0;
  double LongestEventGap = 0.0; ///< seconds between consecutive progress events, the longest
  double LastEvent = 0.0;
  std::string LastText;
  /// per stage: the longest time between two progress events, and when it ended
  std::map<std::string, std::pair<double, double>> StageGaps;
};

void onProgress(vtkObject* caller, unsigned long, void* clientData, void*)
{
  auto* record = static_cast<RunRecord*>(clientData);
  auto* filter = static_cast<vtkSDFCageFilter*>(caller);
  const double t = since(record->Start);
  {
    std::lock_guard<std::mutex> lock(record->Lock);
    const char* text = filter->GetProgressText();
    const std::string s = text ? text : "";
    if (record->Texts.empty() || record->Texts.back().second != s)
      record->Texts.emplace_back(t, s);
    if (record->StageSeen < 0.0 && s == record->TriggerStage)
    {
      record->StageSeen = t;
      if (record->Wake)
        record->Wake->notify_all();
    }
    record->LongestEventGap = std::max(record->LongestEventGap, t - record->LastEvent);
    // a gap belongs to the stage it was spent in (the text before the event that ends it)
    auto& gap = record->StageGaps[record->LastText.empty() ? std::string("start") : record->LastText];
    if (t - record->LastEvent > gap.first)
      gap = { t - record->LastEvent, t };
    record->LastText = s;
    record->LastEvent = t;
    ++record->Events;
  }
  if (record->AbortRequested.load())
    filter->SetAbortExecute(1);
}

/// The stage (progress text) current at `t` seconds.
std::string stageAt(RunRecord& r, double t)
{
  std::lock_guard<std::mutex> lock(r.Lock);
  std::string s = "start";
  for (const auto& e : r.Texts)
  {
    if (e.first > t)
      break;
    s = e.second;
  }
  return s.empty() ? "start" : s;
}

vtkSmartPointer<vtkSDFCageFilter> makeFilter(vtkPolyData* input, const Options& o, RunRecord& record)
{
  auto filter = vtkSmartPointer<vtkSDFCageFilter>::New();
  filter->SetInputData(input);
  filter->SetNumberOfThreads(o.Threads);
  if (o.Vertices >= 0)
    filter->SetTargetNumberOfVertices(o.Vertices);
  if (o.IsoValue > 0)
    filter->SetIsoValue(o.IsoValue);
  filter->SetOptimize(o.Optimize ? 1 : 0);
  vtkNew<vtkCallbackCommand> observer;
  observer->SetCallback(onProgress);
  observer->SetClientData(&record);
  filter->AddObserver(vtkCommand::ProgressEvent, observer);
  return filter;
}

double median(std::vector<double> v)
{
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n == 0 ? 0.0 : n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

} // namespace

int main(int argc, char* argv[])
{
  Options o;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc)
      {
        std::fprintf(stderr, "%s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--per-stage")
      o.PerStage = std::max(1, std::atoi(next()));
    else if (a == "--threads")
      o.Threads = std::max(0, std::atoi(next()));
    else if (a == "--vertices")
      o.Vertices = std::atoi(next());
    else if (a == "--iso")
      o.IsoValue = std::atof(next());
    else if (a == "--optimize")
      o.Optimize = true;
    else if (a == "--builtin")
      o.Builtin = true;
    else if (a == "--no-check")
      o.Check = false;
    else if (a == "--only")
      o.Only.push_back(next());
    else if (a == "-h" || a == "--help")
    {
      std::printf("usage: sdfcage_cancel_benchmark [MESH] [--per-stage K] [--threads T] [--vertices V] [--iso C] "
                  "[--optimize] [--builtin] [--no-check] [--only TEXT]...\n");
      return 0;
    }
    else if (!a.empty() && a[0] == '-')
    {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
    else
      o.Mesh = a;
  }

  sdfcage::PolygonMesh mesh;
  std::string name = "builtin";
  if (o.Builtin)
    mesh = sdfcage::PolygonMesh::fromTriangles(sdfcage::makeBuiltinShape());
  else
  {
    std::string error;
    if (!sdfcage::exact::readPolygonMesh(o.Mesh, mesh, error))
    {
      std::fprintf(stderr, "cannot read %s: %s\n", o.Mesh.c_str(), error.c_str());
      return 2;
    }
    name = o.Mesh.substr(o.Mesh.find_last_of('/') + 1);
  }
  vtkSmartPointer<vtkPolyData> input = toPolyData(mesh);
  sdfcage::TriangleMesh inputTriangles;
  sdfcage::exact::fanTriangulate(mesh, inputTriangles);

  // the uninterrupted run: total time and the stages with their durations
  double total = 0.0;
  std::vector<std::pair<std::string, double>> stages;
  {
    RunRecord record;
    auto filter = makeFilter(input, o, record);
    record.Start = Clock::now();
    filter->Update();
    total = since(record.Start);
    std::printf("%s, uninterrupted: %.2f s, status %s, %lld cage vertices, %d progress events (longest gap %.3f s)\n",
      name.c_str(), total, filter->GetStatusString(), static_cast<long long>(filter->GetOutput()->GetNumberOfPoints()),
      record.Events, record.LongestEventGap);
    std::printf("stages:");
    for (const auto& e : record.Texts)
      std::printf(" %.2f %s;", e.first, e.second.c_str());
    std::printf("\n");
    // each stage once, at its first occurrence: a try waits for the stage's first showing (the
    // optimization's stages come back every sweep; trying them again would repeat the same tries)
    for (std::size_t k = 0; k < record.Texts.size(); ++k)
    {
      const double end = k + 1 < record.Texts.size() ? record.Texts[k + 1].first : total;
      const std::string& text = record.Texts[k].second;
      const bool seen = std::any_of(
        stages.begin(), stages.end(), [&text](const std::pair<std::string, double>& s) { return s.first == text; });
      const bool wanted = o.Only.empty() ||
        std::any_of(o.Only.begin(), o.Only.end(), [&text](const std::string& w) { return text.find(w) != std::string::npos; });
      if (!text.empty() && !seen && wanted)
        stages.emplace_back(text, end - record.Texts[k].first);
    }
    std::printf("longest time between progress events (the filter's Abort is polled there), per stage:\n");
    for (const auto& g : record.StageGaps)
      std::printf("  %-45s %.3f s (until %.2f s)\n", g.first.c_str(), g.second.first, g.second.second);
  }

  std::map<std::string, std::vector<double>> latencies;
  std::vector<std::string> order;
  int broken = 0;
  double worst = 0.0;
  int i = 0;
  for (const auto& stage : stages)
    for (int k = 0; k < o.PerStage; ++k, ++i)
    {
      const double delay = stage.second * (k + 0.5) / o.PerStage;
      RunRecord record;
      auto filter = makeFilter(input, o, record);
      std::condition_variable done;
      bool finished = false;
      Clock::time_point requested{};
      record.TriggerStage = stage.first;
      record.Wake = &done;
      record.Start = Clock::now();
      std::thread timer([&] {
        std::unique_lock<std::mutex> lock(record.Lock);
        done.wait(lock, [&] { return finished || record.StageSeen >= 0.0; });
        if (finished)
          return;
        const auto at = record.Start +
          std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(record.StageSeen + delay));
        if (!done.wait_until(lock, at, [&] { return finished; }))
        {
          requested = Clock::now();
          record.AbortRequested.store(true);
        }
      });
      filter->Update();
      const Clock::time_point returned = Clock::now();
      {
        std::lock_guard<std::mutex> lock(record.Lock);
        finished = true;
      }
      done.notify_all();
      timer.join();
      char when[160];
      std::snprintf(when, sizeof when, "%.2f s into '%s'", delay, stage.first.c_str());
      if (!record.AbortRequested.load())
      {
        std::printf("try %2d: abort %s: the run ended first (%.2f s), status %s\n", i, when,
          since(record.Start, returned), filter->GetStatusString());
        continue;
      }
      const double latency = since(requested, returned);
      const std::string at = stageAt(record, since(record.Start, requested));
      if (!latencies.count(at))
        order.push_back(at);
      latencies[at].push_back(latency);
      worst = std::max(worst, latency);

      vtkPolyData* cage = filter->GetOutput();
      std::string verdict = "empty";
      if (cage->GetNumberOfPoints() > 0)
      {
        if (o.Check)
        {
          const sdfcage::exact::ExactReport report = sdfcage::exact::exactCheck(inputTriangles, toTriangles(cage), 0.0);
          verdict = report.Encloses ? "verified cage of " + std::to_string(cage->GetNumberOfPoints()) + " vertices"
                                    : "BROKEN cage of " + std::to_string(cage->GetNumberOfPoints()) + " vertices";
          broken += report.Encloses ? 0 : 1;
        }
        else
          verdict = "cage of " + std::to_string(cage->GetNumberOfPoints()) + " vertices (not checked)";
      }
      std::printf("try %2d: abort %-50s (in '%s'): %.3f s, status %s, output: %s\n", i, when, at.c_str(), latency,
        filter->GetStatusString(), verdict.c_str());
      std::fflush(stdout);
    }
  std::printf("%-48s %5s %8s %8s\n", "stage", "tries", "median", "worst");
  for (const std::string& s : order)
    std::printf("%-48s %5zu %8.3f %8.3f\n", s.c_str(), latencies[s].size(), median(latencies[s]),
      *std::max_element(latencies[s].begin(), latencies[s].end()));
  std::printf("worst latency %.3f s; broken outputs: %d\n", worst, broken);
  return broken == 0 ? 0 : 1;
}
