// Test only: a .oni file played by OpenNI2's own player (libOniFile), to check
// that ofv's playback of a recording gives what OpenNI2 gives.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace ofv::test {

/// \brief The frames OpenNI2's player gives for a recording.
struct OpenNi2Playback {
  int width = 0, height = 0;  ///< of the depth frames
  float hfov = 0.0f, vfov = 0.0f;
  std::vector<std::uint64_t> time_us;            ///< each depth frame's timestamp
  std::vector<std::vector<std::uint16_t>> depth;  ///< each depth frame, row by row
  std::vector<std::vector<std::uint8_t>> rgb;     ///< each colour frame (RGB888), none without colour
};

/// \brief Plays `path` through OpenNI2, one frame at a time (playback speed
///        -1), depth then colour; stops, waits for its player thread to come
///        to rest, and closes. Fails the test (gtest) when a frame does not come.
OpenNi2Playback play_with_openni2(const std::string& path);

/// \brief The pixels of `depth` [m] that are not OpenNI2's frame `openni2` (1 mm units) read as ofv reads it.
inline std::size_t depth_differences(const std::vector<float>& depth, const std::vector<std::uint16_t>& openni2) {
  std::size_t differ = 0;
  for (std::size_t i = 0; i < depth.size(); ++i) {
    differ += depth[i] == static_cast<float>(openni2.at(i) * 1e-3) ? 0 : 1;
  }
  return differ;
}

}  // namespace ofv::test
