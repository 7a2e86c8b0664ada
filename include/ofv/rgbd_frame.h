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

#include <cmath>
#include <cstdint>
#include <optional>
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

/// \brief Depth counts per metre in TUM RGB-D recordings (16-bit PNG, value / 5000 = metres).
inline constexpr double kTumDepthFactor = 5000.0;

/// \brief A depth [m] as a 16-bit count of 1/`factor` m; 0 for missing, non-finite or out of range.
[[nodiscard]] inline std::uint16_t depth_to_units(double z, double factor) {
  const double value = z > 0.0 && z * factor < 65535.5 ? std::round(z * factor) : 0.0;  // NaN fails z > 0
  return static_cast<std::uint16_t>(value);
}
/// \brief The depth [m] a 16-bit count stands for, exactly as every reader of ofv computes it.
[[nodiscard]] inline float depth_from_units(std::uint16_t units, double factor) {
  return static_cast<float>(units) * static_cast<float>(1.0 / factor);
}

/**
 * \brief What a pixel shows, in the label images of the simulator and of
 *        ofv's own recordings (RgbdFrame::labels).
 */
enum PixelLabel : std::uint16_t {
  kPixelNone = 0,         ///< nothing (no surface within the sensor's range)
  kPixelObject = 1,       ///< the tracked object
  kPixelInteracting = 2,  ///< what holds the object (a body the scene declares interacting)
  kPixelSupport = 3,      ///< the support the object stands on (a table)
  kPixelOccluder0 = 10,   ///< occluding body k is kPixelOccluder0 + k
};

/// \brief Depth, colour and pose of one frame. Images are row-major, width x height.
struct RgbdFrame {
  double timestamp = 0.0;       ///< [s] since the start of the episode or recording
  CameraIntrinsics intrinsics;  ///< of both images (depth registered to colour)
  std::vector<float> depth;     ///< Z depth [m] per pixel; 0 or NaN where missing
  std::vector<std::uint8_t> rgb;  ///< 3 bytes per pixel, R G B
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< camera pose in the world
  /// Ground truth where the source knows it (the simulator, ofv's own
  /// recordings): a PixelLabel per pixel; empty for a real sensor.
  std::vector<std::uint16_t> labels;
  /// Ground truth where the source knows it: the object's surface centroid
  /// in the world [m] (the simulator, ofv's own recordings).
  std::optional<Eigen::Vector3d> object_centroid;

  /// Index of pixel (u, v) in `depth`; multiply by 3 for `rgb`.
  [[nodiscard]] std::size_t index(int u, int v) const {
    return static_cast<std::size_t>(v) * static_cast<std::size_t>(intrinsics.width) +
           static_cast<std::size_t>(u);
  }
};

}  // namespace ofv
