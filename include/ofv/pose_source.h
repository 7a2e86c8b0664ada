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
 * \brief Gives a frame's camera pose before the front end runs. Called once
 *        per frame, in order, with the frame as the source read it (its own
 *        `wMc`: the robot's, the recording's or the simulator's) and the
 *        object's nearest depth in the previous frame's camera [m] (none
 *        before the object is found or when it was lost; nearest_depth()).
 */
using PoseSource = std::function<FramePose(const RgbdFrame& frame, std::optional<double> object_depth)>;

/**
 * \brief The nearest depth of world points in a camera (what a pose source
 *        is given as `object_depth`: the object's supervoxels, seen from the
 *        pose the front end used).
 * \param points_w points in the world frame [m], 3 x N.
 * \param wMc      the camera's pose (world <- camera).
 * \return the smallest Z in the camera frame [m]; none without points.
 */
[[nodiscard]] inline std::optional<double> nearest_depth(const Eigen::Matrix3Xd& points_w, const Eigen::Isometry3d& wMc) {
  if (points_w.cols() == 0) return std::nullopt;
  return (wMc.inverse() * points_w).row(2).minCoeff();
}

}  // namespace ofv
