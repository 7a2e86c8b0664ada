/**
 * \file pcd_sequence.h
 * \brief RGB-D sequences stored as organised PCD files with a pose file.
 *
 * A directory holding `*.pcd` files, read in lexicographic order, each an
 * organised `pcl::PointXYZRGBA` cloud in the camera frame (ViSP axes: X
 * right, Y down, Z forward; metres; NaN where depth is missing), and
 * `poses.txt`: one TUM pose line `t tx ty tz qx qy qz qw` (wMc) per PCD
 * file, in the same order. Optional `intrinsics.txt` (`width height fx fy cx
 * cy`); without it the intrinsics are fitted to the organised points.
 *
 * Each file's header is checked before PCL reads it: VERSION, FIELDS, SIZE,
 * TYPE, COUNT, WIDTH, HEIGHT, POINTS and DATA present, x y z 4-byte floats
 * and a 4-byte rgb or rgba field, POINTS = WIDTH x HEIGHT <= kMaxPcdPoints,
 * binary data inside the file.
 */
#pragma once

#include "ofv/frame_source.h"
#include "ofv/sources/sequence_files.h"

#include <cstdint>
#include <istream>
#include <optional>
#include <string>
#include <vector>

namespace ofv {

/// \brief Largest number of points of one PCD frame (kMaxImageSide squared).
constexpr std::uint64_t kMaxPcdPoints = std::uint64_t{kMaxImageSide} * kMaxImageSide;

/**
 * \brief Checks what PCL would trust in a PCD header (PCL maps binary data
 *        without checking it against the file size, and crashes on empty or
 *        garbage files): every header line present, the per-field lists
 *        consistent, x, y, z as 4-byte floats and a 4-byte rgb or rgba,
 *        POINTS = WIDTH * HEIGHT <= kMaxPcdPoints, and for binary data the
 *        points inside the file.
 * \throws std::invalid_argument "PATH: invalid PCD header: what" (or "PATH:
 *         cannot open the PCD file").
 */
void check_pcd_header(const std::string& path);
/// \brief check_pcd_header() on a file already open at its start, of `file_size` bytes;
///        `path` names it in errors.
void check_pcd_header(std::istream& in, std::uint64_t file_size, const std::string& path);

/// \brief Reads a PCD sequence frame by frame (see the file comment for the layout).
class PcdSequenceSource : public FrameSource {
 public:
  /// \throws std::runtime_error naming the path when the directory, its PCD
  /// files or poses.txt are missing, or the counts differ.
  explicit PcdSequenceSource(const std::string& directory);

  /// \throws std::invalid_argument naming the file when a PCD's header is
  /// malformed, it cannot be read, is not organised, or its intrinsics cannot be fitted.
  std::optional<RgbdFrame> next() override;
  [[nodiscard]] std::string describe() const override;
  /// \brief Frames in the sequence (its PCD files).
  [[nodiscard]] std::size_t size() const { return files_.size(); }

 private:
  std::string directory_;
  std::vector<std::string> files_;
  std::vector<StampedPose> poses_;
  std::optional<CameraIntrinsics> intrinsics_;
  std::size_t next_ = 0;
};

/// \brief Writes frames as a PCD sequence (binary PCD, poses.txt, intrinsics.txt).
class PcdSequenceWriter {
 public:
  /// \throws std::invalid_argument when `directory` exists and is not an empty
  ///         directory (refuse_used_directory()); std::runtime_error naming it when it cannot be created.
  explicit PcdSequenceWriter(const std::string& directory);
  /// \throws std::invalid_argument for inconsistent buffers; std::runtime_error when a file cannot
  /// be written.
  void write(const RgbdFrame& frame);
  /// \brief Frames written so far.
  [[nodiscard]] std::size_t count() const { return count_; }

 private:
  std::string directory_;
  std::size_t count_ = 0;
};

}  // namespace ofv
