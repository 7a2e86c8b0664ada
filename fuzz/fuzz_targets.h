/**
 * \file fuzz_targets.h
 * \brief What each libFuzzer target does with one input, shared by the
 *        fuzzers (fuzz/fuzz_*.cpp) and the replay of their seeds and of every
 *        input that once crashed (test/test_fuzz_regressions.cpp).
 *
 * Each function parses `data` as one kind of input file and uses what it
 * accepted. An input the parser rejects must raise the exception its
 * documentation names (std::invalid_argument; std::runtime_error for the
 * sequence text files); that exception is caught here. Anything else — an
 * other exception, a crash, a leak, a hang — escapes and is a finding.
 */
#pragma once

#include "ofv/io/scene_json.h"
#include "ofv/loop/grid.h"
#include "ofv/sim/scenario.h"
#include "ofv/sources/openni2_source.h"
#include "ofv/sources/pcd_sequence.h"
#include "ofv/sources/sequence_files.h"
#include "oni_player.h"  // src/perception: private to the library, played here as OpenNi2Source plays a file

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>

namespace ofv::fuzz {

inline std::string text_of(const std::uint8_t* data, std::size_t size) {
  return std::string(reinterpret_cast<const char*>(data), size);
}

/// Scene JSON of `ofv estimate`; an accepted scene is written back.
inline void scene_json(const std::uint8_t* data, std::size_t size) {
  try {
    const Scene scene = scene_from_text(text_of(data, size), "fuzz.json");
    (void)scene_to_json(scene).dump();
  } catch (const std::invalid_argument&) {
  }
}

/// Scenario YAML of `ofv simulate`, then one of its random worlds (every parsed
/// motion used). Mesh and trajectory files are looked up relative to the
/// working directory.
inline void scenario_yaml(const std::uint8_t* data, std::size_t size) {
  try {
    const sim::Scenario scenario = sim::scenario_from_yaml(text_of(data, size), "fuzz.yaml");
    (void)sim::with_seed(scenario, 1);
  } catch (const std::invalid_argument&) {
  }
}

/// Settings grid of `ofv compare --grid`.
inline void grid_yaml(const std::uint8_t* data, std::size_t size) {
  try {
    (void)grid_from_yaml(text_of(data, size), "fuzz.yaml");
  } catch (const std::invalid_argument&) {
  }
}

/// The text files of recorded sequences, each parser on the same input: pose
/// files (interpolated as a source does), intrinsics.txt, TUM image lists.
inline void tum_files(const std::uint8_t* data, std::size_t size) {
  const std::string text = text_of(data, size);
  try {
    std::istringstream in(text);
    const auto poses = parse_pose_file(in, "groundtruth.txt");
    if (!poses.empty()) {
      const double t0 = poses.front().time, t1 = poses.back().time;
      for (const double t : {t0 - 1.0, t0, 0.5 * t0 + 0.5 * t1, t1, t1 + 1.0}) {
        (void)interpolate_pose(poses, t);
      }
    }
  } catch (const std::runtime_error&) {
  }
  try {
    std::istringstream in(text);
    (void)parse_intrinsics_file(in, "intrinsics.txt");
  } catch (const std::runtime_error&) {
  }
  try {
    std::istringstream in(text);
    (void)parse_timestamp_list(in, "depth.txt");
  } catch (const std::runtime_error&) {
  }
}

/// The PCD header check in front of PCL's reader.
inline void pcd_header(const std::uint8_t* data, std::size_t size) {
  std::istringstream in(text_of(data, size));
  try {
    check_pcd_header(in, size, "fuzz.pcd");
  } catch (const std::invalid_argument&) {
  }
}

/// The .oni structure check, then the playback of what it accepted (its
/// first 8 frames): the player refuses with std::runtime_error a recording it
/// cannot play (no depth, a pixel format it does not read, no field of view).
inline void oni(const std::uint8_t* data, std::size_t size) {
  try {
    oni::Player player(std::make_unique<std::istringstream>(text_of(data, size)), size, "fuzz.oni", true);
    for (std::size_t k = 0; k < std::min<std::size_t>(player.frames(), 8); ++k) {
      (void)player.frame(k, std::nullopt);
    }
  } catch (const std::invalid_argument&) {
  } catch (const std::runtime_error&) {
  }
}

}  // namespace ofv::fuzz
