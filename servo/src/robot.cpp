// Robots: free-flying camera, kinematic Viper850/Afma6, any vpRobot.
#include "ofv/servo/robot.h"

#include <visp3/core/vpExponentialMap.h>
#include <visp3/core/vpPoseVector.h>
#include <visp3/core/vpTime.h>
#include <visp3/core/vpVelocityTwistMatrix.h>
#include <visp3/robot/vpAfma6.h>
#include <visp3/robot/vpRobot.h>
#include <visp3/robot/vpViper850.h>

#include <cmath>
#include <stdexcept>

namespace ofv {

namespace {

bool usable(const vpColVector& v, double dt) {
  if (v.size() != 6 || !std::isfinite(dt) || dt < 0.0) return false;
  for (unsigned i = 0; i < 6; ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

FreeFlyingCamera::FreeFlyingCamera(const vpHomogeneousMatrix& wMc) : wMc_(wMc) {}

RobotStep FreeFlyingCamera::step(const vpColVector& v, double dt) {
  if (usable(v, dt)) wMc_ = wMc_ * vpExponentialMap::direct(v, dt);
  return {wMc_, false};
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

KinematicArm::KinematicArm(Model model, const vpHomogeneousMatrix& wMc_start) : impl_(std::make_unique<Impl>()) {
  impl_->model = model;
  // A start configuration away from singularities and limits, camera forward.
  q_.resize(6, true);
  if (model == Model::Viper850) {
    q_[1] = -1.2;
    q_[2] = 2.6;
    q_[4] = -1.4;
  } else {
    q_[4] = 0.4;
  }
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
    const vpColVector qdot = impl_->cJ(q_).pseudoInverse() * v;
    const vpColVector lo = joint_min(), hi = joint_max();
    for (unsigned i = 0; i < 6; ++i) {
      const double q = q_[i] + qdot[i] * dt;
      if (q < lo[i] || q > hi[i]) r.limited = true;
      q_[i] = std::min(std::max(q, lo[i]), hi[i]);
    }
  }
  r.wMc = wMc();
  return r;
}

VispRobot::VispRobot(vpRobot& robot, const vpHomogeneousMatrix& fMw, std::string name)
    : robot_(robot), wMf_(fMw.inverse()), name_(std::move(name)) {
  robot_.setRobotState(vpRobot::STATE_VELOCITY_CONTROL);
}

vpHomogeneousMatrix VispRobot::wMc() const {
  vpColVector p;
  robot_.getPosition(vpRobot::REFERENCE_FRAME, p);
  return wMf_ * vpHomogeneousMatrix(vpPoseVector(p[0], p[1], p[2], p[3], p[4], p[5]));
}

RobotStep VispRobot::step(const vpColVector& v, double dt) {
  const double start = vpTime::measureTimeMs();
  robot_.setVelocity(vpRobot::CAMERA_FRAME, usable(v, dt) ? v : vpColVector(6, 0.0));
  vpTime::wait(start, 1000.0 * dt);
  return {wMc(), false};
}

void VispRobot::stop() { robot_.setVelocity(vpRobot::CAMERA_FRAME, vpColVector(6, 0.0)); }

std::unique_ptr<CameraRobot> make_robot(const std::string& name, const vpHomogeneousMatrix& wMc_start) {
  if (name == "camera") return std::make_unique<FreeFlyingCamera>(wMc_start);
  if (name == "viper850") return std::make_unique<KinematicArm>(KinematicArm::Model::Viper850, wMc_start);
  if (name == "afma6") return std::make_unique<KinematicArm>(KinematicArm::Model::Afma6, wMc_start);
  throw std::invalid_argument("unknown robot '" + name + "' (expected camera, viper850, afma6)");
}

}  // namespace ofv
