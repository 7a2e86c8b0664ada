/**
 * \file rgbd_frame.h
 * \brief One RGB-D frame as every source (simulator, OpenNI2, recordings)
 *        produces it and the perception front end consumes it.
 *
 * Camera frame convention (ViSP's): X right, Y down, Z along the optical
 * axis, in metres. `wMc` maps camera coordinates to world coordinates.
 */
#pragma once

#include <Eigen/Geometry>

#include <cstdint>
#include <vector>

namespace ofv {

/// \brief Pinhole intrinsics without distortion [pixels].
struct CameraIntrinsics {
  int width = 640;    ///< image width [px]
  int height = 480;   ///< image height [px]
  double fx = 615.0;  ///< focal length along x [px]
  double fy = 615.0;  ///< focal length along y [px]
  double cx = 320.0;  ///< principal point x [px]
  double cy = 240.0;  ///< principal point y [px]
};

/// \brief Depth, colour and pose of one frame. Images are row-major, width x height.
struct RgbdFrame {
  double timestamp = 0.0;       ///< [s] since the start of the episode or recording
  CameraIntrinsics intrinsics;  ///< of both images (depth registered to colour)
  std::vector<float> depth;     ///< Z depth [m] per pixel; 0 or NaN where missing
  std::vector<std::uint8_t> rgb;  ///< 3 bytes per pixel, R G B
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< camera pose in the world

  /// Index of pixel (u, v) in `depth`; multiply by 3 for `rgb`.
  [[nodiscard]] std::size_t index(int u, int v) const {
    return static_cast<std::size_t>(v) * static_cast<std::size_t>(intrinsics.width) +
           static_cast<std::size_t>(u);
  }
};

}  // namespace ofv
