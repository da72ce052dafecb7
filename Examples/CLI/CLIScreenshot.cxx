// SDFCage — CLI: the offscreen picture of the input and its cage, built as a module of its own
// (libsdfcage_screenshot.so) that the program loads only when a picture is asked for
// (CLIScreenshotLoader.cxx): VTK's OpenGL rendering and the X and GL libraries it pulls in cost
// every run about 75 ms of start-up (dynamic linking and their initializers: `sdfcage --help`
// 0.08 s against 0.008 s for the same program without them), a seventh of a small mesh's run.
#include <string>

#include <vtkActor.h>
#include <vtkCamera.h>
#include <vtkColorTransferFunction.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkProperty.h>
#include <vtkRenderWindow.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkWindowToImageFilter.h>

#include <csignal>
#include <cstdlib>
#include <filesystem>

#include <unistd.h> // write

namespace sdfcage_cli
{

/// In CLIDisplay.cxx, the only file that includes Xlib.h (its macros clash with other headers):
/// the program's one X connection (a Display*), opened once and kept; nullptr on failure.
void* openXDisplay();
void closeXDisplay();

namespace
{

/// VTK's X render window aborts the process when it cannot connect to the display: check the
/// connection ourselves first.
bool displayReachable(std::string& error)
{
  const char* name = std::getenv("DISPLAY");
  if (!name || !*name)
  {
    error = "cannot render: DISPLAY is not set (rendering needs an X server; on a headless "
            "machine run the command under `xvfb-run -a`)";
    return false;
  }
  if (!openXDisplay())
  {
    error = std::string("cannot render: cannot open the X display '") + name +
      "' (rendering needs an X server; on a headless machine run the command under "
      "`xvfb-run -a`)";
    return false;
  }
  return true;
}

vtkSmartPointer<vtkPolyData> withNormals(vtkPolyData* mesh)
{
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputData(mesh);
  normals->SplittingOff();
  normals->ConsistencyOff(); // both meshes are already consistently oriented
  normals->Update();
  return normals->GetOutput();
}

} // namespace

bool canRenderHere(std::string& error)
{
  return displayReachable(error);
}

namespace
{

extern "C" void onAbortWhileRendering(int)
{
  // VTK's X render window calls abort() on some failures (e.g. no usable GLX visual) instead of
  // reporting an error: say what happened before dying (write() is async-signal-safe).
  static const char message[] = "\nsdfcage: error: VTK aborted while rendering the screenshot "
                                "(is the X server usable for OpenGL? try `xvfb-run -a`)\n";
  const ssize_t ignored = write(STDERR_FILENO, message, sizeof(message) - 1);
  (void)ignored;
  std::signal(SIGABRT, SIG_DFL);
  std::raise(SIGABRT);
}

bool render(
  vtkPolyData* input, vtkPolyData* cage, const std::string& title, const std::string& path, std::string& error)
{
  vtkNew<vtkRenderWindow> window;
  window->SetDisplayId(openXDisplay()); // our connection: VTK neither opens nor closes one
  window->SetOffScreenRendering(1);
  window->SetSize(1200, 800);
  window->SetMultiSamples(0);
  window->SetAlphaBitPlanes(1); // depth peeling for the translucent cage
  if (!window->SupportsOpenGL())
  {
    error = "cannot render: the X server offers no usable OpenGL (GLX) context";
    return false;
  }

  vtkNew<vtkRenderer> renderer;
  renderer->GradientBackgroundOn();
  renderer->SetBackground(0.78, 0.82, 0.88); // bottom
  renderer->SetBackground2(1.0, 1.0, 1.0);   // top
  renderer->SetUseDepthPeeling(1);
  renderer->SetMaximumNumberOfPeels(8);
  renderer->SetOcclusionRatio(0.0);
  window->AddRenderer(renderer);

  // input: opaque, light grey
  vtkNew<vtkPolyDataMapper> inputMapper;
  inputMapper->SetInputData(withNormals(input));
  inputMapper->ScalarVisibilityOff();
  vtkNew<vtkActor> inputActor;
  inputActor->SetMapper(inputMapper);
  inputActor->GetProperty()->SetColor(0.83, 0.83, 0.83);
  inputActor->GetProperty()->SetSpecular(0.2);
  inputActor->GetProperty()->SetSpecularPower(20.0);
  renderer->AddActor(inputActor);

  // cage: translucent, coloured by DistanceToInput
  if (cage && cage->GetNumberOfCells() > 0)
  {
    vtkSmartPointer<vtkPolyData> shaded = withNormals(cage);
    vtkNew<vtkPolyDataMapper> cageMapper;
    cageMapper->SetInputData(shaded);
    vtkDataArray* distance = shaded->GetPointData()->GetArray("DistanceToInput");
    // a sequential map (viridis' control colours): the distances of an envelope are nearly
    // constant, a diverging map would show them all as its grey midpoint
    vtkNew<vtkColorTransferFunction> colors;
    colors->SetColorSpaceToLab();
    double range[2] = { 0.0, 1.0 };
    if (distance)
    {
      distance->GetRange(range, 0);
      if (!(range[1] > range[0]))
      {
        range[1] = range[0] + 1e-12;
      }
    }
    const double viridis[5][3] = { { 0.267, 0.005, 0.329 }, { 0.231, 0.322, 0.545 }, { 0.129, 0.569, 0.549 },
      { 0.369, 0.788, 0.384 }, { 0.992, 0.906, 0.145 } };
    for (int k = 0; k < 5; ++k)
    {
      colors->AddRGBPoint(range[0] + (range[1] - range[0]) * k / 4.0, viridis[k][0], viridis[k][1], viridis[k][2]);
    }
    if (distance)
    {
      cageMapper->SetScalarModeToUsePointFieldData();
      cageMapper->SelectColorArray("DistanceToInput");
      cageMapper->SetLookupTable(colors);
      cageMapper->SetScalarRange(range);
      cageMapper->ScalarVisibilityOn();
    }
    else
    {
      cageMapper->ScalarVisibilityOff();
    }
    vtkNew<vtkActor> cageActor;
    cageActor->SetMapper(cageMapper);
    cageActor->GetProperty()->SetOpacity(0.4);
    if (!distance)
    {
      cageActor->GetProperty()->SetColor(0.129, 0.569, 0.549);
    }
    if (cage->GetNumberOfCells() <= 20000)
    {
      // a coarse cage reads better with its edges; a dense envelope would turn black
      cageActor->GetProperty()->EdgeVisibilityOn();
      cageActor->GetProperty()->SetEdgeColor(0.25, 0.25, 0.3);
    }
    renderer->AddActor(cageActor);

    if (distance)
    {
      vtkNew<vtkScalarBarActor> bar;
      bar->SetLookupTable(colors);
      bar->SetTitle("Distance to input");
      bar->SetNumberOfLabels(5);
      bar->SetLabelFormat("%.3g");
      bar->SetPosition(0.87, 0.12);
      bar->SetWidth(0.1);
      bar->SetHeight(0.72);
      bar->UnconstrainedFontSizeOn();
      bar->SetVerticalTitleSeparation(12);
      for (vtkTextProperty* text : { bar->GetTitleTextProperty(), bar->GetLabelTextProperty() })
      {
        text->SetColor(0.15, 0.15, 0.15);
        text->ShadowOff();
        text->ItalicOff();
        text->SetFontSize(16);
      }
      renderer->AddActor2D(bar);
    }
  }

  vtkNew<vtkTextActor> caption;
  caption->SetInput(title.c_str());
  caption->GetTextProperty()->SetFontSize(22);
  caption->GetTextProperty()->SetColor(0.1, 0.1, 0.1);
  caption->GetTextProperty()->SetJustificationToCentered();
  caption->GetTextProperty()->SetVerticalJustificationToTop();
  caption->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  caption->SetPosition(0.5, 0.96);
  renderer->AddActor2D(caption);

  renderer->ResetCamera();
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->Elevation(25.0);
  camera->Azimuth(30.0);
  camera->OrthogonalizeViewUp();
  renderer->ResetCamera();
  camera->Zoom(1.25);

  window->Render();

  vtkNew<vtkWindowToImageFilter> grab;
  grab->SetInput(window);
  grab->SetInputBufferTypeToRGB();
  grab->ReadFrontBufferOff();
  grab->Update();

  vtkNew<vtkPNGWriter> png;
  png->SetFileName(path.c_str());
  png->SetInputConnection(grab->GetOutputPort());
  png->Write();

  window->Finalize(); // release the OpenGL context while our X connection is still open

  std::error_code ec;
  // (errors VTK reported through its output window are checked by the program: CLIMessages)
  if (png->GetErrorCode() != 0 || !std::filesystem::exists(path, ec))
  {
    error = "cannot write the screenshot '" + path + "'";
    return false;
  }
  return true;
}

} // namespace

bool writeScreenshotHere(
  vtkPolyData* input, vtkPolyData* cage, const std::string& title, const std::string& path, std::string& error)
{
  if (!displayReachable(error))
  {
    return false;
  }
  void (*previous)(int) = std::signal(SIGABRT, onAbortWhileRendering);
  const bool ok = render(input, cage, title, path, error); // the window is gone afterwards
  std::signal(SIGABRT, previous);
  closeXDisplay();
  return ok;
}

} // namespace sdfcage_cli

// The module's entry points (CLIScreenshotLoader.cxx finds them with dlsym).
extern "C" bool sdfcage_screenshot_can_render(std::string* error)
{
  return sdfcage_cli::canRenderHere(*error);
}

extern "C" bool sdfcage_screenshot_write(
  vtkPolyData* input, vtkPolyData* cage, const std::string* title, const std::string* path, std::string* error)
{
  return sdfcage_cli::writeScreenshotHere(input, cage, *title, *path, *error);
}
