// SDFCage — CLI: see CLIScreenshot.h. The rendering itself is in the module
// libsdfcage_screenshot.so (CLIScreenshot.cxx), loaded here on first use, so that a run without
// a picture does not load VTK's OpenGL rendering and its X and GL libraries.
#include "CLIScreenshot.h"

#if SDFCAGE_CLI_HAVE_RENDERING

#include <dlfcn.h>

#include <filesystem>
#include <system_error>

namespace sdfcage_cli
{

namespace
{

using CanRenderFunction = bool (*)(std::string*);
using WriteFunction = bool (*)(vtkPolyData*, vtkPolyData*, const std::string*, const std::string*, std::string*);

struct Module
{
  bool Tried = false;
  CanRenderFunction CanRender = nullptr;
  WriteFunction Write = nullptr;
  std::string Error;
};

/// The module sits in the library folder beside the program's: build/lib next to build/bin,
/// <prefix>/lib next to <prefix>/bin.
Module& module()
{
  static Module m;
  if (m.Tried)
  {
    return m;
  }
  m.Tried = true;
  std::error_code ec;
  const std::filesystem::path self = std::filesystem::read_symlink("/proc/self/exe", ec);
  const std::filesystem::path path =
    (ec ? std::filesystem::path(".") : self.parent_path()) / ".." / "lib" / "libsdfcage_screenshot.so";
  void* handle = dlopen(path.c_str(), RTLD_NOW | RTLD_LOCAL);
  if (!handle)
  {
    const char* why = dlerror();
    m.Error = "cannot render: the screenshot module could not be loaded (" + std::string(why ? why : path.string()) +
      "; it is built with the program and installed beside its library folder)";
    return m;
  }
  m.CanRender = reinterpret_cast<CanRenderFunction>(dlsym(handle, "sdfcage_screenshot_can_render"));
  m.Write = reinterpret_cast<WriteFunction>(dlsym(handle, "sdfcage_screenshot_write"));
  if (!m.CanRender || !m.Write)
  {
    m.CanRender = nullptr;
    m.Write = nullptr;
    m.Error = "cannot render: " + path.string() + " is not this program's screenshot module";
  }
  return m; // kept loaded until the process ends (VTK's factories registered by it stay valid)
}

} // namespace

bool renderingAvailable()
{
  return module().Write != nullptr;
}

bool canRender(std::string& error)
{
  Module& m = module();
  if (!m.CanRender)
  {
    error = m.Error;
    return false;
  }
  return m.CanRender(&error);
}

bool writeScreenshot(
  vtkPolyData* input, vtkPolyData* cage, const std::string& title, const std::string& path, std::string& error)
{
  Module& m = module();
  if (!m.Write)
  {
    error = m.Error;
    return false;
  }
  return m.Write(input, cage, &title, &path, &error);
}

} // namespace sdfcage_cli

#else // no rendering in this build

namespace sdfcage_cli
{

bool renderingAvailable()
{
  return false;
}

bool canRender(std::string& error)
{
  error = "cannot render: this sdfcage was built without VTK rendering (VTK::RenderingOpenGL2 "
          "or one of its dependencies was not found when it was configured)";
  return false;
}

bool writeScreenshot(vtkPolyData*, vtkPolyData*, const std::string&, const std::string&, std::string& error)
{
  return canRender(error);
}

} // namespace sdfcage_cli

#endif
