//! \example tutorial-servo-free-camera.cpp
//! Tutorial 2: servo a simulated free-flying camera around a hand that enters
//! between it and the object, with ofv's occlusion-free view as the target.
//!
//!   tutorial-servo-free-camera [SCENARIO] [--robot NAME]
//!
//! The loop is the one of `ofv simulate`: render the RGB-D frame at the
//! camera's pose, take the ground-truth supervoxels (perception errors aside),
//! estimate the view, servo one frame period, repeat.
#include <ofv/loop/episode.h>

#include <cstring>
#include <iostream>

int main(int argc, char** argv) {
  std::string scenario_name = ofv::sim::kDefaultScenario;  // dvd-one-hand
  std::string robot = "camera";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--robot") == 0 && i + 1 < argc) {
      robot = argv[++i];
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

    // 3. Run it; the observer sees every step (here: print twice a second).
    const ofv::EpisodeOutcome outcome =
        ofv::run_episode(setup, [&](const ofv::StepRecord& step, const ofv::StepDetail&) {
          if (std::fmod(step.time + 1e-9, 0.5) < 1.0 / scenario.rate) {
            std::cout << "t=" << step.time << " s  visible " << step.visible_fraction << "  camera "
                      << step.wMc.translation().transpose() << "  " << ofv::to_string(step.status) << '\n';
          }
        });

    // 4. The episode summary: what `ofv simulate` writes to metrics.json.
    const ofv::EpisodeMetrics& m = outcome.metrics;
    std::cout << "mean visible fraction " << m.mean_visible_fraction << ", distance to the sphere within "
              << 100 * m.max_sphere_distance_error << " cm, camera path " << m.path_length << " m\n";
    return m.mean_visible_fraction > 0.5 ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "tutorial-servo-free-camera: " << e.what() << '\n';
    return 2;
  }
}
