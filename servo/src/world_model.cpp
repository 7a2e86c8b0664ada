// The loop's world model: the occluder tracks.
#include "world_model.h"

#include <cmath>

namespace ofv::servo {

const std::vector<OccluderTrack>& WorldModel::update(const Eigen::Matrix3Xd* seen, double dt) {
  if (!(std::isfinite(dt) && dt > 0.0)) tracker_.reset();  // no time base: start the tracks again
  if (seen) {
    (void)tracker_.update(*seen, dt);
  } else {
    (void)tracker_.coast(dt);
  }
  return tracker_.tracks();
}

Eigen::Matrix3Xd WorldModel::predicted(double horizon, int samples, const Eigen::Vector3d& centroid,
                                       double r_sphere) const {
  std::vector<double> times;
  for (int k = 1; k <= samples; ++k) times.push_back(horizon * k / samples);
  const Eigen::Matrix3Xd all = predicted_occluders(tracker_.tracks(), times, min_speed_);
  // Only the copies inside the sphere are occluders (spec §3).
  std::vector<Eigen::Index> inside;
  for (Eigen::Index i = 0; i < all.cols(); ++i) {
    if ((all.col(i) - centroid).norm() < r_sphere) inside.push_back(i);
  }
  return all(Eigen::all, inside);
}

}  // namespace ofv::servo
