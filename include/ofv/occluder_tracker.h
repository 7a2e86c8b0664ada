/**
 * \file occluder_tracker.h
 * \brief Occluders followed from frame to frame, with a velocity: the input
 *        of the loop's anticipation (see ofv::predicted_occluders).
 *
 * Each frame the occluder points (ViewProblem::occluders, from perception or
 * from the simulator's ground truth) are cut into clusters: single linkage,
 * two points in one cluster when a chain of points less than `link_distance`
 * apart joins them (a hand, an arm, a tool). A cluster of 30 points or
 * more that is mostly a wide plane (a table) is cut into the plane and what
 * lies more than 0.3 x `link_distance` off it (a hand seen only against
 * the table, an arm sweeping over it), since a wide plane's motion is
 * measured only along its normal (below): the plane is a least-squares
 * plane refitted three times to the points near the last one, and it must
 * hold 60 % of the points; parts of fewer than 3 points stay with it.
 * Each cluster's centroid is a measurement of one track. A cluster that
 * joins occluders followed apart until now (a hand reaching the table, two
 * hands touching) is cut back into them: each of its points goes to the
 * track whose prediction (last frame's points moved by the track's
 * velocity) is nearest, when at least two tracks each have 3 of the
 * cluster's points within `link_distance` of their prediction; each part
 * is that track's measurement.
 *
 * A track is a constant-velocity Kalman filter on its position: state
 * (position, velocity), white-noise acceleration of spectral density
 * `accel_noise`^2 (the discrete model of Bar-Shalom, "Estimation with
 * Applications to Tracking and Navigation", 6.2.2), position measurements
 * with standard deviation `measurement_noise`. The position measured is
 * the previous position moved by the translation that registers the
 * track's previous points onto the cluster's, not the cluster's centroid:
 * the centroid also moves when the visible part of an occluder changes (an
 * arm entering the sphere, the camera moving along a table), the
 * registered points do not. The registration (translation-only ICP) starts
 * from the predicted motion, from none and from the centroid's motion; the
 * best fit wins, and among fits equally good the smallest motion: what the
 * shape cannot show moving (a capsule along its axis, ends unseen) is taken
 * as still. A wide plane (a table) is measured along its normal only (the
 * aperture problem), and its velocity within itself is none, whatever the
 * track had before it was one; so is a piece of one (a cluster all of
 * whose points lie within 0.3 x `link_distance` of a wide plane of the
 * frame: a table seen in pieces past the object). When too few of the
 * cluster's points find the previous ones (the part seen grew), the
 * previous points are registered onto the cluster's; when neither
 * registers, the track starts again where the cluster is, with its id.
 * The three axes are independent with the same noises, so one 2 x 2
 * covariance (position, velocity of one axis) holds for all three.
 *
 * Association: every track's last centroid is moved by its velocity to
 * the frame's time; cluster and track pairs whose centroids are closer than
 * `gate` are joined greedily, nearest first. A cluster left over starts
 * a track (velocity 0, standard deviation `initial_speed_sigma`); a track
 * left over coasts on its prediction and is dropped after `max_misses`
 * frames without a cluster.
 *
 * Pure geometry on Eigen; deterministic (ids in order of creation).
 *
 * \code
 * ofv::OccluderTracker tracker;                 // documented defaults
 * for (each frame) {
 *   const auto& tracks = tracker.update(problem.occluders, dt);
 *   const Eigen::Matrix3Xd ahead = ofv::predicted_occluders(tracks, {0.2, 0.4}, 0.05);
 * }
 * \endcode
 */
#pragma once

#include <Eigen/Core>

#include <vector>

namespace ofv {

/// \brief Settings of ofv::OccluderTracker (lengths in metres, times in seconds).
struct TrackerSettings {
  double link_distance = 0.05;       ///< points closer than this are one cluster [m]
  double gate = 0.1;                 ///< largest distance of a cluster's centroid from its track's prediction [m]
  double accel_noise = 4.0;          ///< white-noise acceleration of an occluder [m/s^2]
  double measurement_noise = 0.01;   ///< standard deviation of a cluster centroid [m]
  double initial_speed_sigma = 1.0;  ///< velocity standard deviation of a new track [m/s]
  int confirm_hits = 2;              ///< frames with a cluster before a track is confirmed
  int max_misses = 3;                ///< frames without a cluster before a track is dropped
};

/// \brief Throws std::invalid_argument naming a tracker setting out of range.
void validate(const TrackerSettings& settings);

/// \brief One followed occluder (world frame).
struct OccluderTrack {
  int id = 0;                                          ///< unique within a tracker, in order of creation
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  ///< filtered centroid [m]
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  ///< filtered velocity [m/s]
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< the cluster's centroid when last seen, moved by velocity since [m]
  /// Covariance of (position, velocity) along any one axis [m^2, m^2/s, m^2/s^2].
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Zero();
  Eigen::Matrix3Xd points;  ///< the cluster's points this frame (empty when missed)
  int hits = 0;             ///< frames with a cluster
  int misses = 0;           ///< consecutive frames without one
  bool confirmed = false;   ///< hits >= confirm_hits at some time

  /// \brief Standard deviation of the position along one axis [m].
  [[nodiscard]] double position_sigma() const;
  /// \brief Standard deviation of the velocity along one axis [m/s].
  [[nodiscard]] double speed_sigma() const;
};

/// \brief Clusters of points (single linkage at `link_distance`): column
///        indices of each cluster, clusters in order of their first point.
[[nodiscard]] std::vector<std::vector<int>> cluster_points(const Eigen::Matrix3Xd& points, double link_distance);

/// \brief Follows occluders from frame to frame (see the file's description).
class OccluderTracker {
 public:
  /// \throws std::invalid_argument naming a setting out of range.
  explicit OccluderTracker(const TrackerSettings& settings = {});

  /**
   * \brief Takes one frame's occluder points.
   * \param occluders 3 x B points (non-finite columns are ignored).
   * \param dt        time since the previous frame [s] (> 0; ignored on the first frame).
   * \return every track, confirmed or not, in id order.
   */
  const std::vector<OccluderTrack>& update(const Eigen::Matrix3Xd& occluders, double dt);

  /// \brief A frame without an object: the tracks coast (no clusters) by dt.
  const std::vector<OccluderTrack>& coast(double dt);

  /// \brief Every track, confirmed or not, in id order (as the last update() returned).
  [[nodiscard]] const std::vector<OccluderTrack>& tracks() const { return tracks_; }
  /// \brief The settings it was constructed with.
  [[nodiscard]] const TrackerSettings& settings() const { return settings_; }
  /// \brief Forgets every track: the next update() is a first frame, ids start at 0 again.
  void reset();

 private:
  void predict(double dt);

  TrackerSettings settings_;
  std::vector<OccluderTrack> tracks_;
  int next_id_ = 0;
  bool started_ = false;
};

/**
 * \brief Where the occluders will be: the points of every confirmed track
 *        seen this frame and moving faster than `min_speed`, each shifted by
 *        velocity x tau for every tau of `times`.
 * \param tracks    the tracker's tracks (OccluderTracker::tracks()).
 * \param times     future times [s] (> 0).
 * \param min_speed slower tracks are taken as still [m/s].
 * \return 3 x K points (K = 0 when nothing moves).
 */
[[nodiscard]] Eigen::Matrix3Xd predicted_occluders(const std::vector<OccluderTrack>& tracks,
                                                   const std::vector<double>& times, double min_speed);

/// \brief True for a confirmed track seen this frame and moving faster than
///        `min_speed` [m/s] (the tracks predicted_occluders() moves).
[[nodiscard]] bool is_moving(const OccluderTrack& track, double min_speed);

/// \brief True for a confirmed track seen this frame and moving no faster
///        than `min_speed` [m/s]: known to stand still (a new track is not yet).
[[nodiscard]] bool is_still(const OccluderTrack& track, double min_speed);

/// \brief This frame's points of the tracks that stand still (is_still()).
[[nodiscard]] Eigen::Matrix3Xd still_occluders(const std::vector<OccluderTrack>& tracks, double min_speed);

}  // namespace ofv
