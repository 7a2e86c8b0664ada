// The installed ofv::display links and, with no display, refuses to open a
// window with ofv::DisplayUnavailable (what `--display` turns into exit 2).
#include <ofv/display/live_display.h>

#include <cstdlib>
#include <iostream>

int main() {
  unsetenv("DISPLAY");
  ofv::DisplayControl control;
  if (control.handle(ofv::DisplayControl::Event::RightClick) != ofv::DisplayControl::State::Quit)
    return 1;
  try {
    ofv::LiveDisplay display({});
    std::cerr << "consumer_display: opened a window without a display\n";
    return 1;
  } catch (const ofv::DisplayUnavailable& e) {
    std::cout << "refused as it should: " << e.what() << '\n';
    return 0;
  }
}
