// The closed loop in simulation, with ground-truth perception.
#include "ofv/loop/episode.h"

#include <gtest/gtest.h>

namespace ofv {
namespace {

const std::string kOnRay = std::string(OFV_TEST_DATA_DIR) + "/loop/hand-on-initial-ray.yaml";

EpisodeOutcome run(const std::string& scenario, std::vector<std::pair<std::string, std::string>> settings) {
  settings.emplace_back("perception", "ground-truth");
  return run_episode(resolve_episode(sim::load_scenario(scenario), settings));
}

// Mean visible fraction over the last second.
double final_visibility(const EpisodeOutcome& o) {
  double sum = 0.0;
  int n = 0;
  for (const auto& s : o.steps) {
    if (s.time >= o.steps.back().time - 1.0) {
      sum += s.visible_fraction;
      ++n;
    }
  }
  return sum / n;
}

TEST(Episode, KeepsTheObjectInViewOnTheDefaultScenario) {
  const EpisodeOutcome o = run(sim::kDefaultScenario, {});
  const EpisodeMetrics& m = o.metrics;
  EXPECT_EQ(m.steps, 121);
  EXPECT_GE(m.mean_visible_fraction, 0.95);
  ASSERT_TRUE(m.max_recovery_time);
  EXPECT_LE(*m.max_recovery_time, 1.0);
  EXPECT_LE(m.max_sphere_distance_error, 0.02);  // the sphere feature keeps the camera on it
  const ControllerSettings limits;
  EXPECT_LE(m.max_linear_speed, limits.max_linear_speed + 1e-9);
  EXPECT_LE(m.max_angular_speed, limits.max_angular_speed + 1e-9);
  EXPECT_GT(m.path_length, 0.05);  // it moved away from the hand
}

TEST(Episode, BaselinesOnAHandOnTheInitialRay) {
  const double ours = final_visibility(run(kOnRay, {{"method", "estimator"}}));
  const double sampling = final_visibility(run(kOnRay, {{"method", "sampling"}, {"sampling_candidates", "400"}}));
  const double fixed = final_visibility(run(kOnRay, {{"method", "static"}}));
  const double blind = final_visibility(run(kOnRay, {{"method", "initial_view"}}));
  EXPECT_GE(ours, 0.9);
  EXPECT_GE(sampling, 0.9);
  EXPECT_LT(fixed, 0.6);
  EXPECT_LT(blind, 0.6);
}

TEST(Episode, IsDeterministic) {
  const EpisodeOutcome a = run(kOnRay, {{"duration", "1.0"}});
  const EpisodeOutcome b = run(kOnRay, {{"duration", "1.0"}});
  ASSERT_EQ(a.steps.size(), b.steps.size());
  for (std::size_t k = 0; k < a.steps.size(); ++k) {
    EXPECT_EQ(trajectory_csv_row(a.steps[k]).substr(0, 200), trajectory_csv_row(b.steps[k]).substr(0, 200)) << k;
  }
}

TEST(Episode, SettingsAreValidatedByName) {
  const sim::Scenario s = sim::load_scenario(kOnRay);
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"method", "nbv"}, {"gain", "-1"}, {"robot", "puma"}, {"perception", "magic"},
           {"step", "big"}, {"speed", "1"}, {"sampling_candidates", "1.5"}, {"seed", "-2"}}) {
    try {
      (void)resolve_episode(s, {{name, value}});
      ADD_FAILURE() << name << "=" << value << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  // Lengths may refer to the scenario's radii.
  const EpisodeSetup r = resolve_episode(s, {{"push_radius", "r_seed"}});
  EXPECT_DOUBLE_EQ(r.loop.estimator.resolve().push_radius, 0.02);
}

}  // namespace
}  // namespace ofv
