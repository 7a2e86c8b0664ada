// Robots: free-flying camera, kinematic Viper850/Afma6, any vpRobot.
#include "ofv/servo/robot.h"

#include "ofv/servo/target_pose.h"
#include "ofv/settings_table.h"

#include <visp3/core/vpPoseVector.h>
#include <visp3/core/vpTime.h>
#include <visp3/core/vpVelocityTwistMatrix.h>
#include <visp3/robot/vpAfma6.h>
#include <visp3/robot/vpRobot.h>
#include <visp3/robot/vpViper850.h>

#if defined(VISP_HAVE_MODULE_GUI) && defined(VISP_HAVE_PTHREAD)
#include <visp3/robot/vpSimulatorAfma6.h>
#include <visp3/robot/vpSimulatorViper850.h>
#define OFV_HAVE_THREADED_SIMULATORS
#endif

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <iostream>
#include <cmath>
#include <stdexcept>

namespace ofv::servo {

namespace {

constexpr double kDamping = 0.02;       // damped least squares (units of the Jacobian)
constexpr double kMaxJointSpeed = 2.5;  // [rad/s or m/s] per joint

bool usable(const vpColVector& v, double dt) {
  if (v.size() != 6 || !std::isfinite(dt) || dt < 0.0) return false;
  for (unsigned i = 0; i < 6; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

// Joint velocities for the camera twist v by damped least squares on the
// camera-frame Jacobian cJ: near a singularity the pseudo-inverse would ask
// for unbounded joint speeds.
vpColVector damped_joint_velocity(const vpMatrix& cJ, const vpColVector& v) {
  vpMatrix JJt = cJ * cJ.t();
  for (unsigned i = 0; i < 6; ++i) JJt[i][i] += kDamping * kDamping;
  return cJ.t() * (JJt.inverseByLU() * v);
}

}  // namespace

FreeFlyingCamera::FreeFlyingCamera(const vpHomogeneousMatrix& wMc) {
  camera_.setMaxTranslationVelocity(1e6);  // ViSP's defaults (0.2 m/s, 0.7 rad/s) would clip the command
  camera_.setMaxRotationVelocity(1e6);
  camera_.setPosition(wMc);
  camera_.setRobotState(vpRobot::STATE_VELOCITY_CONTROL);
}

RobotStep FreeFlyingCamera::step(const vpColVector& v, double dt) {
  if (usable(v, dt) && dt > 0.0) {
    camera_.setSamplingTime(dt);
    camera_.setVelocity(vpRobot::CAMERA_FRAME, v);
  }
  return {wMc(), false};
}

// The two ViSP models share get_fMc, get_eJe, get_cVe and the joint limits.
struct KinematicArm::Impl {
  Model model;
  vpViper850 viper;
  vpAfma6 afma;
  [[nodiscard]] vpHomogeneousMatrix fMc(const vpColVector& q) const {
    vpHomogeneousMatrix m;
    if (model == Model::Viper850) {
      viper.get_fMc(q, m);
    } else {
      afma.get_fMc(q, m);
    }
    return m;
  }
  [[nodiscard]] vpMatrix cJ(const vpColVector& q) const {  // camera-frame Jacobian cVe eJe
    vpMatrix eJe;
    vpVelocityTwistMatrix cVe;
    if (model == Model::Viper850) {
      viper.get_eJe(q, eJe);
      viper.get_cVe(cVe);
    } else {
      afma.get_eJe(q, eJe);
      afma.get_cVe(cVe);
    }
    return cVe * eJe;
  }
  [[nodiscard]] vpColVector qmin() const { return model == Model::Viper850 ? viper.getJointMin() : afma.getJointMin(); }
  [[nodiscard]] vpColVector qmax() const { return model == Model::Viper850 ? viper.getJointMax() : afma.getJointMax(); }
};

vpColVector KinematicArm::start_joints(Model model) {
  vpColVector q(6, 0.0);
  if (model == Model::Viper850) {
    q[1] = -1.2;
    q[2] = 2.6;
    q[4] = -1.4;
  } else {
    q[4] = 0.4;
  }
  return q;
}

KinematicArm::KinematicArm(Model model, const vpHomogeneousMatrix& wMc_start) : impl_(std::make_unique<Impl>()) {
  impl_->model = model;
  q_ = start_joints(model);
  // Place the base so that this configuration puts the camera at wMc_start.
  wMf_ = wMc_start * impl_->fMc(q_).inverse();
}

KinematicArm::~KinematicArm() = default;

vpHomogeneousMatrix KinematicArm::wMc() const { return wMf_ * impl_->fMc(q_); }

std::string KinematicArm::name() const { return impl_->model == Model::Viper850 ? "viper850" : "afma6"; }

vpColVector KinematicArm::joint_min() const { return impl_->qmin(); }
vpColVector KinematicArm::joint_max() const { return impl_->qmax(); }

void KinematicArm::set_joints(const vpColVector& q) {
  const vpColVector lo = joint_min(), hi = joint_max();
  for (unsigned i = 0; i < 6; ++i) q_[i] = std::min(std::max(q[i], lo[i]), hi[i]);
}

RobotStep KinematicArm::step(const vpColVector& v, double dt) {
  RobotStep r;
  if (usable(v, dt)) {
    const vpColVector qdot = damped_joint_velocity(impl_->cJ(q_), v);
    const vpColVector lo = joint_min(), hi = joint_max();
    // The whole step shortened so that no joint exceeds its speed or passes
    // its limit: the camera keeps the commanded direction (clamping joints one
    // by one would turn it) and slows down or stops.
    double scale = 1.0;
    for (unsigned i = 0; i < 6; ++i) {
      if (std::abs(qdot[i]) > kMaxJointSpeed) scale = std::min(scale, kMaxJointSpeed / std::abs(qdot[i]));
    }
    for (unsigned i = 0; i < 6; ++i) {
      const double dq = qdot[i] * dt;
      const double room = dq > 0.0 ? hi[i] - q_[i] : lo[i] - q_[i];
      if (dq != 0.0 && std::abs(dq) > std::abs(room)) scale = std::min(scale, std::max(0.0, room / dq));
    }
    r.limited = scale < 1.0;
    for (unsigned i = 0; i < 6; ++i) q_[i] = std::min(std::max(q_[i] + scale * qdot[i] * dt, lo[i]), hi[i]);
  }
  r.wMc = wMc();
  return r;
}

VispRobot::VispRobot(vpRobot& robot, PoseReader fMc, const vpHomogeneousMatrix& fMw, std::string name,
                     Command command)
    : robot_(robot), fMc_(std::move(fMc)), command_(std::move(command)), wMf_(fMw.inverse()), name_(std::move(name)) {
  if (!command_) command_ = [&robot](const vpColVector& v) { robot.setVelocity(vpRobot::CAMERA_FRAME, v); };
  robot_.setRobotState(vpRobot::STATE_VELOCITY_CONTROL);
}

vpHomogeneousMatrix VispRobot::wMc() const {
  const vpHomogeneousMatrix fMc = fMc_();
  if (!to_eigen(fMc).matrix().allFinite()) {
    throw std::runtime_error(name_ + ": the driver reported a camera pose that is not finite");
  }
  return wMf_ * fMc;
}

RobotStep VispRobot::step(const vpColVector& v, double dt) {
  command_(usable(v, dt) ? v : vpColVector(6, 0.0));
  // Keep the cadence: this period ends one dt after the previous one did;
  // after an overrun, at once.
  const double now = vpTime::measureTimeMs();
  next_ms_ = std::max(now, (next_ms_ < 0.0 ? now : next_ms_) + 1000.0 * dt);
  vpTime::wait(next_ms_ - now);
  return {wMc(), false};
}

void VispRobot::stop() { command_(vpColVector(6, 0.0)); }

#if defined(OFV_HAVE_THREADED_SIMULATORS)
namespace {
// A threaded simulator whose joints can be set at once (the public
// setPosition() moves there in wall-clock time).
template <class Simulator>
struct Placed : Simulator {
  Placed() : Simulator(false) {}
  void place(const vpColVector& q) {
    this->set_artCoord(q);
    this->compute_fMi();
  }
};
}  // namespace

// ViSP's simulators print their set-up (arm files, camera parameters, the
// control mode) on stdout, which `ofv run --dry-run` keeps for its JSON lines:
// stdout goes to /dev/null while they are set up.
class QuietStdout {
 public:
  QuietStdout() {
    std::cout.flush();
    std::fflush(stdout);
    saved_ = ::dup(STDOUT_FILENO);
    const int null = ::open("/dev/null", O_WRONLY);
    if (saved_ >= 0 && null >= 0) ::dup2(null, STDOUT_FILENO);
    if (null >= 0) ::close(null);
  }
  ~QuietStdout() {
    std::cout.flush();
    std::fflush(stdout);
    if (saved_ >= 0) {
      ::dup2(saved_, STDOUT_FILENO);
      ::close(saved_);
    }
  }
  QuietStdout(const QuietStdout&) = delete;
  QuietStdout& operator=(const QuietStdout&) = delete;

 private:
  int saved_ = -1;
};

struct ThreadedArm::Impl {
  std::unique_ptr<vpRobot> simulator;
  std::unique_ptr<VispRobot> robot;
  std::string name;
  std::function<vpColVector()> joints;
  vpColVector lo, hi;  // the simulator's joint limits
};

namespace {

// How long [s] a joint heading for its limit may keep its speed: it slows
// down as it nears the margin, so that a loop that stalls for less than this
// does not carry it onto the limit (the simulator integrates in wall-clock
// time).
constexpr double kLimitBrakeTime = 0.25;

// The factor (at most 1) ThreadedArm scales the camera twist v by at joints
// q: so that no joint, its velocity estimated by damped least squares on
// cJ, heads for its limit faster than it can brake before
// ThreadedArm::kJointLimitMargin.
double limit_scale(const vpMatrix& cJ, const vpColVector& v, const vpColVector& q, const vpColVector& lo,
                   const vpColVector& hi) {
  const vpColVector qdot = damped_joint_velocity(cJ, v);
  double scale = 1.0;
  for (unsigned i = 0; i < 6; ++i) {
    const double room = (qdot[i] > 0.0 ? hi[i] - q[i] : q[i] - lo[i]) - ThreadedArm::kJointLimitMargin;
    const double allowed = std::max(0.0, room) / kLimitBrakeTime;
    if (std::abs(qdot[i]) > allowed) scale = std::min(scale, allowed / std::abs(qdot[i]));
  }
  return scale;
}

}  // namespace

ThreadedArm::ThreadedArm(KinematicArm::Model model, const vpHomogeneousMatrix& wMc_start)
    : impl_(std::make_unique<Impl>()) {
  // The simulator, headless, started in KinematicArm's start configuration.
  const QuietStdout quiet;
  const vpColVector q0 = KinematicArm::start_joints(model);
  auto make = [&](auto simulator, const char* name) {
    simulator->place(q0);
    simulator->setRobotState(vpRobot::STATE_VELOCITY_CONTROL);
    simulator->setMaxTranslationVelocity(2.0);  // [m/s]; the controller's limits bind first
    simulator->setMaxRotationVelocity(4.0);     // [rad/s]
    vpPoseVector p;
    simulator->getPosition(vpRobot::REFERENCE_FRAME, p);
    const vpHomogeneousMatrix fMw = vpHomogeneousMatrix(p) * wMc_start.inverse();
    auto* sim = simulator.get();
    impl_->joints = [sim] {
      vpColVector q;
      sim->getPosition(vpRobot::ARTICULAR_FRAME, q);
      return q;
    };
    impl_->lo = sim->getJointMin();
    impl_->hi = sim->getJointMax();
    auto command = [sim, joints = impl_->joints, lo = impl_->lo, hi = impl_->hi](const vpColVector& v) {
      // The simulator's own Jacobian at its current joints.
      vpMatrix eJe;
      vpVelocityTwistMatrix cVe;
      sim->get_eJe(eJe);
      sim->get_cVe(cVe);
      sim->setVelocity(vpRobot::CAMERA_FRAME, limit_scale(cVe * eJe, v, joints(), lo, hi) * v);
    };
    impl_->robot = std::make_unique<VispRobot>(*simulator, fMw, name, command);
    impl_->simulator = std::move(simulator);
    impl_->name = name;
  };
  if (model == KinematicArm::Model::Viper850) {
    make(std::make_unique<Placed<vpSimulatorViper850>>(), "viper850-threaded");
  } else {
    make(std::make_unique<Placed<vpSimulatorAfma6>>(), "afma6-threaded");
  }
}

ThreadedArm::~ThreadedArm() {
  if (impl_ && impl_->robot) impl_->robot->stop();
}
vpHomogeneousMatrix ThreadedArm::wMc() const { return impl_->robot->wMc(); }
RobotStep ThreadedArm::step(const vpColVector& v, double dt) { return impl_->robot->step(v, dt); }
std::string ThreadedArm::name() const { return impl_->name; }
vpColVector ThreadedArm::joints() const { return impl_->joints(); }
vpColVector ThreadedArm::joint_min() const { return impl_->lo; }
vpColVector ThreadedArm::joint_max() const { return impl_->hi; }
#else
struct ThreadedArm::Impl {};
ThreadedArm::ThreadedArm(KinematicArm::Model, const vpHomogeneousMatrix&) {
  throw std::runtime_error("this ViSP has no threaded robot simulators (needs its gui module and pthreads)");
}
ThreadedArm::~ThreadedArm() = default;
vpHomogeneousMatrix ThreadedArm::wMc() const { return {}; }
RobotStep ThreadedArm::step(const vpColVector&, double) { return {}; }
std::string ThreadedArm::name() const { return {}; }
vpColVector ThreadedArm::joints() const { return {}; }
vpColVector ThreadedArm::joint_min() const { return {}; }
vpColVector ThreadedArm::joint_max() const { return {}; }
#endif

const char* to_string(RobotKind kind) {
  switch (kind) {
    case RobotKind::Camera: return "camera";
    case RobotKind::Viper850: return "viper850";
    case RobotKind::Afma6: return "afma6";
  }
  return "?";
}

RobotKind parse_robot_kind(const std::string& word) {
  return parse_word<RobotKind>("robot", word,
                               {{"camera", RobotKind::Camera}, {"viper850", RobotKind::Viper850}, {"afma6", RobotKind::Afma6}});
}

std::unique_ptr<CameraRobot> make_robot(RobotKind kind, const vpHomogeneousMatrix& wMc_start, bool real_time) {
  if (kind == RobotKind::Camera) {
    if (real_time) throw std::invalid_argument("robot 'camera' has no real-time simulator (use viper850 or afma6)");
    return std::make_unique<FreeFlyingCamera>(wMc_start);
  }
  const auto model = kind == RobotKind::Viper850 ? KinematicArm::Model::Viper850 : KinematicArm::Model::Afma6;
  if (real_time) return std::make_unique<ThreadedArm>(model, wMc_start);
  return std::make_unique<KinematicArm>(model, wMc_start);
}

}  // namespace ofv::servo
