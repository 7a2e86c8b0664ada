// The loop's world model (internal to ofv::servo): the occluder tracks and
// what the loop keeps of each since it was first seen, updated once per frame.
#pragma once

#include "ofv/occluder_tracker.h"

#include <Eigen/Core>

#include <map>
#include <utility>
#include <vector>

namespace ofv::servo {

/// Each track's id and position at some frame.
using TrackPositions = std::vector<std::pair<int, Eigen::Vector3d>>;

class WorldModel {
 public:
  /// `min_speed`: tracks slower than this stand still (AnticipationSettings::min_speed);
  /// `arrival`, `moved`: RetreatSettings' (revealed_still()).
  WorldModel(const TrackerSettings& tracker, double min_speed, double arrival, double moved)
      : tracker_(tracker), min_speed_(min_speed), arrival_(arrival), moved_(moved) {}

  /// The frame's seen occluders (none: the object lost, the tracks coast).
  /// A period that is not finite and positive starts the tracks again.
  const std::vector<OccluderTrack>& update(const Eigen::Matrix3Xd* seen, double dt);
  void reset();

  [[nodiscard]] const std::vector<OccluderTrack>& tracks() const { return tracker_.tracks(); }
  [[nodiscard]] TrackPositions positions() const;
  /// Copies of the moving tracks' points where their velocity takes them
  /// after horizon x k / samples, k = 1..samples, kept inside the sphere.
  [[nodiscard]] Eigen::Matrix3Xd predicted(double horizon, int samples, const Eigen::Vector3d& centroid,
                                           double r_sphere) const;
  /// This frame's points of the tracks that stand still, did not come into
  /// view moving (within `arrival` of being first seen), and stood within
  /// `moved` of where they are when `then` was recorded (or, not tracked
  /// then, of where they were first seen): what the camera's own motion may
  /// have revealed since.
  [[nodiscard]] Eigen::Matrix3Xd revealed_still(const TrackPositions& then) const;
  /// The frame's seen occluders (those update() took) but the points of the
  /// tracks moving now (is_moving()): where they are says nothing of where
  /// they will be.
  [[nodiscard]] Eigen::Matrix3Xd without_moving(const Eigen::Matrix3Xd& seen) const;

 private:
  /// What the loop keeps of a track since it was first seen.
  struct History {
    Eigen::Vector3d first_position;
    double age = 0.0;      // time since first seen [s]
    bool arrived = false;  // it moved soon after it was first seen: it came into view moving
  };
  void remember(double dt);

  OccluderTracker tracker_;
  double min_speed_, arrival_, moved_;
  std::map<int, History> history_;  // of each current track, by id
};

}  // namespace ofv::servo
