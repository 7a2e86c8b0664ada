// The hindsight planner: a wall with one gap (the optimum by hand), the
// planned values against the renderer's truth, the speed limit, bad settings.
#include "ofv/sim/hindsight.h"
#include "ofv/sim/renderer.h"

#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace ofv::sim {
namespace {

// A small target 0.5 m ahead of the camera and a wall 0.2 m in front of it
// that covers every line of sight left of x = 0.1 at its plane (z = 0.3).
Scenario wall_with_a_gap(double duration) {
  return scenario_from_yaml(
      "duration: " + std::to_string(duration) + "\n"
      "sensor: {noise: {enabled: false}}\n"
      "camera: {position: [0, 0, 0], look_at: [0, 0, 0.5]}\n"
      "object: {shape: box, size: [0.01, 0.01, 0.002], position: [0, 0, 0.5]}\n"
      "occluders:\n"
      "  - {name: wall, shape: box, size: [1.1, 2.0, 0.01], position: [-0.45, 0, 0.3]}\n"
      "estimator: {r_sphere: 0.5}\n",
      "wall.yaml");
}

double step_length(const HindsightPlan& p, std::size_t i) { return (p.views[i] - p.views[i - 1]).norm(); }

// The camera sees the target once the line from it crosses the wall's plane
// right of the edge: 0.2 tan(phi) > 0.1 on the sphere, phi > atan(0.5), an
// arc of 0.5 atan(0.5) = 0.232 m from the start, 0.464 s at 0.5 m/s. Of the
// 31 frames of 1 s, those from 0.4667 s on (17) can see it all: 17/31 is
// the optimum. A lattice's one-step moves are slower than a straight line
// at full speed (a view's neighbours within reach do not all lie ahead);
// straight moves of a few steps come closer, as does a finer lattice; none
// goes beyond.
TEST(Hindsight, AWallWithOneGapIsLeftAsFastAsTheLatticeAllows) {
  const Scenario s = wall_with_a_gap(1.0);
  const double optimum = 17.0 / 31.0;
  double coarser = 0.0;
  for (const double spacing : {0.015, 0.01}) {
    HindsightSettings h;
    h.spacing = spacing;
    const HindsightPlan p = plan_hindsight(s, s.wMc_start, 0.5, s.duration, h);
    ASSERT_EQ(p.times.size(), 31U);
    EXPECT_LE(p.bound, optimum + 1.5 / 31.0) << "spacing " << spacing;  // the target is 1 cm wide
    EXPECT_GE(p.bound, coarser) << "spacing " << spacing;
    coarser = p.bound;
    EXPECT_NEAR(p.unlimited_bound, 1.0, 1e-9);  // clear views exist from the start
    EXPECT_EQ(p.visible.front(), 0.0);          // the start is behind the wall
    EXPECT_EQ(p.visible.back(), 1.0);
    for (std::size_t i = 1; i < p.views.size(); ++i) {
      EXPECT_LE(step_length(p, i), h.max_speed * p.step + 1e-9) << "step " << i;
      EXPECT_NEAR((p.views[i] - p.centroids[i]).norm(), 0.5, 1e-9) << "step " << i;  // on the sphere, straight moves too
      EXPECT_LE(p.visible[i], p.best_visible[i]);
    }
    // Towards the gap (+x) from the first step.
    for (std::size_t i = 1; i < 8; ++i) EXPECT_GT(p.views[i].x(), p.views[i - 1].x()) << "step " << i;
  }
  EXPECT_GE(coarser, optimum - 2.5 / 31.0);  // within 2 frames at 1 cm
  // One-step moves alone: at least two frames later at 1 cm.
  HindsightSettings one_step;
  one_step.segment_steps = 1;
  EXPECT_LE(plan_hindsight(s, s.wMc_start, 0.5, s.duration, one_step).bound, coarser - 2.0 / 31.0 + 1e-9);
}

// Started 3 cm inside its sphere, the camera heads for the gap at once,
// reaching the sphere on the way, rather than along the radius first (two
// steps of 1.67 cm); each step within the speed limit, and on the sphere
// once it got there.
TEST(Hindsight, ACameraOffItsSphereHeadsForTheGapAtOnce) {
  Scenario s = wall_with_a_gap(1.0);
  s.wMc_start.translation().z() = 0.03;
  const HindsightPlan p = plan_hindsight(s, s.wMc_start, 0.5, s.duration, HindsightSettings{});
  const HindsightPlan on_sphere = plan_hindsight(wall_with_a_gap(1.0), wall_with_a_gap(1.0).wMc_start, 0.5, 1.0,
                                                 HindsightSettings{});
  EXPECT_GT(p.views[1].x(), 0.005);
  bool arrived = false;
  for (std::size_t i = 1; i < p.views.size(); ++i) {
    EXPECT_LE(step_length(p, i), 0.5 * p.step + 1e-9) << "step " << i;
    EXPECT_GT(p.views[i].x(), p.views[i - 1].x() - 1e-9) << "step " << i;
    const double off = std::abs((p.views[i] - p.centroids[i]).norm() - 0.5);
    if (arrived) {
      EXPECT_LT(off, 1e-9) << "step " << i;
    }
    arrived = arrived || off < 1e-9;
  }
  EXPECT_TRUE(arrived);
  // 3 cm nearer the wall, its edge is 1.5 cm nearer in x: the camera sees
  // the target no later than from the sphere.
  EXPECT_GE(p.bound, on_sphere.bound);
}

TEST(Hindsight, NothingInTheWayKeepsTheCameraWhereItIs) {
  const Scenario s = scenario_from_yaml(
      "duration: 0.5\nsensor: {noise: {enabled: false}}\ncamera: {position: [0, 0, 0], look_at: [0, 0, 0.5]}\n"
      "object: {shape: box, size: [0.1, 0.1, 0.01], position: [0, 0, 0.5]}\nestimator: {r_sphere: 0.5}\n",
      "free.yaml");
  HindsightSettings h;
  h.spacing = 0.015;
  const HindsightPlan p = plan_hindsight(s, s.wMc_start, 0.5, s.duration, h);
  EXPECT_EQ(p.bound, 1.0);
  for (const Eigen::Vector3d& v : p.views) EXPECT_LT((v - s.wMc_start.translation()).norm(), 1e-12);
  // Nothing moves: a view is scored once, at the first step the camera can
  // be there, and kept; the start twice (as placed at time 0, then turned to
  // the centroid of the surface samples, a hair off its axis). In 0.5 s at
  // 0.5 m/s the camera reaches a tenth of the sphere, and the views there see
  // all, so the unlimited bound needs no other view.
  EXPECT_EQ(p.unlimited_bound, 1.0);
  EXPECT_LT(p.evaluations, p.lattice_views / 5);
  EXPECT_GT(p.evaluations, p.lattice_views / 20);
}

// What the plan says it sees is what the renderer sees from there (the
// views that nothing near them changed are carried from the step before;
// the steps inside straight moves are cast where the camera is).
TEST(Hindsight, PlannedValuesAreTheRenderersTruth) {
  const Scenario s = load_scenario("dvd-one-hand");
  HindsightSettings h;
  h.spacing = 0.03;
  h.frames_per_step = 3;
  const HindsightPlan p = plan_hindsight(s, s.wMc_start, 0.5, 2.0, h);
  Renderer renderer(s);
  for (std::size_t i = 0; i < p.times.size(); ++i) {
    renderer.set_time(p.times[i]);
    EXPECT_NEAR((renderer.object_centroid() - p.centroids[i]).norm(), 0.0, 1e-12);
    Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
    wMc.linear() = (Eigen::Quaterniond::FromTwoVectors(s.wMc_start.linear().col(2), (p.centroids[i] - p.views[i]).normalized()) *
                    Eigen::Quaterniond(s.wMc_start.linear()))
                       .toRotationMatrix();
    wMc.translation() = p.views[i];
    EXPECT_EQ(renderer.visible_fractions({wMc}).front(), p.visible[i]) << "step " << i;
  }
  EXPECT_LE(p.bound, p.unlimited_bound);
  // Between steps the path runs on the sphere around the moving centroid.
  const double t = 0.5 * (p.times[4] + p.times[5]);
  EXPECT_NEAR((p.view_at(t) - p.centroid_at(t)).norm(), 0.5, 1e-9);
  EXPECT_EQ(p.view_at(-1.0), p.views.front());
  EXPECT_EQ(p.view_at(1e3), p.views.back());
}

TEST(Hindsight, BadSettingsAreRefusedByName) {
  const Scenario s = wall_with_a_gap(0.2);
  const auto error = [&](HindsightSettings h, double r = 0.5) -> std::string {
    try {
      (void)plan_hindsight(s, s.wMc_start, r, s.duration, h);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no error";
  };
  HindsightSettings h;
  h.spacing = 0.0;
  EXPECT_NE(error(h).find("hindsight_spacing"), std::string::npos);
  h.spacing = 0.06;  // more than 3 steps of 1.67 cm
  EXPECT_NE(error(h).find("could never move"), std::string::npos);
  h.spacing = 0.02;  // by straight moves only
  h.segment_steps = 1;
  EXPECT_NE(error(h).find("could never move"), std::string::npos);
  h.segment_steps = 3;
  EXPECT_EQ(error(h), "no error");
  h.spacing = 0.001;
  EXPECT_NE(error(h).find("more than 100000"), std::string::npos);
  h = {};
  h.frames_per_step = 0;
  EXPECT_NE(error(h).find("hindsight_step"), std::string::npos);
  h = {};
  h.segment_steps = 0;
  EXPECT_NE(error(h).find("hindsight_segment"), std::string::npos);
  h.segment_steps = 9;
  EXPECT_NE(error(h).find("hindsight_segment"), std::string::npos);
  h = {};
  h.max_speed = std::nan("");
  EXPECT_NE(error(h).find("speed"), std::string::npos);
  EXPECT_NE(error({}, -1.0).find("r_sphere"), std::string::npos);
}

}  // namespace
}  // namespace ofv::sim
