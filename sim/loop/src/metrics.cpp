// Episode summary and trajectory rows.
#include "ofv/loop/metrics.h"

#include "ofv/sources/sequence_files.h"
#ifdef OFV_LOOP_HAVE_ODOMETRY
#include "ofv/odometry/evaluation.h"
#endif

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>
#include <iomanip>
#include <sstream>

namespace ofv {

namespace {

// How long each step stands for: until the next step; the last one for the
// mean period (or 0 for a single step).
std::vector<double> step_durations(const std::vector<StepRecord>& steps) {
  std::vector<double> dt(steps.size(), 0.0);
  for (std::size_t k = 0; k + 1 < steps.size(); ++k) {
    dt[k] = steps[k + 1].time - steps[k].time;
  }
  if (steps.size() >= 2) {
    dt.back() = (steps.back().time - steps.front().time) / static_cast<double>(steps.size() - 1);
  }
  return dt;
}

// One score over the steps: mean and worst (lowest when `higher_is_better`).
ScoreSummary summarise_score(const std::vector<StepRecord>& steps, std::optional<double> perception::PerceptionScores::*score,
                             bool higher_is_better) {
  ScoreSummary out;
  double sum = 0.0;
  const auto worse = [higher_is_better](double a, double b) { return higher_is_better ? a < b : a > b; };
  for (const StepRecord& s : steps) {
    const std::optional<double>& x = s.perception.*score;
    if (!x) continue;
    ++out.frames;
    sum += *x;
    if (!out.worst || worse(*x, *out.worst)) {
      out.worst = *x;
      out.worst_time = s.time;
    }
    if (s.visible_fraction >= 0.5 && (!out.worst_half_visible || worse(*x, *out.worst_half_visible))) {
      out.worst_half_visible = *x;
    }
  }
  if (out.frames > 0) out.mean = sum / out.frames;
  return out;
}

PerceptionSummary summarise_perception(const std::vector<StepRecord>& steps) {
  PerceptionSummary p;
  p.object_precision = summarise_score(steps, &perception::PerceptionScores::object_precision, true);
  p.object_recall = summarise_score(steps, &perception::PerceptionScores::object_recall, true);
  p.occluder_precision = summarise_score(steps, &perception::PerceptionScores::occluder_precision, true);
  p.occluder_recall = summarise_score(steps, &perception::PerceptionScores::occluder_recall, true);
  p.centroid_error = summarise_score(steps, &perception::PerceptionScores::centroid_error, false);
  p.hidden_error = summarise_score(steps, &perception::PerceptionScores::hidden_error, false);
  for (const StepRecord& s : steps) {
    const bool scored = s.perception.object_recall.has_value();
    p.lost_half_visible += scored && !s.perception.centroid_error && s.visible_fraction >= 0.5 ? 1 : 0;
  }
  return p;
}

// The poses block: the steps' pose records against their true poses.
std::optional<PoseSummary> summarise_poses(const std::vector<StepRecord>& steps) {
  std::optional<PoseSummary> out;
  std::map<std::string, int> statuses;
  std::vector<StampedPose> used, truth;
  for (const StepRecord& s : steps) {
    if (!s.pose) continue;
    if (!out) out.emplace().source = s.pose->source;
    PoseSummary& p = *out;
    ++statuses[s.pose->status];
    p.unknown += s.pose->known ? 0 : 1;
    if (s.pose->translation_error > p.max_translation_error) {
      p.max_translation_error = s.pose->translation_error;
      p.max_translation_error_time = s.time;
    }
    p.max_rotation_error = std::max(p.max_rotation_error, s.pose->rotation_error);
    used.push_back({s.time, s.pose->wMc});
    truth.push_back({s.time, s.wMc});
  }
  if (!out) return out;
  out->status_counts.assign(statuses.begin(), statuses.end());
#ifdef OFV_LOOP_HAVE_ODOMETRY
  // Every step is its own association: the same time stamps.
  std::tie(out->ate, out->ate_max) = odometry::absolute_trajectory_error(used, truth, 0.0);
#else
  // Pose records come only from the odometry component; without it (a
  // summary of records made elsewhere) the ATE is not measured.
  out->ate = out->ate_max = std::nan("");
#endif
  return out;
}

}  // namespace

EpisodeMetrics summarise(const std::vector<StepRecord>& steps, double threshold, double hold) {
  EpisodeMetrics m;
  m.visibility_threshold = threshold;
  m.steps = static_cast<int>(steps.size());
  if (steps.empty()) {
    return m;
  }
  const std::vector<double> dt = step_durations(steps);
  double total = 0.0;
  double visible = 0.0;
  double error = 0.0;
  m.min_visible_fraction = steps.front().visible_fraction;
  std::map<std::string, int> statuses, modes;
  for (std::size_t k = 0; k < steps.size(); ++k) {
    const StepRecord& s = steps[k];
    total += dt[k];
    visible += s.visible_fraction * dt[k];
    error += s.angular_error_deg * dt[k];
    m.min_visible_fraction = std::min(m.min_visible_fraction, s.visible_fraction);
    if (s.visible_fraction < threshold) m.time_below_threshold += dt[k];
    if (k > 0) m.path_length += (s.wMc.translation() - steps[k - 1].wMc.translation()).norm();
    m.max_sphere_distance_error = std::max(m.max_sphere_distance_error, std::abs(s.sphere_distance_error));
    m.max_linear_speed = std::max(m.max_linear_speed, s.velocity.head<3>().norm());
    m.max_angular_speed = std::max(m.max_angular_speed, s.velocity.tail<3>().norm());
    m.mean_times.render += s.times.render;
    m.mean_times.perception += s.times.perception;
    m.mean_times.estimate += s.times.estimate;
    m.mean_times.control += s.times.control;
    m.max_times.render = std::max(m.max_times.render, s.times.render);
    m.max_times.perception = std::max(m.max_times.perception, s.times.perception);
    m.max_times.estimate = std::max(m.max_times.estimate, s.times.estimate);
    m.max_times.control = std::max(m.max_times.control, s.times.control);
    m.estimator_iterations_max = std::max(m.estimator_iterations_max, s.iterations);
    m.estimator_calls_mean += s.estimator_calls;
    m.estimator_calls_max = std::max(m.estimator_calls_max, s.estimator_calls);
    ++statuses[to_string(s.status)];
    ++modes[to_string(s.mode)];
  }
  m.duration = total;
  // Time-weighted means; a single step (no duration) weighs as one sample.
  const double w = total > 0.0 ? total : 1.0;
  if (total > 0.0) {
    m.mean_visible_fraction = visible / w;
    m.mean_angular_error_deg = error / w;
  } else {
    m.mean_visible_fraction = steps.front().visible_fraction;
    m.mean_angular_error_deg = steps.front().angular_error_deg;
  }
  const auto n = static_cast<double>(steps.size());
  m.mean_times.render /= n;
  m.mean_times.perception /= n;
  m.mean_times.estimate /= n;
  m.mean_times.control /= n;
  m.estimator_calls_mean /= n;
  m.status_counts.assign(statuses.begin(), statuses.end());
  m.mode_counts.assign(modes.begin(), modes.end());

  // When a count last rose, at or before each step.
  const auto last_rise = [&steps](int StepRecord::*count) {
    std::vector<std::optional<double>> rose(steps.size());
    for (std::size_t k = 1; k < steps.size(); ++k) {
      rose[k] = steps[k].*count > steps[k - 1].*count ? steps[k].time : rose[k - 1];
    }
    return rose;
  };
  const auto entered = last_rise(&StepRecord::occluders_in_sphere);
  const auto in_view = last_rise(&StepRecord::occluders_in_view);
  // Occlusion events: the visibility falls below the threshold, until it is
  // back for `hold` seconds.
  for (std::size_t k = 0; k < steps.size(); ++k) {
    if (steps[k].visible_fraction >= threshold) continue;
    OcclusionEvent event;
    event.onset = steps[k].time;
    event.occluder_entered = entered[k];
    event.occluder_in_view = in_view[k];
    std::size_t j = k + 1;  // the first step of a visible run that lasts `hold`
    while (j < steps.size()) {
      if (steps[j].visible_fraction < threshold) {
        ++j;
        continue;
      }
      std::size_t next_dip = j;
      while (next_dip < steps.size() && steps[next_dip].visible_fraction >= threshold) ++next_dip;
      if (next_dip == steps.size() || steps[next_dip].time - steps[j].time >= hold) break;
      j = next_dip;
    }
    if (j < steps.size()) event.recovery_time = steps[j].time - event.onset;
    m.occlusions.push_back(event);
    k = j - 1;  // on from the recovery
  }
  double worst = 0.0;
  for (const auto& e : m.occlusions) {
    if (e.recovery_time) {
      worst = std::max(worst, *e.recovery_time);
    } else {
      ++m.unrecovered_occlusions;
    }
  }
  if (m.unrecovered_occlusions == 0) m.max_recovery_time = worst;
  m.perception = summarise_perception(steps);
  m.poses = summarise_poses(steps);
  return m;
}

std::string episode_summary(const EpisodeMetrics& m) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(3) << "  " << m.duration << " s, " << m.steps << " steps\n"
      << "  visible fraction: mean " << m.mean_visible_fraction << ", min " << m.min_visible_fraction << ", below "
      << m.visibility_threshold << " for " << m.time_below_threshold << " s\n"
      << "  occlusions (visible < " << m.visibility_threshold << "): " << m.occlusions.size();
  if (!m.occlusions.empty()) {
    out << ", worst recovery ";
    if (m.max_recovery_time) {
      out << *m.max_recovery_time << " s";
    } else {
      out << "never (" << m.unrecovered_occlusions << " still hidden at the end)";
    }
    // The warning before each onset, as the sensor and as the sphere gave it.
    const auto mean_lead = [&m](std::optional<double> OcclusionEvent::*since) -> std::optional<double> {
      double sum = 0.0;
      int n = 0;
      for (const auto& e : m.occlusions) {
        if (!(e.*since)) continue;
        sum += e.onset - *(e.*since);
        ++n;
      }
      return n > 0 ? std::optional<double>(sum / n) : std::nullopt;
    };
    const auto in_view = mean_lead(&OcclusionEvent::occluder_in_view);
    const auto entered = mean_lead(&OcclusionEvent::occluder_entered);
    if (in_view || entered) {
      out << "\n  warning before an onset (mean): ";
      if (in_view) out << "occluder in view " << *in_view << " s";
      if (in_view && entered) out << ", ";
      if (entered) out << "in the sphere " << *entered << " s";
    }
  }
  if (m.perception.scored()) {
    const PerceptionSummary& p = m.perception;
    const auto score = [&out](const char* name, const ScoreSummary& x, double scale = 1.0) {
      out << name;
      if (x.mean) {
        out << ' ' << scale * *x.mean << " (worst " << scale * *x.worst << " at " << x.worst_time << " s)";
      } else {
        out << " -";
      }
    };
    out << "\n  perception: ";
    score("object precision", p.object_precision);
    score(", recall", p.object_recall);
    out << "\n              ";
    score("occluder precision", p.occluder_precision);
    score(", recall", p.occluder_recall);
    out << "\n              ";
    score("centroid error [cm]", p.centroid_error, 100.0);
    score(", hidden part [cm]", p.hidden_error, 100.0);
  }
  if (m.hindsight) {
    const HindsightBound& h = *m.hindsight;
    out << "\n  limit (hindsight): planned " << h.planned << ", followed " << m.mean_visible_fraction
        << ", without a speed limit " << h.unlimited << "; " << h.views << " views x " << h.steps << " steps, "
        << h.evaluations << " evaluations, planned in " << std::setprecision(1) << h.plan_s << " s"
        << std::setprecision(3);
  }
  if (m.poses) {
    const PoseSummary& p = *m.poses;
    out << "\n  poses: " << p.source << ", ATE " << 1000.0 * p.ate << " mm (max " << 1000.0 * p.ate_max
        << "), worst error " << 1000.0 * p.max_translation_error << " mm at " << p.max_translation_error_time << " s, "
        << p.max_rotation_error << " deg;";
    for (const auto& [status, count] : p.status_counts) out << ' ' << status << ' ' << count;
    if (p.unknown > 0) out << "; the loop stopped for " << p.unknown << " frame(s) of unknown pose";
  }
  out << "\n  distance to the sphere: max " << 100.0 * m.max_sphere_distance_error << " cm; path " << m.path_length
      << " m; mean angular error " << m.mean_angular_error_deg << " deg\n"
      << "  compute per step: " << 1e3 * m.mean_times.total() << " ms (render " << 1e3 * m.mean_times.render
      << ", perception " << 1e3 * m.mean_times.perception << ", estimate " << 1e3 * m.mean_times.estimate
      << " (worst " << 1e3 * m.max_times.estimate << ")"
      << ", control " << 1e3 * m.mean_times.control << ")\n";
  return out.str();
}

std::string trajectory_csv_header() {
  return "time,x,y,z,qx,qy,qz,qw,vx,vy,vz,wx,wy,wz,t0x,t0y,t0z,tfx,tfy,tfz,targetx,targety,targetz,status,safety,iterations,"
         "visible_fraction,angular_error_deg,sphere_distance_error,occluders_in_sphere,occluders_in_view,tracks,fastest_track_speed,"
         "predicted_occluders,"
         "render_s,perception_s,estimate_s,control_s,"
         "object_precision,object_recall,occluder_precision,occluder_recall,centroid_error,hidden_error,"
         "mode,guard,proposer,estimator_calls,pose_status,pose_error_m,pose_error_deg";
}

std::string trajectory_csv_row(const StepRecord& s) {
  std::ostringstream out;
  out.precision(12);  // velocities to 1e-12: `ofv run` replays them (test cli.one-loop)
  const Eigen::Quaterniond q(s.wMc.rotation());
  const Eigen::Vector3d p = s.wMc.translation();
  auto vec = [&](const std::optional<Eigen::Vector3d>& v) {
    if (v) {
      out << v->x() << ',' << v->y() << ',' << v->z() << ',';
    } else {
      out << ",,,";
    }
  };
  out << s.time << ',' << p.x() << ',' << p.y() << ',' << p.z() << ',' << q.x() << ',' << q.y()
      << ',' << q.z() << ',' << q.w() << ',';
  for (int k = 0; k < 6; ++k) out << s.velocity(k) << ',';
  vec(s.t0);
  vec(s.tf);
  vec(s.target);
  out << to_string(s.status) << ',' << to_string(s.safety) << ',' << s.iterations << ',' << s.visible_fraction << ','
      << s.angular_error_deg << ',' << s.sphere_distance_error << ',' << s.occluders_in_sphere
      << ',' << s.occluders_in_view << ',' << s.tracks << ',' << s.fastest_track_speed << ',' << s.predicted_occluders << ',' << s.times.render << ',' << s.times.perception << ',' << s.times.estimate << ','
      << s.times.control;
  for (const auto score : {&perception::PerceptionScores::object_precision, &perception::PerceptionScores::object_recall,
                           &perception::PerceptionScores::occluder_precision, &perception::PerceptionScores::occluder_recall,
                           &perception::PerceptionScores::centroid_error, &perception::PerceptionScores::hidden_error}) {
    out << ',';
    if (s.perception.*score) out << *(s.perception.*score);
  }
  out << ',' << to_string(s.mode) << ',' << to_string(s.guard) << ',' << to_string(s.proposer) << ','
      << s.estimator_calls << ',';
  // The simulator's own pose: no status, no error.
  if (s.pose) {
    out << s.pose->status << ',' << s.pose->translation_error << ',' << s.pose->rotation_error;
  } else {
    out << ",,";
  }
  return out.str();
}

}  // namespace ofv
