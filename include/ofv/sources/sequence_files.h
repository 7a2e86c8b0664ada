/**
 * \file sequence_files.h
 * \brief Text files shared by the recorded-sequence formats: poses in the
 *        TUM RGB-D layout and camera intrinsics.
 */
#pragma once

#include "ofv/rgbd_frame.h"

#include <Eigen/Geometry>

#include <functional>
#include <istream>
#include <optional>
#include <string>
#include <vector>

namespace ofv {

/// \brief Throws std::invalid_argument unless `directory` is new or an empty
///        directory: a recording written into another would mix with it.
void refuse_used_directory(const std::string& directory);

/// \brief Largest image side [px] of a recorded sequence (images, intrinsics, PCD rows).
constexpr int kMaxImageSide = 4096;

/**
 * \brief Calls `f(line, number)` for each data line of a sequence text file:
 *        blank lines and `#` comments are skipped; numbers count from 1.
 * \throws std::runtime_error "PATH: cannot open the WHAT" when unreadable,
 *         and whatever `f` throws.
 */
void for_each_data_line(const std::string& path, const std::string& what,
                        const std::function<void(const std::string&, int)>& f);
/// \brief for_each_data_line() on text already open (the file versions' parsers, fuzzed).
void for_each_data_line(std::istream& in, const std::function<void(const std::string&, int)>& f);

/// \brief A timestamped camera pose wMc (camera -> world), ViSP camera axes.
struct StampedPose {
  double time = 0.0;  ///< [s]
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< camera pose in the world [m]
};

/// \brief Largest difference from 1 of a pose file's quaternion norm (files
/// written with 4 decimals are within 2e-4); the quaternion is then normalised.
constexpr double kQuaternionTolerance = 1e-3;

/**
 * \brief Reads a TUM pose file: `t tx ty tz qx qy qz qw` per line, `#` comments;
 *        the quaternion of unit norm within kQuaternionTolerance.
 * \throws std::runtime_error naming the file and line when it cannot be read or parsed.
 */
[[nodiscard]] std::vector<StampedPose> read_pose_file(const std::string& path);
/// \brief read_pose_file() on text already open; `path` names it in errors.
[[nodiscard]] std::vector<StampedPose> parse_pose_file(std::istream& in, const std::string& path);

/// \brief One line of a TUM RGB-D image list (`rgb.txt`, `depth.txt`).
struct TimedFile {
  double time = 0.0;  ///< [s]
  std::string file;   ///< relative to the sequence folder
};

/**
 * \brief Parses a TUM RGB-D image list: `timestamp filename` per line, `#`
 *        comments; sorted by time (stable). `path` names it in errors.
 * \throws std::runtime_error naming the file and line when a line cannot be parsed
 *         or its timestamp is not finite.
 */
[[nodiscard]] std::vector<TimedFile> parse_timestamp_list(std::istream& in, const std::string& path);

/// \brief Appends one pose line to a TUM pose file stream's text.
[[nodiscard]] std::string format_pose_line(double time, const Eigen::Isometry3d& wMc);

/**
 * \brief Writes a TUM pose file: `# ` + `what`, the format's comment line,
 *        then a format_pose_line() per pose (read_pose_file() reads it back).
 * \throws std::runtime_error naming the file when it cannot be written.
 */
void write_pose_file(const std::string& path, const std::vector<StampedPose>& poses, const std::string& what);

/**
 * \brief The pose at `time`: linear/slerp interpolation between the two
 *        bracketing poses, the nearest end pose outside their range.
 * \pre poses sorted by time and not empty.
 */
[[nodiscard]] Eigen::Isometry3d interpolate_pose(const std::vector<StampedPose>& poses,
                                                 double time);

/**
 * \brief Reads `width height fx fy cx cy` (one line, `#` comments) [px]; width and
 *        height at most kMaxImageSide.
 * \throws std::runtime_error naming the file when it cannot be read or parsed.
 */
[[nodiscard]] CameraIntrinsics read_intrinsics_file(const std::string& path);
/// \brief read_intrinsics_file() on text already open; `path` names it in errors.
[[nodiscard]] CameraIntrinsics parse_intrinsics_file(std::istream& in, const std::string& path);

/// \brief Writes what read_intrinsics_file() reads.
/// \throws std::runtime_error naming the file when it cannot be written.
void write_intrinsics_file(const std::string& path, const CameraIntrinsics& k);

}  // namespace ofv
