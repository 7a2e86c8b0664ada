// A simulated frame as pictures and a point cloud.
#include "ofv/loop/frame_files.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace ofv {

namespace {

namespace fs = std::filesystem;

// A distinct colour per label (object blue, interacting green, table brown, occluders red hues).
cv::Vec3b label_colour(std::uint16_t label) {
  switch (label) {
    case sim::kLabelNone: return {0, 0, 0};
    case sim::kLabelObject: return {220, 90, 30};
    case sim::kLabelInteracting: return {60, 200, 60};
    case sim::kLabelBackground: return {90, 110, 140};
    default: {
      const int k = label - sim::kLabelOccluder0;
      return {static_cast<uchar>(40 + 50 * (k % 3)), static_cast<uchar>(40 * (k % 4)), 230};
    }
  }
}

void write_png(const fs::path& path, const cv::Mat& image) {
  if (!cv::imwrite(path.string(), image)) throw std::runtime_error("cannot write " + path.string());
}

}  // namespace

void write_world_cloud(const RgbdFrame& f, const std::string& path) {
  struct Point { Eigen::Vector3d p; const std::uint8_t* rgb; };
  std::vector<Point> points;
  const CameraIntrinsics& k = f.intrinsics;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = f.index(u, v);
      const double z = f.depth[i];
      if (!(z > 0.0)) continue;
      const Eigen::Vector3d pc((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
      points.push_back({f.wMc * pc, &f.rgb[3 * i]});
    }
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  const bool ply = fs::path(path).extension() == ".ply";
  if (ply) {
    out << "ply\nformat ascii 1.0\nelement vertex " << points.size()
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nend_header\n";
  } else {
    out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb\n"
           "SIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH " << points.size()
        << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size() << "\nDATA ascii\n";
  }
  for (const auto& pt : points) {
    out << static_cast<float>(pt.p.x()) << ' ' << static_cast<float>(pt.p.y()) << ' '
        << static_cast<float>(pt.p.z()) << ' ';
    if (ply) {
      out << int(pt.rgb[0]) << ' ' << int(pt.rgb[1]) << ' ' << int(pt.rgb[2]) << '\n';
    } else {
      out << ((std::uint32_t(pt.rgb[0]) << 16) | (std::uint32_t(pt.rgb[1]) << 8) | pt.rgb[2]) << '\n';
    }
  }
}

std::vector<std::string> write_frame_pictures(const std::string& dir, const sim::RenderedFrame& r, double max_depth) {
  const CameraIntrinsics& k = r.frame.intrinsics;
  std::error_code ec;
  fs::create_directories(dir, ec);
  cv::Mat rgb(k.height, k.width, CV_8UC3, const_cast<std::uint8_t*>(r.frame.rgb.data()));
  cv::Mat bgr;
  cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
  cv::Mat depth(k.height, k.width, CV_32F, const_cast<float*>(r.frame.depth.data()));
  cv::Mat scaled, coloured;
  depth.convertTo(scaled, CV_8U, -255.0 / max_depth, 255.0);
  cv::applyColorMap(scaled, coloured, cv::COLORMAP_TURBO);
  coloured.setTo(cv::Scalar(0, 0, 0), depth <= 0.0f);
  cv::Mat labels(k.height, k.width, CV_8UC3);
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) labels.at<cv::Vec3b>(v, u) = label_colour(r.frame.labels[r.frame.index(u, v)]);
  }
  write_png(fs::path(dir) / "colour.png", bgr);
  write_png(fs::path(dir) / "depth.png", coloured);
  write_png(fs::path(dir) / "labels.png", labels);
  return {"colour.png", "depth.png", "labels.png"};
}

}  // namespace ofv
