// The per-frame policy's stages by their properties: the mode machine's
// table, the world model, and one frame of the whole loop under rigid
// motions of the scene (the proposers, the selector and the controller).
#include "ofv/servo/loop_status.h"
#include "ofv/servo/target_pose.h"
#include "ofv/servo/view_loop.h"
#include "world_model.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

namespace ofv::servo {
namespace {

const LoopMode kModes[] = {LoopMode::Pursue, LoopMode::Hold, LoopMode::WayBack, LoopMode::Waiting, LoopMode::Lost};

// --- the mode machine

TEST(ModeMachine, TheTableIsAFunctionOfModeAndGuard) {
  std::set<std::pair<LoopMode, Guard>> seen;
  for (const LoopTransition& t : loop_transitions()) {
    EXPECT_TRUE(seen.emplace(t.from, t.guard).second) << to_string(t.from) << " by " << to_string(t.guard) << " twice";
    EXPECT_NE(t.guard, Guard::None);  // a transition has a reason
    EXPECT_NE(t.from, t.to) << to_string(t.guard);
  }
}

TEST(ModeMachine, EveryModeIsReachedFromTheStartAndLeadsBackToPursue) {
  // Breadth-first over the table from `from`: the modes reached.
  const auto reached = [](LoopMode from) {
    std::set<LoopMode> out{from};
    for (bool grew = true; grew;) {
      grew = false;
      for (const LoopTransition& t : loop_transitions()) {
        if (out.count(t.from) > 0) grew = out.insert(t.to).second || grew;
      }
    }
    return out;
  };
  EXPECT_EQ(reached(LoopMode::Lost).size(), std::size(kModes));  // a loop starts lost
  for (const LoopMode m : kModes) EXPECT_EQ(reached(m).count(LoopMode::Pursue), 1U) << to_string(m) << " is a trap";
}

TEST(ModeMachine, FindingTheObjectLeavesEveryModeWithoutIt) {
  // Modes without the object in view must have a way out when it is found
  // again; the ones with it must have one when it is lost.
  std::map<LoopMode, std::set<Guard>> out;
  for (const LoopTransition& t : loop_transitions()) out[t.from].insert(t.guard);
  for (const LoopMode m : {LoopMode::WayBack, LoopMode::Waiting, LoopMode::Lost}) {
    EXPECT_EQ(out[m].count(Guard::ObjectFound), 1U) << to_string(m);
  }
  for (const LoopMode m : {LoopMode::Pursue, LoopMode::Hold}) {
    EXPECT_EQ(out[m].count(Guard::ObjectLost), 1U) << to_string(m);
  }
}

// --- the world model

// A 4-point cluster around `c` (one occluder for the tracker).
Eigen::Matrix3Xd cluster(const Eigen::Vector3d& c) {
  Eigen::Matrix3Xd m(3, 4);
  m << c.x() - 0.01, c.x() + 0.01, c.x(), c.x(),  //
      c.y(), c.y(), c.y() - 0.01, c.y() + 0.01,   //
      c.z(), c.z(), c.z(), c.z();
  return m;
}

// Two clusters, one standing at `still`, one moving from `from` at `v`, over `frames` frames.
WorldModel watched(const Eigen::Vector3d& still, const Eigen::Vector3d& from, const Eigen::Vector3d& v, int frames,
                   double dt = 1.0 / 30.0) {
  WorldModel world(TrackerSettings{}, /*min_speed=*/0.05);
  for (int k = 0; k < frames; ++k) {
    Eigen::Matrix3Xd seen(3, 8);
    seen << cluster(still), cluster(from + v * (k * dt));
    (void)world.update(&seen, dt);
  }
  return world;
}

TEST(WorldModel, PredictionsAreTheMovingTracksAheadAndInsideTheSphere) {
  const Eigen::Vector3d c(0, 0, 0.5);
  const Eigen::Vector3d v(0.3, 0, 0);
  const WorldModel world = watched(c + Eigen::Vector3d(0, 0.1, -0.1), c + Eigen::Vector3d(-0.1, 0, -0.1), v, 10);
  const Eigen::Matrix3Xd ahead = world.predicted(0.3, 3, c, 0.25);
  ASSERT_EQ(ahead.cols(), 3 * 4);  // the moving cluster's 4 points, 3 times; not the still one
  for (Eigen::Index i = 0; i < ahead.cols(); ++i) {
    EXPECT_LT((ahead.col(i) - c).norm(), 0.25);
    EXPECT_GT(ahead(0, i), -0.1 + 0.3 * 9 / 30.0);  // ahead of where the cluster is now
  }
  // A smaller sphere keeps only the copies inside it.
  const Eigen::Matrix3Xd near = world.predicted(0.3, 3, c, 0.12);
  EXPECT_LT(near.cols(), ahead.cols());
  for (Eigen::Index i = 0; i < near.cols(); ++i) EXPECT_LT((near.col(i) - c).norm(), 0.12);
}

TEST(WorldModel, APeriodThatIsNotATimeStartsTheTracksAgain) {
  WorldModel world = watched({0, 0.1, 0.4}, {-0.1, 0, 0.4}, {0.3, 0, 0}, 10);
  const Eigen::Matrix3Xd seen = cluster({0, 0.1, 0.4});
  for (const double dt : {0.0, -1.0, std::nan("")}) {
    const std::vector<OccluderTrack>& tracks = world.update(&seen, dt);
    ASSERT_EQ(tracks.size(), 1U) << dt;
    EXPECT_EQ(tracks[0].id, 0) << dt;  // new ids: nothing kept from before
    EXPECT_FALSE(tracks[0].confirmed);
  }
}

// --- one frame of the loop under rigid motions

// A curved patch (PCA axes determined) 0.5 m in front of the origin, facing
// it, and a cluster on the line of sight.
ViewProblem occluded_scene() {
  ViewProblem p;
  p.positions.resize(3, 35);
  p.normals.resize(3, 35);
  for (int k = 0; k < 35; ++k) {
    const double x = (k % 7 - 3) * 0.02, y = (k / 7 - 2) * 0.02;
    p.positions.col(k) << x, y, 0.5 + 2.0 * x * x;
    p.normals.col(k) = Eigen::Vector3d(4.0 * x, 0.0, -1.0).normalized();
  }
  p.occluders.resize(3, 9);
  for (int k = 0; k < 9; ++k) p.occluders.col(k) << (k % 3 - 1) * 0.01 + 0.004, (k / 3 - 1) * 0.01 + 0.002, 0.3;
  return p;
}

ViewProblem moved(const ViewProblem& p, const Eigen::Isometry3d& m) {
  ViewProblem out = p;
  out.positions = m * p.positions;
  out.normals = m.linear() * p.normals;
  out.occluders = m * p.occluders;
  return out;
}

TEST(ViewLoop, OneFrameMovesWithTheSceneAndTheCommandDoesNot) {
  // The same scene and camera moved rigidly: the target moves with them, the
  // mode and the proposer are the same, and the command (camera frame) is.
  const ViewProblem scene = occluded_scene();
  const Eigen::Isometry3d camera = Eigen::Isometry3d::Identity();
  const auto first_step = [](const ViewProblem& p, const Eigen::Isometry3d& wMc) {
    ViewLoop loop(LoopSettings{});
    Observation o;
    o.problem = p;
    o.wMc = wMc;
    o.shown_area = 1e-2;
    return loop.step(o, 1.0 / 30.0);
  };
  const LoopStep ref = first_step(scene, camera);
  ASSERT_TRUE(ref.target);
  ASSERT_GT(ref.velocity.frobeniusNorm(), 0.0);
  EXPECT_EQ(ref.status, StepStatus::Converged);
  for (const Eigen::Isometry3d& m :
       {Eigen::Isometry3d(Eigen::Translation3d(0.3, -1.2, 0.8)),
        Eigen::Isometry3d(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized())),
        Eigen::Translation3d(-0.4, 0.1, 2.0) * Eigen::AngleAxisd(2.5, Eigen::Vector3d(0.3, -1, 0.2).normalized())}) {
    const LoopStep s = first_step(moved(scene, m), m * camera);
    ASSERT_TRUE(s.target);
    EXPECT_LT((*s.target - m * *ref.target).norm(), 1e-9);
    EXPECT_EQ(s.mode, ref.mode);
    EXPECT_EQ(s.proposer, ref.proposer);
    EXPECT_EQ(s.status, ref.status);
    for (unsigned i = 0; i < 6; ++i) EXPECT_NEAR(s.velocity[i], ref.velocity[i], 1e-9) << i;
  }
}

// Method hindsight: follow() is the controller and the safety filter alone,
// towards the view it is given; step() refuses the method.
TEST(ViewLoop, FollowDrivesToTheGivenViewThroughTheSafetyFilter) {
  LoopSettings settings;
  settings.method = ViewMethod::Hindsight;
  ViewLoop loop(settings);
  EXPECT_THROW((void)loop.step(Observation{}, 1.0 / 30.0), std::logic_error);
  // The camera at the origin looking at C = (0, 0, 0.5); the view 0.1 m to its right on the sphere.
  const Eigen::Vector3d centroid(0.0, 0.0, 0.5);
  const Eigen::Vector3d view = centroid + 0.5 * Eigen::Vector3d(0.2, 0.0, -1.0).normalized();
  const LoopStep s = loop.follow(view, centroid, Eigen::Isometry3d::Identity(), 1.0 / 30.0, 1.0 / 30.0);
  EXPECT_EQ(s.status, StepStatus::Planned);
  EXPECT_EQ(s.proposer, Proposer::Plan);
  EXPECT_EQ(s.mode, LoopMode::Pursue);
  ASSERT_TRUE(s.target);
  EXPECT_EQ(*s.target, view);
  EXPECT_GT(s.velocity[0], 0.0);  // towards +x, in the camera frame (the camera is the world here)
  // From rest, within the acceleration limit.
  EXPECT_LE(std::hypot(s.velocity[0], s.velocity[1], s.velocity[2]),
            settings.safety.max_linear_accel / 30.0 + 1e-9);
  // A frame older than the stale timeout: no motion.
  const LoopStep stale = loop.follow(view, centroid, Eigen::Isometry3d::Identity(), 10.0, 1.0 / 30.0);
  EXPECT_EQ(stale.velocity.frobeniusNorm(), 0.0);
  EXPECT_THROW((void)loop.follow(view, centroid, Eigen::Isometry3d::Identity(), 0.0, 1.0 / 30.0, -1.0),
               std::invalid_argument);
}

// A path given in advance is tracked: with a time to reach the target, a
// camera moving along the path at its speed is commanded that speed (the
// loop's own gain would command a fraction of it and fall behind).
TEST(ViewLoop, FollowWithinATimeTracksAPathAtItsSpeed) {
  LoopSettings settings;
  settings.method = ViewMethod::Hindsight;
  const double dt = 1.0 / 30.0;
  const Eigen::Vector3d centroid(0.0, 0.0, 0.5);
  const auto on_path = [&](double t) {  // 0.3 m/s around the sphere in the x-z plane, from the camera at the origin
    const double a = 0.3 * t / 0.5;
    return Eigen::Vector3d(centroid + 0.5 * Eigen::Vector3d(std::sin(a), 0.0, -std::cos(a)));
  };
  const auto speed_after = [&](double within, int frames) {
    ViewLoop loop(settings);
    Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
    LoopStep s;
    for (int k = 0; k < frames; ++k) {
      const double t = k * dt;
      wMc.translation() = on_path(t);  // the camera is on the path, turned to look at C
      wMc.linear() = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), (centroid - on_path(t)).normalized())
                         .toRotationMatrix();
      s = loop.follow(on_path(t + (within > 0.0 ? within : dt)), centroid, wMc, dt, dt, within);
    }
    return std::hypot(s.velocity[0], s.velocity[1], s.velocity[2]);
  };
  EXPECT_NEAR(speed_after(dt, 30), 0.3, 0.003);
  EXPECT_LT(speed_after(0.0, 30), 0.3 * 0.5);  // the loop's controller, one frame ahead: lags
}

}  // namespace
}  // namespace ofv::servo
