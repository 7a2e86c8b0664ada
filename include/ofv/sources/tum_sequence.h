/**
 * \file tum_sequence.h
 * \brief RGB-D sequences in the TUM RGB-D benchmark layout
 *        (https://cvg.cit.tum.de/data/datasets/rgbd-dataset/file_formats).
 *
 * A directory holding `rgb/` (8-bit colour PNGs), `depth/` (16-bit PNGs,
 * depth = value / 5000 m, 0 = missing), `rgb.txt` and `depth.txt`
 * (`timestamp filename` per line), `groundtruth.txt` (camera poses
 * `t tx ty tz qx qy qz qw`, camera -> world, optical axes X right, Y down,
 * Z forward) and, optionally, `intrinsics.txt` (`width height fx fy cx cy`,
 * an ofv addition; without it the TUM default 525, 525, 319.5, 239.5 is used).
 * ofv's own recordings of simulated episodes add their ground truth, read
 * into RgbdFrame::labels and RgbdFrame::object_centroid when present:
 * `labels/` (16-bit PNGs of ofv::PixelLabel) listed in `labels.txt`, and
 * `object.txt` (the object's surface centroid, as pose lines without rotation).
 * Images are PNG files of at most kMaxImageSide pixels a side; a depth image
 * is 16-bit grey.
 */
#pragma once

#include "ofv/frame_source.h"
#include "ofv/sources/sequence_files.h"

#include <optional>
#include <string>
#include <vector>

namespace ofv {

/// \brief Options of TumSequenceSource.
struct TumSequenceOptions {
  double depth_factor = 5000.0;       ///< PNG value per metre (TUM: 5000)
  double max_time_difference = 0.02;  ///< largest rgb/depth timestamp gap when associating [s]
  /// Largest gap between a depth image and its nearest ground-truth pose [s]:
  /// a frame without a pose is an error, not the identity or the last pose.
  double max_pose_time_difference = 0.02;
  std::optional<CameraIntrinsics> intrinsics;  ///< overrides intrinsics.txt and the default
  /// False: the camera poses come from elsewhere (RGB-D odometry), and a
  /// sequence without groundtruth.txt is read with the identity for wMc.
  bool require_poses = true;
};

/**
 * \brief Reads a TUM RGB-D sequence frame by frame.
 *
 * Frames follow depth.txt; each takes the colour image nearest in time
 * (within max_time_difference, otherwise no colour) and the ground-truth pose
 * interpolated at its time. Timestamps are made relative to the first depth image.
 */
class TumSequenceSource : public FrameSource {
 public:
  /// \throws std::runtime_error naming the path when the directory or its lists are missing or
  /// broken; std::invalid_argument naming groundtruth.txt when it is missing (unless
  /// require_poses is false) or a depth image has no pose within
  /// max_pose_time_difference (naming its timestamp).
  explicit TumSequenceSource(const std::string& directory, const TumSequenceOptions& options = {});

  /// \throws std::invalid_argument naming the file when an image is missing, not a PNG,
  /// corrupt, larger than kMaxImageSide, of the wrong format (depth: 16-bit grey) or size.
  std::optional<RgbdFrame> next() override;
  [[nodiscard]] std::string describe() const override;
  /// Number of frames in the sequence.
  [[nodiscard]] std::size_t size() const { return entries_.size(); }
  /// Whether the frames carry the sequence's own poses (groundtruth.txt).
  [[nodiscard]] bool has_poses() const { return !poses_.empty(); }

 private:
  struct Entry {
    double time;
    std::string depth;
    std::string rgb;     // empty: no colour within max_time_difference
    std::string labels;  // empty: no labels within max_time_difference
  };
  std::string directory_;
  TumSequenceOptions options_;
  CameraIntrinsics intrinsics_;
  std::vector<Entry> entries_;
  std::vector<StampedPose> poses_;
  std::vector<StampedPose> objects_;  // object.txt: the object's centroid over time
  std::size_t next_ = 0;
};

/**
 * \brief Writes frames as a TUM RGB-D sequence (plus intrinsics.txt).
 *
 * Depth is stored as round(depth * 5000) in 16 bits (up to 13.1 m; missing,
 * non-finite or larger depths become 0). A frame's ground truth (labels,
 * object centroid) is written when it has one.
 */
class TumSequenceWriter {
 public:
  /// \throws std::invalid_argument when `directory` exists and is not an empty
  ///         directory (refuse_used_directory()); std::runtime_error naming it when it cannot be created.
  explicit TumSequenceWriter(const std::string& directory, double depth_factor = 5000.0);
  /// Images are named by timestamp, so timestamps must increase (by 1 us at least).
  /// \throws std::invalid_argument for inconsistent buffers or a timestamp that does
  /// not increase; std::runtime_error when a file cannot be written.
  void write(const RgbdFrame& frame);
  /// Frames written so far.
  [[nodiscard]] std::size_t count() const { return count_; }

 private:
  std::string directory_;
  double depth_factor_;
  double last_time_ = 0.0;
  std::size_t count_ = 0;
  bool intrinsics_written_ = false;
  bool labels_started_ = false;  // labels/ and labels.txt begun (frames with labels)
  bool object_started_ = false;  // object.txt begun (frames with object_centroid)
};

}  // namespace ofv
