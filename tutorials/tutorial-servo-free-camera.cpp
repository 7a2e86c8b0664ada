//! \example tutorial-servo-free-camera.cpp
//! Tutorial 2: servo a simulated free-flying camera around a hand that enters
//! between it and the object, with ofv's occlusion-free view as the target.
//!
//!     tutorial-servo-free-camera [SCENARIO] [--robot NAME] [--display]
//!
//! `--display` shows the loop live in ViSP windows (ofv::LiveDisplay), paced at
//! the scenario's rate: left click pauses, right click or q ends the episode.
//! The loop is the one of `ofv simulate`: render the RGB-D frame at the
//! camera's pose, take the ground-truth supervoxels (perception errors aside),
//! estimate the view, servo one frame period, repeat.
#include <ofv/loop/episode.h>
#if defined(OFV_HAVE_DISPLAY)
#include <ofv/display/live_display.h>
#endif

#include <cstring>
#include <iostream>
#include <memory>

int main(int argc, char** argv) {
  std::string scenario_name = ofv::sim::kDefaultScenario;  // dvd-one-hand
  std::string robot = "camera";
  bool display = false;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--robot") == 0 && i + 1 < argc) {
      robot = argv[++i];
    } else if (std::strcmp(argv[i], "--display") == 0) {
      display = true;
    } else {
      scenario_name = argv[i];
    }
  }
  try {
    // 1. A scenario: the sensor, the object, the occluders and their motion.
    const ofv::sim::Scenario scenario = ofv::sim::load_scenario(scenario_name);

    // 2. Settings by name, as on the command line: the robot, the perception
    //    mode, and any estimator or controller setting.
    const ofv::EpisodeSetup setup = ofv::resolve_episode(
        scenario, {{"robot", robot}, {"perception", "ground-truth"}, {"controller", "sphere"}});

#if defined(OFV_HAVE_DISPLAY)
    // 3a. Optional: live windows; they only read what the loop did.
    std::unique_ptr<ofv::LiveDisplay> live;
    if (display) {
      ofv::LiveDisplayOptions options;
      options.title = "tutorial " + scenario.name;
      options.r_sphere = setup.loop.estimator.resolve().r_sphere;
      options.ground_truth = true;       // the simulator knows the true visible fraction
      options.pace_rate = scenario.rate;  // real time, to be watched
      live = std::make_unique<ofv::LiveDisplay>(options);
    }
    struct EndedByUser {};
#else
    if (display) throw std::invalid_argument("--display: this ofv was built without ofv::display");
#endif

    // 3. Run it; the observer sees every step (here: print twice a second).
    const auto observer = [&](const ofv::StepRecord& step, const ofv::StepDetail& detail) {
      if (std::fmod(step.time + 1e-9, 0.5) < 1.0 / scenario.rate) {
        std::cout << "t=" << step.time << " s  visible " << step.visible_fraction << "  camera "
                  << step.wMc.translation().transpose() << "  " << ofv::to_string(step.status) << '\n';
      }
#if defined(OFV_HAVE_DISPLAY)
      // A right click (or q) in a window ends the episode here.
      if (live && !live->observe(step, detail)) throw EndedByUser{};
#else
      (void)detail;
#endif
    };
#if defined(OFV_HAVE_DISPLAY)
    ofv::EpisodeOutcome outcome;
    try {
      outcome = ofv::run_episode(setup, observer);
    } catch (const EndedByUser&) {
      std::cout << "episode ended from the display\n";
      return 0;
    }
#else
    const ofv::EpisodeOutcome outcome = ofv::run_episode(setup, observer);
#endif

    // 4. The episode summary: what `ofv simulate` writes to metrics.json.
    const ofv::EpisodeMetrics& m = outcome.metrics;
    std::cout << "mean visible fraction " << m.mean_visible_fraction << ", distance to the sphere within "
              << 100 * m.max_sphere_distance_error << " cm, camera path " << m.path_length << " m\n";
    return m.mean_visible_fraction > 0.5 ? 0 : 1;
#if defined(OFV_HAVE_DISPLAY)
  } catch (const ofv::DisplayUnavailable& e) {  // no X display: one line, exit 2
    std::cerr << "tutorial-servo-free-camera: " << e.what() << '\n';
    return 2;
#endif
  } catch (const std::exception& e) {
    std::cerr << "tutorial-servo-free-camera: " << e.what() << '\n';
    return 2;
  }
}
