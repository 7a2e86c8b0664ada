/**
 * \file scene_json.h
 * \brief Scene and result JSON of `ofv estimate` (ESTIMATOR-SPEC.md §8).
 *
 * The only place where the estimator's value types meet a parser. Errors are
 * std::invalid_argument whose message names the source, the field and the
 * offending value, e.g. `scene.json: supervoxels[3].normal: expected an
 * array of 3 numbers, got "up"`.
 */
#pragma once

#include "ofv/estimator.h"

#include <nlohmann/json_fwd.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace ofv {

/// \brief One frame as stored in a scene file: the problem and the parameters.
struct Scene {
  ViewProblem problem;     ///< the supervoxels, occluders and optional inputs [m]
  EstimatorParams params;  ///< the file's `params`: a preset and explicit values
};

/// \brief Parses a scene from JSON; `source` names it in error messages.
/// \throws std::invalid_argument on unknown keys, wrong types, bad values.
[[nodiscard]] Scene scene_from_json(const nlohmann::json& j, const std::string& source);

/// \brief Largest scene file [bytes] read_scene() reads (64 MiB).
constexpr std::uintmax_t kMaxSceneBytes = std::uintmax_t{64} << 20;
/// \brief Deepest nesting of arrays and objects read_scene() reads (a scene needs 4).
constexpr int kMaxSceneDepth = 32;

/// \brief Reads and parses a scene file.
/// \throws std::invalid_argument if the file cannot be read, is larger than
/// kMaxSceneBytes, is not JSON, nests deeper than kMaxSceneDepth or repeats a key
/// in one object; the message names the file and never quotes more than a few
/// characters of it.
[[nodiscard]] Scene read_scene(const std::string& path);

/// \brief Parses a scene file's text, as read_scene() does; `source` names it in errors.
/// \throws std::invalid_argument as read_scene().
[[nodiscard]] Scene scene_from_text(const std::string& text, const std::string& source);

/// \brief Writes a scene as JSON (only the parameters that were given).
[[nodiscard]] nlohmann::ordered_json scene_to_json(const Scene& scene);

/**
 * \brief Sets one parameter from its textual value, as `--set name=value`.
 * \throws std::invalid_argument naming the parameter and value when the name
 *         is unknown or the value is not of the parameter's type.
 */
void set_param(EstimatorParams& params, const std::string& name, const std::string& value);

/// \brief Names of the parameters accepted in `params` and by set_param().
[[nodiscard]] const std::vector<std::string>& param_names();

/// \brief The result object of spec §8, plus diagnostics (`centroid`, `axes`,
/// `tf_to_t0_deg`, `occlusion_points`, and `path` when recorded).
[[nodiscard]] nlohmann::ordered_json estimate_to_json(const ViewEstimate& estimate);

/// \brief JSON for people: objects indented by two spaces, arrays whose items
/// are all numbers (or all short arrays of numbers) kept on one line.
[[nodiscard]] std::string to_pretty_string(const nlohmann::ordered_json& j);

}  // namespace ofv
