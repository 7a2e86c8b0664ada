// The loop's world model (internal to ofv::servo): the occluder tracks,
// updated once per frame, and where the moving ones will be.
#pragma once

#include "ofv/occluder_tracker.h"

#include <Eigen/Core>

#include <vector>

namespace ofv::servo {

class WorldModel {
 public:
  /// `min_speed`: tracks slower than this stand still (AnticipationSettings::min_speed).
  WorldModel(const TrackerSettings& tracker, double min_speed) : tracker_(tracker), min_speed_(min_speed) {}

  /// The frame's seen occluders (none: the object lost, the tracks coast).
  /// A period that is not finite and positive starts the tracks again.
  const std::vector<OccluderTrack>& update(const Eigen::Matrix3Xd* seen, double dt);

  /// Copies of the moving tracks' points where their velocity takes them
  /// after horizon x k / samples, k = 1..samples, kept inside the sphere.
  [[nodiscard]] Eigen::Matrix3Xd predicted(double horizon, int samples, const Eigen::Vector3d& centroid,
                                           double r_sphere) const;

 private:
  OccluderTracker tracker_;
  double min_speed_;
};

}  // namespace ofv::servo
