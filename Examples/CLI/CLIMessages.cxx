// SDFCage — CLI: see CLIMessages.h.
#include "CLIMessages.h"

#include <vtkLogger.h>
#include <vtkObjectFactory.h>
#include <vtkSmartPointer.h>

namespace sdfcage_cli
{

vtkStandardNewMacro(MessageCollector);

MessageCollector* MessageCollector::install()
{
  vtkSmartPointer<MessageCollector> collector = vtkSmartPointer<MessageCollector>::New();
  vtkOutputWindow::SetInstance(collector); // VTK keeps a reference
  // VTK >= 9 also logs every error through vtkLogger (loguru) straight to stderr: silence that
  // copy, the collector has the message.
  vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  return collector;
}

void MessageCollector::DisplayText(const char* text)
{
  // Plain text (e.g. PrintSelf to the output window): treat as a warning so it is not lost.
  if (text && *text)
  {
    this->Warnings.push_back(clean(text));
  }
}

void MessageCollector::DisplayErrorText(const char* text)
{
  this->Errors.push_back(clean(text));
}

void MessageCollector::DisplayWarningText(const char* text)
{
  this->Warnings.push_back(clean(text));
}

void MessageCollector::DisplayGenericWarningText(const char* text)
{
  this->Warnings.push_back(clean(text));
}

void MessageCollector::DisplayDebugText(const char*)
{
  // debug output is never shown by the command-line program
}

void MessageCollector::clear()
{
  this->Errors.clear();
  this->Warnings.clear();
}

std::string MessageCollector::clean(const char* vtkText)
{
  std::string s = vtkText ? vtkText : "";
  // VTK formats "ERROR: In <file>, line <n>\n<class> (<address>): <text>\n\n"; generic
  // warnings have no "<class> (<address>): " part.
  if (s.compare(0, 3, "In ") == 0 || s.find(": In ") != std::string::npos)
  {
    const std::size_t eol = s.find('\n');
    if (eol != std::string::npos)
    {
      s.erase(0, eol + 1);
    }
  }
  const std::size_t eol = s.find('\n');
  const std::size_t obj = s.find("): ");
  if (obj != std::string::npos && (eol == std::string::npos || obj < eol) && s.find(" (0x") != std::string::npos &&
    s.find(" (0x") < obj)
  {
    s.erase(0, obj + 3);
  }
  while (!s.empty() && (s.back() == '\n' || s.back() == ' ' || s.back() == '\r'))
  {
    s.pop_back();
  }
  return s;
}

} // namespace sdfcage_cli
