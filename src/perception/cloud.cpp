// Back-projection, crop and voxelisation of an RgbdFrame (no PCL needed here).
#include "ofv/perception/cloud.h"

#include "ofv/estimator.h"

#include "parallel.h"
#include "point_grid.h"

#include <cmath>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ofv::perception {

void check_frame(const RgbdFrame& frame) {
  const CameraIntrinsics& k = frame.intrinsics;
  if (k.width <= 0 || k.height <= 0) {
    throw std::invalid_argument("RgbdFrame: intrinsics " + std::to_string(k.width) + "x" +
                                std::to_string(k.height) + ": expected a positive size");
  }
  if (!(std::isfinite(k.fx) && std::isfinite(k.fy) && k.fx > 0.0 && k.fy > 0.0)) {
    throw std::invalid_argument("RgbdFrame: intrinsics fx=" + std::to_string(k.fx) + " fy=" +
                                std::to_string(k.fy) + ": expected positive focal lengths");
  }
  const std::size_t n = static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height);
  if (frame.depth.size() != n) {
    throw std::invalid_argument("RgbdFrame: depth has " + std::to_string(frame.depth.size()) +
                                " values, expected " + std::to_string(n));
  }
  // A pose PCL's octree cannot take (NaN, or farther than any length ofv
  // accepts) would abort the process inside PCL, where no one can stop the robot.
  const Eigen::Matrix4d& m = frame.wMc.matrix();
  const Eigen::Matrix3d R = frame.wMc.linear();
  if (!m.allFinite() || frame.wMc.translation().norm() > kMaxLength ||
      !(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0.0) {
    std::ostringstream text;
    text << "RgbdFrame: wMc is not a rigid transform within " << kMaxLength << " m of the origin:\n" << m;
    throw std::invalid_argument(text.str());
  }
  if (!frame.labels.empty() && frame.labels.size() != n) {
    throw std::invalid_argument("RgbdFrame: labels has " + std::to_string(frame.labels.size()) +
                                " values, expected " + std::to_string(n) + " (or none)");
  }
  if (!frame.rgb.empty() && frame.rgb.size() != 3 * n) {
    throw std::invalid_argument("RgbdFrame: rgb has " + std::to_string(frame.rgb.size()) +
                                " bytes, expected " + std::to_string(3 * n) + " (or none)");
  }
}

struct CloudBuilder::Scratch {
  struct Accumulator {
    Eigen::Vector3f sum_point;
    Eigen::Vector3f sum_colour;
    int count;
  };
  static constexpr std::uint64_t kDropped = ~std::uint64_t{0};  // never a cell key (63 bits)
  detail::CellMap cell_of_key;    // voxel key -> index in cells
  std::vector<Accumulator> cells;
  // Per sampled pixel (row by row): its world point and its voxel's key
  // (any other value than kDropped when not voxelising), or kDropped.
  std::vector<Eigen::Vector3f> points;
  std::vector<std::uint64_t> keys;
  std::vector<std::size_t> valid, cropped;  // per sampled row
};

CloudBuilder::CloudBuilder(const CloudSettings& settings)
    : settings_(settings), scratch_(std::make_unique<Scratch>()) {
  if (settings_.pixel_stride < 1) {
    throw std::invalid_argument("pixel_stride " + std::to_string(settings_.pixel_stride) +
                                ": expected an integer >= 1");
  }
}

CloudBuilder::~CloudBuilder() = default;
CloudBuilder::CloudBuilder(CloudBuilder&&) noexcept = default;
CloudBuilder& CloudBuilder::operator=(CloudBuilder&&) noexcept = default;

void CloudBuilder::build(const RgbdFrame& frame, const CropVolume& crop, WorldCloud& out) {
  check_frame(frame);
  out.clear();
  const CameraIntrinsics& k = frame.intrinsics;
  const Eigen::Matrix3f wRc = frame.wMc.linear().cast<float>();
  const Eigen::Vector3f wtc = frame.wMc.translation().cast<float>();
  const bool use_box = !crop.box.isEmpty();
  const Eigen::Vector3f box_min =
      use_box ? Eigen::Vector3f(crop.box.min().cast<float>()) : Eigen::Vector3f::Zero();
  const Eigen::Vector3f box_max =
      use_box ? Eigen::Vector3f(crop.box.max().cast<float>()) : Eigen::Vector3f::Zero();
  const bool use_sphere = crop.radius > 0.0;
  const Eigen::Vector3f centre = crop.centre.cast<float>();
  const float radius2 = static_cast<float>(crop.radius * crop.radius);
  const float max_depth = static_cast<float>(crop.max_depth);
  const float inv_fx = static_cast<float>(1.0 / k.fx);
  const float inv_fy = static_cast<float>(1.0 / k.fy);
  const float cx = static_cast<float>(k.cx);
  const float cy = static_cast<float>(k.cy);
  const bool has_rgb = !frame.rgb.empty();
  const double res = settings_.voxel_resolution;
  const bool voxelise = res > 0.0;
  const float inv_res = voxelise ? static_cast<float>(1.0 / res) : 0.0f;
  const int stride = settings_.pixel_stride;
  const auto rows = static_cast<std::size_t>((k.height + stride - 1) / stride);
  const auto cols = static_cast<std::size_t>((k.width + stride - 1) / stride);
  Scratch& s = *scratch_;
  s.points.resize(rows * cols);
  s.keys.resize(rows * cols);
  s.valid.resize(rows);
  s.cropped.resize(rows);

  // 1. Every sampled pixel's world point and voxel, rows in parallel.
  detail::for_each_index(rows, 8, [&](std::size_t r) {
    const int v = static_cast<int>(r) * stride;
    const float yn = (static_cast<float>(v) - cy) * inv_fy;
    std::size_t valid = 0, cropped = 0;
    for (std::size_t c = 0; c < cols; ++c) {
      const int u = static_cast<int>(c) * stride;
      std::uint64_t& key = s.keys[r * cols + c];
      key = Scratch::kDropped;
      const float z = frame.depth[frame.index(u, v)];
      if (!(z > 0.0f) || !std::isfinite(z)) continue;
      ++valid;
      if (z > max_depth) continue;
      const Eigen::Vector3f pc((static_cast<float>(u) - cx) * inv_fx * z, yn * z, z);
      const Eigen::Vector3f pw = wRc * pc + wtc;
      if (use_box && ((pw.array() < box_min.array()).any() || (pw.array() > box_max.array()).any())) continue;
      if (use_sphere && (pw - centre).squaredNorm() > radius2) continue;
      ++cropped;
      s.points[r * cols + c] = pw;
      key = voxelise ? detail::cell_key(pw, inv_res) : 0;
    }
    s.valid[r] = valid;
    s.cropped[r] = cropped;
  });
  for (std::size_t r = 0; r < rows; ++r) {
    out.valid_pixels += s.valid[r];
    out.cropped_points += s.cropped[r];
  }

  // 2. Points, or voxel means, in pixel order: the voxels in the order of
  // their first pixel, each sum in pixel order (the same cloud whatever the
  // threads).
  s.cell_of_key.reset(s.cells.size());  // the last frame's voxel count
  s.cells.clear();
  // Neighbouring pixels mostly fall in one voxel: the last one is looked up first.
  std::uint64_t last_key = Scratch::kDropped;
  int last = -1;
  for (std::size_t r = 0; r < rows; ++r) {
    for (std::size_t c = 0; c < cols; ++c) {
      const std::uint64_t key = s.keys[r * cols + c];
      if (key == Scratch::kDropped) continue;
      const Eigen::Vector3f& pw = s.points[r * cols + c];
      const std::size_t i = frame.index(static_cast<int>(c) * stride, static_cast<int>(r) * stride);
      const Eigen::Vector3f colour =
          has_rgb ? Eigen::Vector3f(frame.rgb[3 * i], frame.rgb[3 * i + 1], frame.rgb[3 * i + 2])
                  : Eigen::Vector3f(128.0f, 128.0f, 128.0f);
      if (!voxelise) {
        out.points.push_back(pw);
        out.colours.push_back(colour);
        continue;
      }
      if (key != last_key) {
        int& slot = s.cell_of_key.find_or_insert(key);
        if (slot < 0) {
          slot = static_cast<int>(s.cells.size());
          s.cells.push_back({Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero(), 0});
        }
        last_key = key;
        last = slot;
      }
      Scratch::Accumulator& a = s.cells[static_cast<std::size_t>(last)];
      a.sum_point += pw;
      a.sum_colour += colour;
      ++a.count;
    }
  }
  if (voxelise) {
    out.points.reserve(s.cells.size());
    out.colours.reserve(s.cells.size());
    for (const Scratch::Accumulator& a : s.cells) {
      const float inv = 1.0f / static_cast<float>(a.count);
      out.points.push_back(a.sum_point * inv);
      out.colours.push_back(a.sum_colour * inv);
    }
  }
}

}  // namespace ofv::perception
