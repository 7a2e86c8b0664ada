// Aggregation for the reports: metric columns, groups, Student t intervals.
#include "ofv/loop/statistics.h"

#include <algorithm>
#include <cmath>

namespace ofv {

namespace {

// Two-sided 95 % Student t quantiles for 1..30 degrees of freedom.
double t_quantile_95(int dof) {
  static const double table[] = {12.706, 4.303, 2.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                 2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                 2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                 2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof < 1) return 0.0;
  return dof <= 30 ? table[dof - 1] : 1.96;
}

double mean_score(const ScoreSummary& s) { return s.mean ? *s.mean : std::nan(""); }

}  // namespace

Interval mean_interval(const std::vector<double>& xs) {
  Interval r;
  std::vector<double> v;
  for (double x : xs) {
    if (std::isfinite(x)) v.push_back(x);
  }
  r.n = static_cast<int>(v.size());
  if (v.empty()) {
    r.mean = std::nan("");
    return r;
  }
  double sum = 0.0;
  for (double x : v) sum += x;
  r.mean = sum / r.n;
  if (r.n >= 2) {
    double ss = 0.0;
    for (double x : v) ss += (x - r.mean) * (x - r.mean);
    const double sd = std::sqrt(ss / (r.n - 1));
    // Equal samples may differ in the last bits (times summed differently): no spread.
    if (sd > 1e-12 * std::max(1.0, std::abs(r.mean))) r.half_width = t_quantile_95(r.n - 1) * sd / std::sqrt(r.n);
  }
  return r;
}

const std::vector<MetricColumn>& metric_columns() {
  static const std::vector<MetricColumn> c{
      {"mean_visible_fraction", "mean visible fraction", [](const EpisodeMetrics& m) { return m.mean_visible_fraction; }},
      {"min_visible_fraction", "min visible fraction", [](const EpisodeMetrics& m) { return m.min_visible_fraction; }},
      {"time_below_threshold_s", "time below 0.9 [s]", [](const EpisodeMetrics& m) { return m.time_below_threshold; }},
      {"max_recovery_time_s", "worst recovery [s]", [](const EpisodeMetrics& m) {
         return m.max_recovery_time ? *m.max_recovery_time : std::nan("");
       }},
      {"unrecovered_occlusions", "unrecovered", [](const EpisodeMetrics& m) { return static_cast<double>(m.unrecovered_occlusions); }},
      {"mean_angular_error_deg", "angular error [deg]", [](const EpisodeMetrics& m) { return m.mean_angular_error_deg; }},
      {"path_length_m", "path [m]", [](const EpisodeMetrics& m) { return m.path_length; }},
      {"max_sphere_distance_error_m", "max sphere dist. err. [m]", [](const EpisodeMetrics& m) { return m.max_sphere_distance_error; }},
      {"mean_estimate_ms", "estimate [ms]", [](const EpisodeMetrics& m) { return 1e3 * m.mean_times.estimate; }},
      {"max_estimate_ms", "worst estimate [ms]", [](const EpisodeMetrics& m) { return 1e3 * m.max_times.estimate; }},
      {"mean_step_ms", "whole step [ms]", [](const EpisodeMetrics& m) { return 1e3 * m.mean_times.total(); }},
      // Perception scores, means over the frames (n/a with ground-truth perception).
      {"hindsight_bound", "limit planned", [](const EpisodeMetrics& m) { return m.hindsight ? m.hindsight->planned : std::nan(""); }},
      {"object_precision", "obj. precision", [](const EpisodeMetrics& m) { return mean_score(m.perception.object_precision); }},
      {"object_recall", "obj. recall", [](const EpisodeMetrics& m) { return mean_score(m.perception.object_recall); }},
      {"occluder_precision", "occl. precision", [](const EpisodeMetrics& m) { return mean_score(m.perception.occluder_precision); }},
      {"occluder_recall", "occl. recall", [](const EpisodeMetrics& m) { return mean_score(m.perception.occluder_recall); }},
      {"centroid_error_cm", "centroid err. [cm]", [](const EpisodeMetrics& m) { return 100.0 * mean_score(m.perception.centroid_error); }},
      // The poses a pose source gave the loop (setting poses; n/a with the simulator's).
      {"pose_ate_mm", "pose ATE [mm]", [](const EpisodeMetrics& m) { return m.poses ? 1e3 * m.poses->ate : std::nan(""); }},
      {"pose_unknown_frames", "pose unknown [frames]", [](const EpisodeMetrics& m) {
         return m.poses ? static_cast<double>(m.poses->unknown) : std::nan("");
       }},
  };
  return c;
}

Interval EpisodeGroup::interval(const MetricColumn& column) const {
  std::vector<double> xs;
  for (const auto& r : rows) xs.push_back(column.get(r.metrics));
  return mean_interval(xs);
}

const EpisodeGroup* EpisodeGroups::find(const std::string& scenario,
                                        const std::string& variant) const {
  const auto g = std::find_if(groups.begin(), groups.end(), [&](const EpisodeGroup& x) {
    return x.scenario == scenario && x.variant.name == variant;
  });
  return g == groups.end() ? nullptr : &*g;
}

EpisodeGroups group_episodes(const std::vector<EpisodeRow>& rows) {
  EpisodeGroups out;
  for (const auto& r : rows) {
    auto g = std::find_if(out.groups.begin(), out.groups.end(), [&](const EpisodeGroup& x) {
      return x.scenario == r.spec.scenario && x.variant.name == r.spec.variant.name;
    });
    if (g == out.groups.end()) {
      out.groups.push_back(EpisodeGroup{r.spec.scenario, r.spec.variant, {}});
      g = out.groups.end() - 1;
    }
    g->rows.push_back(r);
    auto& scenarios = out.scenarios;
    auto& variants = out.variants;
    if (std::find(scenarios.begin(), scenarios.end(), r.spec.scenario) == scenarios.end()) scenarios.push_back(r.spec.scenario);
    if (std::find(variants.begin(), variants.end(), r.spec.variant.name) == variants.end()) variants.push_back(r.spec.variant.name);
  }
  return out;
}

}  // namespace ofv
