/**
 * \file pose_source.h
 * \brief Camera poses from somewhere other than the frame: a pose source
 *        (RGB-D odometry, ofv::odometry) gives each frame's pose before
 *        the front end sees it, in `ofv perceive`, `ofv simulate` and
 *        `ofv run` (setting `poses`).
 *
 * A source that cannot tell a frame's pose says so (FramePose::ok false)
 * and gives its last good pose, never a jump: the loop then stops for that
 * frame (ofv::Observation::pose, ofv::servo::SafetyAction::PoseUnknown).
 */
#pragma once

#include "ofv/rgbd_frame.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

/**
 * \brief A frame's camera pose from a pose source other than the frame's own.
 */
struct FramePose {
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< the pose the front end gets (world <- camera) [m]
  /// False when the source could not tell this frame's pose: `wMc` is then
  /// its last good one, never a jump.
  bool ok = true;
  std::string source;  ///< the source's word, for the records (`odometry`)
  std::string status;  ///< its word for this frame, for the records (`ok`, `failed`, ...)
  std::vector<std::pair<std::string, double>> diagnostics;  ///< numbers for the records, in order
};

/**
 * \brief What the front end found of the object in the previous frame, for a
 *        pose source: its supervoxels' centroids in that frame's camera.
 *        Odometry leaves out what is nearer than the object (hands) and tells
 *        whether the scene apart from the object fixes the camera's motion.
 */
struct ObjectHint {
  /// [m], 3 x N; empty before the object is found or when it was lost.
  Eigen::Matrix3Xd points_c = Eigen::Matrix3Xd(3, 0);

  /// \brief The nearest depth (the smallest Z) [m]; none without points.
  [[nodiscard]] std::optional<double> nearest_depth() const {
    if (points_c.cols() == 0) return std::nullopt;
    return points_c.row(2).minCoeff();
  }
};

/**
 * \brief The hint of world points seen from a camera (the object's
 *        supervoxels, seen from the pose the front end used).
 * \param points_w points in the world frame [m], 3 x N.
 * \param wMc      the camera's pose (world <- camera).
 */
[[nodiscard]] inline ObjectHint object_hint(const Eigen::Matrix3Xd& points_w, const Eigen::Isometry3d& wMc) {
  ObjectHint hint;
  if (points_w.cols() > 0) hint.points_c = wMc.inverse() * points_w;
  return hint;
}

/**
 * \brief Gives a frame's camera pose before the front end runs. Called once
 *        per frame, in order, with the frame as the source read it (its own
 *        `wMc`: the robot's, the recording's or the simulator's) and the
 *        object as the front end found it in the previous frame (empty
 *        before the object is found or when it was lost; object_hint()).
 */
using PoseSource = std::function<FramePose(const RgbdFrame& frame, const ObjectHint& object)>;

}  // namespace ofv
