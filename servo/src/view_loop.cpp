// The per-frame policy: view selection, target continuity, control, safety.
#include "ofv/servo/view_loop.h"

#include "ofv/estimator_settings.h"
#include "ofv/servo/target_pose.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace ofv {

namespace {

using Clock = std::chrono::steady_clock;

// The estimator's working memory, prepared on the loop's thread before its
// first frame (not counted in estimate_s): the largest problems of the
// built-in scenarios make about 1.2·10^5 occlusion points (sweep, with the
// predicted occluders). 12 MB.
constexpr std::size_t kReservedOcclusionPoints = 250'000;

constexpr double kAway = 0.01;     // [m]: the camera has moved from a view
constexpr double kEvidence = 0.5;  // [s]: how long what a view showed counts as evidence
// A steady target: within kSteadyDeg of the previous frame's for
// kSteadyFrames frames (ViewLoop::retreat); on the way there, only a loss
// of more than kSteadyLoss of what the camera showed counts.
constexpr double kSteadyDeg = 10.0;
constexpr int kSteadyFrames = 10;
constexpr double kSteadyLoss = 0.5;

double seconds_since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}


// `none`, or xmin,ymin,zmin,xmax,ymax,zmax [m].
Eigen::AlignedBox3d parse_workspace(const std::string& value) {
  if (value == "none") return {};
  std::istringstream in(value);
  double v[6];
  char comma = ',';
  for (int i = 0; i < 6; ++i) {
    if ((i > 0 && !(in >> comma)) || comma != ',' || !(in >> v[i]) || !std::isfinite(v[i])) {
      throw std::invalid_argument("setting 'workspace' must be none or six numbers xmin,ymin,zmin,xmax,ymax,zmax, got \"" +
                                  value + "\"");
    }
  }
  in >> std::ws;
  const Eigen::AlignedBox3d box(Eigen::Vector3d(v[0], v[1], v[2]), Eigen::Vector3d(v[3], v[4], v[5]));
  if (!in.eof() || box.isEmpty()) {
    throw std::invalid_argument("setting 'workspace' must be none or a non-empty box xmin,ymin,zmin,xmax,ymax,zmax, got \"" +
                                value + "\"");
  }
  return box;
}

// The text parse_workspace() reads back.
std::string workspace_text(const Eigen::AlignedBox3d& box) {
  if (box.isEmpty()) return "none";
  std::string out;
  for (const Eigen::Vector3d& corner : {box.min(), box.max()}) {
    for (int a = 0; a < 3; ++a) out += (out.empty() ? "" : ",") + format_number(corner(a));
  }
  return out;
}

SettingsTable<LoopSettings> make_table() {
  using L = LoopSettings;
  const LoopSettings d;
  SettingsTable<L> t;
  t.include(estimator_settings_table(), [](auto& l) -> auto& { return l.estimator; });
  t.add({"method", "estimator | static | initial_view | sampling", to_string(d.method), "",
         "how the target view is chosen: the occlusion-free view, or a baseline"},
        [](L& l, const std::string& v) {
          l.method = parse_word<ViewMethod>("method", v,
                                            {{"estimator", ViewMethod::Estimator},
                                             {"static", ViewMethod::Static},
                                             {"initial_view", ViewMethod::InitialView},
                                             {"sampling", ViewMethod::Sampling}});
        },
        [](const L& l) { return std::string(to_string(l.method)); });
  t.add({"sampling_candidates", "integer in [1, 1000000]", std::to_string(d.sampling.candidates), "",
         "candidate views on the sphere of method=sampling (Fibonacci lattice), 1 to 1e6"},
        [](L& l, const std::string& v) {
          l.sampling.candidates = static_cast<int>(parse_integer("sampling_candidates", v, 1, 1000000));
        },
        [](const L& l) { return std::to_string(l.sampling.candidates); });
  t.add({"sampling_occluder_radius", "number in (0, 1]", format_number(d.sampling.occluder_radius), "m",
         "method=sampling: an occluder point blocks lines of sight passing closer than this"},
        [](L& l, const std::string& v) {
          l.sampling.occluder_radius = parse_number("sampling_occluder_radius", v, 0.0, 1.0, true);
        },
        [](const L& l) { return format_number(l.sampling.occluder_radius); });
  t.add({"controller", "sphere | pbvs", d.controller.law == ControllerSettings::Law::Sphere ? "sphere" : "pbvs", "",
         "sphere: FeatureSphereView, along the sphere with the object centred; pbvs: straight to the target pose"},
        [](L& l, const std::string& v) {
          l.controller.law = parse_word<ControllerSettings::Law>(
              "controller", v, {{"sphere", ControllerSettings::Law::Sphere}, {"pbvs", ControllerSettings::Law::Pbvs}});
        },
        [](const L& l) { return std::string(l.controller.law == ControllerSettings::Law::Sphere ? "sphere" : "pbvs"); });
  t.add({"gain", "number in (0, 100]", format_number(d.controller.gain), "1/s",
         "lambda: the error decays as exp(-gain t) until the speed limits bind"},
        [](L& l, const std::string& v) { l.controller.gain = parse_number("gain", v, 0.0, 100.0, true); },
        [](const L& l) { return format_number(l.controller.gain); });
  t.add({"adaptive_gain", "bool", format_bool(d.controller.adaptive_gain), "",
         "twice the gain near zero error, the gain far away (vpAdaptiveGain)"},
        [](L& l, const std::string& v) { l.controller.adaptive_gain = parse_bool("adaptive_gain", v); },
        [](const L& l) { return format_bool(l.controller.adaptive_gain); });
  t.add({"max_linear_speed", "number in (0, 10]", format_number(d.controller.max_linear_speed), "m/s",
         "the controller scales the linear velocity down to this; the safety filter enforces it"},
        [](L& l, const std::string& v) {
          l.controller.max_linear_speed = l.safety.max_linear_speed = parse_number("max_linear_speed", v, 0.0, 10.0, true);
        },
        [](const L& l) { return format_number(l.controller.max_linear_speed); });
  t.add({"max_angular_speed", "number in (0, 20]", format_number(d.controller.max_angular_speed), "rad/s",
         "the controller scales the angular velocity down to this; the safety filter enforces it"},
        [](L& l, const std::string& v) {
          l.controller.max_angular_speed = l.safety.max_angular_speed =
              parse_number("max_angular_speed", v, 0.0, 20.0, true);
        },
        [](const L& l) { return format_number(l.controller.max_angular_speed); });
  t.add({"target_filter", "number in [0, 10]", format_number(d.controller.target_filter), "s",
         "time constant of a low-pass on the target position; 0 = off"},
        [](L& l, const std::string& v) { l.controller.target_filter = parse_number("target_filter", v, 0.0, 10.0, false); },
        [](const L& l) { return format_number(l.controller.target_filter); });
  t.add({"target_hysteresis", "bool", format_bool(d.target_hysteresis), "",
         "while t0 is occluded, continue from the previous target (warm start) instead of re-estimating from t0"},
        [](L& l, const std::string& v) { l.target_hysteresis = parse_bool("target_hysteresis", v); },
        [](const L& l) { return format_bool(l.target_hysteresis); });
  t.add({"anticipation", "off | predict", to_string(d.anticipation.mode), "",
         "off: the paper's reactive view; predict: also keep clear of where tracked occluders will be over the horizon"},
        [](L& l, const std::string& v) {
          l.anticipation.mode = parse_word<Anticipation>("anticipation", v,
                                                         {{"off", Anticipation::Off}, {"predict", Anticipation::Predict}});
        },
        [](const L& l) { return std::string(to_string(l.anticipation.mode)); });
  t.add({"anticipation_horizon", "number in (0, 5]", format_number(d.anticipation.horizon), "s",
         "anticipation=predict: how far ahead the occluders' motion is followed"},
        [](L& l, const std::string& v) {
          l.anticipation.horizon = parse_number("anticipation_horizon", v, 0.0, 5.0, true);
        },
        [](const L& l) { return format_number(l.anticipation.horizon); });
  t.add({"anticipation_samples", "integer in [1, 10]", std::to_string(d.anticipation.samples), "",
         "anticipation=predict: predicted copies of a moving occluder over the horizon, 1 to 10"},
        [](L& l, const std::string& v) {
          l.anticipation.samples = static_cast<int>(parse_integer("anticipation_samples", v, 1, 10));
        },
        [](const L& l) { return std::to_string(l.anticipation.samples); });
  t.add({"anticipation_min_speed", "number in [0, 10]", format_number(d.anticipation.min_speed), "m/s",
         "anticipation=predict: occluders tracked slower than this are taken as still"},
        [](L& l, const std::string& v) {
          l.anticipation.min_speed = parse_number("anticipation_min_speed", v, 0.0, 10.0, false);
        },
        [](const L& l) { return format_number(l.anticipation.min_speed); });
  t.add({"track_link_distance", "number in (0, 1]", format_number(d.tracker.link_distance), "m",
         "occluder tracks: points closer than this are one occluder"},
        [](L& l, const std::string& v) {
          l.tracker.link_distance = parse_number("track_link_distance", v, 0.0, 1.0, true);
        },
        [](const L& l) { return format_number(l.tracker.link_distance); });
  t.add({"track_gate", "number in (0, 10]", format_number(d.tracker.gate), "m",
         "occluder tracks: largest distance of an occluder's centroid from its track's prediction"},
        [](L& l, const std::string& v) { l.tracker.gate = parse_number("track_gate", v, 0.0, 10.0, true); },
        [](const L& l) { return format_number(l.tracker.gate); });
  t.add({"track_accel_noise", "number in (0, 1000]", format_number(d.tracker.accel_noise), "m/s^2",
         "occluder tracks: white-noise acceleration of the constant-velocity Kalman filter"},
        [](L& l, const std::string& v) {
          l.tracker.accel_noise = parse_number("track_accel_noise", v, 0.0, 1000.0, true);
        },
        [](const L& l) { return format_number(l.tracker.accel_noise); });
  t.add({"track_measurement_noise", "number in (0, 1]", format_number(d.tracker.measurement_noise), "m",
         "occluder tracks: standard deviation of an occluder's measured centroid"},
        [](L& l, const std::string& v) {
          l.tracker.measurement_noise = parse_number("track_measurement_noise", v, 0.0, 1.0, true);
        },
        [](const L& l) { return format_number(l.tracker.measurement_noise); });
  t.add({"track_confirm_hits", "integer in [1, 1000]", std::to_string(d.tracker.confirm_hits), "",
         "occluder tracks: frames seen before a track is used, 1 to 1000"},
        [](L& l, const std::string& v) {
          l.tracker.confirm_hits = static_cast<int>(parse_integer("track_confirm_hits", v, 1, 1000));
        },
        [](const L& l) { return std::to_string(l.tracker.confirm_hits); });
  t.add({"track_max_misses", "integer in [0, 1000]", std::to_string(d.tracker.max_misses), "",
         "occluder tracks: frames unseen before a track is dropped, 0 to 1000"},
        [](L& l, const std::string& v) {
          l.tracker.max_misses = static_cast<int>(parse_integer("track_max_misses", v, 0, 1000));
        },
        [](const L& l) { return std::to_string(l.tracker.max_misses); });
  t.add({"retreat_drop", "number in [0, 1]", format_number(d.no_free_view.retreat_drop), "",
         "the fraction of the object the camera may see less, because it moved, than at the view that showed the "
         "most in the last 0.5 s, before it goes back there and holds (not when occluders moved in or came there "
         "too; on the way to a steady free view, only a loss of more than half); the object lost soon after, it "
         "drives back there too; 0 (off) to 1"},
        [](L& l, const std::string& v) { l.no_free_view.retreat_drop = parse_number("retreat_drop", v, 0.0, 1.0, false); },
        [](const L& l) { return format_number(l.no_free_view.retreat_drop); });
  t.add({"look_ahead", "bool", format_bool(d.no_free_view.look_ahead), "",
         "with retreat_drop > 0, until t0 has been clear (what hides the object was there from the start): where, on "
         "its way to the target, the occluders would hide retreat_drop more of the object (as far as it travels before "
         "it could stop), the camera climbs to a nearby view that sees clearly more, or holds"},
        [](L& l, const std::string& v) { l.no_free_view.look_ahead = parse_bool("look_ahead", v); },
        [](const L& l) { return format_bool(l.no_free_view.look_ahead); });
  t.add({"look_ahead_margin", "number in [0, 1]", format_number(d.no_free_view.margin), "",
         "look_ahead: a nearby view the camera climbs to must see this fraction more of the object than the current one, 0 to 1"},
        [](L& l, const std::string& v) {
          l.no_free_view.margin = parse_number("look_ahead_margin", v, 0.0, 1.0, false);
        },
        [](const L& l) { return format_number(l.no_free_view.margin); });
  t.add({"max_linear_accel", "number in (0, 100]", format_number(d.safety.max_linear_accel), "m/s^2",
         "safety filter: largest change of the linear velocity"},
        [](L& l, const std::string& v) { l.safety.max_linear_accel = parse_number("max_linear_accel", v, 0.0, 100.0, true); },
        [](const L& l) { return format_number(l.safety.max_linear_accel); });
  t.add({"max_angular_accel", "number in (0, 1000]", format_number(d.safety.max_angular_accel), "rad/s^2",
         "safety filter: largest change of the angular velocity"},
        [](L& l, const std::string& v) {
          l.safety.max_angular_accel = parse_number("max_angular_accel", v, 0.0, 1000.0, true);
        },
        [](const L& l) { return format_number(l.safety.max_angular_accel); });
  t.add({"stale_timeout", "number in (0, 60]", format_number(d.safety.stale_timeout), "s",
         "safety filter: a frame older than this when its command is sent stops the robot"},
        [](L& l, const std::string& v) { l.safety.stale_timeout = parse_number("stale_timeout", v, 0.0, 60.0, true); },
        [](const L& l) { return format_number(l.safety.stale_timeout); });
  t.add({"workspace", "none | xmin,ymin,zmin,xmax,ymax,zmax", "none", "m",
         "safety filter: the camera stays inside this box (world frame)"},
        [](L& l, const std::string& v) { l.safety.workspace = parse_workspace(v); },
        [](const L& l) { return workspace_text(l.safety.workspace); });
  return t;
}

}  // namespace

const SettingsTable<LoopSettings>& loop_settings_table() {
  static const SettingsTable<LoopSettings> table = make_table();
  return table;
}

const char* to_string(Anticipation a) { return a == Anticipation::Off ? "off" : "predict"; }

const char* to_string(StepStatus status) {
  switch (status) {
    case StepStatus::Converged: return "converged";
    case StepStatus::NotConverged: return "not_converged";
    case StepStatus::NoOccluders: return "no_occluders";
    case StepStatus::ObjectLost: return "object_lost";
  }
  return "?";
}

ViewLoop::ViewLoop(const LoopSettings& settings)
    : settings_(settings),
      estimator_(settings.estimator.resolve()),
      controller_(settings.controller),
      safety_(settings.safety),
      tracker_(settings.tracker) {
  if (settings_.sampling.candidates < 1 || !(settings_.sampling.occluder_radius > 0.0)) {
    throw std::invalid_argument("sampling settings: candidates must be >= 1 and occluder_radius positive");
  }
}

void ViewLoop::reset() {
  previous_view_.reset();
  previous_target_.reset();
  controller_.reset();
  safety_.reset();
  tracker_.reset();
  best_seen_.reset();
  held_.reset();
  low_frames_ = 0;
  target_direction_.reset();
  steady_frames_ = 0;
  release_when_steady_ = false;
  steadiness_ends_holds_ = false;
  t0_was_clear_ = false;
  last_centroid_.reset();
  track_history_.clear();
}

std::optional<Eigen::Vector3d> ViewLoop::retreat(const ViewProblem& problem, Eigen::Index seen,
                                                 const ViewEstimate& estimate, double shown, double dt,
                                                 const std::optional<Eigen::Vector3d>& target) {
  const NoFreeViewSettings& s = settings_.no_free_view;
  const Eigen::Vector3d& c = estimate.centroid;
  const Eigen::Vector3d& here = *problem.camera;
  if (s.retreat_drop <= 0.0) return target;
  constexpr int kFrames = 2;      // a loss counts when it lasts this many frames (one frame is noise)
  constexpr int kReleaseFrames = 6;  // back at the held view, this many frames showing less release it
  const double keep = 1.0 - s.retreat_drop;
  // A steady free view: the estimator converges, frame after frame, to a
  // target within kSteadyDeg of the previous frame's, for kSteadyFrames
  // frames. A way around an occluder stays where it is, and the camera may
  // lose some of the object on its way there (past the occluder's edge):
  // unless it loses more than half of what it showed (kSteadyLoss), that
  // is no reason to retreat. A hold that began while the target was not
  // yet steady (an occluder arriving) ends when it is. Gaps that only
  // perception's noise opens (an object in a cage of occluders) mostly
  // move from frame to frame; a hold that began on the way to a steady
  // target (it failed) is not ended by steadiness. Nor is any hold until
  // t0 has been clear: since the first frame (until then no occluder has
  // arrived: what hides t0 was there from the start, like a cage), and
  // again after a hold that steadiness ended (a steady target failed: in
  // a still cage the gaps are steady too).
  if (target && estimate.status == ViewStatus::Converged) {
    const Eigen::Vector3d direction = (*target - c).normalized();
    const bool near = target_direction_ && direction.dot(*target_direction_) >= std::cos(kSteadyDeg * EIGEN_PI / 180.0);
    steady_frames_ = near ? steady_frames_ + 1 : 1;
    target_direction_ = direction;
  } else {
    steady_frames_ = 0;
    target_direction_.reset();
  }
  const bool steady = steady_frames_ >= kSteadyFrames;
  if (estimate.iterations == 0) steadiness_ends_holds_ = t0_was_clear_ = true;
  if (held_) {
    const bool there = (here - held_->position).norm() <= kAway;
    low_frames_ = there && shown < keep * held_->shown ? low_frames_ + 1 : 0;
    const bool hold = estimate.iterations > 0 && low_frames_ < kReleaseFrames;
    if (hold && !(steady && release_when_steady_)) return held_->position;
    if (hold) steadiness_ends_holds_ = false;  // steadiness ended it
    held_.reset();  // t0 clear, or back there it keeps showing much less: the scene changed
    best_seen_ = SeenView{here, shown, problem.occluders.leftCols(seen), 0.0, track_positions()};
    low_frames_ = 0;
    return target;
  }
  if (best_seen_) best_seen_->age += dt;
  // What a view showed longer ago than kEvidence is no evidence any more
  // (the occluders move): the current view starts again.
  if (!best_seen_ || shown >= best_seen_->shown || !(best_seen_->age <= kEvidence)) {
    best_seen_ = SeenView{here, shown, problem.occluders.leftCols(seen), 0.0, track_positions()};
    low_frames_ = 0;
    return target;
  }
  const bool away = (here - best_seen_->position).norm() > kAway;
  const bool lost = shown < keep * best_seen_->shown && (!steady || shown < kSteadyLoss * best_seen_->shown);
  low_frames_ = away && lost ? low_frames_ + 1 : 0;
  if (low_frames_ < kFrames) return target;
  const double r = estimator_.r_sphere;
  const auto score = [&](const ViewProblem& scene, const Eigen::Vector3d& p) {
    return score_view(scene, c, r, c + r * (p - c).normalized(), s.occluder_radius).visible_fraction;
  };
  // The loss must come from the camera's own motion: with the occluders as
  // they were when that view showed the most, and those of this frame known
  // to stand still (revealed by the motion), here shows less than there by
  // retreat_drop too. Occluders that moved in since cost the object
  // wherever the camera is.
  const Eigen::Matrix3Xd still = revealed_still(*best_seen_);
  ViewProblem then = problem;
  then.occluders.resize(3, best_seen_->occluders.cols() + still.cols());
  then.occluders << best_seen_->occluders, still;
  if (!(score(then, here) < keep * score(then, best_seen_->position))) return target;
  // The frame's occluders must make that view clearly better, or at least
  // not worse where they hide most of the object from here.
  const double here_score = score(problem, here);
  const double margin = here_score < 0.5 ? 0.0 : 0.1;
  if (score(problem, best_seen_->position) < here_score + margin) return target;  // the occluders came there too
  held_ = best_seen_;
  release_when_steady_ = !steady && steadiness_ends_holds_;
  low_frames_ = 0;
  return held_->position;
}

std::optional<Eigen::Vector3d> ViewLoop::look_ahead(const ViewProblem& problem,
                                                     const Eigen::Vector3d& c,
                                                     const std::optional<Eigen::Vector3d>& target, double dt,
                                                     double frame_age) const {
  const NoFreeViewSettings& s = settings_.no_free_view;
  // Only until t0 has been clear: what hides the object was there from the
  // start and stands still (a cage). What came in since may stand on the
  // way out of the valley the camera is in, where going on beats holding
  // (an arm that stopped over the object; the retreat still acts on a loss).
  if (!s.look_ahead || !(s.retreat_drop > 0.0) || !target || held_ || t0_was_clear_) return target;
  const double r = estimator_.r_sphere;
  const Eigen::Vector3d from = (*problem.camera - c).normalized();
  const auto score = [&](const Eigen::Vector3d& direction) {
    return score_view(problem, c, r, c + r * direction, s.occluder_radius).visible_fraction;
  };
  const double now = score(from);
  // How far the camera may go before a frame shows the loss and it stops:
  // at the speed limit for the frame's age and one period, then braking.
  const double v = settings_.safety.max_linear_speed;
  const double a = settings_.safety.max_linear_accel;
  const double reach = v * (std::max(frame_age, 0.0) + dt) + v * v / (2.0 * a);
  const bool steady = steady_frames_ >= kSteadyFrames;
  // Whether the way to `goal` (3 points on the great circle, the last at
  // `reach`) loses what the look-ahead counts.
  const auto loses_on_the_way = [&](const Eigen::Vector3d& goal) {
    const Eigen::Vector3d to = (goal - c).normalized();
    const double angle = std::acos(std::clamp(from.dot(to), -1.0, 1.0));
    if (r * angle <= kAway || !(std::sin(angle) > 1e-9)) return false;  // there, or straight across: no one way
    double worst = now;
    constexpr int kSamples = 3;
    for (int k = 1; k <= kSamples; ++k) {
      const double along = std::min(angle, reach / r) * k / kSamples;  // from `from` towards `to`
      worst = std::min(worst, score((std::sin(angle - along) * from + std::sin(along) * to) / std::sin(angle)));
    }
    return worst < (1.0 - s.retreat_drop) * now && (!steady || worst < kSteadyLoss * now);
  };
  if (!loses_on_the_way(*target)) return target;
  // Climb to a nearby view that sees clearly more, if the way there keeps
  // what the camera sees (holding alone, it would stay wherever it
  // started); else hold.
  const Eigen::Vector3d climb = most_visible_view(problem, c, r, *problem.camera, {}, s).view;
  return loses_on_the_way(climb) ? c + r * from : climb;
}

std::vector<std::pair<int, Eigen::Vector3d>> ViewLoop::track_positions() const {
  std::vector<std::pair<int, Eigen::Vector3d>> out;
  for (const OccluderTrack& t : tracker_.tracks()) out.emplace_back(t.id, t.position);
  return out;
}

Eigen::Matrix3Xd ViewLoop::revealed_still(const SeenView& then) const {
  // A track that stands still now came there, and was not revealed by the
  // camera, when it moved farther than this since `then` (or, not tracked
  // then, since it was first seen), or when it came into view moving (an
  // arm that arrived and stopped).
  constexpr double kMovedSince = 0.05;  // [m]
  std::vector<OccluderTrack> still;
  for (const OccluderTrack& t : tracker_.tracks()) {
    if (!is_still(t, settings_.anticipation.min_speed)) continue;
    const TrackHistory& history = track_history_.at(t.id);
    const auto was = std::find_if(then.tracks.begin(), then.tracks.end(), [&](const auto& p) { return p.first == t.id; });
    const Eigen::Vector3d& since = was != then.tracks.end() ? was->second : history.first_position;
    if (!history.arrived && (t.position - since).norm() <= kMovedSince) still.push_back(t);
  }
  return still_occluders(still, settings_.anticipation.min_speed);
}

void ViewLoop::remember_tracks(const std::vector<OccluderTrack>& tracks, double dt) {
  // Moving within this time of being first seen, a track came into view
  // moving: it arrived, the camera did not reveal it.
  constexpr double kArrival = 0.3;  // [s]
  std::map<int, TrackHistory> history;
  for (const OccluderTrack& t : tracks) {
    const auto known = track_history_.find(t.id);
    TrackHistory h{t.position};
    if (known != track_history_.end()) {
      h = known->second;
      h.age += dt;
    }
    h.arrived = h.arrived || (h.age <= kArrival && is_moving(t, settings_.anticipation.min_speed));
    history.emplace(t.id, h);
  }
  track_history_ = std::move(history);
}

std::optional<Eigen::Vector3d> ViewLoop::way_back(const Eigen::Vector3d& here, double dt) {
  if (settings_.no_free_view.retreat_drop <= 0.0 || !last_centroid_) return std::nullopt;
  if (!held_) {
    if (!best_seen_) return std::nullopt;
    best_seen_->age += dt;
    if (!(best_seen_->age <= kEvidence)) return std::nullopt;  // not lost by the camera's recent motion
    held_ = best_seen_;
    release_when_steady_ = false;
    low_frames_ = 0;
  }
  if ((here - held_->position).norm() <= kAway) return std::nullopt;  // back there: wait for perception
  return held_->position;
}

std::optional<ViewEstimate> ViewLoop::from_previous_target(const ViewProblem& problem) const {
  if (!settings_.target_hysteresis || !previous_target_) return std::nullopt;
  ViewProblem from_previous = problem;
  from_previous.previous_view = *previous_target_;
  EstimatorSettings warm = estimator_;
  warm.warm_start = true;
  return estimate_view(from_previous, warm);
}

std::optional<Eigen::Vector3d> ViewLoop::choose_target(const ViewProblem& problem, const ViewEstimate& estimate,
                                                       const std::optional<ViewEstimate>& kept) {
  const double r_sphere = estimator_.r_sphere;
  switch (settings_.method) {
    case ViewMethod::Static: return std::nullopt;
    case ViewMethod::InitialView: return estimate.t0;
    case ViewMethod::Sampling: {
      const Eigen::Vector3d best = sample_best_view(problem, estimate.centroid, r_sphere, settings_.sampling).view;
      if (!settings_.target_hysteresis || !previous_target_) return best;
      // Keep the previous view while it sees as much as the new best.
      const Eigen::Vector3d previous = estimate.centroid + r_sphere * (*previous_target_ - estimate.centroid).normalized();
      const double rho = settings_.sampling.occluder_radius;
      return score_view(problem, estimate.centroid, r_sphere, previous, rho).visible_fraction >=
                     score_view(problem, estimate.centroid, r_sphere, best, rho).visible_fraction
                 ? previous
                 : best;
    }
    case ViewMethod::Estimator: break;
  }
  if (settings_.target_hysteresis && previous_target_ && estimate.iterations > 0) {
    // t0 is occluded: continue from the previous target (the spec's warm
    // start), which stays where it is while clear and otherwise moves to
    // the nearest clear view. While t0 is clear, t0 is the target.
    const std::optional<ViewEstimate> warm = kept ? kept : from_previous_target(problem);
    if (is_free(warm->status)) return warm->tf;
  }
  // Without a free view, the spec's best iterate.
  return estimate.tf;
}

Eigen::Matrix3Xd ViewLoop::predicted(const Eigen::Vector3d& centroid) const {
  const AnticipationSettings& a = settings_.anticipation;
  std::vector<double> times;
  for (int k = 1; k <= a.samples; ++k) times.push_back(a.horizon * k / a.samples);
  const Eigen::Matrix3Xd all = predicted_occluders(tracker_.tracks(), times, a.min_speed);
  // Only the copies inside the sphere are occluders (spec §3).
  std::vector<Eigen::Index> inside;
  for (Eigen::Index i = 0; i < all.cols(); ++i) {
    if ((all.col(i) - centroid).norm() < estimator_.r_sphere) inside.push_back(i);
  }
  return all(Eigen::all, inside);
}

LoopStep ViewLoop::step(const Observation& observation, double dt) {
  LoopStep out;
  reserve_estimator_memory(kReservedOcclusionPoints);  // once per thread
  auto start = Clock::now();
  const vpHomogeneousMatrix wMc = to_visp(observation.wMc);
  const double frame_age = observation.age;
  // The estimator avoids the occluders seen and those presumed (last).
  std::optional<ViewProblem> problem = observation.problem;
  const Eigen::Index seen = problem ? problem->occluders.cols() : 0;
  if (problem) {
    if (observation.presumed.cols() > 0) problem->occluders = observation.all_occluders();
    problem->camera = observation.wMc.translation();
    problem->previous_view = previous_view_;
    out.estimate = estimate_view(*problem, estimator_);
    if (out.estimate->status == ViewStatus::NoSupervoxels) out.estimate.reset();
  }
  const bool timed = std::isfinite(dt) && dt > 0.0;
  if (!timed) {  // no time base: start the tracks again
    tracker_.reset();
    track_history_.clear();
  }
  if (problem) {
    out.presumed_occluders = problem->occluders.cols() - seen;
    out.tracks = tracker_.update(problem->occluders.leftCols(seen), dt);
  } else {
    out.tracks = tracker_.coast(dt);
  }
  remember_tracks(out.tracks, timed ? dt : 0.0);
  if (out.estimate) {
    switch (out.estimate->status) {
      case ViewStatus::Converged: out.status = StepStatus::Converged; break;
      case ViewStatus::NotConverged:
      case ViewStatus::OutOfTime: out.status = StepStatus::NotConverged; break;
      default: out.status = StepStatus::NoOccluders; break;
    }
    const ViewProblem* basis = &*problem;
    ViewProblem ahead;
    std::optional<ViewEstimate> kept;  // from the previous target, on `ahead`
    if (settings_.anticipation.mode == Anticipation::Predict) {
      const Eigen::Matrix3Xd future = predicted(out.estimate->centroid);
      if (future.cols() > 0) {
        ahead = *problem;
        ahead.occluders.resize(3, problem->occluders.cols() + future.cols());
        ahead.occluders << problem->occluders, future;
        // From the view clear of the occluders as they are now (the spec's
        // warm start): fewer iterations than from t0 when the future ones
        // only nudge it.
        ahead.previous_view = out.estimate->tf;
        EstimatorSettings from_now = estimator_;
        from_now.warm_start = true;
        // That view stays the target if it is clear of the predicted
        // occluders too (0 iterations: only whether the start is clear).
        // Otherwise choose_target continues from the previous target and
        // takes that if it is free: estimated first here, so that the
        // search from the frame's view runs only when it is not.
        from_now.max_iterations = 0;
        ViewEstimate anticipated = estimate_view(ahead, from_now);
        if (!is_free(anticipated.status)) {
          kept = settings_.method == ViewMethod::Estimator ? from_previous_target(ahead) : std::nullopt;
          if (kept && is_free(kept->status)) {
            anticipated = *kept;
          } else {
            from_now.max_iterations = estimator_.max_iterations;
            anticipated = estimate_view(ahead, from_now);
          }
        }
        if (is_free(anticipated.status)) {
          out.predicted_occluders = future.cols();
          out.anticipated = std::move(anticipated);
          basis = &ahead;
        } else {
          kept.reset();  // on `ahead`, not on the basis
        }
      }
    }
    out.target = choose_target(*basis, out.anticipated ? *out.anticipated : *out.estimate, kept);
    if (settings_.method == ViewMethod::Estimator && observation.shown_area) {
      out.target = retreat(*problem, seen, *out.estimate, *observation.shown_area, dt, out.target);
      out.target = look_ahead(*problem, out.estimate->centroid, out.target, dt, frame_age);
    }
    previous_view_ = out.estimate->tf;
    previous_target_ = out.target;
    last_centroid_ = out.estimate->centroid;
  } else if (settings_.method == ViewMethod::Estimator) {
    out.target = way_back(observation.wMc.translation(), dt);
  }
  out.estimate_s = seconds_since(start);

  start = Clock::now();
  if (out.target) {
    out.command = controller_.update(*out.target, *last_centroid_, estimator_.r_sphere, wMc, dt);
  }
  // Lost, the camera moves only on its way back (way_back).
  out.velocity = safety_.filter(out.command, wMc, dt, out.estimate.has_value() || out.target.has_value(), frame_age);
  out.safety = safety_.last_action();
  out.control_s = seconds_since(start);
  return out;
}

}  // namespace ofv
