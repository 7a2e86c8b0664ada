// The cone of sight from a point to a ball, shared inside ofv_sim by the
// renderer (whether a body may stand between a camera and the object) and
// the hindsight planner (whether a moving body may have changed a view).
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>

namespace ofv::sim::detail {

// Every segment from `apex` to a point of a ball lies in this cone (the
// apex outside the ball).
class SightCone {
 public:
  SightCone(const Eigen::Vector3d& apex, const Eigen::Vector3d& centre, double radius)
      : apex_(apex), axis_(centre - apex), length_(axis_.norm()), radius_(radius),
        half_angle_(std::asin(std::min(1.0, radius / length_))) {}

  // The distance from the apex to the ball's centre.
  [[nodiscard]] double length() const { return length_; }

  // Whether a ball may meet one of those segments: it holds the apex, or it
  // reaches into the cone and not only beyond the far side of the target.
  [[nodiscard]] bool may_meet(const Eigen::Vector3d& centre, double radius) const {
    const Eigen::Vector3d to = centre - apex_;
    const double dist = to.norm();
    if (dist <= radius) return true;
    if (dist - radius > length_ + radius_) return false;
    const double angle = std::acos(std::clamp(to.dot(axis_) / (dist * length_), -1.0, 1.0));
    return angle <= half_angle_ + std::asin(radius / dist);
  }

 private:
  Eigen::Vector3d apex_, axis_;
  double length_, radius_, half_angle_;
};

}  // namespace ofv::sim::detail
