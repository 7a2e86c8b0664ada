/**
 * \file scene_picture.h
 * \brief The Fig. 6-style scene view of one frame, drawn from a virtual
 *        observer beside the camera: what `ofv simulate` saves as
 *        scene_*.png and episode.avi show, and what the live display
 *        (ofv::LiveDisplay) shows in its scene window.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/rgbd_frame.h"
#include "ofv/servo/loop_status.h"
#include "ofv/servo/view_loop.h"

#include <Eigen/Geometry>

#include <cstdint>
#include <optional>
#include <vector>

namespace ofv {

/// \brief An 8-bit colour picture, row-major, 3 bytes per pixel (R G B).
struct RgbPicture {
  int width = 0;                  ///< [px]
  int height = 0;                 ///< [px]
  std::vector<std::uint8_t> rgb;  ///< width x height x 3 bytes
};

/// \brief What the scene view of one frame shows (world frame, metres).
struct SceneState {
  double time = 0.0;                                      ///< [s]
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< the real camera
  /// The object's centroid when the step has no estimate (simulation: the
  /// true centroid; elsewhere the last one known).
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::optional<double> visible_fraction;  ///< the true visible fraction (simulation only)
  std::optional<servo::StepStatus> status;        ///< the loop's status (none: a loop of the caller's own)
  const Observation* observation = nullptr;  ///< supervoxels, occluders seen and presumed; nullptr: none
  const servo::LoopStep* step = nullptr;          ///< estimate, target, tracks; nullptr when none
  /// The target when there is no step (a caller's own servo loop).
  std::optional<Eigen::Vector3d> target;
};

/**
 * \brief Draws the scene view, 640 x 480: object supervoxels and normals
 *        (blue), occluders (red; hollow where presumed beyond the image
 *        border, servo::LoopStep::presumed_occluders), the sphere of radius `r_sphere`, C, the
 *        real camera and its path (white), t0 (yellow), tf (green), the
 *        target the controller follows where it differs from tf (magenta),
 *        each confirmed occluder track as an orange arrow to where it will
 *        be in 0.5 s with its id, and a line of text (time, visible
 *        fraction and status when known).
 * \param state what to draw.
 * \param path the camera positions so far (world) [m].
 * \param r_sphere the sphere's radius [m].
 */
[[nodiscard]] RgbPicture scene_picture(const SceneState& state,
                                       const std::vector<Eigen::Vector3d>& path, double r_sphere);

}  // namespace ofv
