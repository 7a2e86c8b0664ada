// The view controller: PBVS or the sphere feature, saturated.
#include "ofv/servo/controller.h"

#include "ofv/servo/target_pose.h"

#include <algorithm>
#include <visp3/visual_features/vpFeatureThetaU.h>
#include <visp3/visual_features/vpFeatureTranslation.h>
#include <visp3/vs/vpAdaptiveGain.h>
#include <visp3/vs/vpServo.h>

#include <cmath>
#include <stdexcept>
#include <string>

namespace ofv::servo {

namespace {

void require_positive(const char* name, double v) {
  if (!std::isfinite(v) || v <= 0.0) {
    throw std::invalid_argument(std::string("controller setting '") + name + "' must be finite and positive, got " + std::to_string(v));
  }
}

bool finite(const vpColVector& v) {
  for (unsigned i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) return false;
  }
  return true;
}

}  // namespace

void validate(const ControllerSettings& s) {
  require_positive("gain", s.gain);
  require_positive("max_linear_speed", s.max_linear_speed);
  require_positive("max_angular_speed", s.max_angular_speed);
  if (!std::isfinite(s.target_filter) || s.target_filter < 0.0) {
    throw std::invalid_argument("controller setting 'target_filter' must be >= 0, got " + std::to_string(s.target_filter));
  }
}

vpColVector saturate(const vpColVector& v, double max_linear, double max_angular) {
  vpColVector out = v;
  double lin = 0.0, ang = 0.0;
  for (unsigned i = 0; i < 3; ++i) {
    lin += v[i] * v[i];
    ang += v[i + 3] * v[i + 3];
  }
  lin = std::sqrt(lin);
  ang = std::sqrt(ang);
  const double k = std::min({1.0, lin > 0.0 ? max_linear / lin : 1.0, ang > 0.0 ? max_angular / ang : 1.0});
  if (k < 1.0) out *= k;
  return out;
}

struct ViewController::Task {
  vpServo servo;
  FeatureSphereView sphere, sphere_star;  // s* = 0
  vpFeatureTranslation translation{vpFeatureTranslation::cdMc};
  vpFeatureThetaU rotation{vpFeatureThetaU::cdRc};

  explicit Task(ControllerSettings::Law law) {
    servo.setServo(vpServo::EYEINHAND_CAMERA);
    servo.setInteractionMatrixType(vpServo::CURRENT);
    if (law == ControllerSettings::Law::Pbvs) {
      servo.addFeature(translation);
      servo.addFeature(rotation);
    } else {
      servo.addFeature(sphere, sphere_star);
    }
  }
};

ViewController::ViewController(const ControllerSettings& settings) : settings_(settings) {
  validate(settings_);
  task_ = std::make_unique<Task>(settings_.law);
}
ViewController::~ViewController() = default;
ViewController::ViewController(ViewController&&) noexcept = default;
ViewController& ViewController::operator=(ViewController&&) noexcept = default;

double ViewController::lambda(double error_norm) const {
  if (!settings_.adaptive_gain) return settings_.gain;
  const vpAdaptiveGain g(2.0 * settings_.gain, settings_.gain, 30.0);
  return g.value(error_norm);
}

vpColVector ViewController::update(const Eigen::Vector3d& tf, const Eigen::Vector3d& centroid, double r_sphere,
                                   const vpHomogeneousMatrix& wMc, double dt) {
  vpColVector zero(6, 0.0);
  if (!tf.allFinite() || !centroid.allFinite() || !(r_sphere > 0.0) || !std::isfinite(dt) || dt < 0.0 ||
      (tf - centroid).norm() < 1e-9) {
    return zero;
  }
  // Low-pass on the target, exact for a constant target over dt.
  Eigen::Vector3d target = tf;
  if (settings_.target_filter > 0.0 && filtered_) {
    const double a = 1.0 - std::exp(-dt / settings_.target_filter);
    target = *filtered_ + a * (tf - *filtered_);
  }
  filtered_ = target;

  vpColVector v(6, 0.0);
  if (settings_.law == ControllerSettings::Law::Pbvs) {
    const vpHomogeneousMatrix wMcd = target_pose(target, centroid, wMc);
    const vpHomogeneousMatrix cdMc = wMcd.inverse() * wMc;
    task_->translation.buildFrom(cdMc);
    task_->rotation.buildFrom(cdMc);
    vpColVector e(6);
    for (unsigned i = 0; i < 3; ++i) {
      e[i] = task_->translation[i];
      e[i + 3] = task_->rotation[i];
    }
    last_error_ = e.frobeniusNorm();
    task_->servo.setLambda(lambda(last_error_));
    v = task_->servo.computeControlLaw();
  } else {
    const Eigen::Isometry3d cMw = to_eigen(wMc).inverse();
    if ((cMw * centroid).z() <= 1e-6) return zero;  // the object is behind the camera: do not guess
    Eigen::Vector3d aim = target;
    const Eigen::Vector3d d_w = (to_eigen(wMc).translation() - centroid).normalized();
    if (d_w.dot((target - centroid).normalized()) < -1.0 + 1e-6) {
      // Antipodal target: every tangent direction is as short; lean towards the camera's x.
      aim += 1e-3 * (target - centroid).norm() * to_eigen(wMc).linear().col(0);
    }
    task_->sphere.build(to_visp(cMw), vpColVector{centroid.x(), centroid.y(), centroid.z()},
                        vpColVector{aim.x(), aim.y(), aim.z()}, r_sphere);
    last_error_ = task_->sphere.get_s().frobeniusNorm();
    task_->servo.setLambda(lambda(last_error_));
    v = task_->servo.computeControlLaw();
  }
  if (!finite(v)) return zero;
  return saturate(v, settings_.max_linear_speed, settings_.max_angular_speed);
}

}  // namespace ofv::servo
