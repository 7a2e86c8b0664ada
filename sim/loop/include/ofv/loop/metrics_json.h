/**
 * \file metrics_json.h
 * \brief EpisodeMetrics as JSON (`metrics.json`, the episode files of `ofv compare`).
 */
#pragma once

#include "ofv/loop/metrics.h"

#include <nlohmann/json.hpp>

namespace ofv {

/// \brief Every field of the summary; times in seconds, unset values as null.
[[nodiscard]] nlohmann::json metrics_to_json(const EpisodeMetrics& m);
/// \brief Inverse of metrics_to_json(). \throws nlohmann::json::exception on a malformed object.
[[nodiscard]] EpisodeMetrics metrics_from_json(const nlohmann::json& j);

}  // namespace ofv
