/**
 * \file openni2_source.h
 * \brief OpenNI2 devices and `.oni` recordings as frame sources, and a
 *        writer of `.oni` recordings from any frames.
 *
 * OpenNI2 gives depth in the depth camera's pixels; with registration on,
 * the device maps depth onto the colour image (what RgbdFrame expects).
 * Intrinsics come from the streams' fields of view (principal point at the
 * image centre) unless given. OpenNI2 records no camera pose: a recording
 * made by OniWriter carries its poses in `PATH.poses.txt` (TUM pose lines),
 * which OpenNi2Source reads when present; otherwise wMc is the identity.
 */
#pragma once

#include "ofv/frame_source.h"
#include "ofv/sources/sequence_files.h"

#include <cstdint>
#include <fstream>
#include <istream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ofv {

/// \brief Options of OpenNi2Source.
struct OpenNi2Options {
  /// Map depth onto the colour image (live devices that support it; a
  /// recording keeps whatever registration it was made with).
  bool registration = true;
  /// Recordings only: 1 = real time, 2 = twice as fast (frames that are
  /// past due when next() asks give way to the newest due one, as a live
  /// sensor's would); 0 or -1 = every frame, each as soon as next() asks.
  float playback_speed = -1.0f;
  int timeout_ms = 3000;                       ///< devices only: longest wait for a frame [ms]
  std::optional<CameraIntrinsics> intrinsics;  ///< overrides the fields of view
  bool colour = true;                          ///< also read the colour stream when there is one
};

/**
 * \brief Checks the structure of a `.oni` file (OpenNI2 file format 1.0.1.0),
 *        as OpenNi2Source does before it plays one.
 *
 * The file header (magic NI10, version 1.0.1.0, at most 16 nodes) and every
 * record up to END: magic, known type, node id added and within the header's
 * maximum, fields that exactly fill the record (names of at most 80 bytes,
 * 8-byte integer and real properties), payloads of at most 1600 x 1200 x 3
 * bytes inside the file (uncompressed frames exactly width x height x bytes
 * per pixel of the node's mode), undo positions at earlier records, frame
 * numbers 1, 2, ... per node and as many as NODE_ADDED claims, a seek table
 * (OpenNI2's recorder writes one) pointing at frames of its node; the video
 * mode at most 4096 x 4096, the field of view in (0, pi). Every compressed
 * frame (codecs 16zP, 16zT, Im8z, JPEG) is decoded, one at a time and bounded,
 * and must give exactly that frame (JPEG: its width, height and channels).
 * \throws std::invalid_argument "PATH: offset N: what" at the first problem.
 */
void check_oni_file(const std::string& path);
/// \brief check_oni_file() on a file already open, of `size` bytes; `path` names it in errors.
void check_oni_file(std::istream& in, std::uint64_t size, const std::string& path);

/**
 * \brief Frames from an OpenNI2 device (URI, e.g. a PrimeSense device URI,
 *        `Dummy`) or a `.oni` file.
 *
 * Depth 1 mm or 100 um and RGB888 colour are supported; colour of another
 * size than depth is resized (nearest neighbour). A device is read through
 * OpenNI2. A `.oni` recording is played by ofv itself, after
 * check_oni_file(), from OpenNI2's record format (uncompressed, 16zP, 16zT,
 * Im8z and JPEG frames), each depth frame with the colour frame nearest in
 * time: OpenNI2's own player (libOniFile) crashes when its streams are
 * destroyed or its device closed soon after they stop, and on seek.
 */
class OpenNi2Source : public FrameSource {
 public:
  /// An empty URI opens the first device OpenNI2 finds; a URI ending in `.oni` is a recording.
  /// \throws std::runtime_error naming the URI or path when OpenNI2 cannot
  /// initialise, the device or file cannot be opened, it has no depth stream,
  /// or a recording's depth or colour pixel format is not supported;
  /// std::invalid_argument when a file fails check_oni_file() or its poses file
  /// has fewer poses than the recording has frames.
  explicit OpenNi2Source(const std::string& uri, const OpenNi2Options& options = {});
  ~OpenNi2Source() override;
  OpenNi2Source(const OpenNi2Source&) = delete;
  OpenNi2Source& operator=(const OpenNi2Source&) = delete;

  /// The next frame; std::nullopt at the end of a recording.
  /// \throws std::runtime_error naming the URI when a device's frame does not
  /// arrive in time, or a recording's file can no longer be read as checked;
  /// BadFrame when a frame does not have the size of the given intrinsics.
  std::optional<RgbdFrame> next() override;
  [[nodiscard]] std::string describe() const override;
  /// True for a `.oni` recording.
  [[nodiscard]] bool is_file() const;
  /// Depth frames in a recording (0 for a live device).
  [[nodiscard]] int number_of_frames() const;
  /// Starts a recording again from its first frame; no effect on a device.
  void rewind();

 private:
  struct Impl;
  void open_recording();
  void open_device();
  std::optional<RgbdFrame> next_recorded();
  std::optional<RgbdFrame> next_live();
  std::string uri_;
  OpenNi2Options options_;
  std::unique_ptr<Impl> impl_;
};

/**
 * \brief Writes frames to a `.oni` recording that OpenNI2's own player reads:
 *        uncompressed depth (1 mm, 16 bits) and RGB888 nodes with their video
 *        mode, field of view and cropping records, in the OpenNI2 record
 *        format (file format 1.0.1.0). Poses go to `PATH.poses.txt`.
 *
 * All frames must have the size and intrinsics of the first; colour is
 * written when the first frame has it. The file is complete after close()
 * (or destruction).
 */
class OniWriter {
 public:
  /// \throws std::invalid_argument when `path` exists and is not a regular file (a device, a
  ///         directory: its poses file would land beside it); std::runtime_error naming the path
  ///         when it cannot be created.
  explicit OniWriter(const std::string& path, int fps = 30);
  ~OniWriter();
  OniWriter(const OniWriter&) = delete;
  OniWriter& operator=(const OniWriter&) = delete;

  /// Depth is stored in millimetres (0 where missing, clamped at 65.535 m).
  /// \throws std::invalid_argument when the frame differs in size, or has colour
  /// unlike the first; std::runtime_error when writing fails.
  void write(const RgbdFrame& frame);
  /// Patches the frame counts and ends the file. Idempotent.
  void close();
  /// \brief Frames written so far.
  [[nodiscard]] int count() const { return count_; }

 private:
  struct Node {
    std::uint32_t id = 0;
    std::uint64_t added_position = 0;  // NODE_ADDED record, patched on close
    std::uint64_t last_data_position = 0;
  };
  void write_node_header(Node& node, bool depth, const CameraIntrinsics& k);
  void write_data_begin(const Node& node);
  void write_frame(Node& node, std::uint64_t timestamp_us, const void* data, std::size_t bytes);
  void write_node_added(const Node& node, bool depth, std::uint32_t frames, std::uint64_t max_time);

  std::string path_;
  int fps_;
  std::ofstream out_;
  std::ofstream poses_;
  Node depth_, image_;
  bool has_colour_ = false;
  CameraIntrinsics intrinsics_;
  int count_ = 0;
  std::uint64_t first_time_us_ = 0;
  std::uint64_t last_time_us_ = 0;
  bool closed_ = false;
  std::vector<std::uint16_t> depth_buffer_;
};

}  // namespace ofv
