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

#include <algorithm>
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

/// \brief Colour without brightness: R, G, B over their sum (shading-invariant;
///        black stays black). The front end's colour tests and SupportPlane::chroma use it.
[[nodiscard]] inline Eigen::Vector3f chromaticity(const Eigen::Vector3f& rgb) {
  return rgb / std::max(rgb.sum(), 1.0f);
}

/// \brief The still plane an object stands on, as the front end found it.
struct SupportPlane {
  Eigen::Vector4d plane = Eigen::Vector4d(0.0, 0.0, 1.0, 0.0);  ///< n·p + d = 0, n unit [m]
  Eigen::Vector3f chroma = Eigen::Vector3f::Constant(1.0f / 3.0f);  ///< its mean chromaticity()
};

/**
 * \brief What the front end found of the object in the previous frame, for a
 *        pose source: its supervoxels' centroids and the plane it stands on,
 *        in that frame's camera. Odometry leaves out what is nearer than the
 *        object but off the plane (hands) and tells whether the scene apart
 *        from the object fixes the camera's motion.
 */
struct ObjectHint {
  /// [m], 3 x N; empty before the object is found or when it was lost.
  Eigen::Matrix3Xd points_c = Eigen::Matrix3Xd(3, 0);
  /// The plane it stands on, when the front end found one.
  std::optional<SupportPlane> plane_c;

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
 * \param plane_w  the support plane in the world frame.
 */
[[nodiscard]] inline ObjectHint object_hint(const Eigen::Matrix3Xd& points_w, const Eigen::Isometry3d& wMc,
                                            const std::optional<SupportPlane>& plane_w = std::nullopt) {
  ObjectHint hint;
  if (points_w.cols() > 0) hint.points_c = wMc.inverse() * points_w;
  if (plane_w) {  // n_c = R^T n_w; a camera point p_c is at R p_c + t in the world
    const Eigen::Vector3d n = plane_w->plane.head<3>();
    hint.plane_c = plane_w;
    hint.plane_c->plane.head<3>() = wMc.linear().transpose() * n;
    hint.plane_c->plane(3) = n.dot(wMc.translation()) + plane_w->plane(3);
  }
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
