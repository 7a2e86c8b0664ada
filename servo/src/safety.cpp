// Safety filter for real robots.
#include "ofv/servo/safety.h"

#include "ofv/servo/controller.h"
#include "ofv/servo/target_pose.h"

#include <cmath>

namespace ofv {

SafetyFilter::SafetyFilter(const SafetySettings& settings) : settings_(settings) {}

vpColVector SafetyFilter::filter(const vpColVector& v_in, const vpHomogeneousMatrix& wMc, double dt,
                                 bool object_tracked, double frame_age) {
  // Conditions that stop the robot at once (the drive's own deceleration applies).
  auto stop = [this](const char* why) {
    reason_ = why;
    previous_ = vpColVector(6, 0.0);
    return previous_;
  };
  bool finite = v_in.size() == 6 && std::isfinite(dt) && dt > 0.0;
  for (unsigned i = 0; finite && i < 6; ++i) finite = std::isfinite(v_in[i]);
  if (!finite) return stop("invalid command");
  if (!object_tracked) return stop("object lost");
  if (!(frame_age <= settings_.stale_timeout)) return stop("stale frame");

  reason_ = "";
  vpColVector v = saturate(v_in, settings_.max_linear_speed, settings_.max_angular_speed);
  if (v != v_in) reason_ = "speed limit";
  // Acceleration: the change from the previous command, per part.
  const vpColVector dv = v - previous_;
  const vpColVector limited = saturate(dv, settings_.max_linear_accel * dt, settings_.max_angular_accel * dt);
  if (limited != dv) {
    v = previous_ + limited;
    reason_ = "acceleration limit";
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
      reason_ = "workspace bound";
    }
  }
  previous_ = v;
  return v;
}

}  // namespace ofv
