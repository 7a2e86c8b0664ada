// The record of a perceived frame (ofv/perception/perceive_files.h): the
// estimator's JSON comes from ofv::io, so the perception library links it
// privately and its public headers stay parser-free.
#include "ofv/perception/perceive_files.h"

#include "ofv/io/scene_json.h"
#include "ofv/perception/picture.h"

#include <nlohmann/json.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <stdexcept>

namespace ofv::perception {

namespace {

nlohmann::ordered_json counts_json(const PerceptionCounts& c) {
  return {{"valid_pixels", c.valid_pixels},
          {"cropped_points", c.cropped_points},
          {"voxels", c.voxels},
          {"supervoxels", c.supervoxels},
          {"adjacency_edges", c.adjacency_edges},
          {"object", c.object},
          {"object_voxels", c.object_voxels},
          {"hidden_voxels", c.hidden_voxels},
          {"hidden_vertices", c.hidden_vertices},
          {"interacting", c.interacting},
          {"occluders", c.occluders},
          {"beyond_view", c.beyond_view}};
}

nlohmann::ordered_json timings_json(const PerceptionTimings& t, double estimate_ms) {
  return {{"cloud", t.cloud},       {"supervoxels", t.supervoxels}, {"adjacency", t.adjacency},
          {"tracking", t.tracking}, {"classify", t.classify},       {"front_end", t.total},
          {"estimate", estimate_ms}};
}

nlohmann::ordered_json frame_json(const PerceivedFrame& f, const EstimatorParams& params) {
  const PerceptionResult& r = f.result;
  nlohmann::ordered_json j;
  j["frame"] = f.index;
  j["timestamp"] = f.frame.timestamp;
  j["status"] = to_string(r.status);
  if (!r.message.empty()) {
    j["message"] = r.message;
  }
  if (f.pose) {  // the pose came from a pose source (odometry): what it said
    nlohmann::ordered_json pose;
    pose["source"] = f.pose->source;
    pose["status"] = f.pose->status;
    pose["ok"] = f.pose->ok;
    for (const auto& [name, value] : f.pose->diagnostics) pose[name] = value;
    j["pose"] = pose;
  }
  // The problem as the estimator got it (previous_view included) only when it ran.
  j["problem"] =
      f.estimate ? scene_to_json(Scene{r.problem, params}) : nlohmann::ordered_json(nullptr);
  j["estimate"] = f.estimate ? estimate_to_json(*f.estimate) : nlohmann::ordered_json(nullptr);
  j["counts"] = counts_json(r.counts);
  j["timings_ms"] = timings_json(r.timings, f.estimate_ms);
  if (f.scores) {  // a labelled frame: the scores against its ground truth (null where undefined)
    const auto value = [](const std::optional<double>& x) { return x ? nlohmann::ordered_json(*x) : nlohmann::ordered_json(nullptr); };
    const PerceptionScores& s = *f.scores;
    j["scores"] = {{"object_precision", value(s.object_precision)},   {"object_recall", value(s.object_recall)},
                   {"occluder_precision", value(s.occluder_precision)}, {"occluder_recall", value(s.occluder_recall)},
                   {"centroid_error_m", value(s.centroid_error)}};
  }
  return j;
}

}  // namespace

std::string perceived_frame_json(const PerceivedFrame& frame, const EstimatorParams& params,
                                 int indent) {
  return frame_json(frame, params).dump(indent);
}

void write_perceived_frame(const std::string& dir, const PerceivedFrame& frame,
                           const EstimatorParams& params, bool picture, double r_sphere) {
  char name[32];
  std::snprintf(name, sizeof name, "frame_%06ld", frame.index);
  const std::string base = (std::filesystem::path(dir) / name).string();
  std::ofstream file(base + ".json");
  file << perceived_frame_json(frame, params, 2) << '\n';
  if (!file) {
    throw std::runtime_error(base + ".json: cannot write");
  }
  if (picture) {
    save_perception_picture(base + ".png", frame.frame, frame.result, frame.estimate, r_sphere);
  }
}

}  // namespace ofv::perception
