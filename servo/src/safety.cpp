// Safety filter for real robots.
#include "ofv/servo/safety.h"

#include "ofv/servo/target_pose.h"
#include "ofv/settings_table.h"

#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace ofv::servo {

const char* to_string(SafetyAction action) {
  switch (action) {
    case SafetyAction::None: return "";
    case SafetyAction::SpeedLimit: return "speed limit";
    case SafetyAction::AccelerationLimit: return "acceleration limit";
    case SafetyAction::WorkspaceBound: return "workspace bound";
    case SafetyAction::InvalidCommand: return "invalid command";
    case SafetyAction::ObjectLost: return "object lost";
    case SafetyAction::StaleFrame: return "stale frame";
    case SafetyAction::BadFrame: return "bad frame";
    case SafetyAction::PoseUnknown: return "pose unknown";
  }
  return "?";
}

bool stops(SafetyAction action) {
  return action == SafetyAction::InvalidCommand || action == SafetyAction::ObjectLost ||
         action == SafetyAction::StaleFrame || action == SafetyAction::BadFrame || action == SafetyAction::PoseUnknown;
}

void validate(const SafetySettings& s) {
  const std::pair<const char*, double> limits[] = {{"max_linear_speed", s.max_linear_speed},
                                                   {"max_angular_speed", s.max_angular_speed},
                                                   {"max_linear_accel", s.max_linear_accel},
                                                   {"max_angular_accel", s.max_angular_accel},
                                                   {"stale_timeout", s.stale_timeout}};
  for (const auto& [name, v] : limits) {
    if (!std::isfinite(v) || v <= 0.0) {
      throw std::invalid_argument(std::string("safety setting '") + name + "' must be finite and positive, got " +
                                  format_number(v));
    }
  }
}

SafetyFilter::SafetyFilter(const SafetySettings& settings) : settings_(settings) { validate(settings_); }

vpColVector SafetyFilter::filter(const vpColVector& v_in, const vpHomogeneousMatrix& wMc, double dt,
                                 bool object_tracked, double frame_age, bool pose_known) {
  // Conditions that stop the robot at once (the drive's own deceleration applies).
  auto stop = [this](SafetyAction why) {
    action_ = why;
    previous_ = vpColVector(6, 0.0);
    return previous_;
  };
  bool finite = v_in.size() == 6 && std::isfinite(dt) && dt > 0.0;
  for (unsigned i = 0; finite && i < 6; ++i) finite = std::isfinite(v_in[i]);
  if (!finite) return stop(SafetyAction::InvalidCommand);
  // Before the object: a way back (lost, driving to the best view seen) is
  // driven from the camera's pose, unknown here.
  if (!pose_known) return stop(SafetyAction::PoseUnknown);
  if (!object_tracked) return stop(SafetyAction::ObjectLost);
  if (!(frame_age <= settings_.stale_timeout)) return stop(SafetyAction::StaleFrame);

  action_ = SafetyAction::None;
  vpColVector v = saturate(v_in, settings_.max_linear_speed, settings_.max_angular_speed);
  if (v != v_in) action_ = SafetyAction::SpeedLimit;
  // Acceleration: the change from the previous command, scaled as a whole
  // until each part is within its limit (as the speed above).
  const vpColVector dv = v - previous_;
  const vpColVector limited = saturate(dv, settings_.max_linear_accel * dt, settings_.max_angular_accel * dt);
  if (limited != dv) {
    v = previous_ + limited;
    action_ = SafetyAction::AccelerationLimit;
  }
  // Workspace: drop the world-frame linear components that would leave the box.
  if (!settings_.workspace.isEmpty()) {
    const Eigen::Isometry3d m = to_eigen(wMc);
    Eigen::Vector3d vw = m.linear() * Eigen::Vector3d(v[0], v[1], v[2]);
    const Eigen::Vector3d next = m.translation() + vw * dt;
    bool clipped = false;
    for (int a = 0; a < 3; ++a) {
      if ((next[a] > settings_.workspace.max()[a] && vw[a] > 0.0) ||
          (next[a] < settings_.workspace.min()[a] && vw[a] < 0.0)) {
        vw[a] = 0.0;
        clipped = true;
      }
    }
    if (clipped) {
      const Eigen::Vector3d vc = m.linear().transpose() * vw;
      for (unsigned i = 0; i < 3; ++i) v[i] = vc[static_cast<int>(i)];
      action_ = SafetyAction::WorkspaceBound;
    }
  }
  previous_ = v;
  return v;
}

}  // namespace ofv::servo
