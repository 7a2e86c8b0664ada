/**
 * \file frame_source.h
 * \brief Anything that yields RGB-D frames: the simulator, an OpenNI2 device
 *        or `.oni` recording, a TUM RGB-D sequence, a PCD sequence.
 */
#pragma once

#include "ofv/rgbd_frame.h"

#include <chrono>
#include <deque>
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

/**
 * \brief How many bad frames a run takes (ofv::servo::run_on_robot, `ofv
 *        perceive`): more than `in_row` in a row, or more than `per_minute`
 *        within 60 s of wall-clock time, end it.
 */
class BadFrameBudget {
 public:
  using Clock = std::chrono::steady_clock;  ///< the clock of the minute
  /// \param in_row     bad frames in a row a run goes on after.
  /// \param per_minute bad frames within 60 s a run goes on after.
  BadFrameBudget(int in_row, int per_minute) : in_row_(in_row), per_minute_(per_minute) {}
  /// \brief One bad frame, at `when`, for `reason`.
  /// \throws std::runtime_error naming the bound and `reason` when it is exceeded.
  void bad(Clock::time_point when, const std::string& reason) {
    times_.push_back(when);
    while (when - times_.front() > std::chrono::minutes(1)) times_.pop_front();
    const bool too_many_in_row = ++bad_in_row_ > in_row_;
    if (too_many_in_row || static_cast<long>(times_.size()) > per_minute_) {
      throw std::runtime_error((too_many_in_row ? std::to_string(bad_in_row_) + " bad frames in a row"
                                                : std::to_string(times_.size()) + " bad frames in a minute") +
                               ", the last: " + reason);
    }
  }
  /// \brief A good frame: the bad ones are no longer in a row.
  void good() { bad_in_row_ = 0; }

 private:
  int in_row_, per_minute_;
  int bad_in_row_ = 0;
  std::deque<Clock::time_point> times_;  // of the bad frames of the last minute
};

/// \brief A run's default bounds on bad frames (BadFrameBudget).
inline constexpr int kMaxBadFramesInRow = 10;
/// \brief See kMaxBadFramesInRow.
inline constexpr int kMaxBadFramesPerMinute = 30;

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
