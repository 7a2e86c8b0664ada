// ViewLoop (the per-frame policy) and run_on_robot (its driver on robots):
// statuses, the safety filter in the loop, stale frames, the stop flag.
#include "ofv/servo/robot_loop.h"
#include "ofv/servo/target_pose.h"
#include "ofv/servo/view_loop.h"

#include <gtest/gtest.h>

#include <deque>
#include <stdexcept>
#include <utility>
#include <vector>
#include <cmath>
#include <chrono>
#include <limits>
#include <thread>
#include <mutex>
#include <condition_variable>

namespace ofv {
namespace {

// A 5 x 5 patch 0.5 m ahead of a camera at the origin, facing it; an occluder
// cluster on the line of sight when `occluded`.
ViewProblem patch(bool occluded) {
  ViewProblem p;
  p.positions.resize(3, 25);
  p.normals.resize(3, 25);
  for (int k = 0; k < 25; ++k) {
    p.positions.col(k) << (k % 5 - 2) * 0.02, (k / 5 - 2) * 0.02, 0.5;
    p.normals.col(k) << 0, 0, -1;
  }
  p.occluders.resize(3, occluded ? 9 : 0);
  for (int k = 0; occluded && k < 9; ++k) p.occluders.col(k) << (k % 3 - 1) * 0.01 + 0.005, (k / 3 - 1) * 0.01, 0.3;
  return p;
}

// The loop's input from a problem (std::nullopt: lost), the camera pose, the
// frame's age, the shown area and how many of the problem's occluders (the
// last ones) are presumed.
Observation observed(std::optional<ViewProblem> problem, const vpHomogeneousMatrix& wMc, double age,
                     std::optional<double> shown = std::nullopt, Eigen::Index presumed = 0) {
  Observation o;
  o.wMc = servo::to_eigen(wMc);
  o.age = age;
  o.shown_area = shown;
  if (problem) {
    const Eigen::Index n = problem->occluders.cols();
    presumed = std::min(presumed, n);
    o.presumed = problem->occluders.rightCols(presumed);
    problem->occluders = Eigen::Matrix3Xd(problem->occluders.leftCols(n - presumed));
  }
  o.problem = std::move(problem);
  return o;
}

// Observes `problem` on every frame (std::nullopt: lost).
class Fixed : public Observer {
 public:
  explicit Fixed(std::optional<ViewProblem> problem) : problem_(std::move(problem)) {}
  Observation observe(const RgbdFrame& frame) override { return observed(problem_, servo::to_visp(frame.wMc), 0.0); }

 private:
  std::optional<ViewProblem> problem_;
};

double speed(const vpColVector& v) { return std::hypot(v[0], v[1], v[2]); }

TEST(ViewLoop, StatusesAndTheSafetyFilterInTheLoop) {
  servo::LoopSettings settings;
  servo::ViewLoop loop(settings);
  const vpHomogeneousMatrix wMc;  // at the origin, looking along +z at the patch
  const double dt = 1.0 / 30.0;
  servo::LoopStep s = loop.step(observed(patch(false), wMc, 0.0), dt);
  EXPECT_EQ(s.status, servo::StepStatus::NoOccluders);
  ASSERT_TRUE(s.target);
  s = loop.step(observed(patch(true), wMc, 0.0), dt);
  EXPECT_EQ(s.status, servo::StepStatus::Converged);
  EXPECT_GT(s.estimate->iterations, 0);
  // From rest the command is cut to what the acceleration limit allows.
  EXPECT_GT(speed(s.command), settings.safety.max_linear_accel * dt);
  EXPECT_EQ(s.safety, servo::SafetyAction::AccelerationLimit);
  EXPECT_LE(speed(s.velocity), 2.0 * settings.safety.max_linear_accel * dt + 1e-12);
  // A lost object or a stale frame stops the robot at once.
  s = loop.step(observed(std::nullopt, wMc, 0.0), dt);
  EXPECT_EQ(s.status, servo::StepStatus::ObjectLost);
  EXPECT_EQ(s.safety, servo::SafetyAction::ObjectLost);
  EXPECT_EQ(s.velocity.frobeniusNorm(), 0.0);
  s = loop.step(observed(patch(true), wMc, 5.0), dt);
  EXPECT_EQ(s.safety, servo::SafetyAction::StaleFrame);
  EXPECT_EQ(s.velocity.frobeniusNorm(), 0.0);
  // No usable supervoxel is a lost object, not an exception.
  ViewProblem broken = patch(true);
  broken.normals.setZero();
  EXPECT_EQ(loop.step(observed(broken, wMc, 0.0), dt).status, servo::StepStatus::ObjectLost);
  // The static baseline never moves.
  settings.method = ViewMethod::Static;
  servo::ViewLoop still(settings);
  EXPECT_EQ(still.step(observed(patch(true), wMc, 0.0), dt).velocity.frobeniusNorm(), 0.0);
}

// A frame whose camera pose the pose source could not tell (RGB-D odometry
// failed): exactly zero velocity, whatever the frame shows, and the next
// frame starts again from rest within the acceleration limits.
TEST(ViewLoop, AFrameOfUnknownPoseStopsAndTheNextStartsFromRest) {
  const servo::LoopSettings settings;
  servo::ViewLoop loop(settings);
  const vpHomogeneousMatrix wMc;
  const double dt = 1.0 / 30.0;
  servo::LoopStep s;
  for (int k = 0; k < 6; ++k) s = loop.step(observed(patch(true), wMc, 0.0), dt);
  ASSERT_GT(speed(s.velocity), 1.5 * settings.safety.max_linear_accel * dt);  // under way, beyond one step from rest
  Observation unknown = observed(patch(true), wMc, 0.0);
  unknown.pose = PoseStatus::Unknown;
  s = loop.step(unknown, dt);
  EXPECT_EQ(s.safety, servo::SafetyAction::PoseUnknown);
  EXPECT_TRUE(stops(s.safety));
  EXPECT_STREQ(to_string(s.safety), "pose unknown");
  EXPECT_EQ(s.status, servo::StepStatus::Converged);  // the frame was seen; only its pose is not known
  for (unsigned i = 0; i < 6; ++i) EXPECT_EQ(s.velocity[i], 0.0) << i;
  // The next frame, its pose known: from rest, within the acceleration limits.
  s = loop.step(observed(patch(true), wMc, 0.0), dt);
  EXPECT_FALSE(stops(s.safety));
  EXPECT_GT(speed(s.velocity), 0.0);
  EXPECT_LE(speed(s.velocity), settings.safety.max_linear_accel * dt * (1.0 + 1e-9));
  EXPECT_LE(std::hypot(s.velocity[3], s.velocity[4], s.velocity[5]), settings.safety.max_angular_accel * dt * (1.0 + 1e-9));
  // Unknown and lost: the pose is the reason (a way back would be driven from it).
  unknown = observed(std::nullopt, wMc, 0.0);
  unknown.pose = PoseStatus::Unknown;
  s = loop.step(unknown, dt);
  EXPECT_EQ(s.safety, servo::SafetyAction::PoseUnknown);
  EXPECT_EQ(s.velocity.frobeniusNorm(), 0.0);
}

// The first frame whose target is more than 1 cm from t0 (the origin), as an
// occluder cluster at 30 cm from the camera crosses the line of sight at
// 0.6 m/s; -1 if none.
int first_move(servo::Anticipation anticipation) {
  servo::LoopSettings settings;
  settings.anticipation.mode = anticipation;
  servo::ViewLoop loop(settings);
  const vpHomogeneousMatrix wMc;  // the camera stays at the origin: only the target matters
  const double dt = 1.0 / 30.0;
  for (int k = 0; k < 30; ++k) {
    ViewProblem p = patch(false);
    p.occluders.resize(3, 9);
    for (int i = 0; i < 9; ++i) p.occluders.col(i) << -0.35 + 0.6 * k * dt + (i % 3) * 0.01, (i / 3 - 1) * 0.01, 0.3;
    const servo::LoopStep s = loop.step(observed(p, wMc, 0.0), dt);
    if (s.target && s.target->norm() > 0.01) return k;
  }
  return -1;
}

TEST(ViewLoop, AnticipationLeavesBeforeTheOccluderArrives) {
  // Reactive: the view moves once occlusion rays reach t0, when the cluster
  // is about 3 cm from the line of sight (frame 16). Predicting 0.8 s ahead,
  // it moves as soon as the track is confirmed and its path crosses t0.
  const int reactive = first_move(servo::Anticipation::Off);
  const int ahead = first_move(servo::Anticipation::Predict);
  ASSERT_GE(reactive, 0);
  ASSERT_GE(ahead, 0);
  EXPECT_GE(reactive, 14);
  EXPECT_LE(ahead + 8, reactive) << "anticipating " << ahead << ", reactive " << reactive;
}

// The patch with a small cluster in front of a corner (side 1: +x +y, -1:
// -x -y): t0 is occluded, the estimator converges to the same view frame
// after frame.
ViewProblem occluded_patch(double side = 1.0) {
  ViewProblem start = patch(false);
  start.occluders.resize(3, 9);
  for (int k = 0; k < 9; ++k) {
    start.occluders.col(k) << (k % 3 - 1) * 0.01 + 0.02 * side, (k / 3 - 1) * 0.01 + 0.02 * side, 0.3;
  }
  return start;
}

// `frames` frames at the origin showing 100; returns the last target.
Eigen::Vector3d stay(servo::ViewLoop& loop, int frames, double side = 1.0) {
  servo::LoopStep s;
  for (int k = 0; k < frames; ++k) s = loop.step(observed(occluded_patch(side), vpHomogeneousMatrix(), 0.0, 100.0), 1.0 / 30.0);
  EXPECT_TRUE(s.target);
  return s.target.value_or(Eigen::Vector3d::Constant(NAN));
}

// A frame at the origin with nothing in front of the patch: t0 is clear.
void see_t0_clear(servo::ViewLoop& loop) { (void)loop.step(observed(patch(false), vpHomogeneousMatrix(), 0.0, 100.0), 1.0 / 30.0); }

vpHomogeneousMatrix at(const Eigen::Vector3d& p) { return vpHomogeneousMatrix(vpTranslationVector(p.x(), p.y(), p.z()), vpRotationMatrix()); }

TEST(ViewLoop, LostOnItsWayItGoesBackToWhereItSawTheObject) {
  // The origin showed the most (100); 6 cm away the frame shows 95, then
  // perception loses the object: the camera heads back to the origin (the
  // safety filter lets this motion through), and stops there.
  const double dt = 1.0 / 30.0;
  const Eigen::Vector3d away(0.06, 0.0, 0.0);
  servo::LoopSettings settings;
  servo::ViewLoop loop(settings);
  (void)stay(loop, 1);
  (void)loop.step(observed(occluded_patch(), at(away), 0.0, 95.0), dt);
  servo::LoopStep s = loop.step(observed(std::nullopt, at(away), 0.0), dt);
  EXPECT_EQ(s.status, servo::StepStatus::ObjectLost);
  EXPECT_EQ(s.guard, servo::Guard::ObjectLost);
  EXPECT_EQ(s.mode, servo::LoopMode::WayBack);
  EXPECT_EQ(s.proposer, servo::Proposer::BestSeen);
  ASSERT_TRUE(s.target);
  EXPECT_LT(s.target->norm(), 1e-12);
  EXPECT_NE(s.safety, servo::SafetyAction::ObjectLost);
  EXPECT_LT(s.velocity[0], -1e-3);  // camera frame = world frame here: towards the origin
  EXPECT_LE(speed(s.velocity), settings.safety.max_linear_speed + 1e-12);
  s = loop.step(observed(std::nullopt, at(Eigen::Vector3d(0.005, 0, 0)), 0.0), dt);
  EXPECT_EQ(s.guard, servo::Guard::BackThere);
  EXPECT_EQ(s.mode, servo::LoopMode::Waiting);
  EXPECT_FALSE(s.target);
  EXPECT_EQ(s.safety, servo::SafetyAction::ObjectLost);
  EXPECT_EQ(s.velocity.frobeniusNorm(), 0.0);
  // Found again there: it holds that view (guard object_found), until t0 is clear.
  s = loop.step(observed(occluded_patch(), at(Eigen::Vector3d(0.005, 0, 0)), 0.0, 100.0), dt);
  EXPECT_EQ(s.guard, servo::Guard::ObjectFound);
  EXPECT_EQ(s.mode, servo::LoopMode::Hold);
  EXPECT_EQ(s.proposer, servo::Proposer::BestSeen);
  s = loop.step(observed(patch(false), at(Eigen::Vector3d(0.005, 0, 0)), 0.0, 100.0), dt);
  EXPECT_EQ(s.guard, servo::Guard::T0Clear);
  EXPECT_EQ(s.mode, servo::LoopMode::Pursue);
  EXPECT_EQ(s.proposer, servo::Proposer::Estimate);

  // Without the retreat (retreat_drop = 0), or lost where the camera has
  // been for longer than 0.5 s (the best view since is here), a lost object
  // stops the camera.
  settings.retreat.drop = 0.0;
  servo::ViewLoop no_retreat(settings);
  (void)stay(no_retreat, 1);
  (void)no_retreat.step(observed(occluded_patch(), at(away), 0.0, 95.0), dt);
  s = no_retreat.step(observed(std::nullopt, at(away), 0.0), dt);
  EXPECT_EQ(s.mode, servo::LoopMode::Lost);
  EXPECT_FALSE(s.target);
  EXPECT_EQ(s.velocity.frobeniusNorm(), 0.0);
  servo::ViewLoop late(servo::LoopSettings{});
  (void)stay(late, 1);
  for (int k = 0; k < 20; ++k) (void)late.step(observed(occluded_patch(), at(away), 0.0, 95.0), dt);
  s = late.step(observed(std::nullopt, at(away), 0.0), dt);
  EXPECT_EQ(s.guard, servo::Guard::BackThere);  // the origin is too long ago: the best view of the last 0.5 s is here
  EXPECT_EQ(s.mode, servo::LoopMode::Waiting);
  EXPECT_FALSE(s.target);
  EXPECT_EQ(s.velocity.frobeniusNorm(), 0.0);
}

TEST(ViewLoop, AHoldEndsWhenTheHeldViewKeepsShowingLess) {
  // Lost 6 cm from the origin (which showed 100), back there, found again:
  // it holds the origin. There every frame shows 50 (the scene changed):
  // the hold ends after release_frames such frames, not before.
  const double dt = 1.0 / 30.0;
  const servo::LoopSettings settings;
  servo::ViewLoop loop(settings);
  (void)stay(loop, 1);
  const Eigen::Vector3d back(0.005, 0, 0);
  (void)loop.step(observed(occluded_patch(), at(Eigen::Vector3d(0.06, 0, 0)), 0.0, 95.0), dt);
  EXPECT_EQ(loop.step(observed(std::nullopt, at(Eigen::Vector3d(0.06, 0, 0)), 0.0), dt).mode, servo::LoopMode::WayBack);
  EXPECT_EQ(loop.step(observed(std::nullopt, at(back), 0.0), dt).mode, servo::LoopMode::Waiting);
  for (int k = 1; k <= settings.retreat.release_frames; ++k) {
    const servo::LoopStep s = loop.step(observed(occluded_patch(), at(back), 0.0, 50.0), dt);
    if (k < settings.retreat.release_frames) {
      EXPECT_EQ(s.mode, servo::LoopMode::Hold) << k;
      EXPECT_EQ(s.proposer, servo::Proposer::BestSeen) << k;
      ASSERT_TRUE(s.target);
      EXPECT_LT(s.target->norm(), 1e-12);
    } else {
      EXPECT_EQ(s.guard, servo::Guard::SceneChanged);
      EXPECT_EQ(s.mode, servo::LoopMode::Pursue);
      EXPECT_NE(s.proposer, servo::Proposer::BestSeen);
    }
  }
}

TEST(ViewLoop, PresumedOccludersAreAvoidedButNotTracked) {
  // The problem's last 30 occluders are presumed (perception's continuation
  // beyond the image border): the estimator avoids them, the tracks leave them out.
  ViewProblem p = occluded_patch();
  p.occluders.conservativeResize(3, 9 + 30);
  for (int i = 0; i < 30; ++i) p.occluders.col(9 + i) << -0.2 - 0.02 * (i % 10), 0.02 * (i / 10), 0.3;
  const auto tracked_points = [](const servo::LoopStep& s) {
    Eigen::Index n = 0;
    for (const OccluderTrack& t : s.tracks) n += t.points.cols();
    return n;
  };
  servo::ViewLoop with(servo::LoopSettings{}), all(servo::LoopSettings{});
  servo::LoopStep a, b;
  for (int k = 0; k < 3; ++k) {
    a = with.step(observed(p, vpHomogeneousMatrix(), 0.0, std::nullopt, 30), 1.0 / 30.0);
    b = all.step(observed(p, vpHomogeneousMatrix(), 0.0), 1.0 / 30.0);
  }
  EXPECT_EQ(tracked_points(a), 9);
  EXPECT_EQ(tracked_points(b), 39);
  EXPECT_EQ(a.presumed_occluders, 30);
  EXPECT_EQ(b.presumed_occluders, 0);
  ASSERT_TRUE(a.estimate && b.estimate);
  EXPECT_EQ(a.estimate->occlusion_points, b.estimate->occlusion_points);
  // More than the problem holds is all of it.
  const servo::LoopStep c = with.step(observed(p, vpHomogeneousMatrix(), 0.0, std::nullopt, 1000), 1.0 / 30.0);
  EXPECT_EQ(tracked_points(c), 0);
  EXPECT_EQ(c.presumed_occluders, 39);
}

// The first frame's target at the origin with one still occluder point 5 cm
// in front of the camera's way `along` m from the origin towards the
// estimator's view (`side` rad around the line of sight: 0 = on the way),
// with the look-ahead (`on`) and without it (`off`). The point hides the
// whole patch from there (every line of sight passes within its 2 cm),
// none of it from the origin.
struct Post {
  Eigen::Vector3d on, off;
  servo::Proposer by = servo::Proposer::None;  ///< whose view `on` is
  [[nodiscard]] bool goes() const { return (on - off).norm() < 1e-9; }
  /// Holds, or heads more than 45 deg off the way without the look-ahead.
  [[nodiscard]] bool turns_off() const {
    return on.norm() < 1e-9 || on.normalized().dot(off.normalized()) < std::cos(EIGEN_PI / 4);
  }
};
Post with_a_post(double along, double side, bool t0_was_clear = false) {
  servo::ViewLoop plain(servo::LoopSettings{});
  const Eigen::Vector3d away = stay(plain, 1);
  const Eigen::Vector3d object(0, 0, 0.5);
  const Eigen::Vector3d way = Eigen::AngleAxisd(side, Eigen::Vector3d::UnitZ()) * away.normalized();
  const Eigen::Vector3d there = along * way;
  ViewProblem p = occluded_patch();
  p.occluders.conservativeResize(3, 10);
  p.occluders.col(9) = there + 0.05 * (object - there).normalized();
  servo::Proposer by = servo::Proposer::None;
  const auto target = [&](bool look_ahead) {
    servo::LoopSettings settings;
    settings.retreat.look_ahead = look_ahead;
    servo::ViewLoop loop(settings);
    if (t0_was_clear) see_t0_clear(loop);
    const servo::LoopStep s = loop.step(observed(p, vpHomogeneousMatrix(), 0.0, 100.0), 1.0 / 30.0);
    EXPECT_TRUE(s.target);
    if (look_ahead) by = s.proposer;
    return s.target.value_or(Eigen::Vector3d::Constant(NAN));
  };
  const Eigen::Vector3d on = target(true);
  return {on, target(false), by};
}

TEST(ViewLoop, ItDoesNotGoWhereItsOwnMotionWouldHideTheObject) {
  // Within what the camera travels before a frame could show the loss and
  // it could stop (0.5 m/s for one period, then 8 m/s^2 of braking: 3.2 cm),
  // the way to the estimator's view passes behind a still occluder: it
  // holds, or climbs to a nearby view that sees more, not along that way.
  // With the occluder off its way or beyond that reach it goes as without
  // the look-ahead; and once t0 has been clear (what hides the object came
  // in: it may stand on the only way out), it goes on too.
  const Post blocked = with_a_post(0.025, 0.0);
  EXPECT_FALSE(blocked.goes());
  EXPECT_TRUE(blocked.turns_off());
  EXPECT_TRUE(blocked.by == servo::Proposer::Here || blocked.by == servo::Proposer::Climb) << to_string(blocked.by);
  EXPECT_NE(with_a_post(0.07, 0.0).by, servo::Proposer::Here);
  EXPECT_TRUE(with_a_post(0.025, EIGEN_PI / 2).goes());
  EXPECT_TRUE(with_a_post(0.07, 0.0).goes());
  EXPECT_TRUE(with_a_post(0.025, 0.0, true).goes());
}

TEST(ViewLoop, SettingsByNameAreValidated) {
  servo::LoopSettings s;
  servo::loop_settings_table().set(s, "max_linear_speed", "0.3");
  EXPECT_EQ(s.controller.max_linear_speed, 0.3);
  EXPECT_EQ(s.safety.max_linear_speed, 0.3);  // one setting, both limits
  servo::loop_settings_table().set(s, "workspace", "-1,-1,0,1,1,2");
  EXPECT_TRUE(s.safety.workspace.contains(Eigen::Vector3d(0, 0, 1)));
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"max_linear_speed", "inf"}, {"max_linear_speed", "1e9"}, {"gain", "0"}, {"method", "nbv"},
           {"workspace", "1,1,1,0,0,0"}, {"workspace", "1,2,3"}, {"stale_timeout", "-1"}}) {
    try {
      servo::loop_settings_table().set(s, name, value);
      ADD_FAILURE() << name << "=" << value << " accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
}

// Frames with given timestamps (the problem comes from a Fixed observer).
class Timestamps : public FrameSource {
 public:
  explicit Timestamps(std::deque<double> t) : t_(std::move(t)) {}
  std::optional<RgbdFrame> next() override {
    if (t_.empty()) return std::nullopt;
    RgbdFrame f;
    f.timestamp = t_.front();
    t_.pop_front();
    return f;
  }
  [[nodiscard]] std::string describe() const override { return "timestamps"; }

 private:
  std::deque<double> t_;
};

TEST(RobotLoop, AGapInTheRecordingIsStaleAndTheRobotIsLeftAtRest) {
  Timestamps source({0.0, 1.0 / 30, 2.0 / 30, 5.0, 5.0 + 1.0 / 30});
  servo::FreeFlyingCamera robot{vpHomogeneousMatrix()};
  servo::RobotLoopOptions options;
  Fixed observer(patch(true));
  std::vector<servo::SafetyAction> actions;
  const servo::RobotLoopSummary summary = servo::run_on_robot(source, observer, robot, servo::LoopSettings{}, options, [&](const servo::RobotLoopFrame& f) {
    actions.push_back(f.step->safety);
    ASSERT_NE(f.observation, nullptr);
    EXPECT_DOUBLE_EQ(f.observation->age, f.frame_age);
  });
  EXPECT_EQ(summary.frames, 5);
  EXPECT_EQ(summary.lost, 0);
  ASSERT_EQ(actions.size(), 5U);
  EXPECT_FALSE(stops(actions[1]));
  EXPECT_EQ(actions[3], servo::SafetyAction::StaleFrame);  // 5 s after the previous frame
  EXPECT_FALSE(stops(actions[4]));
}

// RobotLoopOptions::pose_source: the observer and the loop get its pose,
// the frame keeps its own, and a frame whose pose it cannot tell stops the
// robot (and only that frame). It is told the object as the previous frame
// showed it, seen from the pose it gave (here its nearest depth).
TEST(RobotLoop, APoseSourceGivesThePoseAndAFrameWithoutOneStopsTheRobot) {
  Timestamps source({0.0, 1.0 / 30, 2.0 / 30, 3.0 / 30, 4.0 / 30});
  servo::FreeFlyingCamera robot{vpHomogeneousMatrix()};
  servo::RobotLoopOptions options;
  std::vector<std::optional<double>> depths;
  int calls = 0;
  options.pose_source = [&](const RgbdFrame& frame, const ObjectHint& object) {
    depths.push_back(object.nearest_depth());
    EXPECT_TRUE(frame.wMc.isApprox(Eigen::Isometry3d::Identity()));  // the frame's own
    FramePose pose;
    pose.wMc = Eigen::Translation3d(0.0, 0.0, 0.01 * std::min(calls, 2)) * Eigen::Isometry3d::Identity();
    pose.ok = calls != 3;
    pose.status = pose.ok ? "ok" : "failed";
    ++calls;
    return pose;
  };
  Fixed observer(patch(true));
  std::vector<servo::SafetyAction> actions;
  std::vector<double> speeds;
  const servo::RobotLoopSummary summary =
      servo::run_on_robot(source, observer, robot, servo::LoopSettings{}, options, [&](const servo::RobotLoopFrame& f) {
        actions.push_back(f.step->safety);
        speeds.push_back(speed(f.step->velocity));
        ASSERT_NE(f.pose, nullptr);
        EXPECT_EQ(f.pose->status, f.index == 3 ? "failed" : "ok");
        EXPECT_TRUE(f.frame->wMc.isApprox(Eigen::Isometry3d::Identity()));
        EXPECT_DOUBLE_EQ(f.observation->wMc.translation().z(), 0.01 * std::min<long>(f.index, 2));
        EXPECT_EQ(f.observation->pose, f.index == 3 ? PoseStatus::Unknown : PoseStatus::Known);
      });
  EXPECT_EQ(summary.frames, 5);
  EXPECT_EQ(summary.pose_unknown, 1);
  ASSERT_EQ(actions.size(), 5U);
  EXPECT_EQ(actions[3], servo::SafetyAction::PoseUnknown);
  EXPECT_EQ(speeds[3], 0.0);
  EXPECT_GT(speeds[2], 0.0);
  EXPECT_FALSE(stops(actions[4]));
  // The patch is 0.5 m ahead of the world origin: 0.5 - z of the pose used.
  ASSERT_EQ(depths.size(), 5U);
  EXPECT_FALSE(depths[0]);
  ASSERT_TRUE(depths[1] && depths[2]);
  EXPECT_NEAR(*depths[1], 0.5, 1e-12);
  EXPECT_NEAR(*depths[2], 0.49, 1e-12);
}

TEST(RobotLoop, TheStopFlagEndsTheRunAndMaxDurationTheSource) {
  volatile std::sig_atomic_t stop = 1;
  Timestamps source({0.0, 0.1, 0.2});
  servo::FreeFlyingCamera robot{vpHomogeneousMatrix()};
  servo::RobotLoopOptions options;
  Fixed observer(patch(false));
  options.stop = &stop;
  servo::RobotLoopSummary summary = servo::run_on_robot(source, observer, robot, servo::LoopSettings{}, options);
  EXPECT_EQ(summary.frames, 0);
  EXPECT_TRUE(summary.stopped);
  stop = 0;
  options.max_duration = 0.15;
  summary = servo::run_on_robot(source, observer, robot, servo::LoopSettings{}, options);
  EXPECT_EQ(summary.frames, 2);  // 0 and 0.1 s; the frame at 0.2 s is past the duration
  EXPECT_FALSE(summary.stopped);
}

// A source that serves `before` frames at 30 Hz, then blocks `gap` s (a
// stalled sensor; infinity: until release()), then serves `after` frames.
class Stalling : public FrameSource {
 public:
  Stalling(int before, double gap, int after) : before_(before), after_(after), gap_(gap) {}
  std::optional<RgbdFrame> next() override {
    if (served_ == before_) {
      std::unique_lock<std::mutex> lock(mutex_);
      if (std::isinf(gap_)) {
        released_.wait(lock, [&] { return release_; });
      } else {
        released_.wait_for(lock, std::chrono::duration<double>(gap_), [&] { return release_; });
      }
      if (release_) return std::nullopt;
    }
    if (served_ >= before_ + after_) return std::nullopt;
    RgbdFrame f;
    f.timestamp = served_++ / 30.0;
    return f;
  }
  void release() {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      release_ = true;
    }
    released_.notify_all();
  }
  [[nodiscard]] std::string describe() const override { return "stalling"; }

 private:
  int before_, after_, served_ = 0;
  double gap_;
  std::mutex mutex_;
  std::condition_variable released_;
  bool release_ = false;
};

// A free-flying camera that records when each command came and how fast it
// was, and blocks `block` s in its `block_at`-th command (a stuck driver).
class Recording : public servo::CameraRobot {
 public:
  explicit Recording(int block_at = -1, double block = 0.0) : block_at_(block_at), block_(block) {}
  [[nodiscard]] vpHomogeneousMatrix wMc() const override { return camera_.wMc(); }
  servo::RobotStep step(const vpColVector& v, double dt) override {
    if (calls_++ == block_at_) std::this_thread::sleep_for(std::chrono::duration<double>(block_));
    const std::lock_guard<std::mutex> lock(mutex_);
    log_.emplace_back(std::chrono::steady_clock::now(), speed(v));
    return camera_.step(v, dt);
  }
  [[nodiscard]] std::string name() const override { return "recording"; }
  [[nodiscard]] std::vector<std::pair<std::chrono::steady_clock::time_point, double>> log() {
    const std::lock_guard<std::mutex> lock(mutex_);
    return log_;
  }

 private:
  servo::FreeFlyingCamera camera_{vpHomogeneousMatrix()};
  int calls_ = 0, block_at_;
  double block_;
  std::mutex mutex_;
  std::vector<std::pair<std::chrono::steady_clock::time_point, double>> log_;
};

servo::LoopSettings watched_settings() {
  servo::LoopSettings s;
  s.safety.stale_timeout = 0.2;
  return s;
}

TEST(RobotLoop, TheWatchdogStopsTheRobotWhileTheSourceStallsAndTheLoopResumesAfter) {
  // 10 frames moving the camera, 0.6 s without a frame, 10 more.
  Stalling source(10, 0.6, 10);
  Recording robot;
  Fixed observer(patch(true));
  servo::RobotLoopOptions options;
  options.wall_clock_age = true;
  const servo::RobotLoopSummary summary = servo::run_on_robot(source, observer, robot, watched_settings(), options);
  EXPECT_EQ(summary.frames, 20);
  EXPECT_EQ(summary.watchdog_stops, 1);
  const auto log = robot.log();
  ASSERT_GT(log.size(), 21U);
  // The 11th call is the watchdog's: zero, stale_timeout (to 0.1 s) after the 10th.
  EXPECT_GT(log[9].second, 0.0);
  EXPECT_EQ(log[10].second, 0.0);
  const double after = std::chrono::duration<double>(log[10].first - log[9].first).count();
  EXPECT_GE(after, 0.2);
  EXPECT_LT(after, 0.35);
  EXPECT_GT(log[12].second, 0.0);  // the loop commands again with the frames
  EXPECT_EQ(log.back().second, 0.0);  // and leaves the robot at rest
}

TEST(RobotLoop, TheWatchdogStopsTheRobotWhenTheSourceBlocksForever) {
  Stalling source(10, std::numeric_limits<double>::infinity(), 0);
  Recording robot;
  Fixed observer(patch(true));
  std::thread run([&] { (void)servo::run_on_robot(source, observer, robot, watched_settings(), servo::RobotLoopOptions{}); });
  std::this_thread::sleep_for(std::chrono::milliseconds(600));
  const auto log = robot.log();  // while the source still blocks
  source.release();  // as a signal would end a blocking read
  run.join();
  ASSERT_EQ(log.size(), 11U);
  EXPECT_GT(log[9].second, 0.0);
  EXPECT_EQ(log[10].second, 0.0);
}

TEST(RobotLoop, ADriverStuckInACommandEndsTheRunWithTheRobotAtRest) {
  Stalling source(30, 0.0, 0);
  Recording robot(/*block_at=*/5, /*block=*/0.5);
  Fixed observer(patch(true));
  try {
    (void)servo::run_on_robot(source, observer, robot, watched_settings(), servo::RobotLoopOptions{});
    ADD_FAILURE() << "a driver stuck for 0.5 s went unnoticed";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("recording: a command took longer than its period plus stale_timeout"), std::string::npos)
        << e.what();
  }
  const auto log = robot.log();
  ASSERT_EQ(log.size(), 7U);  // 6 commands, then the stop
  EXPECT_EQ(log.back().second, 0.0);
}

}  // namespace
}  // namespace ofv
