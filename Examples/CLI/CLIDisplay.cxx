// SDFCage — CLI: the X display check, alone in this file because Xlib.h defines macros
// (Status, Bool, None, ...) that clash with other headers.
#include <X11/Xlib.h>

namespace sdfcage_cli
{

bool canOpenXDisplay()
{
  Display* display = XOpenDisplay(nullptr);
  if (!display)
  {
    return false;
  }
  XCloseDisplay(display);
  return true;
}

} // namespace sdfcage_cli
