// The closed loop in simulation, with ground-truth perception (and the
// front end where a test says so).
#include "ofv/loop/episode.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <cmath>

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
  const servo::ControllerSettings limits;
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

TEST(Episode, LatencyDelaysEveryCommandByWholeFrames) {
  // On the hand-on-the-ray scene the camera moves from the first frame; with
  // a latency of 3 frames it stays still for 3 periods, then makes the moves
  // the loop commanded 3 frames earlier.
  const EpisodeOutcome now = run(kOnRay, {{"duration", "0.5"}});
  const EpisodeOutcome late = run(kOnRay, {{"duration", "0.5"}, {"latency", "3"}});
  EXPECT_GT((now.steps[1].wMc.translation() - now.steps[0].wMc.translation()).norm(), 1e-4);
  for (int k = 1; k <= 3; ++k) {
    EXPECT_TRUE(late.steps[static_cast<std::size_t>(k)].wMc.isApprox(late.steps[0].wMc, 0.0)) << k;
  }
  EXPECT_GT((late.steps[4].wMc.translation() - late.steps[3].wMc.translation()).norm(), 1e-4);
  // The first command is the same; its move comes 3 periods later.
  EXPECT_TRUE(late.steps[0].velocity.isApprox(now.steps[0].velocity, 1e-12));
  EXPECT_TRUE((late.steps[4].wMc.translation() - late.steps[3].wMc.translation())
                  .isApprox(now.steps[1].wMc.translation() - now.steps[0].wMc.translation(), 1e-9));
}

TEST(Episode, FullPerceptionTracksTheScenariosObjectWhateverIsAtTheImageCentre) {
  // A hand covers the case's centre in the first frame. From the labels
  // (select=labels, the default) perception tracks the case, and the camera
  // stays on the sphere around it; left to itself (select=auto) it picks
  // the hand, the cluster at the image centre, and the camera follows
  // a sphere around the hand.
  const std::string scenario = std::string(OFV_TEST_DATA_DIR) + "/loop/hand-over-case-at-start.yaml";
  const auto run_full = [&](const std::string& select) {
    return run_episode(resolve_episode(sim::load_scenario(scenario), {{"perception", "full"}, {"select", select}}));
  };
  const EpisodeOutcome labels = run_full("labels");
  const EpisodeOutcome automatic = run_full("auto");
  for (const StepRecord& s : labels.steps) EXPECT_NE(s.status, servo::StepStatus::ObjectLost) << s.time;
  EXPECT_LE(labels.metrics.max_sphere_distance_error, 0.02);
  EXPECT_GT(automatic.metrics.max_sphere_distance_error, 0.1);
}

// Every frame of a front end is scored against the rendered labels; the
// labels mode (a perfect classifier of the same frames) scores 1 on
// precision and the default front end, on the default scenario, within
// 0.01 of its visible fraction. Ground-truth perception has no front end
// to score.
TEST(Episode, PerceptionIsScoredOnEveryFrame) {
  const auto run_mode = [](const std::string& mode) {
    return run_episode(resolve_episode(sim::load_scenario(sim::kDefaultScenario),
                                       {{"perception", mode}, {"duration", "2.5"}}));
  };
  const EpisodeOutcome full = run_mode("full");
  const EpisodeOutcome labels = run_mode("labels");
  const EpisodeOutcome truth = run_mode("ground-truth");
  for (const EpisodeOutcome* o : {&full, &labels}) {
    for (const StepRecord& s : o->steps) {
      ASSERT_TRUE(s.perception.object_recall) << s.time;
      ASSERT_TRUE(s.perception.centroid_error) << s.time;
    }
    const PerceptionSummary& p = o->metrics.perception;
    ASSERT_TRUE(p.scored());
    EXPECT_EQ(p.object_recall.frames, o->metrics.steps);
    EXPECT_GT(p.occluder_recall.frames, 0) << "the hand never came into the sphere";
    EXPECT_LE(*p.centroid_error.worst, 0.02);
    EXPECT_EQ(p.lost_half_visible, 0);
  }
  EXPECT_DOUBLE_EQ(*labels.metrics.perception.object_precision.worst, 1.0);
  EXPECT_DOUBLE_EQ(*labels.metrics.perception.occluder_precision.worst, 1.0);
  EXPECT_GE(*labels.metrics.perception.object_recall.worst_half_visible, 0.98);
  // Issue 32's 0.99 on every frame with half the object in view: worst
  // 0.995; 0.977 while the support plane's voxels and the holder's stayed
  // in the object's supervoxels that straddle them and the case.
  EXPECT_GE(*full.metrics.perception.object_precision.worst_half_visible, 0.99);
  EXPECT_GE(*full.metrics.perception.object_recall.mean, 0.95);
  EXPECT_NEAR(full.metrics.mean_visible_fraction, labels.metrics.mean_visible_fraction, 0.01);
  EXPECT_FALSE(truth.metrics.perception.scored());
  for (const StepRecord& s : truth.steps) EXPECT_FALSE(s.perception.object_recall);
}

TEST(Episode, EveryModeChangeIsATransitionOfTheTable) {
  // A board passing just before the camera fills the view for half a
  // second: the front end loses the object, the camera drives back, waits,
  // finds the object and holds (full perception: an episode that visits
  // every mode but the first frame's). Each frame's mode follows from the
  // previous one by the guard it reports: one transition of
  // loop_transitions(), or, when the object was found or lost again, that
  // one and then one of the new mode's.
  const EpisodeOutcome o = run_episode(resolve_episode(
      sim::load_scenario(std::string(OFV_TEST_DATA_DIR) + "/loop/board-before-camera.yaml"), {{"perception", "full"}}));
  const auto& table = servo::loop_transitions();
  const auto edge = [&](servo::LoopMode from, servo::Guard guard, servo::LoopMode to) {
    return std::any_of(table.begin(), table.end(),
                       [&](const servo::LoopTransition& t) { return t.from == from && t.guard == guard && t.to == to; });
  };
  std::map<servo::LoopMode, int> frames;
  servo::LoopMode before = servo::LoopMode::Lost;  // a loop's mode before its first frame
  for (const StepRecord& s : o.steps) {
    ++frames[s.mode];
    if (s.guard == servo::Guard::None) {
      EXPECT_EQ(s.mode, before) << s.time;
    } else {
      bool path = edge(before, s.guard, s.mode);
      for (const servo::LoopTransition& first : table) {
        const bool again = first.guard == servo::Guard::ObjectFound || first.guard == servo::Guard::ObjectLost;
        path = path || (first.from == before && again && edge(first.to, s.guard, s.mode));
      }
      EXPECT_TRUE(path) << s.time << ": " << to_string(before) << " by " << to_string(s.guard) << " to "
                        << to_string(s.mode);
    }
    // Each mode's target comes from its proposers.
    if (s.mode == servo::LoopMode::Hold || s.mode == servo::LoopMode::WayBack) {
      EXPECT_EQ(s.proposer, servo::Proposer::BestSeen) << s.time;
    }
    if (s.mode == servo::LoopMode::Waiting || s.mode == servo::LoopMode::Lost) {
      EXPECT_EQ(s.proposer, servo::Proposer::None) << s.time;
    }
    before = s.mode;
  }
  EXPECT_GT(frames[servo::LoopMode::Hold], 0);
  EXPECT_GT(frames[servo::LoopMode::WayBack], 0);
  EXPECT_GT(frames[servo::LoopMode::Waiting], 0);
}

TEST(Episode, SettingsAreValidatedByName) {
  const sim::Scenario s = sim::load_scenario(kOnRay);
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"method", "nbv"}, {"gain", "-1"}, {"robot", "puma"}, {"perception", "magic"},
           {"step", "big"}, {"speed", "1"}, {"sampling_candidates", "1.5"}, {"seed", "-2"},
           {"latency", "31"}, {"latency", "-1"}, {"anticipation", "psychic"}, {"anticipation_horizon", "0"},
           {"look_ahead_margin", "2"}, {"track_gate", "inf"}}) {
    try {
      (void)resolve_episode(s, {{name, value}});
      ADD_FAILURE() << name << "=" << value << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  // Valid one by one, meaningless together: at 30 Hz, 8 frames of latency
  // make every command older than the 0.2 s stale timeout.
  try {
    (void)resolve_episode(s, {{"latency", "8"}});
    ADD_FAILURE() << "latency=8 with stale_timeout=0.2 accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("stale_timeout"), std::string::npos) << e.what();
  }
  EXPECT_NO_THROW((void)resolve_episode(s, {{"latency", "8"}, {"stale_timeout", "0.5"}}));
  // Lengths may refer to the scenario's radii.
  const EpisodeSetup r = resolve_episode(s, {{"push_radius", "r_seed"}});
  EXPECT_DOUBLE_EQ(r.loop.estimator.resolve().push_radius, 0.02);
}

TEST(Episode, LengthIsBoundedHoweverTheSetupWasMade) {
  // A setup made in code skips the settings' bounds: run_episode checks the
  // number of frames before it becomes an integer (1e20 s once gave 0 steps).
  const EpisodeSetup s = resolve_episode(sim::load_scenario(kOnRay), {{"perception", "ground-truth"}});
  const auto refused = [](EpisodeSetup bad, const std::string& word) {
    try {
      (void)run_episode(bad);
      ADD_FAILURE() << word << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(word), std::string::npos) << e.what();
    }
  };
  for (const double d : {1e20, kMaxEpisodeDuration * 1.01, -1.0, std::nan(""), HUGE_VAL}) {
    EpisodeSetup bad = s;
    bad.duration = d;
    refused(bad, "duration");
  }
  for (const double r : {0.0, -30.0, std::nan(""), HUGE_VAL}) {
    EpisodeSetup bad = s;
    bad.scenario.rate = r;
    refused(bad, "rate");
  }
  EpisodeSetup fast = s;  // in range each, too many frames together
  fast.duration = kMaxEpisodeDuration;
  fast.scenario.rate = 1e9;
  refused(fast, "frames");
  EXPECT_THROW((void)resolve_episode(sim::load_scenario(kOnRay), {{"duration", "1e20"}}), std::invalid_argument);
}

TEST(Episode, EveryNumericSettingDocumentsTheRangeItChecks) {
  // The type column ("number in (0, 10]", "integer in [0, 30]") is the
  // documented range: its bounds are accepted, just beyond them is refused.
  const sim::Scenario scenario = sim::load_scenario(kOnRay);
  const auto accepted = [&](const std::string& name, const std::string& value) {
    try {
      // A long latency needs a stale timeout that its frames stay within.
      if (name == "latency") {
        (void)resolve_episode(scenario, {{"stale_timeout", "60"}, {name, value}});
        return true;
      }
      (void)resolve_episode(scenario, {{name, value}});
      return true;
    } catch (const std::invalid_argument&) {
      return false;
    }
  };
  int checked = 0;
  for (const SettingDoc& d : episode_settings_table().docs()) {
    const bool integer = d.type.rfind("integer", 0) == 0;
    if (!integer && d.type.rfind("number", 0) != 0) continue;
    const auto in = d.type.find(" in ");
    ASSERT_NE(in, std::string::npos) << d.name << ": no documented range in \"" << d.type << "\"";
    const char open = d.type.at(in + 4);
    const auto comma = d.type.find(", ", in);
    const auto close = d.type.find(']', comma);
    ASSERT_TRUE((open == '(' || open == '[') && comma != std::string::npos && close != std::string::npos) << d.type;
    const std::string lo = d.type.substr(in + 5, comma - in - 5);
    const std::string hi = d.type.substr(comma + 2, close - comma - 2);
    const auto beyond = [&](const std::string& v, double step) {
      if (integer) return std::to_string(std::stoll(v) + static_cast<long long>(step));
      const double x = std::stod(v);
      return format_number(x + step * std::max(1e-3, 1e-3 * std::abs(x)));
    };
    EXPECT_TRUE(accepted(d.name, hi)) << d.name << "=" << hi;
    EXPECT_FALSE(accepted(d.name, beyond(hi, 1))) << d.name << "=" << beyond(hi, 1);
    EXPECT_EQ(accepted(d.name, lo), open == '[') << d.name << "=" << lo;
    if (open == '[') {
      EXPECT_FALSE(accepted(d.name, beyond(lo, -1))) << d.name << "=" << beyond(lo, -1);
    }
    ++checked;
  }
  EXPECT_GE(checked, 29);
}

TEST(Episode, ResolvedSettingsReadBackToTheSameEpisode) {
  // Every setting's resolved value (the preset's and the scenario's where
  // they apply), given back as settings, resolves to the same values.
  const sim::Scenario scenario = sim::load_scenario(kOnRay);
  const EpisodeSetup setup = resolve_episode(
      scenario, {{"preset", "authors_code"}, {"r_seed", "0.01"}, {"workspace", "-1,-1,0,1,1,2.5"},
                 {"anticipation", "predict"}, {"seed", "4"}, {"latency", "1"}, {"perception", "ground-truth"}});
  const auto values = episode_settings_table().values(setup);
  ASSERT_EQ(values.size(), episode_settings_table().docs().size());
  const auto value = [&](const std::string& name) {
    for (const auto& [k, v] : values) {
      if (k == name) return v;
    }
    return std::string("(absent)");
  };
  EXPECT_EQ(value("preset"), "authors_code");
  EXPECT_EQ(value("step"), "0.005");  // the preset's r_seed / 2, with the final r_seed
  EXPECT_EQ(value("clearance"), "0.02");
  EXPECT_EQ(value("max_iterations"), "50");
  EXPECT_EQ(value("workspace"), "-1,-1,0,1,1,2.5");
  EXPECT_EQ(value("anticipation"), "predict");
  EXPECT_EQ(value("seed"), "4");
  EXPECT_EQ(value("duration"), format_number(scenario.duration));
  EXPECT_EQ(episode_settings_table().values(resolve_episode(scenario, values)), values);
}

}  // namespace
}  // namespace ofv
