// Pose and intrinsics text files of the recorded-sequence formats.
#include "ofv/sources/sequence_files.h"
#include "ofv/text_file.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace ofv {

void refuse_used_directory(const std::string& directory) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(directory, ec)) return;
  if (!fs::is_directory(directory, ec)) {
    throw std::invalid_argument(directory + ": exists and is not a directory: give a new directory");
  }
  if (!fs::is_empty(directory, ec)) {
    throw std::invalid_argument(directory + ": not empty (a recording written into it would mix with what is "
                                "there): give a new or empty directory");
  }
}

namespace {
// A recording's list, pose or intrinsics file: one line per frame, a few
// MB for hours of frames.
std::string read_list_file(const std::string& path, const std::string& what) {
  constexpr std::uintmax_t kMaxListBytes = 256 << 20;
  return read_text_file(path, kMaxListBytes, what);
}

// A line of the file as an error message quotes it: at most 80 characters.
std::string quoted(const std::string& line) {
  return "'" + (line.size() > 80 ? line.substr(0, 80) + "..." : line) + "'";
}
}  // namespace

void for_each_data_line(std::istream& in, const std::function<void(const std::string&, int)>& f) {
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const auto first = line.find_first_not_of(" \t\r");
    if (first != std::string::npos && line[first] != '#') {
      f(line, number);
    }
  }
}

void for_each_data_line(const std::string& path, const std::string& what,
                        const std::function<void(const std::string&, int)>& f) {
  std::istringstream in(read_list_file(path, what));
  for_each_data_line(in, f);
}

std::vector<StampedPose> parse_pose_file(std::istream& in, const std::string& path) {
  std::vector<StampedPose> poses;
  for_each_data_line(in, [&](const std::string& line, int number) {
    std::istringstream fields(line);
    double t = 0, tx = 0, ty = 0, tz = 0, qx = 0, qy = 0, qz = 0, qw = 0;
    if (!(fields >> t >> tx >> ty >> tz >> qx >> qy >> qz >> qw)) {
      throw std::runtime_error(path + ":" + std::to_string(number) +
                               ": expected 't tx ty tz qx qy qz qw', got " + quoted(line));
    }
    const Eigen::Quaterniond q(qw, qx, qy, qz);
    if (!std::isfinite(tx + ty + tz + t)) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": invalid pose " + quoted(line));
    }
    if (!(std::abs(q.norm() - 1.0) <= kQuaternionTolerance)) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": quaternion norm " +
                               std::to_string(q.norm()) + ", expected 1 +- " +
                               std::to_string(kQuaternionTolerance));
    }
    StampedPose p;
    p.time = t;
    p.wMc.linear() = q.normalized().toRotationMatrix();
    p.wMc.translation() = Eigen::Vector3d(tx, ty, tz);
    poses.push_back(p);
  });
  std::stable_sort(poses.begin(), poses.end(),
                   [](const StampedPose& a, const StampedPose& b) { return a.time < b.time; });
  return poses;
}

std::vector<StampedPose> read_pose_file(const std::string& path) {
  std::istringstream in(read_list_file(path, "pose file"));
  return parse_pose_file(in, path);
}

std::vector<TimedFile> parse_timestamp_list(std::istream& in, const std::string& path) {
  std::vector<TimedFile> out;
  for_each_data_line(in, [&](const std::string& line, int number) {
    std::istringstream fields(line);
    TimedFile e{};
    if (!(fields >> e.time >> e.file) || !std::isfinite(e.time)) {
      throw std::runtime_error(path + ":" + std::to_string(number) + ": expected 'timestamp filename', got " +
                               quoted(line));
    }
    out.push_back(e);
  });
  std::stable_sort(out.begin(), out.end(), [](const TimedFile& a, const TimedFile& b) { return a.time < b.time; });
  return out;
}

std::string format_pose_line(double time, const Eigen::Isometry3d& wMc) {
  const Eigen::Quaterniond q(wMc.linear());
  const Eigen::Vector3d t = wMc.translation();
  char buffer[256];
  std::snprintf(buffer, sizeof buffer, "%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\n", time, t.x(),
                t.y(), t.z(), q.x(), q.y(), q.z(), q.w());
  return buffer;
}

void write_pose_file(const std::string& path, const std::vector<StampedPose>& poses, const std::string& what) {
  std::ofstream file(path);
  file << "# " << what << "\n# timestamp tx ty tz qx qy qz qw\n";
  for (const StampedPose& p : poses) file << format_pose_line(p.time, p.wMc);
  if (!file) throw std::runtime_error(path + ": cannot write the poses");
}

Eigen::Isometry3d interpolate_pose(const std::vector<StampedPose>& poses, double time) {
  const auto after = std::lower_bound(poses.begin(), poses.end(), time,
                                      [](const StampedPose& p, double t) { return p.time < t; });
  if (after == poses.begin()) {
    return poses.front().wMc;
  }
  if (after == poses.end()) {
    return poses.back().wMc;
  }
  if (after->time == time) {
    return after->wMc;  // a frame's own pose, exactly
  }
  const StampedPose& b = *after;
  const StampedPose& a = *(after - 1);
  const double span = b.time - a.time;
  const double s = span > 0.0 ? (time - a.time) / span : 0.0;
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = Eigen::Quaterniond(a.wMc.linear())
                     .slerp(s, Eigen::Quaterniond(b.wMc.linear()))
                     .toRotationMatrix();
  out.translation() = (1.0 - s) * a.wMc.translation() + s * b.wMc.translation();
  return out;
}

CameraIntrinsics parse_intrinsics_file(std::istream& in, const std::string& path) {
  std::optional<CameraIntrinsics> found;
  for_each_data_line(in, [&](const std::string& line, int) {
    if (found) {
      return;
    }
    std::istringstream fields(line);
    CameraIntrinsics k;
    if (!(fields >> k.width >> k.height >> k.fx >> k.fy >> k.cx >> k.cy) || k.width <= 0 ||
        k.height <= 0 || k.width > kMaxImageSide || k.height > kMaxImageSide || !std::isfinite(k.cx) || !std::isfinite(k.cy) ||
        !std::isfinite(k.fx) || !std::isfinite(k.fy) || !(k.fx > 0.0) || !(k.fy > 0.0)) {
      throw std::runtime_error(path + ": expected 'width height fx fy cx cy' (sizes 1 to " +
                               std::to_string(kMaxImageSide) + ", focal lengths > 0), got " + quoted(line));
    }
    found = k;
  });
  if (!found) {
    throw std::runtime_error(path + ": no 'width height fx fy cx cy' line");
  }
  return *found;
}

CameraIntrinsics read_intrinsics_file(const std::string& path) {
  std::istringstream in(read_list_file(path, "intrinsics file"));
  return parse_intrinsics_file(in, path);
}

void write_intrinsics_file(const std::string& path, const CameraIntrinsics& k) {
  std::ofstream out(path);
  out.precision(10);
  out << "# width height fx fy cx cy [px]\n"
      << k.width << ' ' << k.height << ' ' << k.fx << ' ' << k.fy << ' ' << k.cx << ' ' << k.cy
      << '\n';
  if (!out) {
    throw std::runtime_error(path + ": cannot write the intrinsics file");
  }
}

}  // namespace ofv
