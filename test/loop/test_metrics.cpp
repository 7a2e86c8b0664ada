// Episode metrics on hand-made step sequences.
#include "ofv/loop/metrics.h"
#include "ofv/loop/metrics_json.h"

#include <gtest/gtest.h>

#include <map>

namespace ofv {
namespace {

// Steps at 10 Hz with the given visibilities and occluder counts.
std::vector<StepRecord> episode(const std::vector<double>& visible, const std::vector<int>& occluders) {
  std::vector<StepRecord> steps(visible.size());
  for (std::size_t k = 0; k < steps.size(); ++k) {
    steps[k].time = 0.1 * static_cast<double>(k);
    steps[k].visible_fraction = visible[k];
    steps[k].occluders_in_sphere = occluders[k];
    steps[k].wMc.translation() = Eigen::Vector3d(0.01 * static_cast<double>(k), 0, 0);
    steps[k].status = k % 2 ? servo::StepStatus::Converged : servo::StepStatus::NoOccluders;
  }
  return steps;
}

TEST(Metrics, VisibilityRecoveryAndPath) {
  const auto steps = episode({1.0, 1.0, 0.5, 0.6, 0.95, 1.0}, {0, 0, 1, 1, 1, 1});
  const EpisodeMetrics m = summarise(steps);
  EXPECT_EQ(m.steps, 6);
  EXPECT_NEAR(m.duration, 0.6, 1e-12);
  EXPECT_NEAR(m.mean_visible_fraction, (1 + 1 + 0.5 + 0.6 + 0.95 + 1) / 6, 1e-12);
  EXPECT_EQ(m.min_visible_fraction, 0.5);
  EXPECT_NEAR(m.time_below_threshold, 0.2, 1e-12);
  ASSERT_EQ(m.occlusions.size(), 1U);
  EXPECT_NEAR(m.occlusions[0].onset, 0.2, 1e-12);
  ASSERT_TRUE(m.occlusions[0].recovery_time);
  EXPECT_NEAR(*m.occlusions[0].recovery_time, 0.2, 1e-12);
  EXPECT_NEAR(*m.max_recovery_time, 0.2, 1e-12);
  EXPECT_NEAR(m.path_length, 0.05, 1e-12);
  ASSERT_EQ(m.status_counts.size(), 2U);
  EXPECT_EQ(m.status_counts[0].first, "converged");
  EXPECT_EQ(m.status_counts[0].second, 3);
}

TEST(Metrics, AnOcclusionThatNeverClearsIsUnrecovered) {
  const auto steps = episode({1.0, 0.2, 0.3, 0.4}, {0, 2, 2, 2});
  const EpisodeMetrics m = summarise(steps);
  ASSERT_EQ(m.occlusions.size(), 1U);
  EXPECT_FALSE(m.occlusions[0].recovery_time);
  EXPECT_NEAR(*m.occlusions[0].occluder_entered, 0.1, 1e-12);
  EXPECT_EQ(m.unrecovered_occlusions, 1);
  EXPECT_FALSE(m.max_recovery_time);
}

TEST(Metrics, AnOccluderThatDoesNotHideIsNoEvent) {
  const auto steps = episode({1.0, 1.0, 1.0}, {0, 1, 0});
  const EpisodeMetrics m = summarise(steps);
  EXPECT_TRUE(m.occlusions.empty());
  EXPECT_EQ(*m.max_recovery_time, 0.0);
  EXPECT_EQ(m.time_below_threshold, 0.0);
}

TEST(Metrics, DipsCloserThanTheHoldAreOneEvent) {
  // Occluder enters at 0.1 s; hidden 0.3-0.4, back for 0.1 s only, hidden at
  // 0.6, back for good from 0.7; a later dip at 1.2 s is a second event.
  const std::vector<double> v{1, 1, 1, 0.5, 0.5, 0.95, 0.5, 1, 1, 1, 1, 1, 0.8, 1, 1};
  std::vector<int> occ(v.size(), 1);
  occ[0] = 0;
  const EpisodeMetrics m = summarise(episode(v, occ), 0.9, 0.2);
  ASSERT_EQ(m.occlusions.size(), 2U);
  EXPECT_NEAR(m.occlusions[0].onset, 0.3, 1e-12);
  EXPECT_NEAR(*m.occlusions[0].recovery_time, 0.4, 1e-12);
  EXPECT_NEAR(*m.occlusions[0].occluder_entered, 0.1, 1e-12);
  EXPECT_NEAR(m.occlusions[1].onset, 1.2, 1e-12);
  EXPECT_NEAR(*m.occlusions[1].recovery_time, 0.1, 1e-12);
  EXPECT_NEAR(*m.max_recovery_time, 0.4, 1e-12);
  // With no hold, each dip is an event of its own.
  EXPECT_EQ(summarise(episode(v, occ), 0.9, 0.0).occlusions.size(), 3U);
}

TEST(Metrics, HiddenFromTheStartWithoutAnEntryHasNoWarning) {
  const EpisodeMetrics m = summarise(episode({0.3, 0.3, 1.0}, {1, 1, 1}));
  ASSERT_EQ(m.occlusions.size(), 1U);
  EXPECT_NEAR(m.occlusions[0].onset, 0.0, 1e-12);
  EXPECT_NEAR(*m.occlusions[0].recovery_time, 0.2, 1e-12);
  EXPECT_FALSE(m.occlusions[0].occluder_entered);
}

TEST(Metrics, TheSensorsWarningIsWhenTheOccluderCameIntoView) {
  // In the sphere from 0.1 s, in the image from 0.3 s, hiding from 0.4 s.
  auto steps = episode({1, 1, 1, 1, 0.5, 1, 1}, {0, 1, 1, 1, 1, 1, 1});
  for (std::size_t k = 3; k < steps.size(); ++k) steps[k].occluders_in_view = 1;
  const EpisodeMetrics m = summarise(steps);
  ASSERT_EQ(m.occlusions.size(), 1U);
  EXPECT_NEAR(*m.occlusions[0].occluder_entered, 0.1, 1e-12);
  EXPECT_NEAR(*m.occlusions[0].occluder_in_view, 0.3, 1e-12);
  // Seen from the first frame: no warning to speak of.
  for (auto& s : steps) s.occluders_in_view = 1;
  EXPECT_FALSE(summarise(steps).occlusions[0].occluder_in_view);
}

TEST(Metrics, EmptyAndSingleStepEpisodes) {
  EXPECT_EQ(summarise({}).steps, 0);
  const EpisodeMetrics one = summarise(episode({0.7}, {0}));
  EXPECT_EQ(one.mean_visible_fraction, 0.7);
  EXPECT_EQ(one.duration, 0.0);
}

TEST(Metrics, TrajectoryRowMatchesTheHeader) {
  StepRecord s;
  s.tf = Eigen::Vector3d(1, 2, 3);
  s.status = servo::StepStatus::Converged;
  const auto count = [](const std::string& line) { return std::count(line.begin(), line.end(), ','); };
  EXPECT_EQ(count(trajectory_csv_row(s)), count(trajectory_csv_header()));
}

// Perception scores: means over the frames that have them, the worst with
// its time, the worst where at least half of the object is in view; lost
// frames with the object half in view are counted.
TEST(Metrics, PerceptionScoresSummariseOverTheFramesThatHaveThem) {
  auto steps = episode({1.0, 0.4, 0.8, 0.9, 1.0}, {0, 1, 1, 1, 0});
  const std::vector<std::optional<double>> precision{1.0, 0.5, 0.9, std::nullopt, 0.95};
  const std::vector<std::optional<double>> recall{1.0, 0.6, 0.8, 0.0, 1.0};
  const std::vector<std::optional<double>> error{0.01, 0.04, 0.02, std::nullopt, 0.01};
  for (std::size_t k = 0; k < steps.size(); ++k) {
    steps[k].perception.object_precision = precision[k];
    steps[k].perception.object_recall = recall[k];
    steps[k].perception.centroid_error = error[k];
  }
  const EpisodeMetrics m = summarise(steps);
  const PerceptionSummary& p = m.perception;
  ASSERT_TRUE(p.scored());
  EXPECT_EQ(p.object_precision.frames, 4);
  EXPECT_NEAR(*p.object_precision.mean, (1.0 + 0.5 + 0.9 + 0.95) / 4, 1e-12);
  EXPECT_EQ(*p.object_precision.worst, 0.5);
  EXPECT_NEAR(p.object_precision.worst_time, 0.1, 1e-12);
  EXPECT_EQ(*p.object_precision.worst_half_visible, 0.9);  // 0.5 was with 0.4 in view
  EXPECT_EQ(*p.object_recall.worst, 0.0);
  EXPECT_EQ(*p.centroid_error.worst, 0.04);  // errors: the largest is the worst
  EXPECT_EQ(*p.centroid_error.worst_half_visible, 0.02);
  EXPECT_EQ(p.lost_half_visible, 1);  // t = 0.3: recall 0, no centroid, 0.9 in view
  EXPECT_FALSE(p.occluder_recall.mean);
  EXPECT_EQ(p.occluder_recall.frames, 0);

  // metrics.json keeps the block; an episode without scores has none.
  const EpisodeMetrics back = metrics_from_json(metrics_to_json(m));
  EXPECT_EQ(back.perception.object_precision.frames, 4);
  EXPECT_EQ(*back.perception.object_precision.worst_half_visible, 0.9);
  EXPECT_EQ(*back.perception.centroid_error.worst, 0.04);
  EXPECT_FALSE(back.perception.occluder_recall.worst);
  EXPECT_EQ(back.perception.lost_half_visible, 1);
  EXPECT_TRUE(metrics_to_json(summarise(episode({1.0}, {0})))["perception"].is_null());

  // trajectory.csv: the scores by name, empty where there is none.
  const auto fields = [](const std::string& line) {
    std::vector<std::string> out(1);
    for (const char c : line) {
      if (c == ',') {
        out.emplace_back();
      } else {
        out.back().push_back(c);
      }
    }
    return out;
  };
  const std::vector<std::string> header = fields(trajectory_csv_header()), row = fields(trajectory_csv_row(steps[3]));
  ASSERT_EQ(header.size(), row.size());
  std::map<std::string, std::string> value;
  for (std::size_t i = 0; i < header.size(); ++i) value[header[i]] = row[i];
  EXPECT_EQ(value["object_precision"], "");
  EXPECT_EQ(value["object_recall"], "0");
  for (const char* empty : {"occluder_precision", "occluder_recall", "centroid_error", "hidden_error"}) {
    EXPECT_EQ(value[empty], "") << empty;
  }
  EXPECT_EQ(value["mode"], "lost");
  EXPECT_EQ(value["proposer"], "none");
}

}  // namespace
}  // namespace ofv
