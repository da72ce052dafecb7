// SDFCage — CLI: offscreen picture of the input and its cage.
#pragma once

#include <string>

class vtkPolyData;

namespace sdfcage_cli
{

/// True when this build can render (VTK's OpenGL rendering was found at configure time).
bool renderingAvailable();

/// True when a screenshot can be attempted now: rendering is built in and the X display opens.
/// Otherwise false with a reason that says what to do (e.g. run under `xvfb-run -a`).
bool canRender(std::string& error);

/// Renders `input` (opaque, light grey) and `cage` (translucent, coloured by its point array
/// "DistanceToInput", with a colour bar) under `title`, offscreen, into the PNG `path`.
/// Needs an X server (run under `xvfb-run -a` on a headless machine): checked first, so a
/// missing display is an error message, never a crash. Returns false with a reason.
bool writeScreenshot(
  vtkPolyData* input, vtkPolyData* cage, const std::string& title, const std::string& path, std::string& error);

} // namespace sdfcage_cli
