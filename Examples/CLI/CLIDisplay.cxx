// SDFCage — CLI: the X display connection, alone in this file because Xlib.h defines macros
// (Status, Bool, None, ...) that clash with other headers.
#include <X11/Xlib.h>

namespace sdfcage_cli
{

namespace
{
Display* TheDisplay = nullptr;
}

void* openXDisplay()
{
  // Kept open until closeXDisplay(): an X server without -noreset (Xvfb's default) resets when
  // its last client disconnects, and a connection attempted during that reset fails. VTK's
  // render window aborts the process when its own connection fails, so the program opens one
  // connection, keeps it, and hands it to VTK.
  if (!TheDisplay)
  {
    TheDisplay = XOpenDisplay(nullptr);
  }
  return TheDisplay;
}

void closeXDisplay()
{
  if (TheDisplay)
  {
    XCloseDisplay(TheDisplay);
    TheDisplay = nullptr;
  }
}

} // namespace sdfcage_cli
