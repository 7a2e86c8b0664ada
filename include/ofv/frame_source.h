/**
 * \file frame_source.h
 * \brief Anything that yields RGB-D frames: the simulator, an OpenNI2 device
 *        or `.oni` recording, a TUM RGB-D sequence, a PCD sequence.
 */
#pragma once

#include "ofv/rgbd_frame.h"

#include <optional>
#include <stdexcept>
#include <string>

namespace ofv {

/// \brief Thrown by FrameSource::next() for one unusable frame (a short
///        read, an image of the wrong size) after which the source can go on.
class BadFrame : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// \brief A sequence of RGB-D frames, read one at a time.
class FrameSource {
 public:
  virtual ~FrameSource() = default;
  /// \brief The next frame, or std::nullopt at the end of the sequence.
  /// \throws BadFrame for one unusable frame (the next call reads the one after);
  ///         std::runtime_error when the device or file fails mid-way.
  virtual std::optional<RgbdFrame> next() = 0;
  /// \brief Human-readable description (device URI, file path, scenario name).
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace ofv
