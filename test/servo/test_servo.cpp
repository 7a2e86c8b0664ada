// The servo side: target pose, the sphere feature against finite differences,
// the controller in closed loop, robots, the safety filter.
#include "ofv/servo/controller.h"
#include "ofv/constants.h"
#include "ofv/servo/robot.h"
#include "ofv/servo/safety.h"
#include "ofv/servo/target_pose.h"
#include "ofv/servo/view_loop.h"

#include <gtest/gtest.h>

#include <limits>
#include <visp3/core/vpExponentialMap.h>
#include <visp3/robot/vpSimulatorCamera.h>

#include <chrono>
#include <random>
#include <type_traits>

namespace ofv {
namespace {


// A camera at position p looking at `at` (y roughly down).
vpHomogeneousMatrix looking_at(const Eigen::Vector3d& p, const Eigen::Vector3d& at) {
  const Eigen::Vector3d z = (at - p).normalized();
  Eigen::Vector3d y = Eigen::Vector3d(0, 1, 0) - z.y() * z;
  if (y.norm() < 1e-6) y = Eigen::Vector3d(1, 0, 0) - z.x() * z;
  y.normalize();
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() << y.cross(z), y, z;
  m.translation() = p;
  return servo::to_visp(m);
}

TEST(TargetPose, LooksAtTheCentroidWithTheLeastRotation) {
  const Eigen::Vector3d c(0.1, -0.2, 1.0), t(0.4, -0.1, 0.6);
  const vpHomogeneousMatrix wMc = looking_at({0, 0, 0}, c);
  const Eigen::Isometry3d wMcd = servo::to_eigen(servo::target_pose(t, c, wMc));
  EXPECT_TRUE(wMcd.translation().isApprox(t));
  EXPECT_TRUE(wMcd.linear().col(2).isApprox((c - t).normalized(), 1e-12));
  // The rotation between the two orientations is the angle between their Z axes.
  const Eigen::Matrix3d cRcd = servo::to_eigen(wMc).linear().transpose() * wMcd.linear();
  const double angle = Eigen::AngleAxisd(cRcd).angle();
  EXPECT_NEAR(angle, std::acos(servo::to_eigen(wMc).linear().col(2).dot(wMcd.linear().col(2))), 1e-9);
  // Already looking at C: the orientation is kept exactly.
  const vpHomogeneousMatrix same = servo::target_pose(Eigen::Vector3d(0, 0, 0), c, wMc);
  EXPECT_TRUE(servo::to_eigen(same).linear().isApprox(servo::to_eigen(wMc).linear(), 1e-12));
  EXPECT_THROW((void)servo::target_pose(c, c, wMc), std::invalid_argument);
}

// s after the camera moves by twist v for a time h.
vpColVector feature_after(const vpHomogeneousMatrix& wMc, const vpColVector& c, const vpColVector& t,
                          const vpColVector& v, double h) {
  servo::FeatureSphereView s;
  s.build((wMc * vpExponentialMap::direct(v, h)).inverse(), c, t, 0.5);
  return s.get_s();
}

TEST(FeatureSphereView, InteractionMatrixMatchesFiniteDifferences) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const vpColVector c{0.3 * u(rng), 0.3 * u(rng), 1.0 + 0.3 * u(rng)};
    const vpColVector t{u(rng), u(rng), u(rng)};
    const vpHomogeneousMatrix wMc = looking_at({0.1 * u(rng), 0.1 * u(rng), 0.1 * u(rng)},
                                               {c[0] + 0.05 * u(rng), c[1], c[2]});
    servo::FeatureSphereView s;
    s.build(wMc.inverse(), c, t, 0.5);
    const vpMatrix L = s.interaction();
    ASSERT_EQ(L.getRows(), 6U);
    for (int k = 0; k < 6; ++k) {
      vpColVector v(6);
      for (unsigned i = 0; i < 6; ++i) v[i] = u(rng);
      const double h = 1e-6;
      const vpColVector numeric = (feature_after(wMc, c, t, v, h) - feature_after(wMc, c, t, v, -h)) / (2 * h);
      const vpColVector analytic = L * v;
      for (unsigned i = 0; i < 6; ++i) EXPECT_NEAR(numeric[i], analytic[i], 1e-6) << "row " << i;
    }
  }
  // Selection keeps the chosen rows.
  servo::FeatureSphereView s;
  const vpHomogeneousMatrix wMc = looking_at({0, 0, 0}, {0, 0, 0.5});
  s.build(wMc.inverse(), vpColVector{0.0, 0.0, 0.5}, vpColVector{0.5, 0.0, 0.5}, 0.5);
  EXPECT_EQ(s.interaction(servo::FeatureSphereView::selectRho() | servo::FeatureSphereView::selectX()).getRows(), 2U);
  EXPECT_THROW(s.build(wMc.inverse(), vpColVector{0.0, 0.0, -0.5}, vpColVector{1.0, 0.0, 0.0}, 0.5),
               std::invalid_argument);
}

// Servo a free-flying camera from a view on the sphere towards a target view
// 90 degrees away; returns the largest |distance to C - R| and the smallest distance.
std::pair<double, double> servo_to(servo::ControllerSettings::Law law, double* final_error = nullptr) {
  const Eigen::Vector3d c(0, 0, 0.5), tf(0.5, 0, 0.5);
  const double r = 0.5;
  servo::ControllerSettings settings;
  settings.law = law;
  servo::ViewController controller(settings);
  servo::FreeFlyingCamera camera(looking_at({0, 0, 0}, c));
  double worst = 0.0, nearest = 1e9;
  for (int k = 0; k < 150; ++k) {
    const vpColVector v = controller.update(tf, c, r, camera.wMc(), 1.0 / 30);
    camera.step(v, 1.0 / 30);
    const double dist = (servo::to_eigen(camera.wMc()).translation() - c).norm();
    worst = std::max(worst, std::abs(dist - r));
    nearest = std::min(nearest, dist);
  }
  if (final_error) *final_error = (servo::to_eigen(camera.wMc()).translation() - tf).norm();
  return {worst, nearest};
}

TEST(ViewController, TheSphereLawTravelsAlongTheSphereWhilePbvsCutsTheChord) {
  double err_sphere = 0.0, err_pbvs = 0.0;
  const auto sphere = servo_to(servo::ControllerSettings::Law::Sphere, &err_sphere);
  const auto pbvs = servo_to(servo::ControllerSettings::Law::Pbvs, &err_pbvs);
  EXPECT_LT(sphere.first, 0.02);
  EXPECT_LT(pbvs.second, 0.5 - 0.1);  // the chord passes ~0.35 m from C
  EXPECT_LT(err_sphere, 0.005);       // both arrive
  EXPECT_LT(err_pbvs, 0.005);
}

TEST(ViewController, CommandsAreBoundedAndFinite) {
  servo::ControllerSettings s;
  s.gain = 1000.0;
  servo::ViewController controller(s);
  const vpHomogeneousMatrix wMc = looking_at({0, 0, 0}, {0, 0, 0.5});
  const vpColVector v = controller.update({0.5, 0, 0.5}, {0, 0, 0.5}, 0.5, wMc, 1.0 / 30);
  EXPECT_LE(std::hypot(v[0], v[1], v[2]), s.max_linear_speed + 1e-12);
  EXPECT_LE(std::hypot(v[3], v[4], v[5]), s.max_angular_speed + 1e-12);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(controller.update({nan, 0, 0}, {0, 0, 0.5}, 0.5, wMc, 0.03).frobeniusNorm(), 0.0);
  EXPECT_EQ(controller.update({0, 0, 0.5}, {0, 0, 0.5}, 0.5, wMc, 0.03).frobeniusNorm(), 0.0);
  servo::ControllerSettings bad;
  bad.max_linear_speed = -1;
  EXPECT_THROW(servo::ViewController{bad}, std::invalid_argument);
}

TEST(ViewController, ASaturatedCommandKeepsTheObjectCentred) {
  // A target view 150 degrees round the sphere asks for more than both
  // speed limits at once. The twist is scaled as a whole: the translation
  // and the rotation that keeps C centred while it moves stay in step. (Each
  // part saturated on its own, the camera looked 48 degrees off C.)
  const Eigen::Vector3d c(0, 0, 0.5);
  const double r = 0.5, a = 150.0 * kPi / 180.0;
  const Eigen::Vector3d tf = c + r * Eigen::Vector3d(std::sin(a), 0.0, -std::cos(a));
  servo::ControllerSettings settings;
  settings.gain = 4.0;
  servo::ViewController controller(settings);
  servo::FreeFlyingCamera camera(looking_at({0, 0, 0}, c));
  double worst = 0.0;
  for (int k = 0; k < 90; ++k) {
    const vpColVector v = controller.update(tf, c, r, camera.wMc(), 1.0 / 30);
    EXPECT_LE(std::hypot(v[0], v[1], v[2]), settings.max_linear_speed + 1e-12);
    EXPECT_LE(std::hypot(v[3], v[4], v[5]), settings.max_angular_speed + 1e-12);
    camera.step(v, 1.0 / 30);
    const Eigen::Isometry3d m = servo::to_eigen(camera.wMc());
    const Eigen::Vector3d axis = m.linear().col(2);
    worst = std::max(worst, std::acos(std::min(1.0, axis.dot((c - m.translation()).normalized()))));
  }
  EXPECT_LT(worst, 1.0 * kPi / 180.0);
  EXPECT_LT((servo::to_eigen(camera.wMc()).translation() - tf).norm(), 0.01);
}

TEST(Robots, FollowAConstantTwist) {
  const vpHomogeneousMatrix start = looking_at({0, 0, 0}, {0, 0, 0.5});
  const vpColVector v{0.05, -0.02, 0.03, 0.1, -0.05, 0.08};
  for (const servo::RobotKind kind : {servo::RobotKind::Camera, servo::RobotKind::Viper850, servo::RobotKind::Afma6}) {
    const std::string name = to_string(kind);
    EXPECT_EQ(servo::parse_robot_kind(name), kind);
    auto robot = servo::make_robot(kind, start);
    EXPECT_TRUE(servo::to_eigen(robot->wMc()).isApprox(servo::to_eigen(start), 1e-9)) << name;
    const double dt = 0.01;
    const servo::RobotStep step = robot->step(v, dt);
    const Eigen::Isometry3d expected = servo::to_eigen(start * vpExponentialMap::direct(v, dt));
    EXPECT_LT((servo::to_eigen(step.wMc).translation() - expected.translation()).norm(), 1e-5) << name;
    EXPECT_LT(Eigen::AngleAxisd(servo::to_eigen(step.wMc).linear().transpose() * expected.linear()).angle(), 1e-4) << name;
    EXPECT_FALSE(step.limited) << name;
  }
  EXPECT_THROW((void)servo::parse_robot_kind("puma560"), std::invalid_argument);
}

// ViSP's threaded simulator, driven in wall-clock time, against its
// kinematic twin: same start, same commands, same motion. A rotation-heavy
// twist, so that reading the pose in the wrong rotation convention would show.
TEST(Robots, ThreadedArmFollowsItsKinematicTwinInWallClockTime) {
  const vpHomogeneousMatrix start = looking_at({0.1, -0.05, 0}, {0, 0, 0.5});
  for (const auto model : {servo::KinematicArm::Model::Viper850, servo::KinematicArm::Model::Afma6}) {
    servo::ThreadedArm threaded(model, start);
    servo::KinematicArm twin(model, start);
    EXPECT_TRUE(servo::to_eigen(threaded.wMc()).isApprox(servo::to_eigen(start), 1e-6)) << threaded.name();
    const vpColVector v{0.04, 0.0, 0.02, 0.0, 0.3, 0.15};
    const double dt = 1.0 / 30.0;
    const auto t0 = std::chrono::steady_clock::now();
    for (int k = 0; k < 15; ++k) {
      (void)threaded.step(v, dt);
      (void)twin.step(v, dt);
    }
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_GE(elapsed, 15 * dt - 0.02) << "one period of wall-clock time per step";
    const Eigen::Isometry3d a = servo::to_eigen(threaded.wMc()), b = servo::to_eigen(twin.wMc());
    EXPECT_LT((a.translation() - b.translation()).norm(), 0.015) << threaded.name();
    EXPECT_LT(Eigen::AngleAxisd(a.linear().transpose() * b.linear()).angle(), 3.0 * kPi / 180.0) << threaded.name();
    EXPECT_GT(Eigen::AngleAxisd(servo::to_eigen(start).linear().transpose() * b.linear()).angle(), 5.0 * kPi / 180.0)
        << "the twin should have turned";
  }
  EXPECT_THROW((void)servo::make_robot(servo::RobotKind::Camera, start, /*real_time=*/true), std::invalid_argument);
}

// Driven into a joint limit and then held still, the threaded arm stops
// short of the limit and its pose stays finite: ViSP's simulators turn every
// joint into NaN when a joint standing on its limit gets no velocity.
TEST(Robots, ThreadedArmStopsShortOfItsJointLimits) {
  const vpHomogeneousMatrix start = looking_at({0.1, -0.05, 0}, {0, 0, 0.5});
  const double dt = 1.0 / 30.0;
  // Twists that bring the wrist (joint 5) onto its limit within a second,
  // sent for 40 frames.
  for (const auto& [model, v] : {std::pair{servo::KinematicArm::Model::Viper850, vpColVector{0, 0, -0.3, 0, 0, 0}},
                                 std::pair{servo::KinematicArm::Model::Afma6, vpColVector{0, 0, 0, -1.0, 0, 0}}}) {
    servo::ThreadedArm arm(model, start);
    const vpColVector lo = arm.joint_min(), hi = arm.joint_max();
    for (int k = 0; k < 45; ++k) {
      (void)arm.step(k < 40 ? v : vpColVector(6, 0.0), dt);
      const vpColVector q = arm.joints();
      for (unsigned i = 0; i < 6; ++i) {
        ASSERT_TRUE(std::isfinite(q[i])) << arm.name() << " step " << k;
        EXPECT_GE(q[i] - lo[i], 0.5 * servo::ThreadedArm::kJointLimitMargin) << arm.name() << " joint " << i << " step " << k;
        EXPECT_GE(hi[i] - q[i], 0.5 * servo::ThreadedArm::kJointLimitMargin) << arm.name() << " joint " << i << " step " << k;
      }
    }
    const vpColVector q = arm.joints();
    double nearest = 1e9;
    for (unsigned i = 0; i < 6; ++i) nearest = std::min({nearest, q[i] - lo[i], hi[i] - q[i]});
    EXPECT_LT(nearest, 0.1) << arm.name() << ": the twist should have brought a joint near its limit";
    EXPECT_TRUE(servo::to_eigen(arm.wMc()).matrix().allFinite()) << arm.name();
  }
}

TEST(Robots, JointLimitsClamp) {
  servo::KinematicArm arm(servo::KinematicArm::Model::Viper850, looking_at({0, 0, 0}, {0, 0, 0.5}));
  bool limited = false;
  for (int k = 0; k < 400 && !limited; ++k) limited = arm.step(vpColVector{0, 0, 0, 0, 0, 1.0}, 0.05).limited;
  EXPECT_TRUE(limited);
  const vpColVector q = arm.joints(), lo = arm.joint_min(), hi = arm.joint_max();
  for (unsigned i = 0; i < 6; ++i) {
    EXPECT_GE(q[i], lo[i]);
    EXPECT_LE(q[i], hi[i]);
  }
}

// At the wrist singularity of the Viper850 (q5 = 0) the pseudo-inverse asks
// for unbounded joint speeds; the arm must neither jump nor exceed the
// commanded camera speed.
TEST(Robots, ArmsStayBoundedAtASingularity) {
  servo::KinematicArm arm(servo::KinematicArm::Model::Viper850, looking_at({0, 0, 0}, {0, 0, 0.5}));
  vpColVector q = servo::KinematicArm::start_joints(servo::KinematicArm::Model::Viper850);
  q[4] = 1e-4;
  arm.set_joints(q);
  const vpColVector v{0.3, 0.2, 0.0, 0.5, 0.4, 0.0};
  const double dt = 1.0 / 30.0;
  for (int k = 0; k < 30; ++k) {
    const vpColVector before = arm.joints();
    const Eigen::Vector3d p0 = servo::to_eigen(arm.wMc()).translation();
    (void)arm.step(v, dt);
    EXPECT_LE((servo::to_eigen(arm.wMc()).translation() - p0).norm(), 1.05 * std::hypot(0.3, 0.2) * dt + 1e-3) << "step " << k;
    for (unsigned i = 0; i < 6; ++i) EXPECT_LE(std::abs(arm.joints()[i] - before[i]), 2.5 * dt + 1e-12) << "joint " << i;
  }
}

// A driver that reports a pose with NaN (ViSP's threaded Viper850 can, at its
// wrist singularity) ends the run with an error naming the robot: the
// pose must not reach the renderer or the controller.
TEST(Robots, ADriverPoseThatIsNotFiniteIsAnError) {
  vpSimulatorCamera driver;
  bool faulty = false;
  servo::VispRobot robot(
      driver,
      [&faulty] {
        vpHomogeneousMatrix fMc;
        if (faulty) fMc[1][3] = std::numeric_limits<double>::quiet_NaN();
        return fMc;
      },
      vpHomogeneousMatrix(), "test-arm");
  EXPECT_TRUE(servo::to_eigen(robot.wMc()).matrix().allFinite());
  faulty = true;
  try {
    (void)robot.wMc();
    ADD_FAILURE() << "no error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("test-arm"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("not finite"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)robot.step(vpColVector(6, 0.0), 0.0), std::runtime_error);
}

TEST(Safety, EachRule) {
  servo::SafetySettings s;
  s.workspace = Eigen::AlignedBox3d(Eigen::Vector3d(-1, -1, -1), Eigen::Vector3d(1, 1, 0.05));
  const vpHomogeneousMatrix wMc = looking_at({0, 0, 0}, {0, 0, 0.5});
  const vpColVector fast{1.0, 0, 0, 0, 0, 0};
  {
    servo::SafetyFilter f(s);
    EXPECT_EQ(f.filter(fast, wMc, 0.03, false, 0.0).frobeniusNorm(), 0.0);
    EXPECT_EQ(f.last_action(), servo::SafetyAction::ObjectLost);
    EXPECT_EQ(f.filter(fast, wMc, 0.03, true, 1.0).frobeniusNorm(), 0.0);
    EXPECT_EQ(f.last_action(), servo::SafetyAction::StaleFrame);
  }
  {
    servo::SafetyFilter f(s);  // from rest, the acceleration limit binds first
    const vpColVector v = f.filter(fast, wMc, 0.03, true, 0.0);
    EXPECT_NEAR(v[0], s.max_linear_accel * 0.03, 1e-12);
    for (int k = 0; k < 100; ++k) (void)f.filter(fast, wMc, 0.03, true, 0.0);
    EXPECT_NEAR(f.filter(fast, wMc, 0.03, true, 0.0)[0], s.max_linear_speed, 1e-12);
  }
  {
    servo::SafetyFilter f(s);  // forward (+z world) would leave the box at z = 0.05
    vpHomogeneousMatrix at_edge = wMc;
    at_edge[2][3] = 0.05;
    vpColVector forward(6, 0.0);
    forward[2] = 0.01;
    EXPECT_EQ(f.filter(forward, at_edge, 0.03, true, 0.0)[2], 0.0);
    EXPECT_EQ(f.last_action(), servo::SafetyAction::WorkspaceBound);
  }
  servo::SafetyFilter f(s);
  EXPECT_EQ(f.filter(vpColVector{std::nan(""), 0, 0, 0, 0, 0}, wMc, 0.03, true, 0.0).frobeniusNorm(), 0.0);
  EXPECT_EQ(f.last_action(), servo::SafetyAction::InvalidCommand);
  EXPECT_TRUE(stops(f.last_action()));
  servo::SafetySettings bad;
  bad.max_linear_accel = std::numeric_limits<double>::infinity();
  EXPECT_THROW(servo::SafetyFilter{bad}, std::invalid_argument);
}

// The names of ofv 0.1 (before ofv::servo) stay for one release as
// deprecated aliases of the same types and functions.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wdeprecated-declarations"
TEST(Namespaces, TheOldServoNamesAreTheNewOnes) {
  static_assert(std::is_same_v<ofv::ViewLoop, servo::ViewLoop>);
  static_assert(std::is_same_v<ofv::LoopSettings, servo::LoopSettings>);
  static_assert(std::is_same_v<ofv::CameraRobot, servo::CameraRobot>);
  static_assert(std::is_same_v<ofv::SafetyAction, servo::SafetyAction>);
  EXPECT_EQ(&ofv::loop_transitions(), &servo::loop_transitions());
  EXPECT_STREQ(ofv::to_string(ofv::RobotKind::Afma6), servo::to_string(servo::RobotKind::Afma6));
}
#pragma GCC diagnostic pop

}  // namespace
}  // namespace ofv
