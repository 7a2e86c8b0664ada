// EpisodeMetrics <-> JSON.
#include "ofv/loop/metrics_json.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

namespace {

using nlohmann::json;

json times_to_json(const StageTimes& t) {
  return {{"render_s", t.render},   {"perception_s", t.perception}, {"estimate_s", t.estimate},
          {"control_s", t.control}, {"total_s", t.total()}};
}

StageTimes times_from_json(const json& j) {
  StageTimes t;
  t.render = j.at("render_s").get<double>();
  t.perception = j.at("perception_s").get<double>();
  t.estimate = j.at("estimate_s").get<double>();
  t.control = j.at("control_s").get<double>();
  return t;
}

template <class T>
json optional_json(const std::optional<T>& v) {
  return v ? json(*v) : json(nullptr);
}

json score_to_json(const ScoreSummary& s) {
  return {{"frames", s.frames},
          {"mean", optional_json(s.mean)},
          {"worst", optional_json(s.worst)},
          {"worst_time_s", s.worst_time},
          {"worst_half_visible", optional_json(s.worst_half_visible)}};
}

std::optional<double> optional_from_json(const json& j) {
  return j.is_null() ? std::nullopt : std::optional<double>(j.get<double>());
}

ScoreSummary score_from_json(const json& j) {
  ScoreSummary s;
  s.frames = j.at("frames").get<int>();
  s.mean = optional_from_json(j.at("mean"));
  s.worst = optional_from_json(j.at("worst"));
  s.worst_time = j.at("worst_time_s").get<double>();
  s.worst_half_visible = optional_from_json(j.at("worst_half_visible"));
  return s;
}

// The scores by their names in metrics.json.
const std::vector<std::pair<const char*, ScoreSummary PerceptionSummary::*>>& perception_scores() {
  static const std::vector<std::pair<const char*, ScoreSummary PerceptionSummary::*>> names{
      {"object_precision", &PerceptionSummary::object_precision},
      {"object_recall", &PerceptionSummary::object_recall},
      {"occluder_precision", &PerceptionSummary::occluder_precision},
      {"occluder_recall", &PerceptionSummary::occluder_recall},
      {"centroid_error_m", &PerceptionSummary::centroid_error},
      {"hidden_error_m", &PerceptionSummary::hidden_error}};
  return names;
}

json perception_to_json(const PerceptionSummary& p) {
  if (!p.scored()) return nullptr;
  json j = {{"lost_half_visible_frames", p.lost_half_visible}};
  for (const auto& [name, member] : perception_scores()) j[name] = score_to_json(p.*member);
  return j;
}

PerceptionSummary perception_from_json(const json& j) {
  PerceptionSummary p;
  // null, or only the mode (`ofv simulate` adds it): nothing was scored.
  if (!j.is_object() || !j.contains("lost_half_visible_frames")) return p;
  p.lost_half_visible = j.at("lost_half_visible_frames").get<int>();
  for (const auto& [name, member] : perception_scores()) p.*member = score_from_json(j.at(name));
  return p;
}

json hindsight_to_json(const HindsightBound& h) {
  return {{"planned", h.planned}, {"unlimited_speed", h.unlimited}, {"views", h.views},         {"steps", h.steps},
          {"step_s", h.step},     {"spacing_m", h.spacing},         {"evaluations", h.evaluations}, {"plan_s", h.plan_s}};
}

HindsightBound hindsight_from_json(const json& j) {
  HindsightBound h;
  h.planned = j.at("planned").get<double>();
  h.unlimited = j.at("unlimited_speed").get<double>();
  h.views = j.at("views").get<int>();
  h.steps = j.at("steps").get<int>();
  h.step = j.at("step_s").get<double>();
  h.spacing = j.at("spacing_m").get<double>();
  h.evaluations = j.at("evaluations").get<long>();
  h.plan_s = j.at("plan_s").get<double>();
  return h;
}

json poses_to_json(const PoseSummary& p) {
  json statuses = json::object();
  for (const auto& [status, count] : p.status_counts) statuses[status] = count;
  // Not measured (NaN, a build without odometry): null.
  const auto number = [](double x) { return std::isfinite(x) ? json(x) : json(nullptr); };
  return {{"source", p.source},
          {"ate_m", number(p.ate)},
          {"ate_max_m", number(p.ate_max)},
          {"status_counts", statuses},
          {"unknown_frames", p.unknown},
          {"max_translation_error_m", p.max_translation_error},
          {"max_translation_error_time_s", p.max_translation_error_time},
          {"max_rotation_error_deg", p.max_rotation_error}};
}

PoseSummary poses_from_json(const json& j) {
  PoseSummary p;
  const auto number = [](const json& x) { return x.is_null() ? std::nan("") : x.get<double>(); };
  p.source = j.at("source").get<std::string>();
  p.ate = number(j.at("ate_m"));
  p.ate_max = number(j.at("ate_max_m"));
  for (const auto& [status, count] : j.at("status_counts").items()) p.status_counts.emplace_back(status, count.get<int>());
  p.unknown = j.at("unknown_frames").get<int>();
  p.max_translation_error = j.at("max_translation_error_m").get<double>();
  p.max_translation_error_time = j.at("max_translation_error_time_s").get<double>();
  p.max_rotation_error = j.at("max_rotation_error_deg").get<double>();
  return p;
}

}  // namespace

json metrics_to_json(const EpisodeMetrics& m) {
  json occlusions = json::array();
  for (const auto& e : m.occlusions) {
    occlusions.push_back({{"onset_s", e.onset},
                          {"recovery_time_s", optional_json(e.recovery_time)},
                          {"occluder_entered_s", optional_json(e.occluder_entered)},
                          {"occluder_in_view_s", optional_json(e.occluder_in_view)}});
  }
  json statuses = json::object();
  for (const auto& [status, count] : m.status_counts) statuses[status] = count;
  json modes = json::object();
  for (const auto& [mode, count] : m.mode_counts) modes[mode] = count;
  return {{"steps", m.steps},
          {"duration_s", m.duration},
          {"visibility_threshold", m.visibility_threshold},
          {"mean_visible_fraction", m.mean_visible_fraction},
          {"min_visible_fraction", m.min_visible_fraction},
          {"time_below_threshold_s", m.time_below_threshold},
          {"occlusions", occlusions},
          {"max_recovery_time_s", optional_json(m.max_recovery_time)},
          {"unrecovered_occlusions", m.unrecovered_occlusions},
          {"mean_angular_error_deg", m.mean_angular_error_deg},
          {"path_length_m", m.path_length},
          {"max_sphere_distance_error_m", m.max_sphere_distance_error},
          {"max_linear_speed_mps", m.max_linear_speed},
          {"max_angular_speed_radps", m.max_angular_speed},
          {"mean_compute_time", times_to_json(m.mean_times)},
          {"max_compute_time", times_to_json(m.max_times)},
          {"estimator_iterations_max", m.estimator_iterations_max},
          {"estimator_calls_mean", m.estimator_calls_mean},
          {"estimator_calls_max", m.estimator_calls_max},
          {"status_counts", statuses},
          {"mode_counts", modes},
          {"perception", perception_to_json(m.perception)},
          {"hindsight_bound", m.hindsight ? hindsight_to_json(*m.hindsight) : json()},
          {"poses", m.poses ? poses_to_json(*m.poses) : json()}};
}

EpisodeMetrics metrics_from_json(const json& j) {
  EpisodeMetrics m;
  m.steps = j.at("steps").get<int>();
  m.duration = j.at("duration_s").get<double>();
  m.visibility_threshold = j.at("visibility_threshold").get<double>();
  m.mean_visible_fraction = j.at("mean_visible_fraction").get<double>();
  m.min_visible_fraction = j.at("min_visible_fraction").get<double>();
  m.time_below_threshold = j.at("time_below_threshold_s").get<double>();
  for (const auto& e : j.at("occlusions")) {
    OcclusionEvent ev;
    ev.onset = e.at("onset_s").get<double>();
    if (!e.at("recovery_time_s").is_null()) ev.recovery_time = e.at("recovery_time_s").get<double>();
    if (!e.at("occluder_entered_s").is_null()) ev.occluder_entered = e.at("occluder_entered_s").get<double>();
    if (!e.at("occluder_in_view_s").is_null()) ev.occluder_in_view = e.at("occluder_in_view_s").get<double>();
    m.occlusions.push_back(ev);
  }
  m.max_recovery_time = optional_from_json(j.at("max_recovery_time_s"));
  m.unrecovered_occlusions = j.at("unrecovered_occlusions").get<int>();
  m.mean_angular_error_deg = j.at("mean_angular_error_deg").get<double>();
  m.path_length = j.at("path_length_m").get<double>();
  m.max_sphere_distance_error = j.at("max_sphere_distance_error_m").get<double>();
  m.max_linear_speed = j.at("max_linear_speed_mps").get<double>();
  m.max_angular_speed = j.at("max_angular_speed_radps").get<double>();
  m.mean_times = times_from_json(j.at("mean_compute_time"));
  m.max_times = times_from_json(j.at("max_compute_time"));
  m.estimator_iterations_max = j.at("estimator_iterations_max").get<int>();
  m.estimator_calls_mean = j.value("estimator_calls_mean", 0.0);
  m.estimator_calls_max = j.value("estimator_calls_max", 0);
  const json modes = j.value("mode_counts", json::object());
  for (const auto& [mode, count] : modes.items()) m.mode_counts.emplace_back(mode, count.get<int>());
  for (const auto& [status, count] : j.at("status_counts").items()) {
    m.status_counts.emplace_back(status, count.get<int>());
  }
  // Episodes written before the perception scores have none.
  if (j.contains("perception")) m.perception = perception_from_json(j.at("perception"));
  if (j.contains("hindsight_bound") && !j.at("hindsight_bound").is_null()) m.hindsight = hindsight_from_json(j.at("hindsight_bound"));
  // Episodes written before the poses block (or with the simulator's poses) have none.
  if (j.contains("poses") && !j.at("poses").is_null()) m.poses = poses_from_json(j.at("poses"));
  return m;
}

}  // namespace ofv
