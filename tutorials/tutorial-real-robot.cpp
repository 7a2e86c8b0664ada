//! \example tutorial-real-robot.cpp
//! Tutorial 4: attach a real robot. Any ViSP vpRobot driver carries the camera;
//! ofv::servo::VispRobot commands it in the camera frame. ofv::servo::ViewLoop is the
//! per-frame policy that `ofv simulate` and `ofv run` use: from the frame's
//! observation (object supervoxels and occluders, from ofv::perception::PerceptionObserver
//! on your sensor's frames, and the camera pose) to a safe camera twist — view
//! selection, target continuity, the controller and the safety filter
//! (speed, acceleration, workspace, zero velocity when the object is lost or
//! the frame is stale). This program is compiled everywhere; the driver part
//! only where ViSP has the driver (Debian's libvisp-dev has none: it then says
//! so and exits, or with `--dry-run` prints the commands on a simulated camera).
//!
//!     tutorial-real-robot [--dry-run] [--display]
//!
//! `--display` shows the loop live (ofv::LiveDisplay): the problem's
//! supervoxels and occluders as the camera sees them, the feature, the scene
//! view and the curves. A left click pauses (the robot is sent a zero
//! velocity first), a right click or q stops as Ctrl-C does.
//!
//! With a sensor, `ofv::servo::run_on_robot(source, perception, robot, settings,
//! options)` runs this same loop until Ctrl-C, `perception` an
//! ofv::perception::PerceptionObserver; `ofv run` is that call. The front end's
//! `PerceptionSettings::selection` points out the object in the first frame
//! (a world box or an image rectangle, as `ofv run --box` / `--rect`); by
//! default it takes the cluster nearest the image centre.
#include <ofv/servo/robot.h>
#include <ofv/servo/view_loop.h>
#include <ofv/servo/target_pose.h>
#if defined(OFV_HAVE_DISPLAY)
#include <ofv/display/live_display.h>
#endif

#include <visp3/core/vpConfig.h>
#if defined(VISP_HAVE_VIPER850)
#include <visp3/robot/vpRobotViper850.h>
#endif

#include <csignal>
#include <cstring>
#include <iostream>
#include <memory>

namespace {
volatile std::sig_atomic_t stop_requested = 0;
void on_sigint(int) { stop_requested = 1; }

// Stand-in for ofv::perception::Perception's output: a 10 x 10 cm patch 0.8 m ahead
// facing the camera, and a hand-sized occluder that crosses its line of sight.
ofv::ViewProblem frame_problem(double t) {
  ofv::ViewProblem p;
  p.positions.resize(3, 25);
  p.normals.resize(3, 25);
  for (int k = 0; k < 25; ++k) {
    p.positions.col(k) << (k % 5 - 2) * 0.025, (k / 5 - 2) * 0.025, 0.8;
    p.normals.col(k) << 0, 0, -1;
  }
  p.occluders.resize(3, 9);
  for (int k = 0; k < 9; ++k) p.occluders.col(k) << -0.3 + 0.3 * t + (k % 3) * 0.02, (k / 3 - 1) * 0.02, 0.5;
  return p;
}
}  // namespace

int main(int argc, char** argv) {
  bool dry_run = false, display = false;
  for (int i = 1; i < argc; ++i) {
    dry_run = dry_run || std::strcmp(argv[i], "--dry-run") == 0;
    display = display || std::strcmp(argv[i], "--display") == 0;
  }
  std::signal(SIGINT, on_sigint);  // Ctrl-C: zero velocity, then exit

  // 1. Settings by name, as `ofv run --set` takes them; here a workspace box for the camera.
  ofv::servo::LoopSettings settings;
  ofv::servo::loop_settings_table().set(settings, "workspace", "-0.4,-0.4,0.1,0.4,0.4,0.9");
  ofv::servo::loop_settings_table().set(settings, "max_linear_speed", "0.25");
  ofv::servo::ViewLoop loop(settings);

  // 2. The robot.
#if defined(VISP_HAVE_VIPER850)
  vpRobotViper850 driver;
  ofv::servo::VispRobot robot(driver, vpHomogeneousMatrix(), "viper850");
#else
  if (!dry_run) {
    std::cout << "This ViSP has no real-robot driver (VISP_HAVE_VIPER850, VISP_HAVE_FRANKA, ...); "
                 "run with --dry-run to see the commands on a simulated camera.\n";
    return 0;
  }
  ofv::servo::FreeFlyingCamera robot(vpHomogeneousMatrix(0.0, 0.0, 0.3, 0.0, 0.0, 0.0));
#endif

  // 3. The loop: one frame period at a time.
  const double dt = 1.0 / 30.0;
#if defined(OFV_HAVE_DISPLAY)
  // Optional live windows; a pause holds the robot, a quit stops as Ctrl-C.
  std::unique_ptr<ofv::LiveDisplay> live;
  if (display) {
    try {
      ofv::LiveDisplayOptions options;
      options.title = "tutorial-real-robot";
      options.r_sphere = loop.estimator().r_sphere;
      options.pace_rate = 1.0 / dt;
      live = std::make_unique<ofv::LiveDisplay>(options);
      live->set_pause_hook([&robot] { robot.step(vpColVector(6, 0.0), 0.0); });
    } catch (const ofv::DisplayUnavailable& e) {
      std::cerr << "tutorial-real-robot: " << e.what() << '\n';
      return 2;
    }
  }
#else
  if (display) {
    std::cerr << "tutorial-real-robot: --display: this ofv was built without ofv::display\n";
    return 2;
  }
#endif
  int clear = 0;
  for (int k = 0; k < 60 && !stop_requested; ++k) {
    ofv::Observation seen;  // what ofv::perception::PerceptionObserver::observe gives for a frame
    seen.problem = frame_problem(k * dt);
    const vpHomogeneousMatrix wMc = robot.wMc();
    seen.wMc = ofv::servo::to_eigen(wMc);
    seen.age = 0.0;  // how old the frame is when the command is sent
    const ofv::servo::LoopStep s = loop.step(seen, dt);
    if (dry_run) {
      std::cout << "step " << k << ": " << ofv::to_string(s.status) << ", v = " << s.velocity.t();
      if (s.safety != ofv::servo::SafetyAction::None) std::cout << "  (" << ofv::to_string(s.safety) << ')';
      std::cout << '\n';
    }
    clear += s.status == ofv::servo::StepStatus::Converged || s.status == ofv::servo::StepStatus::NoOccluders ? 1 : 0;
    robot.step(s.velocity, dt);
#if defined(OFV_HAVE_DISPLAY)
    if (live) {
      ofv::DisplayInput in;
      in.time = k * dt;
      in.wMc = ofv::servo::to_eigen(wMc);
      in.observation = &seen;
      in.step = &s;
      if (!live->show(in)) stop_requested = 1;  // the same stop as Ctrl-C
    }
#endif
  }
  robot.step(vpColVector(6, 0.0), 0.0);  // leave the robot at rest
  return clear > 0 ? 0 : 1;
}
