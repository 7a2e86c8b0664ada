// The loop's world model: occluder tracks and their history.
#include "world_model.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <set>

namespace ofv::servo {

const std::vector<OccluderTrack>& WorldModel::update(const Eigen::Matrix3Xd* seen, double dt) {
  const bool timed = std::isfinite(dt) && dt > 0.0;
  if (!timed) {  // no time base: start the tracks again
    tracker_.reset();
    history_.clear();
  }
  if (seen) {
    (void)tracker_.update(*seen, dt);
  } else {
    (void)tracker_.coast(dt);
  }
  remember(timed ? dt : 0.0);
  return tracker_.tracks();
}

void WorldModel::reset() {
  tracker_.reset();
  history_.clear();
}

void WorldModel::remember(double dt) {
  std::map<int, History> history;
  for (const OccluderTrack& t : tracker_.tracks()) {
    const auto known = history_.find(t.id);
    History h{t.position};
    if (known != history_.end()) {
      h = known->second;
      h.age += dt;
    }
    h.arrived = h.arrived || (h.age <= arrival_ && is_moving(t, min_speed_));
    history.emplace(t.id, h);
  }
  history_ = std::move(history);
}

TrackPositions WorldModel::positions() const {
  TrackPositions out;
  for (const OccluderTrack& t : tracker_.tracks()) out.emplace_back(t.id, t.position);
  return out;
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

Eigen::Matrix3Xd WorldModel::revealed_still(const TrackPositions& then) const {
  std::vector<OccluderTrack> still;
  for (const OccluderTrack& t : tracker_.tracks()) {
    if (!is_still(t, min_speed_)) continue;
    const History& history = history_.at(t.id);
    const auto was = std::find_if(then.begin(), then.end(), [&](const auto& p) { return p.first == t.id; });
    const Eigen::Vector3d& since = was != then.end() ? was->second : history.first_position;
    if (!history.arrived && (t.position - since).norm() <= moved_) still.push_back(t);
  }
  return still_occluders(still, min_speed_);
}

Eigen::Matrix3Xd WorldModel::without_moving(const Eigen::Matrix3Xd& seen) const {
  // A track's points are copies of the frame's: found by their exact coordinates.
  const auto key = [](const Eigen::Vector3d& p) { return std::array<double, 3>{p.x(), p.y(), p.z()}; };
  std::set<std::array<double, 3>> moving;
  for (const OccluderTrack& t : tracker_.tracks()) {
    if (!is_moving(t, min_speed_)) continue;
    for (Eigen::Index i = 0; i < t.points.cols(); ++i) moving.insert(key(t.points.col(i)));
  }
  if (moving.empty()) return seen;
  std::vector<Eigen::Index> kept;
  for (Eigen::Index i = 0; i < seen.cols(); ++i) {
    if (moving.count(key(seen.col(i))) == 0) kept.push_back(i);
  }
  return seen(Eigen::all, kept);
}

}  // namespace ofv::servo
