// What check_oni_file() learns of a .oni file while it checks it: each node's
// stream (type, codec, pixel format, video mode, cropping, field of view) and
// where its frames lie. OpenNi2Source plays recordings from it; private to the
// perception library.
#pragma once

#include <cstdint>
#include <istream>
#include <memory>
#include <string>
#include <vector>

namespace ofv::oni {

/// \brief One NEW_DATA record: its payload's place in the file, its time, and
///        the frame it holds as the node's records before it describe it (a
///        recording may change its mode, cropping or pixel format).
struct FrameRecord {
  std::uint64_t offset = 0;   ///< of the payload
  std::uint32_t bytes = 0;    ///< payload size
  std::uint64_t time_us = 0;  ///< the record's timestamp [us]
  std::uint64_t width = 0, height = 0;  ///< the frame's (the cropping window's when cropped)
  std::uint64_t crop_x = 0, crop_y = 0;  ///< the window's origin in the video mode (0 uncropped)
  std::uint64_t mode_width = 0, mode_height = 0;  ///< the video mode
  std::uint64_t pixel_format = 0;  ///< OpenNI2's OniPixelFormat
  std::uint64_t bytes_per_pixel = 0;
};

/// \brief A node that is still added at the file's END.
struct NodeIndex {
  std::uint32_t type = 0;  ///< kNodeTypeDepth, kNodeTypeImage or kNodeTypeIr
  std::uint32_t codec = 0;
  double hfov = 0.0, vfov = 0.0;  ///< xnFOV [rad] as last recorded; 0 when not recorded
  std::vector<FrameRecord> frames;
};

/// \brief check_oni_file() and what it learned: the nodes in the order they were added.
/// \throws std::invalid_argument as check_oni_file().
std::vector<NodeIndex> index_oni_file(std::istream& in, std::uint64_t size, const std::string& path);

/// \brief The file `path`, open for reading, and its size in `size`.
/// \throws std::invalid_argument "PATH: cannot read the .oni file".
std::unique_ptr<std::istream> open_oni_file(const std::string& path, std::uint64_t& size);

}  // namespace ofv::oni
