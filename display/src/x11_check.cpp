// Whether an X display accepts a connection. Its own file: Xlib defines
// macros (None, Status, ...) that clash with ofv's enumerators.
#include <X11/Xlib.h>

namespace ofv::detail {

bool x11_connects(const char* name) {
  ::Display* x = XOpenDisplay(name);
  if (x == nullptr) return false;
  XCloseDisplay(x);
  return true;
}

}  // namespace ofv::detail
