// Back-projection, crop and voxelisation of an RgbdFrame (no PCL needed here).
#include "ofv/perception/cloud.h"

#include "ofv/estimator.h"

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

CloudBuilder::CloudBuilder(const CloudSettings& settings)
    : settings_(settings), cell_of_key_(std::make_unique<detail::CellMap>()) {
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
  cell_of_key_->reset(cells_.size());  // the last frame's voxel count
  cells_.clear();
  // Neighbouring pixels mostly fall in one voxel: the last one is looked up first.
  std::uint64_t last_key = ~std::uint64_t{0};
  int last = -1;

  const int stride = settings_.pixel_stride;
  for (int v = 0; v < k.height; v += stride) {
    const float yn = (static_cast<float>(v) - cy) * inv_fy;
    for (int u = 0; u < k.width; u += stride) {
      const std::size_t i = frame.index(u, v);
      const float z = frame.depth[i];
      if (!(z > 0.0f) || !std::isfinite(z)) {
        continue;
      }
      ++out.valid_pixels;
      if (z > max_depth) {
        continue;
      }
      const Eigen::Vector3f pc((static_cast<float>(u) - cx) * inv_fx * z, yn * z, z);
      const Eigen::Vector3f pw = wRc * pc + wtc;
      if (use_box &&
          ((pw.array() < box_min.array()).any() || (pw.array() > box_max.array()).any())) {
        continue;
      }
      if (use_sphere && (pw - centre).squaredNorm() > radius2) {
        continue;
      }
      ++out.cropped_points;
      const Eigen::Vector3f colour =
          has_rgb ? Eigen::Vector3f(frame.rgb[3 * i], frame.rgb[3 * i + 1], frame.rgb[3 * i + 2])
                  : Eigen::Vector3f(128.0f, 128.0f, 128.0f);
      if (!voxelise) {
        out.points.push_back(pw);
        out.colours.push_back(colour);
        continue;
      }
      const std::uint64_t key = detail::cell_key((pw * inv_res).array().floor().cast<int>());
      if (key != last_key) {
        int& slot = cell_of_key_->find_or_insert(key);
        if (slot < 0) {
          slot = static_cast<int>(cells_.size());
          cells_.push_back({Eigen::Vector3f::Zero(), Eigen::Vector3f::Zero(), 0});
        }
        last_key = key;
        last = slot;
      }
      Accumulator& a = cells_[static_cast<std::size_t>(last)];
      a.sum_point += pw;
      a.sum_colour += colour;
      ++a.count;
    }
  }
  if (voxelise) {
    out.points.reserve(cells_.size());
    out.colours.reserve(cells_.size());
    for (const Accumulator& a : cells_) {
      const float inv = 1.0f / static_cast<float>(a.count);
      out.points.push_back(a.sum_point * inv);
      out.colours.push_back(a.sum_colour * inv);
    }
  }
}

}  // namespace ofv::perception
