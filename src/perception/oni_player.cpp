#include "oni_player.h"

#include "oni_codecs.h"
#include "oni_format.h"
#include "ofv/frame_source.h"

#include <OniCEnums.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

namespace ofv::oni {

double depth_scale(std::uint64_t pixel_format) {
  return pixel_format == ONI_PIXEL_FORMAT_DEPTH_1_MM     ? 1e-3
         : pixel_format == ONI_PIXEL_FORMAT_DEPTH_100_UM ? 1e-4
                                                          : 0.0;
}

void fill_depth(const Image& depth, double scale, RgbdFrame& f) {
  f.depth.resize(static_cast<std::size_t>(depth.width) * static_cast<std::size_t>(depth.height));
  for (int v = 0; v < depth.height; ++v) {
    const std::uint8_t* row = depth.data + static_cast<std::size_t>(v) * static_cast<std::size_t>(depth.stride);
    for (int u = 0; u < depth.width; ++u) {
      std::uint16_t d;
      std::memcpy(&d, row + 2 * u, 2);
      f.depth[f.index(u, v)] = static_cast<float>(d * scale);
    }
  }
}

void fill_colour(const Image& colour, RgbdFrame& f) {
  const int w = f.intrinsics.width, h = f.intrinsics.height;
  f.rgb.resize(3 * static_cast<std::size_t>(w) * static_cast<std::size_t>(h));
  for (int v = 0; v < h; ++v) {
    const std::uint8_t* row =
        colour.data + static_cast<std::size_t>(v * colour.height / h) * static_cast<std::size_t>(colour.stride);
    for (int u = 0; u < w; ++u) {
      std::copy_n(row + 3 * (u * colour.width / w), 3, f.rgb.begin() + static_cast<std::ptrdiff_t>(3 * f.index(u, v)));
    }
  }
}

CameraIntrinsics intrinsics_from_fov(const std::string& uri, double hfov, double vfov, int width, int height,
                                     double crop_x, double crop_y) {
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fx = 0.5 * width / std::tan(0.5 * hfov);
  k.fy = 0.5 * height / std::tan(0.5 * vfov);
  k.cx = 0.5 * width - crop_x;
  k.cy = 0.5 * height - crop_y;
  if (!std::isfinite(k.fx) || !std::isfinite(k.fy) || !(k.fx > 0.0) || !(k.fy > 0.0)) {
    throw std::runtime_error(uri + ": the depth stream reports no usable field of view; give the intrinsics");
  }
  return k;
}

Player::Player(std::unique_ptr<std::istream> in, std::uint64_t size, const std::string& path, bool colour)
    : in_(std::move(in)), path_(path), nodes_(index_oni_file(*in_, size, path)) {
  for (const NodeIndex& n : nodes_) {
    if (n.type == kNodeTypeDepth && depth_ == nullptr) depth_ = &n;
    if (n.type == kNodeTypeImage && colour_ == nullptr && colour && !n.frames.empty()) colour_ = &n;
  }
  if (depth_ == nullptr) throw std::runtime_error(path_ + ": no depth stream");
  for (const NodeIndex* n : {depth_, colour_}) {
    if (n == nullptr) continue;
    for (const FrameRecord& r : n->frames) {
      if (n == depth_ ? depth_scale(r.pixel_format) == 0.0 : r.pixel_format != ONI_PIXEL_FORMAT_RGB888) {
        throw std::runtime_error(path_ + ": unsupported " + (n == depth_ ? "depth" : "colour") + " pixel format " +
                                 std::to_string(r.pixel_format));
      }
    }
  }
}

Image Player::read(const NodeIndex& node, std::size_t k) {
  const FrameRecord& r = node.frames[k];
  payload_.resize(r.bytes);
  in_->clear();
  in_->seekg(static_cast<std::streamoff>(r.offset));
  in_->read(reinterpret_cast<char*>(payload_.data()), static_cast<std::streamsize>(r.bytes));
  if (!*in_) throw std::runtime_error(path_ + ": cannot read the frame at offset " + std::to_string(r.offset));
  if (node.codec == kCodecUncompressed) {
    decoded_.swap(payload_);  // the check found it the frame's size
  } else {
    const std::string why = decode_frame(node.codec, payload_.data(), payload_.size(), {r.width, r.height, r.bytes_per_pixel}, decoded_);
    if (!why.empty()) throw std::runtime_error(path_ + ": offset " + std::to_string(r.offset) + ": " + why);
  }
  return {decoded_.data(), static_cast<int>(r.width), static_cast<int>(r.height), static_cast<int>(r.width * r.bytes_per_pixel)};
}

RgbdFrame Player::frame(std::size_t k, const std::optional<CameraIntrinsics>& intrinsics) {
  const FrameRecord& r = depth_->frames.at(k);
  RgbdFrame f;
  if (intrinsics) {
    f.intrinsics = *intrinsics;
    if (static_cast<std::uint64_t>(f.intrinsics.width) != r.width ||
        static_cast<std::uint64_t>(f.intrinsics.height) != r.height) {
      throw BadFrame(path_ + ": a frame is " + std::to_string(r.width) + "x" + std::to_string(r.height) +
                     ", the given intrinsics " + std::to_string(f.intrinsics.width) + "x" +
                     std::to_string(f.intrinsics.height));
    }
  } else {
    f.intrinsics = intrinsics_from_fov(path_, depth_->hfov, depth_->vfov, static_cast<int>(r.mode_width),
                                       static_cast<int>(r.mode_height), static_cast<double>(r.crop_x),
                                       static_cast<double>(r.crop_y));
    f.intrinsics.width = static_cast<int>(r.width);
    f.intrinsics.height = static_cast<int>(r.height);
  }
  f.timestamp = static_cast<double>(r.time_us) * 1e-6;
  fill_depth(read(*depth_, k), depth_scale(r.pixel_format), f);
  if (colour_ != nullptr) {
    // The colour frame nearest in time (the earlier of two as near).
    const std::vector<FrameRecord>& c = colour_->frames;
    const auto after = std::lower_bound(c.begin(), c.end(), r.time_us,
                                        [](const FrameRecord& x, std::uint64_t t) { return x.time_us < t; });
    std::size_t j = static_cast<std::size_t>(after - c.begin());
    if (j == c.size() || (j > 0 && r.time_us - c[j - 1].time_us <= c[j].time_us - r.time_us)) --j;
    fill_colour(read(*colour_, j), f);
  }
  return f;
}

}  // namespace ofv::oni
