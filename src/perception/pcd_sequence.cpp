// PCD sequences: organised pcl::PointXYZRGBA clouds (camera frame) + poses.txt.
#include "ofv/sources/pcd_sequence.h"

#include "ofv/perception/cloud.h"

#include <pcl/console/print.h>
#include <pcl/io/pcd_io.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace ofv {

namespace {

/// Least-squares fit of x/z = (u - cx)/fx and y/z = (v - cy)/fy over the valid points.
std::optional<CameraIntrinsics> fit_intrinsics(const pcl::PointCloud<pcl::PointXYZRGBA>& cloud) {
  Eigen::Matrix2d au = Eigen::Matrix2d::Zero(), av = Eigen::Matrix2d::Zero();
  Eigen::Vector2d bu = Eigen::Vector2d::Zero(), bv = Eigen::Vector2d::Zero();
  int n = 0;
  for (std::uint32_t v = 0; v < cloud.height; ++v) {
    for (std::uint32_t u = 0; u < cloud.width; ++u) {
      const pcl::PointXYZRGBA& p = cloud(u, v);
      if (!std::isfinite(p.z) || !(p.z > 0.0f)) {
        continue;
      }
      // u = fx (x/z) + cx: unknowns (fx, cx).
      const Eigen::Vector2d ru(p.x / p.z, 1.0), rv(p.y / p.z, 1.0);
      au += ru * ru.transpose();
      bu += ru * static_cast<double>(u);
      av += rv * rv.transpose();
      bv += rv * static_cast<double>(v);
      ++n;
    }
  }
  if (n < 3 || std::abs(au.determinant()) < 1e-12 || std::abs(av.determinant()) < 1e-12) {
    return std::nullopt;
  }
  const Eigen::Vector2d su = au.ldlt().solve(bu), sv = av.ldlt().solve(bv);
  CameraIntrinsics k;
  k.width = static_cast<int>(cloud.width);
  k.height = static_cast<int>(cloud.height);
  k.fx = su(0);
  k.cx = su(1);
  k.fy = sv(0);
  k.cy = sv(1);
  if (!(k.fx > 0.0) || !(k.fy > 0.0)) {
    return std::nullopt;
  }
  return k;
}

}  // namespace

PcdSequenceSource::PcdSequenceSource(const std::string& directory) : directory_(directory) {
  // PCL reports on the terminal; ofv's errors name the file instead.
  pcl::console::setVerbosityLevel(pcl::console::L_ALWAYS);
  if (!fs::is_directory(directory)) {
    throw std::runtime_error(directory + ": not a directory (expected a PCD sequence)");
  }
  for (const auto& entry : fs::directory_iterator(directory)) {
    if (entry.is_regular_file() && entry.path().extension() == ".pcd") {
      files_.push_back(entry.path().string());
    }
  }
  std::sort(files_.begin(), files_.end());
  if (files_.empty()) {
    throw std::runtime_error(directory + ": no .pcd files");
  }
  const fs::path poses = fs::path(directory) / "poses.txt";
  if (!fs::exists(poses)) {
    throw std::runtime_error(poses.string() + ": missing (one pose line per .pcd file)");
  }
  // Pose i belongs to the i-th PCD file (read_pose_file orders by time, as the files are).
  poses_ = read_pose_file(poses.string());
  if (poses_.size() != files_.size()) {
    throw std::runtime_error(poses.string() + ": " + std::to_string(poses_.size()) + " poses for " +
                             std::to_string(files_.size()) + " .pcd files");
  }
  const fs::path intrinsics = fs::path(directory) / "intrinsics.txt";
  if (fs::exists(intrinsics)) {
    intrinsics_ = read_intrinsics_file(intrinsics.string());
  }
}

std::optional<RgbdFrame> PcdSequenceSource::next() {
  if (next_ >= files_.size()) {
    return std::nullopt;
  }
  const std::string& path = files_[next_];
  const StampedPose& pose = poses_[next_];
  ++next_;
  check_pcd_header(path);
  pcl::PointCloud<pcl::PointXYZRGBA> cloud;
  pcl::PCDReader reader;
  int status = 0;
  try {
    status = reader.read(path, cloud);
  } catch (const std::exception& e) {  // PCL throws on data its header check let through
    throw std::invalid_argument(path + ": cannot read the PCD file: " + e.what());
  }
  if (status != 0) {
    throw std::invalid_argument(path + ": cannot read the PCD file");
  }
  if (!cloud.isOrganized()) {
    throw std::invalid_argument(path +
                                ": the cloud is not organised (height 1); an RGB-D frame needs rows");
  }
  if (!intrinsics_) {
    intrinsics_ = fit_intrinsics(cloud);
    if (!intrinsics_) {
      throw std::invalid_argument(path + ": cannot fit intrinsics to the points; add intrinsics.txt");
    }
  }
  RgbdFrame f;
  f.intrinsics = *intrinsics_;
  if (static_cast<int>(cloud.width) != f.intrinsics.width ||
      static_cast<int>(cloud.height) != f.intrinsics.height) {
    throw std::invalid_argument(path + ": " + std::to_string(cloud.width) + "x" +
                             std::to_string(cloud.height) + " points, the intrinsics say " +
                             std::to_string(f.intrinsics.width) + "x" +
                             std::to_string(f.intrinsics.height));
  }
  f.timestamp = pose.time - poses_.front().time;
  f.wMc = pose.wMc;
  const std::size_t n = cloud.size();
  f.depth.resize(n);
  f.rgb.resize(3 * n);
  for (std::uint32_t v = 0; v < cloud.height; ++v) {
    for (std::uint32_t u = 0; u < cloud.width; ++u) {
      const pcl::PointXYZRGBA& p = cloud(u, v);
      const std::size_t i = f.index(static_cast<int>(u), static_cast<int>(v));
      f.depth[i] = std::isfinite(p.z) && p.z > 0.0f ? p.z : 0.0f;
      f.rgb[3 * i] = p.r;
      f.rgb[3 * i + 1] = p.g;
      f.rgb[3 * i + 2] = p.b;
    }
  }
  return f;
}

std::string PcdSequenceSource::describe() const {
  return "PCD sequence " + directory_ + " (" + std::to_string(files_.size()) + " frames)";
}

PcdSequenceWriter::PcdSequenceWriter(const std::string& directory) : directory_(directory) {
  refuse_used_directory(directory);
  std::error_code ec;
  fs::create_directories(directory, ec);
  if (!fs::is_directory(directory)) {
    throw std::runtime_error(directory + ": cannot create the sequence directory");
  }
  std::ofstream out(fs::path(directory) / "poses.txt", std::ios::trunc);
  out << "# camera pose wMc of each .pcd file, in file order\n# timestamp tx ty tz qx qy qz qw\n";
  if (!out) {
    throw std::runtime_error((fs::path(directory) / "poses.txt").string() + ": cannot write");
  }
}

void PcdSequenceWriter::write(const RgbdFrame& frame) {
  check_frame(frame);
  const CameraIntrinsics& k = frame.intrinsics;
  if (count_ == 0) {
    write_intrinsics_file((fs::path(directory_) / "intrinsics.txt").string(), k);
  }
  pcl::PointCloud<pcl::PointXYZRGBA> cloud(static_cast<std::uint32_t>(k.width),
                                           static_cast<std::uint32_t>(k.height));
  cloud.is_dense = false;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = frame.index(u, v);
      pcl::PointXYZRGBA& p = cloud(static_cast<std::uint32_t>(u), static_cast<std::uint32_t>(v));
      const float z = frame.depth[i];
      if (std::isfinite(z) && z > 0.0f) {
        p.x = static_cast<float>((u - k.cx) / k.fx) * z;
        p.y = static_cast<float>((v - k.cy) / k.fy) * z;
        p.z = z;
      } else {
        p.x = p.y = p.z = nan;
      }
      if (!frame.rgb.empty()) {
        p.r = frame.rgb[3 * i];
        p.g = frame.rgb[3 * i + 1];
        p.b = frame.rgb[3 * i + 2];
      }
      p.a = 255;
    }
  }
  char name[32];
  std::snprintf(name, sizeof name, "%06zu.pcd", count_);
  const std::string path = (fs::path(directory_) / name).string();
  if (pcl::io::savePCDFileBinary(path, cloud) != 0) {
    throw std::runtime_error(path + ": cannot write the PCD file");
  }
  std::ofstream(fs::path(directory_) / "poses.txt", std::ios::app)
      << format_pose_line(frame.timestamp, frame.wMc);
  ++count_;
}

}  // namespace ofv
