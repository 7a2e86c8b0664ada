/**
 * \file perceive_files.h
 * \brief The record of one perceived frame (perceive.h) as `ofv perceive`
 *        writes it: JSON text and, in a directory, frame_NNNNNN.json and .png.
 *
 * The record is one JSON object:
 * `{"frame", "timestamp", "status", ["message",] "problem", "estimate", "counts", "timings_ms"}`.
 * `problem` is a scene for `ofv estimate` (ofv/io/scene_json.h: the problem
 * and the parameters that were given) and `estimate` the estimator's result
 * object; both are null when the object is lost. `message` is present only
 * when the front end gave one. `counts` holds PerceptionCounts and
 * `timings_ms` PerceptionTimings [ms] (`total` as `front_end`) and `estimate`,
 * PerceivedFrame::estimate_ms [ms].
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/perception/perceive.h"

#include <string>

namespace ofv::perception {

/**
 * \brief The frame's record as JSON text.
 * \param frame  the frame as perceive() gave it to its observer.
 * \param params the estimator parameters given by the user (written into `problem`).
 * \param indent as nlohmann::json::dump: -1 one line (no newline), >= 0 that
 *        many spaces per level.
 */
[[nodiscard]] std::string perceived_frame_json(const PerceivedFrame& frame,
                                               const EstimatorParams& params, int indent = -1);

/**
 * \brief Writes `dir`/frame_NNNNNN.json (the record indented by 2, then a
 *        newline; NNNNNN the frame index) and, with `picture`,
 *        `dir`/frame_NNNNNN.png (save_perception_picture() with the estimate
 *        and `r_sphere` [m]). `dir` must exist.
 * \throws std::runtime_error naming the file that cannot be written.
 */
void write_perceived_frame(const std::string& dir, const PerceivedFrame& frame,
                           const EstimatorParams& params, bool picture, double r_sphere);

}  // namespace ofv::perception

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::perception::.
namespace ofv {
using perception::perceived_frame_json;
using perception::write_perceived_frame;
}  // namespace ofv
/// \endcond
