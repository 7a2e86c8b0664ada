//! \example tutorial-real-robot.cpp
//! Tutorial 4: attach a real robot. Any ViSP vpRobot driver carries the camera;
//! ofv::VispRobot commands it in the camera frame and ofv::SafetyFilter stands
//! between the controller and the hardware (speed, acceleration, workspace,
//! zero velocity when the object is lost or the frame is stale). This program
//! is compiled everywhere; the driver part only where ViSP has the driver
//! (Debian's libvisp-dev has none: it then says so and exits).
//!
//!   tutorial-real-robot [--dry-run]
#include <ofv/servo/controller.h>
#include <ofv/servo/robot.h>
#include <ofv/servo/safety.h>

#include <visp3/core/vpConfig.h>
#if defined(VISP_HAVE_VIPER850)
#include <visp3/robot/vpRobotViper850.h>
#endif

#include <csignal>
#include <cstring>
#include <iostream>

namespace {
volatile std::sig_atomic_t stop_requested = 0;
void on_sigint(int) { stop_requested = 1; }
}  // namespace

int main(int argc, char** argv) {
  const bool dry_run = argc > 1 && std::strcmp(argv[1], "--dry-run") == 0;
  std::signal(SIGINT, on_sigint);  // Ctrl-C: zero velocity, then exit

  ofv::SafetySettings safety;
  safety.workspace = Eigen::AlignedBox3d(Eigen::Vector3d(-0.4, -0.4, 0.2), Eigen::Vector3d(0.4, 0.4, 0.9));
  ofv::SafetyFilter filter(safety);
  ofv::ViewController controller;

#if defined(VISP_HAVE_VIPER850)
  vpRobotViper850 driver;
  ofv::VispRobot robot(driver, vpHomogeneousMatrix(), "viper850");
#else
  if (!dry_run) {
    std::cout << "This ViSP has no real-robot driver (VISP_HAVE_VIPER850, VISP_HAVE_FRANKA, ...); "
                 "run with --dry-run to see the commands on a simulated camera.\n";
    return 0;
  }
  ofv::FreeFlyingCamera robot(vpHomogeneousMatrix(0.0, 0.0, 0.3, 0.0, 0.0, 0.0));
#endif

  // In a real application, C and t_f come from `ofv perceive`'s pipeline every
  // frame; here they are fixed: hold a view 20 degrees to the side.
  const Eigen::Vector3d centroid(0.0, 0.0, 0.8), tf(0.17, 0.0, 0.33);
  for (int k = 0; k < 60 && !stop_requested; ++k) {
    const double dt = 1.0 / 30.0;
    const vpColVector v = controller.update(tf, centroid, 0.5, robot.wMc(), dt);
    const vpColVector safe = filter.filter(v, robot.wMc(), dt, /*object_tracked=*/true, /*frame_age=*/0.0);
    if (dry_run) {
      std::cout << "step " << k << ": v = " << safe.t() << (*filter.last_reason() ? "  (" : "")
                << filter.last_reason() << (*filter.last_reason() ? ")" : "") << '\n';
    }
    robot.step(safe, dt);
  }
  robot.step(vpColVector(6, 0.0), 0.0);  // leave the robot at rest
  return 0;
}
