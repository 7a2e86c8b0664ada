// A .oni recording played from OpenNI2's record format (oni_index.h): the
// frames OpenNi2Source gives for a file, and the image conversions it shares
// with its device path. Private to the perception library (and the fuzz
// target that plays what the check accepts).
#pragma once

#include "oni_index.h"
#include "ofv/rgbd_frame.h"

#include <cstdint>
#include <istream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ofv::oni {

/// \brief Pixels of an image: `width` x `height`, rows `stride` bytes apart.
struct Image {
  const std::uint8_t* data = nullptr;
  int width = 0, height = 0, stride = 0;
};

/// \brief Metres per depth unit of an OpenNI2 pixel format; 0 for a format that is no depth.
double depth_scale(std::uint64_t pixel_format);
/// \brief `depth` (16-bit pixels) into `f.depth` [m]; `f.intrinsics` must have its size.
void fill_depth(const Image& depth, double scale, RgbdFrame& f);
/// \brief `colour` (RGB888) into `f.rgb` at `f.intrinsics`' size, nearest neighbour when the sizes differ.
void fill_colour(const Image& colour, RgbdFrame& f);
/// \brief Intrinsics from fields of view [rad] over a `width` x `height` mode, the principal
///        point at the mode's centre less a cropping window's origin; `width` x `height` as the size.
/// \throws std::runtime_error naming `uri` when the fields of view give no finite focal length.
CameraIntrinsics intrinsics_from_fov(const std::string& uri, double hfov, double vfov, int width, int height,
                                     double crop_x = 0.0, double crop_y = 0.0);

/// \brief The frames of a .oni recording: each depth frame with the colour frame nearest in time.
class Player {
 public:
  /// \brief Checks and indexes the recording `in` of `size` bytes (`path` names it in errors).
  /// \param colour false: depth only, even when the recording has colour.
  /// \throws std::invalid_argument as check_oni_file(); std::runtime_error naming `path` when it has no
  ///         depth node, or a depth or colour pixel format other than depth 1 mm / 100 um and RGB888.
  Player(std::unique_ptr<std::istream> in, std::uint64_t size, const std::string& path, bool colour);
  /// \brief The recording's depth frames.
  [[nodiscard]] std::size_t frames() const { return depth_->frames.size(); }
  /// \brief Depth frame `k`'s timestamp as recorded [us].
  [[nodiscard]] std::uint64_t time_us(std::size_t k) const { return depth_->frames[k].time_us; }
  /// \brief Depth frame `k` < frames() [m], with colour when there is some; its timestamp the record's [s],
  ///        wMc the identity. The intrinsics from the recording's field of view, or `intrinsics`.
  /// \throws BadFrame when `intrinsics` has another size than the frame; std::runtime_error naming the path
  ///         when the file can no longer be read as it was checked, or it records no field of view.
  RgbdFrame frame(std::size_t k, const std::optional<CameraIntrinsics>& intrinsics);

 private:
  Image read(const NodeIndex& node, std::size_t k);
  std::unique_ptr<std::istream> in_;
  std::string path_;
  std::vector<NodeIndex> nodes_;
  const NodeIndex* depth_ = nullptr;
  const NodeIndex* colour_ = nullptr;
  std::vector<std::uint8_t> payload_, decoded_;
};

}  // namespace ofv::oni
