/**
 * \file observation.h
 * \brief What one frame tells the per-frame policy (ofv::servo::ViewLoop), and the
 *        interface of whatever makes it from a frame: the perception front
 *        end (ofv::perception::PerceptionObserver) or, in simulation, the ground truth
 *        cut down to what a front end would give.
 *
 * Every driver (ofv::run_episode, ofv::servo::run_on_robot) hands the loop an
 * Observation and nothing else: what the loop knows of the world comes
 * through here.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/pose_source.h"
#include "ofv/rgbd_frame.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <optional>

namespace ofv {

/// \brief Whether the loop knows the camera pose of a frame (Observation::pose).
enum class PoseStatus {
  Known,    ///< the frame's own pose (robot, recording, simulator) or one a pose source estimated
  /// The pose source could not tell it (RGB-D odometry failed, found an
  /// implausible motion or a scene that cannot fix it): `wMc` is its last good pose. The loop commands
  /// zero velocity for the frame (ofv::servo::SafetyAction::PoseUnknown).
  Unknown,
};
/// \brief The status's word in files and on the terminal: known, unknown.
[[nodiscard]] const char* to_string(PoseStatus status);

/// \brief One frame's observation, world frame [m].
struct Observation {
  /// The estimator's input: the object's supervoxels and the occluders seen
  /// in the frame; std::nullopt when the object is lost. The loop sets its
  /// camera and previous_view.
  std::optional<ViewProblem> problem;
  /// Occluder points presumed, not seen (the front end's continuation of
  /// occluders the image border cuts, PerceptionSettings::beyond_view): the
  /// estimator avoids them, the occluder tracks leave them out.
  Eigen::Matrix3Xd presumed = Eigen::Matrix3Xd(3, 0);
  /// How much of the object's surface the frame shows [m²]: its voxels seen
  /// in the frame times a voxel's face; std::nullopt when unknown (then the
  /// loop never retreats, RetreatSettings::drop).
  std::optional<double> shown_area;
  /// Pose of the camera that took the frame (world ← camera): the frame's
  /// own, or a pose source's (ofv::PoseSource, e.g. RGB-D odometry).
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
  /// The still plane the object stands on (world frame), when the front end
  /// found one: a pose source keeps its pixels.
  std::optional<SupportPlane> support_plane;
  /// Whether `wMc` is known for this frame: a pose source that could not
  /// tell it leaves its last good pose in `wMc` and says Unknown here; the
  /// loop then stops, as for a stale frame. The driver sets it.
  PoseStatus pose = PoseStatus::Known;
  /// How old the frame is when its command is sent [s] (older than the
  /// stale timeout: stop). The driver sets it.
  double age = 0.0;

  /// \brief The occluders the estimator avoids: the seen ones, then the presumed ones.
  [[nodiscard]] Eigen::Matrix3Xd all_occluders() const;
};

/// \brief Makes an Observation from each frame of a sequence, in order.
class Observer {
 public:
  virtual ~Observer() = default;
  /// \brief The frame's observation (its age left 0: the driver sets it).
  /// \throws std::invalid_argument for a frame it cannot read.
  [[nodiscard]] virtual Observation observe(const RgbdFrame& frame) = 0;
};

}  // namespace ofv
