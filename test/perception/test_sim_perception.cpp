// The front end against the simulator's ground truth (ofv::sim renderer,
// built-in scenarios with sensor noise).
#include "ofv/perception/perception.h"
#include "ofv/perception/scores.h"
#include "ofv/sim/renderer.h"
#include "ofv/sim/scenario.h"

#include "cli_run.h"
#include "evaluation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <set>

namespace ofv {
namespace {

struct EpisodeStats {
  int frames = 0;
  int scored = 0;  // frames with the object at least 80 % visible
  int lost = 0;
  double worst_precision = 1.0;
  double worst_recall = 1.0;
  double worst_centroid_error = 0.0;          // against the whole object's surface centroid
  double worst_visible_centroid_error = 0.0;  // against the object-labelled voxels' mean
  int frames_with_occluder_in_sphere = 0;
  int frames_occluder_found = 0;
  int frames_holder_visible = 0;
  int frames_holder_interacting = 0;
  int holder_as_object = 0;
};

/// Runs the front end on every frame of a scenario from its start camera, up to `until` [s].
EpisodeStats run_scenario(const std::string& name, double until,
                          perception::SupervoxelSettings::Method supervoxels = perception::SupervoxelSettings{}.method) {
  const sim::Scenario scenario = sim::load_scenario(name);
  sim::Renderer renderer(scenario);
  perception::PerceptionSettings settings;
  settings.supervoxels.method = supervoxels;
  perception::Perception perception(settings);
  EpisodeStats s;
  const int frames = static_cast<int>(std::min(until, scenario.duration) * scenario.rate);
  for (int k = 0; k < frames; ++k) {
    renderer.set_time(k / scenario.rate);
    const sim::RenderedFrame rendered = renderer.render(scenario.wMc_start, k);
    const RgbdFrame& frame = rendered.frame;
    const std::vector<int> labels(rendered.frame.labels.begin(), rendered.frame.labels.end());
    const perception::PerceptionResult r = perception.process(frame);
    ++s.frames;
    if (r.status == perception::TrackingStatus::Lost) {
      ++s.lost;
      continue;
    }
    const auto truth = test::supervoxel_truth(r, frame, labels);
    const sim::ObjectTruth object = renderer.truth(scenario.wMc_start, settings.r_sphere);
    if (object.visible_fraction >= 0.8) {
      ++s.scored;
      const auto score = test::score_object(r, truth, sim::kLabelObject);
      s.worst_precision = std::min(s.worst_precision, score.precision);
      s.worst_recall = std::min(s.worst_recall, score.recall);
      s.worst_centroid_error =
          std::max(s.worst_centroid_error, (r.centroid - object.centroid).norm());
      if (r.counts.hidden_voxels == 0) {
        s.worst_visible_centroid_error = std::max(
            s.worst_visible_centroid_error,
            (r.centroid - test::truth_centroid(r, frame, labels, sim::kLabelObject)).norm());
      }
    }
    // Occluders: every occluder label seen in the image whose supervoxels lie
    // inside the sphere must give occluder supervoxels.
    std::set<int> occluders_in_sphere;
    for (std::size_t i = 0; i < truth.size(); ++i) {
      if (truth[i] >= sim::kLabelOccluder0 &&
          (r.supervoxels[i].centroid - r.centroid).norm() < settings.r_sphere &&
          !r.obb.contains(r.supervoxels[i].centroid)) {
        occluders_in_sphere.insert(truth[i]);
      }
    }
    for (const int label : occluders_in_sphere) {
      ++s.frames_with_occluder_in_sphere;
      s.frames_occluder_found +=
          test::count_truth_as(r, truth, label, perception::SupervoxelClass::Occluder) > 0 ? 1 : 0;
    }
    if (std::count(truth.begin(), truth.end(), sim::kLabelInteracting) > 0) {
      ++s.frames_holder_visible;
      s.frames_holder_interacting +=
          test::count_truth_as(r, truth, sim::kLabelInteracting, perception::SupervoxelClass::Interacting) > 0
              ? 1
              : 0;
      s.holder_as_object +=
          test::count_truth_as(r, truth, sim::kLabelInteracting, perception::SupervoxelClass::Object);
    }
  }
  return s;
}

void expect_quality(const EpisodeStats& s, bool whole_object_centroid = true) {
  EXPECT_EQ(s.lost, 0);
  EXPECT_GT(s.scored, 0);
  EXPECT_GE(s.worst_precision, 0.95);
  EXPECT_GE(s.worst_recall, 0.90);
  if (whole_object_centroid) {
    // 7.6 mm of it is the case's half thickness, never seen; the rest the
    // remembered hidden part, moved with the noise of the estimated motion.
    EXPECT_LE(s.worst_centroid_error, 0.011);
  }
  EXPECT_LE(s.worst_visible_centroid_error, 0.01);
  EXPECT_EQ(s.frames_occluder_found, s.frames_with_occluder_in_sphere);
  EXPECT_EQ(s.frames_holder_interacting, s.frames_holder_visible);
  EXPECT_EQ(s.holder_as_object, 0);
}

TEST(SimPerception, DvdOneHand) {
  const EpisodeStats s = run_scenario("dvd-one-hand", 2.5);
  expect_quality(s);
  EXPECT_GT(s.frames_with_occluder_in_sphere, 0) << "the entering hand never reached the sphere";
  EXPECT_GT(s.frames_holder_visible, 0);
}

TEST(SimPerception, DvdStatic) {
  const EpisodeStats s = run_scenario("dvd-static", 3.0);
  expect_quality(s);
  EXPECT_GT(s.frames_holder_visible, 0);
}

TEST(SimPerception, DvdTwoHands) {
  const EpisodeStats s = run_scenario("dvd-two-hands", 4.0);
  expect_quality(s);
  EXPECT_GT(s.frames_with_occluder_in_sphere, 0);
}

TEST(SimPerception, ClothOccluder) {
  const EpisodeStats s = run_scenario("cloth-occluder", 4.0);
  expect_quality(s);
  EXPECT_GT(s.frames_with_occluder_in_sphere, 0);
}

// The case slides 0.2 m and turns 20 degrees into a static hand, seen from
// a camera that stays where it started. The part sliding behind the hand
// stays remembered, moved with the motion estimated from the visible part
// (follow_motion): C is within 1.5 cm of the whole case's centroid (13.3 mm
// measured, 7.6 mm of it the half thickness the camera never sees; 18.5 mm
// when the hidden part was left behind), and the visible part's own C is
// checked on the frames with nothing hidden.
// ofv's supervoxel stage against PCL's on the same frames (docs/perception.md
// "Two supervoxel stages"): the front end is as right with either, worst
// frame by worst frame, on a hand over the case and on the bending cloth.
TEST(SimPerception, OfvSupervoxelsScoreAsPcls) {
  using Method = perception::SupervoxelSettings::Method;
  for (const auto& [name, until] : {std::pair<const char*, double>{"dvd-one-hand", 2.5}, {"cloth-occluder", 4.0}}) {
    SCOPED_TRACE(name);
    const EpisodeStats pcl = run_scenario(name, until, Method::Pcl);
    const EpisodeStats mine = run_scenario(name, until, Method::Ofv);
    EXPECT_EQ(mine.lost, 0);
    EXPECT_EQ(mine.scored, pcl.scored);
    EXPECT_GE(mine.worst_precision, std::min(pcl.worst_precision, 0.99) - 0.01);
    EXPECT_GE(mine.worst_recall, pcl.worst_recall - 0.01);
    EXPECT_LE(mine.worst_visible_centroid_error, std::max(pcl.worst_visible_centroid_error, 0.005) + 0.002);
    EXPECT_EQ(mine.frames_occluder_found, mine.frames_with_occluder_in_sphere);
    EXPECT_EQ(mine.frames_holder_interacting, mine.frames_holder_visible);
    EXPECT_EQ(mine.holder_as_object, 0);
  }
}

TEST(SimPerception, MovingObject) {
  const EpisodeStats s = run_scenario("moving-object", 5.0);
  expect_quality(s, /*whole_object_centroid=*/false);
  EXPECT_LE(s.worst_centroid_error, 0.015);
  EXPECT_GT(s.frames_with_occluder_in_sphere, 0);
}

// While the hand covers part of the case, the hidden part's remembered
// voxels stay in the estimator's problem as vertices: each lies on the case
// and is not seen, behind the hand or in the sensor's shadow beside it:
// within half a seed of its pixel, a pixel shows the hand or has no depth.
// Without the setting the problem holds only what the frame shows.
TEST(SimPerception, HiddenObjectSupervoxelsStayInTheProblem) {
  const sim::Scenario scenario = sim::load_scenario("dvd-one-hand");
  sim::Renderer renderer(scenario);
  perception::PerceptionSettings with;
  perception::PerceptionSettings without;
  without.tracking.hidden_vertices = false;
  perception::Perception a(with), b(without);
  const Eigen::Isometry3d cMw = scenario.wMc_start.inverse();
  std::size_t most_hidden = 0;
  for (int k = 0; k < static_cast<int>(2.3 * scenario.rate); ++k) {
    renderer.set_time(k / scenario.rate);
    const sim::RenderedFrame rendered = renderer.render(scenario.wMc_start, k);
    const perception::PerceptionResult ra = a.process(rendered.frame);
    const perception::PerceptionResult rb = b.process(rendered.frame);
    ASSERT_NE(ra.status, perception::TrackingStatus::Lost);
    ASSERT_NE(rb.status, perception::TrackingStatus::Lost);
    EXPECT_EQ(rb.counts.hidden_vertices, 0U);
    const auto seen = static_cast<std::size_t>(std::count_if(
        rb.supervoxels.begin(), rb.supervoxels.end(),
        [](const perception::SupervoxelInfo& s) { return s.label == perception::SupervoxelClass::Object && s.normal_valid; }));
    EXPECT_EQ(static_cast<std::size_t>(rb.problem.positions.cols()), seen);
    const auto n = static_cast<Eigen::Index>(ra.counts.hidden_vertices);
    ASSERT_EQ(ra.problem.normals.cols(), ra.problem.positions.cols());
    most_hidden = std::max(most_hidden, ra.counts.hidden_vertices);
    for (Eigen::Index j = ra.problem.positions.cols() - n; j < ra.problem.positions.cols(); ++j) {
      const Eigen::Vector3d p = ra.problem.positions.col(j);
      EXPECT_LT(std::abs(p.z() - 0.5), 0.02) << "a remembered vertex off the case: " << p.transpose();
      const Eigen::Vector3d pc = cMw * p;
      const CameraIntrinsics& in = rendered.frame.intrinsics;
      const auto u = static_cast<int>(std::lround(in.fx * pc.x() / pc.z() + in.cx));
      const auto v = static_cast<int>(std::lround(in.fy * pc.y() / pc.z() + in.cy));
      ASSERT_TRUE(u >= 0 && v >= 0 && u < in.width && v < in.height);
      const int reach = static_cast<int>(std::ceil(0.5 * with.supervoxels.seed_resolution * in.fx / pc.z()));
      bool unseen = false;
      for (int dv = -reach; dv <= reach && !unseen; ++dv) {
        for (int du = -reach; du <= reach && !unseen; ++du) {
          const int x = u + du;
          const int y = v + dv;
          if (x < 0 || y < 0 || x >= in.width || y >= in.height || du * du + dv * dv > reach * reach) continue;
          const std::size_t i = rendered.frame.index(x, y);
          unseen = rendered.frame.labels[i] >= sim::kLabelOccluder0 || !(rendered.frame.depth[i] > 0.0f);
        }
      }
      EXPECT_TRUE(unseen) << "a remembered vertex in plain sight: " << p.transpose();
    }
  }
  EXPECT_GE(most_hidden, 5U) << "the hand should hide several of the case's supervoxels";
}

TEST(SimPerception, RecordedEpisodesPlayBackThroughPerceive) {
  for (const std::string format : {"oni", "tum", "pcd"}) {
    const std::string out = (std::filesystem::path(test::scratch_dir()) /
                             ("ofv_record_" + format + (format == "oni" ? ".oni" : "")))
                                .string();
    std::filesystem::remove_all(out);
    const CommandRun rec =
        run("record dvd-one-hand --format " + format + " --out " + out + " --until 0.5");
    ASSERT_EQ(rec.code, 0) << rec.err;
    const CommandRun perceive = run("perceive " + out);
    ASSERT_EQ(perceive.code, 0) << perceive.err;
    EXPECT_NE(perceive.err.find("15 frames, 0 lost"), std::string::npos)
        << format << ": " << perceive.err;
  }
  const CommandRun bad = run("record no-such-scenario --out /tmp/ofv_never");
  EXPECT_EQ(bad.code, 2);
  EXPECT_EQ(std::count(bad.err.begin(), bad.err.end(), '\n'), 1);
}

}  // namespace
}  // namespace ofv

namespace ofv {
namespace {

// Classes::Labels is a perfect classifier of the sensor's frames: on every
// frame of a scene with a holder, an entering hand and the table, what it
// calls object and occluder is object and occluder (precision 1 by the
// scores' own definition), it finds what the frame shows of both, and the
// same frames without labels are refused.
TEST(SimPerception, LabelsModeIsAPerfectClassifierOfTheFrame) {
  const sim::Scenario scenario = sim::load_scenario("dvd-one-hand");
  sim::Renderer renderer(scenario);
  perception::PerceptionSettings settings;
  settings.classes = perception::PerceptionSettings::Classes::Labels;
  perception::Perception perception(settings);
  int occluded_frames = 0;
  for (int k = 0; k < static_cast<int>(2.5 * scenario.rate); ++k) {
    renderer.set_time(k / scenario.rate);
    const sim::RenderedFrame rendered = renderer.render(scenario.wMc_start, k);
    const perception::PerceptionResult r = perception.process(rendered.frame);
    ASSERT_NE(r.status, perception::TrackingStatus::Lost) << "frame " << k;
    perception::PerceptionTruth truth;
    truth.centroid = rendered.frame.object_centroid;
    ASSERT_TRUE(truth.centroid);
    EXPECT_LT((*truth.centroid - renderer.truth(scenario.wMc_start, settings.r_sphere).centroid).norm(), 1e-12);
    truth.r_sphere = settings.r_sphere;
    truth.surface = renderer.object_surface();
    const perception::PerceptionScores s = perception::score_perception(rendered.frame, r, truth, settings);
    EXPECT_DOUBLE_EQ(*s.object_precision, 1.0) << "frame " << k;
    EXPECT_GE(*s.object_recall, 0.98) << "frame " << k;
    if (s.occluder_precision) {
      EXPECT_DOUBLE_EQ(*s.occluder_precision, 1.0) << "frame " << k;
    }
    if (s.occluder_recall && s.occluder_cells >= 20) {
      ++occluded_frames;
      EXPECT_GE(*s.occluder_recall, 0.95) << "frame " << k;
    }
    // The holder is never an occluder, the support only by the paper's rule.
    for (const perception::SupervoxelInfo& sv : r.supervoxels) {
      if (sv.label == perception::SupervoxelClass::Occluder) {
        EXPECT_LT((sv.centroid - r.centroid).norm(), settings.r_sphere);
      }
    }
    if (s.hidden_error) {
      EXPECT_LT(*s.hidden_error, 0.01) << "frame " << k;
    }
  }
  EXPECT_GT(occluded_frames, 0) << "the hand never came into the sphere";

  renderer.set_time(0.0);
  sim::RenderedFrame unlabelled = renderer.render(scenario.wMc_start, 0);
  unlabelled.frame.labels.clear();
  perception::Perception fresh(settings);
  EXPECT_THROW((void)fresh.process(unlabelled.frame), std::invalid_argument);
}

}  // namespace
}  // namespace ofv
