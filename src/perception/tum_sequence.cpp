// TUM RGB-D layout: reader (PNG through libpng's simplified API, which reports
// errors in its result rather than on the terminal) and writer (OpenCV).
#include "ofv/sources/tum_sequence.h"
#include "ofv/text_file.h"

#include "ofv/perception/cloud.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace fs = std::filesystem;

namespace ofv {

namespace {

using ListEntry = TimedFile;

std::vector<ListEntry> read_list(const std::string& path) {
  constexpr std::uintmax_t kMaxListBytes = 256 << 20;  // one line per frame
  std::istringstream in(read_text_file(path, kMaxListBytes, "TUM RGB-D list"));
  return parse_timestamp_list(in, path);
}

/// A PNG file whose header has been read and checked, ready to decode.
class Png {
 public:
  Png(const std::string& path, const char* what) : path_(path), what_(what) {
    image_.version = PNG_IMAGE_VERSION;
    // Reads the chunks before the pixel data only: the size is checked before any decoding.
    if (png_image_begin_read_from_file(&image_, path.c_str()) == 0) {
      fail("not a readable PNG (" + std::string(image_.message) + ")");
    }
    if (image_.width > kMaxImageSide || image_.height > kMaxImageSide) {
      fail(std::to_string(image_.width) + "x" + std::to_string(image_.height) +
           " pixels, more than " + std::to_string(kMaxImageSide) + " a side");
    }
  }
  ~Png() { png_image_free(&image_); }
  Png(const Png&) = delete;
  Png& operator=(const Png&) = delete;

  [[nodiscard]] int width() const { return static_cast<int>(image_.width); }
  [[nodiscard]] int height() const { return static_cast<int>(image_.height); }
  /// The file's format in words, e.g. "16-bit RGB".
  [[nodiscard]] std::string format() const {
    const png_uint_32 f = image_.format;
    return std::string((f & PNG_FORMAT_FLAG_LINEAR) != 0 ? "16-bit " : "8-bit ") +
           ((f & PNG_FORMAT_FLAG_COLORMAP) != 0 ? "palette " : "") +
           ((f & PNG_FORMAT_FLAG_COLOR) != 0 ? "RGB" : "grey") +
           ((f & PNG_FORMAT_FLAG_ALPHA) != 0 ? "A" : "");
  }
  [[nodiscard]] bool is_grey16() const { return image_.format == PNG_FORMAT_LINEAR_Y; }

  /// Decodes to `format` (PNG_FORMAT_LINEAR_Y: 16-bit values as stored; PNG_FORMAT_RGB).
  template <typename T>
  std::vector<T> decode(png_uint_32 format) {
    image_.format = format;
    std::vector<T> pixels(PNG_IMAGE_SIZE(image_) / sizeof(T));
    if (png_image_finish_read(&image_, nullptr, pixels.data(), 0, nullptr) == 0) {
      fail("corrupt PNG (" + std::string(image_.message) + ")");
    }
    return pixels;
  }

 private:
  // Frees libpng's state first: a constructor that throws runs no destructor.
  [[noreturn]] void fail(const std::string& why) {
    const std::string message = path_ + ": " + what_ + ": " + why;
    png_image_free(&image_);
    throw std::invalid_argument(message);
  }
  std::string path_;
  const char* what_;
  png_image image_{};
};

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
  const auto optional_list = [&dir](const char* name) {
    return fs::exists(dir / name) ? read_list((dir / name).string()) : std::vector<ListEntry>{};
  };
  const auto rgb = optional_list("rgb.txt");
  const auto labels = optional_list("labels.txt");  // ofv's recordings: ground-truth labels
  // The file of `list` nearest `time`, within max_time_difference; "" when none.
  const auto nearest = [&options](const std::vector<ListEntry>& list, double time) {
    const auto it = std::lower_bound(list.begin(), list.end(), time,
                                     [](const ListEntry& x, double t) { return x.time < t; });
    double best = options.max_time_difference;
    std::string file;
    for (auto c = it == list.begin() ? it : it - 1; c != list.end() && c <= it; ++c) {
      if (std::abs(c->time - time) <= best) {
        best = std::abs(c->time - time);
        file = c->file;
      }
    }
    return file;
  };
  for (const ListEntry& d : depth) entries_.push_back(Entry{d.time, d.file, nearest(rgb, d.time), nearest(labels, d.time)});
  if (fs::exists(dir / "object.txt")) objects_ = read_pose_file((dir / "object.txt").string());
  const std::string ground_truth = (dir / "groundtruth.txt").string();
  const bool has_ground_truth = fs::exists(ground_truth);
  if (!has_ground_truth && options.require_poses) {
    throw std::invalid_argument(ground_truth +
                                ": missing (the camera pose of each depth image; without it, poses from RGB-D "
                                "odometry: --poses odometry)");
  }
  if (has_ground_truth) poses_ = read_pose_file(ground_truth);
  // Every depth image has a pose when the file is there (an empty one included).
  for (std::size_t k = 0; has_ground_truth && k < entries_.size(); ++k) {
    const Entry& e = entries_[k];
    const auto after = std::lower_bound(poses_.begin(), poses_.end(), e.time,
                                        [](const StampedPose& p, double t) { return p.time < t; });
    double gap = std::numeric_limits<double>::infinity();
    if (after != poses_.end()) gap = after->time - e.time;
    if (after != poses_.begin()) gap = std::min(gap, e.time - (after - 1)->time);
    if (!(gap <= options.max_pose_time_difference)) {
      char stamp[64];
      std::snprintf(stamp, sizeof stamp, "%.6f", e.time);
      throw std::invalid_argument(ground_truth + ": no pose within " +
                                  std::to_string(options.max_pose_time_difference) +
                                  " s of the depth image at timestamp " + stamp);
    }
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
  Png depth(depth_path, "depth image");
  if (!depth.is_grey16()) {
    throw std::invalid_argument(depth_path + ": depth image: expected a 16-bit grey PNG, found " +
                                depth.format());
  }
  if (depth.width() != intrinsics_.width || depth.height() != intrinsics_.height) {
    throw std::invalid_argument(depth_path + ": " + std::to_string(depth.width()) + "x" +
                                std::to_string(depth.height()) + " pixels, the intrinsics say " +
                                std::to_string(intrinsics_.width) + "x" +
                                std::to_string(intrinsics_.height));
  }
  const std::vector<png_uint_16> units = depth.decode<png_uint_16>(PNG_FORMAT_LINEAR_Y);
  f.depth.resize(units.size());
  for (std::size_t i = 0; i < units.size(); ++i) {
    f.depth[i] = depth_from_units(units[i], options_.depth_factor);
  }
  if (!e.rgb.empty()) {
    const std::string rgb_path = (dir / e.rgb).string();
    Png rgb(rgb_path, "colour image");
    if (rgb.width() != depth.width() || rgb.height() != depth.height()) {
      throw std::invalid_argument(rgb_path + ": colour and depth sizes differ");
    }
    f.rgb = rgb.decode<std::uint8_t>(PNG_FORMAT_RGB);
  }
  if (!e.labels.empty()) {
    const std::string labels_path = (dir / e.labels).string();
    Png labels(labels_path, "label image");
    if (!labels.is_grey16() || labels.width() != depth.width() || labels.height() != depth.height()) {
      throw std::invalid_argument(labels_path + ": label image: expected a 16-bit grey PNG the size of the depth image");
    }
    f.labels = labels.decode<std::uint16_t>(PNG_FORMAT_LINEAR_Y);
  }
  if (!objects_.empty()) f.object_centroid = interpolate_pose(objects_, e.time).translation();
  return f;
}

std::string TumSequenceSource::describe() const {
  return "TUM RGB-D sequence " + directory_ + " (" + std::to_string(entries_.size()) + " frames)";
}

TumSequenceWriter::TumSequenceWriter(const std::string& directory, double depth_factor)
    : directory_(directory), depth_factor_(depth_factor) {
  refuse_used_directory(directory);
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
  if (!frame.labels.empty()) {
    const std::string labels_name = std::string("labels/") + stamp + ".png";
    if (!labels_started_) {
      fs::create_directories(dir / "labels");
      std::ofstream(dir / "labels.txt", std::ios::trunc) << "# ground-truth labels (16-bit PNG, ofv::PixelLabel)\n# timestamp filename\n";
      labels_started_ = true;
    }
    const cv::Mat labels(h, w, CV_16UC1, const_cast<std::uint16_t*>(frame.labels.data()));
    if (!cv::imwrite((dir / labels_name).string(), labels)) {
      throw std::runtime_error((dir / labels_name).string() + ": cannot write");
    }
    std::ofstream(dir / "labels.txt", std::ios::app) << time << ' ' << labels_name << '\n';
  }
  if (frame.object_centroid) {
    if (!object_started_) {
      std::ofstream(dir / "object.txt", std::ios::trunc)
          << "# the object's true surface centroid (ground truth), as a pose without rotation\n"
             "# timestamp tx ty tz qx qy qz qw\n";
      object_started_ = true;
    }
    std::ofstream(dir / "object.txt", std::ios::app)
        << format_pose_line(frame.timestamp, Eigen::Isometry3d(Eigen::Translation3d(*frame.object_centroid)));
  }
  ++count_;
}

}  // namespace ofv
