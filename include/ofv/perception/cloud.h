/**
 * \file cloud.h
 * \brief First stage of the perception front end: an RgbdFrame as a
 *        coloured, cropped, voxelised point set in the world frame.
 *
 * PCL-free on purpose: the front end's value types are plain Eigen so that
 * callers (commands, tests, the simulator) never include PCL.
 */
#pragma once

#include "ofv/rgbd_frame.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <memory>
#include <vector>

namespace ofv::perception {

/// \brief The working volume: points outside it are dropped before anything else.
struct CropVolume {
  /// Keep points inside this world-frame axis-aligned box [m] (empty box: no box test).
  Eigen::AlignedBox3d box;
  /// Keep points within `radius` of `centre` (world frame, [m]); radius <= 0: no sphere test.
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  double radius = 0.0;     ///< radius of the sphere test [m]; <= 0: no sphere test
  double max_depth = 3.0;  ///< drop points farther than this along the optical axis [m]
};

/// \brief Settings of frame_to_cloud().
struct CloudSettings {
  /// Use every n-th pixel in u and v (1 = all). At 0.5 m a 615 px focal
  /// length gives 0.8 mm per pixel, far below the 8 mm voxels: a stride of 2
  /// loses nothing after voxelisation and quarters the work.
  int pixel_stride = 2;
  double voxel_resolution = 0.008;  ///< voxel edge [m]; <= 0 keeps every point
};

/**
 * \brief Coloured points in the world frame [m], one per occupied voxel
 *        (voxel mean of position and colour).
 */
struct WorldCloud {
  std::vector<Eigen::Vector3f> points;   ///< world frame [m]
  std::vector<Eigen::Vector3f> colours;  ///< R, G, B in [0, 255]
  std::size_t valid_pixels = 0;          ///< pixels with finite, positive depth (after stride)
  std::size_t cropped_points = 0;        ///< of those, inside the crop volume

  /// \brief Empties it for the next frame (the vectors keep their capacity).
  void clear() {
    points.clear();
    colours.clear();
    valid_pixels = 0;
    cropped_points = 0;
  }
};

/**
 * \brief Back-projects, crops and voxelises a frame; reuses its buffers across calls.
 *
 * A pixel (u, v) with depth Z gives the camera point ((u - cx) Z / fx,
 * (v - cy) Z / fy, Z) (ViSP convention), mapped to the world with wMc.
 * Zero and NaN depths are dropped.
 */
class CloudBuilder {
 public:
  /// \throws std::invalid_argument if `pixel_stride` < 1.
  explicit CloudBuilder(const CloudSettings& settings = {});
  ~CloudBuilder();
  CloudBuilder(CloudBuilder&&) noexcept;             ///< moves the settings and the buffers
  CloudBuilder& operator=(CloudBuilder&&) noexcept;  ///< moves the settings and the buffers

  /// \brief Fills `out` from `frame` cropped to `crop`.
  /// \throws std::invalid_argument if the frame's image sizes disagree with its intrinsics.
  void build(const RgbdFrame& frame, const CropVolume& crop, WorldCloud& out);

  /// \brief The settings it was constructed with.
  [[nodiscard]] const CloudSettings& settings() const { return settings_; }

 private:
  struct Scratch;  // buffers kept from frame to frame
  CloudSettings settings_;
  std::unique_ptr<Scratch> scratch_;
};

/// \brief Checks that a frame's depth and colour buffers match its intrinsics,
///        and that its pose wMc is a finite rigid transform within kMaxLength of the origin.
/// \throws std::invalid_argument naming the mismatch.
void check_frame(const RgbdFrame& frame);

}  // namespace ofv::perception

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::perception::.
namespace ofv {
using CloudBuilder [[deprecated("use ofv::perception::CloudBuilder")]] = perception::CloudBuilder;
using CloudSettings [[deprecated("use ofv::perception::CloudSettings")]] = perception::CloudSettings;
using CropVolume [[deprecated("use ofv::perception::CropVolume")]] = perception::CropVolume;
using WorldCloud [[deprecated("use ofv::perception::WorldCloud")]] = perception::WorldCloud;
using perception::check_frame;
}  // namespace ofv
/// \endcond
