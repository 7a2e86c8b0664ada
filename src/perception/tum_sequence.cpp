// TUM RGB-D layout: reader and writer (PNG I/O with OpenCV).
#include "ofv/sources/tum_sequence.h"

#include "ofv/perception/cloud.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace ofv {

namespace {

struct ListEntry {
  double time;
  std::string file;
};

std::vector<ListEntry> read_list(const std::string& path) {
  std::vector<ListEntry> out;
  for_each_data_line(
      path, "list (not a TUM RGB-D sequence?)", [&](const std::string& line, int number) {
        std::istringstream fields(line);
        ListEntry e{};
        if (!(fields >> e.time >> e.file) || !std::isfinite(e.time)) {
          throw std::runtime_error(path + ":" + std::to_string(number) +
                                   ": expected 'timestamp filename', got '" + line + "'");
        }
        out.push_back(e);
      });
  std::stable_sort(out.begin(), out.end(),
                   [](const ListEntry& a, const ListEntry& b) { return a.time < b.time; });
  return out;
}

}  // namespace

TumSequenceSource::TumSequenceSource(const std::string& directory,
                                     const TumSequenceOptions& options)
    : directory_(directory), options_(options) {
  if (!fs::is_directory(directory)) {
    throw std::runtime_error(directory + ": not a directory (expected a TUM RGB-D sequence)");
  }
  if (!(options.depth_factor > 0.0)) {
    throw std::invalid_argument("depth_factor " + std::to_string(options.depth_factor) +
                                ": expected > 0");
  }
  const fs::path dir(directory);
  const auto depth = read_list((dir / "depth.txt").string());
  const auto rgb = fs::exists(dir / "rgb.txt") ? read_list((dir / "rgb.txt").string())
                                               : std::vector<ListEntry>{};
  for (const ListEntry& d : depth) {
    Entry e{d.time, d.file, {}};
    const auto it = std::lower_bound(rgb.begin(), rgb.end(), d.time,
                                     [](const ListEntry& x, double t) { return x.time < t; });
    double best = options.max_time_difference;
    for (auto c = it == rgb.begin() ? it : it - 1; c != rgb.end() && c <= it; ++c) {
      if (std::abs(c->time - d.time) <= best) {
        best = std::abs(c->time - d.time);
        e.rgb = c->file;
      }
    }
    entries_.push_back(e);
  }
  if (fs::exists(dir / "groundtruth.txt")) {
    poses_ = read_pose_file((dir / "groundtruth.txt").string());
  }
  if (options.intrinsics) {
    intrinsics_ = *options.intrinsics;
  } else if (fs::exists(dir / "intrinsics.txt")) {
    intrinsics_ = read_intrinsics_file((dir / "intrinsics.txt").string());
  } else {
    intrinsics_ = CameraIntrinsics{640, 480, 525.0, 525.0, 319.5, 239.5};  // TUM's default
  }
}

std::optional<RgbdFrame> TumSequenceSource::next() {
  if (next_ >= entries_.size()) {
    return std::nullopt;
  }
  const Entry& e = entries_[next_++];
  const fs::path dir(directory_);
  RgbdFrame f;
  f.timestamp = e.time - entries_.front().time;
  f.intrinsics = intrinsics_;
  f.wMc = poses_.empty() ? Eigen::Isometry3d::Identity() : interpolate_pose(poses_, e.time);

  const std::string depth_path = (dir / e.depth).string();
  const cv::Mat depth = cv::imread(depth_path, cv::IMREAD_ANYDEPTH);
  if (depth.empty()) {
    throw std::runtime_error(depth_path + ": cannot read the depth image");
  }
  if (depth.type() != CV_16UC1) {
    throw std::runtime_error(depth_path + ": expected a 16-bit single-channel PNG");
  }
  if (depth.cols != intrinsics_.width || depth.rows != intrinsics_.height) {
    throw std::runtime_error(depth_path + ": " + std::to_string(depth.cols) + "x" +
                             std::to_string(depth.rows) + " pixels, the intrinsics say " +
                             std::to_string(intrinsics_.width) + "x" +
                             std::to_string(intrinsics_.height));
  }
  f.depth.resize(static_cast<std::size_t>(depth.total()));
  for (int v = 0; v < depth.rows; ++v) {
    const auto* row = depth.ptr<std::uint16_t>(v);
    for (int u = 0; u < depth.cols; ++u) {
      f.depth[f.index(u, v)] = depth_from_units(row[u], options_.depth_factor);
    }
  }
  if (!e.rgb.empty()) {
    const std::string rgb_path = (dir / e.rgb).string();
    const cv::Mat bgr = cv::imread(rgb_path, cv::IMREAD_COLOR);
    if (bgr.empty()) {
      throw std::runtime_error(rgb_path + ": cannot read the colour image");
    }
    if (bgr.cols != depth.cols || bgr.rows != depth.rows) {
      throw std::runtime_error(rgb_path + ": colour and depth sizes differ");
    }
    cv::Mat rgb;
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
    f.rgb.assign(rgb.data, rgb.data + rgb.total() * 3);
  }
  return f;
}

std::string TumSequenceSource::describe() const {
  return "TUM RGB-D sequence " + directory_ + " (" + std::to_string(entries_.size()) + " frames)";
}

TumSequenceWriter::TumSequenceWriter(const std::string& directory, double depth_factor)
    : directory_(directory), depth_factor_(depth_factor) {
  std::error_code ec;
  fs::create_directories(fs::path(directory) / "rgb", ec);
  fs::create_directories(fs::path(directory) / "depth", ec);
  if (!fs::is_directory(fs::path(directory) / "depth")) {
    throw std::runtime_error(directory + ": cannot create the sequence directory");
  }
  const fs::path dir(directory);
  for (const auto& [name, header] :
       {std::pair<const char*, const char*>{"rgb.txt", "# colour images\n# timestamp filename\n"},
        {"depth.txt", "# depth images (16-bit PNG, value / 5000 = metres)\n# timestamp filename\n"},
        {"groundtruth.txt", "# camera pose wMc\n# timestamp tx ty tz qx qy qz qw\n"}}) {
    std::ofstream out(dir / name, std::ios::trunc);
    out << header;
    if (!out) {
      throw std::runtime_error((dir / name).string() + ": cannot write");
    }
  }
}

void TumSequenceWriter::write(const RgbdFrame& frame) {
  check_frame(frame);
  if (count_ > 0 && !(frame.timestamp >= last_time_ + 1e-6)) {
    throw std::invalid_argument("TUM writer " + directory_ + ": timestamp " +
                                std::to_string(frame.timestamp) + " does not follow " +
                                std::to_string(last_time_));
  }
  last_time_ = frame.timestamp;
  const fs::path dir(directory_);
  if (!intrinsics_written_) {
    write_intrinsics_file((dir / "intrinsics.txt").string(), frame.intrinsics);
    intrinsics_written_ = true;
  }
  const int w = frame.intrinsics.width;
  const int h = frame.intrinsics.height;
  char stamp[64];  // file names: microseconds; lists and poses: every digit, so a replay has the same times
  std::snprintf(stamp, sizeof stamp, "%.6f", frame.timestamp);
  char time[64];
  std::snprintf(time, sizeof time, "%.17g", frame.timestamp);
  const std::string depth_name = std::string("depth/") + stamp + ".png";
  const std::string rgb_name = std::string("rgb/") + stamp + ".png";

  cv::Mat depth(h, w, CV_16UC1);
  for (int v = 0; v < h; ++v) {
    auto* row = depth.ptr<std::uint16_t>(v);
    for (int u = 0; u < w; ++u) {
      row[u] = depth_to_units(frame.depth[frame.index(u, v)], depth_factor_);
    }
  }
  if (!cv::imwrite((dir / depth_name).string(), depth)) {
    throw std::runtime_error((dir / depth_name).string() + ": cannot write");
  }
  std::ofstream(dir / "depth.txt", std::ios::app) << time << ' ' << depth_name << '\n';
  if (!frame.rgb.empty()) {
    const cv::Mat rgb(h, w, CV_8UC3, const_cast<std::uint8_t*>(frame.rgb.data()));
    cv::Mat bgr;
    cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
    if (!cv::imwrite((dir / rgb_name).string(), bgr)) {
      throw std::runtime_error((dir / rgb_name).string() + ": cannot write");
    }
    std::ofstream(dir / "rgb.txt", std::ios::app) << time << ' ' << rgb_name << '\n';
  }
  std::ofstream(dir / "groundtruth.txt", std::ios::app)
      << format_pose_line(frame.timestamp, frame.wMc);
  ++count_;
}

}  // namespace ofv
