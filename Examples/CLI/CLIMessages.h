// SDFCage — CLI: collects VTK's error/warning output so the program can print one clean line
// ("sdfcage: error: ...") instead of VTK's multi-line, source-located messages.
#pragma once

#include <vtkOutputWindow.h>

#include <string>
#include <vector>

namespace sdfcage_cli
{

/// Replaces VTK's global output window (install() once, at start). Messages are stored, not
/// printed; the program decides what to show after each step.
class MessageCollector : public vtkOutputWindow
{
public:
  static MessageCollector* New();
  vtkTypeMacro(MessageCollector, vtkOutputWindow);

  /// Makes a collector VTK's output window and returns it (owned by VTK).
  static MessageCollector* install();

  void DisplayText(const char* text) override;
  void DisplayErrorText(const char* text) override;
  void DisplayWarningText(const char* text) override;
  void DisplayGenericWarningText(const char* text) override;
  void DisplayDebugText(const char* text) override;

  /// Messages since the last clear(), cleaned of VTK's "ERROR: In file, line N" prefix.
  const std::vector<std::string>& errors() const { return this->Errors; }
  const std::vector<std::string>& warnings() const { return this->Warnings; }
  void clear();

  /// "In file.cxx, line 12\nvtkClass (0x...): text" -> "text".
  static std::string clean(const char* vtkText);

protected:
  MessageCollector() = default;
  ~MessageCollector() override = default;

private:
  MessageCollector(const MessageCollector&) = delete;
  void operator=(const MessageCollector&) = delete;

  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
};

} // namespace sdfcage_cli
