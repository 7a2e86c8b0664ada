/**
 * \file frame_source.h
 * \brief Anything that yields RGB-D frames: the simulator, an OpenNI2 device
 *        or `.oni` recording, a TUM RGB-D sequence, a PCD sequence.
 */
#pragma once

#include "ofv/rgbd_frame.h"

#include <optional>
#include <string>

namespace ofv {

/// \brief A sequence of RGB-D frames, read one at a time.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// \brief The next frame, or std::nullopt at the end of the sequence.
  /// \throws std::runtime_error when the device or file fails mid-way.
  virtual std::optional<RgbdFrame> next() = 0;
  /// \brief Human-readable description (device URI, file path, scenario name).
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace ofv
