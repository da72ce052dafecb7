// SDFCage — small helpers shared by the C++ filter tests.
#pragma once

#include "vtkCommand.h"
#include "vtkNew.h"
#include "vtkSmartPointer.h"

#include <iostream>
#include <sstream>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkPolyData;

namespace sdfcage_test
{

/// Arguments every test case gets: a scratch folder and the data folder (may not exist).
struct Context
{
  std::string Scratch;
  std::string DataDir;
};

/// Exit code of a skipped test (CTest SKIP_RETURN_CODE).
constexpr int Skipped = 125;

/// Records error and warning events instead of letting them reach the output window, so that a
/// test can assert that an expected error happened (and unexpected ones still fail it).
class MessageRecorder : public vtkCommand
{
public:
  static MessageRecorder* New() { return new MessageRecorder; }

  void Execute(vtkObject*, unsigned long event, void* callData) override
  {
    // The event carries "ERROR: In <file>, line <n>\n<class> (<address>): <message>\n\n";
    // keep the message only (printing the full text would trip CTest's "ERROR:" check).
    std::string text = callData ? static_cast<const char*>(callData) : "";
    const std::size_t start = text.find("): ");
    if (start != std::string::npos)
    {
      text.erase(0, start + 3);
    }
    while (!text.empty() && (text.back() == '\n' || text.back() == ' '))
    {
      text.pop_back();
    }
    if (event == vtkCommand::ErrorEvent)
    {
      this->Errors.push_back(text);
    }
    else if (event == vtkCommand::WarningEvent)
    {
      this->Warnings.push_back(text);
    }
  }

  /// Listens to `object` (a filter and, for the "returned failure" report, its executive).
  void Watch(vtkObject* object)
  {
    object->AddObserver(vtkCommand::ErrorEvent, this);
    object->AddObserver(vtkCommand::WarningEvent, this);
  }

  bool ErrorContains(const std::string& needle) const
  {
    for (const std::string& e : this->Errors)
    {
      if (e.find(needle) != std::string::npos)
      {
        return true;
      }
    }
    return false;
  }

  void Clear()
  {
    this->Errors.clear();
    this->Warnings.clear();
  }

  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
};

/// Collects failures; a test fails if any check failed.
class Checker
{
public:
  explicit Checker(const char* name)
    : Name(name)
  {
  }

  bool Check(bool condition, const std::string& what)
  {
    if (!condition)
    {
      ++this->Failures;
      std::cerr << "FAILED [" << this->Name << "]: " << what << "\n";
    }
    return condition;
  }

  int Result() const
  {
    if (this->Failures == 0)
    {
      std::cout << "passed [" << this->Name << "]\n";
      return 0;
    }
    std::cerr << this->Failures << " check(s) failed in " << this->Name << "\n";
    return 1;
  }

private:
  std::string Name;
  int Failures = 0;
};

template <typename T>
std::string Str(const T& value)
{
  std::ostringstream s;
  s << value;
  return s.str();
}

/// Number of boundary plus non-manifold edges (0 for a closed 2-manifold surface).
vtkIdType CountOpenEdges(vtkPolyData* mesh);

/// A closed triangulated sphere (vtkSphereSource), outward oriented.
vtkSmartPointer<vtkPolyData> MakeSphere(double radius, int resolution);

// Test cases (each returns 0, 1 or Skipped).
int TestSphere(const Context&);
int TestOptimizeFilter(const Context&);
int TestOptimizeTightOptions(const Context&);
int TestOptimizeKeepsPartsApart(const Context&);
int TestBuiltinShape(const Context&);
int TestOpenInput(const Context&);
int TestChooseIsoValueFirst(const Context&);
int TestNoSurface(const Context&);
int TestEmptyInput(const Context&);
int TestAbort(const Context&);
int TestDistanceField(const Context&);
int TestParameters(const Context&);
int TestDataKnight(const Context&);
int TestDataBunnyOFF(const Context&);
int TestOFFRoundTrip(const Context&);
int TestOFFVariants(const Context&);
int TestOFFMalformed(const Context&);
int TestActivePointsBuiltin(const Context&);
int TestActivePointsErrors(const Context&);

} // namespace sdfcage_test
