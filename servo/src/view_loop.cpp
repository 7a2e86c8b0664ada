// The per-frame policy: view selection, target continuity, control, safety.
#include "ofv/servo/view_loop.h"

#include "ofv/estimator_settings.h"
#include "ofv/servo/target_pose.h"
#include "world_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

namespace ofv::servo {

namespace {

using Clock = std::chrono::steady_clock;

// The estimator's working memory, prepared on the loop's thread before its
// first frame (not counted in estimate_s): the largest problems of the
// built-in scenarios make about 1.2·10^5 occlusion points (sweep, with the
// predicted occluders). 12 MB.
constexpr std::size_t kReservedOcclusionPoints = 250'000;


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
  t.add({"retreat_drop", "number in [0, 1]", format_number(d.retreat.drop), "",
         "the fraction of the object the camera may see less, because it moved, than at the view that showed the "
         "most in the last 0.5 s, before it goes back there and holds (not when occluders moved in or came there "
         "too); the object lost soon after, it drives back there too; 0 (off) to 1"},
        [](L& l, const std::string& v) { l.retreat.drop = parse_number("retreat_drop", v, 0.0, 1.0, false); },
        [](const L& l) { return format_number(l.retreat.drop); });
  t.add({"look_ahead", "bool", format_bool(d.retreat.look_ahead), "",
         "with retreat_drop > 0, until t0 has been clear (what hides the object was there from the start): where, on "
         "its way to the target, the occluders would hide retreat_drop more of the object (as far as it travels before "
         "it could stop), the camera climbs to a nearby view that sees clearly more, or holds"},
        [](L& l, const std::string& v) { l.retreat.look_ahead = parse_bool("look_ahead", v); },
        [](const L& l) { return format_bool(l.retreat.look_ahead); });
  t.add({"look_ahead_margin", "number in [0, 1]", format_number(d.retreat.climb.margin), "",
         "look_ahead: a nearby view the camera climbs to must see this fraction more of the object than the current one, 0 to 1"},
        [](L& l, const std::string& v) {
          l.retreat.climb.margin = parse_number("look_ahead_margin", v, 0.0, 1.0, false);
        },
        [](const L& l) { return format_number(l.retreat.climb.margin); });
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

const char* to_string(LoopMode mode) {
  switch (mode) {
    case LoopMode::Pursue: return "pursue";
    case LoopMode::Hold: return "hold";
    case LoopMode::WayBack: return "way_back";
    case LoopMode::Waiting: return "waiting";
    case LoopMode::Lost: return "lost";
  }
  return "?";
}

const char* to_string(Guard guard) {
  switch (guard) {
    case Guard::None: return "none";
    case Guard::CameraCostView: return "camera_cost_view";
    case Guard::T0Clear: return "t0_clear";
    case Guard::SceneChanged: return "scene_changed";
    case Guard::ObjectLost: return "object_lost";
    case Guard::ObjectLostNoView: return "object_lost_no_view";
    case Guard::BackThere: return "back_there";
    case Guard::AwayAgain: return "away_again";
    case Guard::ObjectFound: return "object_found";
  }
  return "?";
}

const char* to_string(Proposer proposer) {
  switch (proposer) {
    case Proposer::None: return "none";
    case Proposer::Estimate: return "estimate";
    case Proposer::Anticipated: return "anticipated";
    case Proposer::WarmStart: return "warm_start";
    case Proposer::Climb: return "climb";
    case Proposer::Here: return "here";
    case Proposer::BestSeen: return "best_seen";
    case Proposer::InitialView: return "initial_view";
    case Proposer::Sampling: return "sampling";
  }
  return "?";
}

namespace {

// A view and who proposed it (no view: the camera stops).
struct Candidate {
  std::optional<Eigen::Vector3d> view;
  Proposer by = Proposer::None;
};


}  // namespace

const std::vector<LoopTransition>& loop_transitions() {
  static const std::vector<LoopTransition> table{
      {LoopMode::Pursue, Guard::CameraCostView, LoopMode::Hold},
      {LoopMode::Pursue, Guard::ObjectLost, LoopMode::WayBack},
      {LoopMode::Pursue, Guard::ObjectLostNoView, LoopMode::Lost},
      {LoopMode::Hold, Guard::T0Clear, LoopMode::Pursue},
      {LoopMode::Hold, Guard::SceneChanged, LoopMode::Pursue},
      {LoopMode::Hold, Guard::ObjectLost, LoopMode::WayBack},
      {LoopMode::WayBack, Guard::BackThere, LoopMode::Waiting},
      {LoopMode::WayBack, Guard::ObjectFound, LoopMode::Hold},
      {LoopMode::Waiting, Guard::AwayAgain, LoopMode::WayBack},
      {LoopMode::Waiting, Guard::ObjectFound, LoopMode::Hold},
      {LoopMode::Lost, Guard::ObjectFound, LoopMode::Pursue},
  };
  return table;
}

struct ViewLoop::Impl {
  explicit Impl(const LoopSettings& s)
      : settings(s),
        estimator(s.estimator.resolve()),
        controller(s.controller),
        safety(s.safety),
        world(s.tracker, s.anticipation.min_speed, s.retreat.arrival, s.retreat.moved) {
    if (settings.sampling.candidates < 1 || !(settings.sampling.occluder_radius > 0.0)) {
      throw std::invalid_argument("sampling settings: candidates must be >= 1 and occluder_radius positive");
    }
    const RetreatSettings& r = settings.retreat;
    if (!(r.drop >= 0.0 && r.drop <= 1.0) || !(r.memory > 0.0) || r.frames < 1 || r.release_frames < 1 ||
        !(r.at >= 0.0) || !(r.arrival >= 0.0) || !(r.moved >= 0.0) || r.look_ahead_samples < 1 ||
        !(r.climb.step_deg > 0.0) || !(r.climb.margin >= 0.0) || !(r.climb.occluder_radius > 0.0)) {
      throw std::invalid_argument(
          "retreat settings: drop in [0, 1], memory > 0 s, frames, release_frames and look_ahead_samples >= 1, "
          "at, arrival, moved and climb.margin >= 0, climb.step_deg and climb.occluder_radius > 0");
    }
  }

  // A camera position (world), how much of the object it showed, the
  // occluders seen in that frame, how long ago that was and where the
  // occluder tracks were.
  struct SeenView {
    Eigen::Vector3d position;
    double shown = 0.0;
    Eigen::Matrix3Xd occluders;
    double age = 0.0;  // time since [s]
    TrackPositions tracks;
  };

  // What one frame brings to the stages after the world model.
  struct Frame {
    const ViewProblem& problem;  // seen and presumed occluders
    const OcclusionField& field;  // prepared from `problem`
    Eigen::Index seen;            // its first `seen` occluders were seen
    const ViewEstimate& estimate;
    Eigen::Vector3d here;
    double shown;  // [m²]
    double dt, age;
  };

  LoopStep step(const Observation& observation, double dt);
  void reset();

  // --- proposers
  ViewEstimate estimate_view_counted(const OcclusionField& field, const EstimatorSettings& settings,
                                     const std::optional<Eigen::Vector3d>& start);
  std::optional<ViewEstimate> from_previous_target(const OcclusionField& field);
  Candidate pursue(const ViewProblem& problem, const OcclusionField& field, LoopStep& out);
  Candidate look_ahead(const Frame& f, const Candidate& pursuit) const;
  // --- the mode machine
  void transition(Guard guard, LoopStep& out);
  void found(const Frame& f, LoopStep& out);
  void lost(const Eigen::Vector3d& here, double dt, LoopStep& out);
  bool camera_cost_view(const Frame& f);
  [[nodiscard]] SeenView seen_here(const Frame& f) const {
    return SeenView{f.here, f.shown, f.problem.occluders.leftCols(f.seen), 0.0, world.positions()};
  }

  LoopSettings settings;
  EstimatorSettings estimator;
  ViewController controller;
  SafetyFilter safety;
  WorldModel world;
  int estimator_calls = 0;
  LoopMode mode = LoopMode::Lost;
  std::optional<Eigen::Vector3d> previous_view, previous_target;
  std::optional<Eigen::Vector3d> last_centroid;  // C of the last frame that found the object
  std::optional<SeenView> best_seen;  // the view that showed the most of the object
  std::optional<SeenView> held;       // modes hold, way back, waiting: that view
  int low_frames = 0;                 // frames in a row showing much less than best_seen or held
  bool t0_was_clear = false;          // t0 was clear in some frame since the start
};

ViewLoop::ViewLoop(const LoopSettings& settings) : impl_(std::make_unique<Impl>(settings)) {}
ViewLoop::~ViewLoop() = default;
ViewLoop::ViewLoop(ViewLoop&&) noexcept = default;
ViewLoop& ViewLoop::operator=(ViewLoop&&) noexcept = default;
LoopStep ViewLoop::step(const Observation& observation, double dt) { return impl_->step(observation, dt); }
void ViewLoop::reset() { impl_->reset(); }
const LoopSettings& ViewLoop::settings() const { return impl_->settings; }
const EstimatorSettings& ViewLoop::estimator() const { return impl_->estimator; }

void ViewLoop::Impl::reset() {
  previous_view.reset();
  previous_target.reset();
  controller.reset();
  safety.reset();
  world.reset();
  mode = LoopMode::Lost;
  best_seen.reset();
  held.reset();
  low_frames = 0;
  t0_was_clear = false;
  last_centroid.reset();
}

ViewEstimate ViewLoop::Impl::estimate_view_counted(const OcclusionField& field, const EstimatorSettings& s,
                                                   const std::optional<Eigen::Vector3d>& start) {
  ++estimator_calls;
  return estimate_view(field, s, start);
}

std::optional<ViewEstimate> ViewLoop::Impl::from_previous_target(const OcclusionField& field) {
  if (!settings.target_hysteresis || !previous_target) return std::nullopt;
  EstimatorSettings warm = estimator;
  warm.warm_start = true;
  return estimate_view_counted(field, warm, previous_target);
}

// The proposers of mode pursue: the frame's estimate, the anticipated
// estimate, the warm start from the previous target, or a baseline's view.
Candidate ViewLoop::Impl::pursue(const ViewProblem& problem, const OcclusionField& field, LoopStep& out) {
  const ViewEstimate& estimate = *out.estimate;
  const OcclusionField* basis = &field;
  std::optional<OcclusionField> ahead;
  std::optional<ViewEstimate> kept;  // from the previous target, on `ahead`
  if (settings.anticipation.mode == Anticipation::Predict) {
    const AnticipationSettings& a = settings.anticipation;
    const Eigen::Matrix3Xd future = world.predicted(a.horizon, a.samples, estimate.centroid, estimator.r_sphere);
    if (future.cols() > 0) {
      ViewProblem with_future = problem;
      with_future.occluders.resize(3, problem.occluders.cols() + future.cols());
      with_future.occluders << problem.occluders, future;
      ahead.emplace(with_future, estimator.r_sphere);
      // From the view clear of the occluders as they are now (the spec's
      // warm start): fewer iterations than from t0 when the future ones
      // only nudge it. That view stays the target if it is clear of the
      // predicted occluders too (0 iterations: only whether the start is
      // clear). Otherwise the warm start from the previous target, if it
      // is free; only then the search from the frame's view.
      EstimatorSettings from_now = estimator;
      from_now.warm_start = true;
      from_now.max_iterations = 0;
      ViewEstimate anticipated = estimate_view_counted(*ahead, from_now, estimate.tf);
      if (!is_free(anticipated.status)) {
        kept = settings.method == ViewMethod::Estimator ? from_previous_target(*ahead) : std::nullopt;
        if (kept && is_free(kept->status)) {
          anticipated = *kept;
        } else {
          from_now.max_iterations = estimator.max_iterations;
          anticipated = estimate_view_counted(*ahead, from_now, estimate.tf);
        }
      }
      if (is_free(anticipated.status)) {
        out.predicted_occluders = future.cols();
        out.anticipated = std::move(anticipated);
        basis = &*ahead;
      } else {
        kept.reset();  // on `ahead`, not on the basis
      }
    }
  }
  const ViewEstimate& chosen = out.anticipated ? *out.anticipated : estimate;
  const double r_sphere = estimator.r_sphere;
  switch (settings.method) {
    case ViewMethod::Static: return {};
    case ViewMethod::InitialView: return {chosen.t0, Proposer::InitialView};
    case ViewMethod::Sampling: {
      const Eigen::Vector3d best = sample_best_view(*basis, settings.sampling).view;
      if (!settings.target_hysteresis || !previous_target) return {best, Proposer::Sampling};
      // Keep the previous view while it sees as much as the new best.
      const Eigen::Vector3d previous = chosen.centroid + r_sphere * (*previous_target - chosen.centroid).normalized();
      const double rho = settings.sampling.occluder_radius;
      const bool keep =
          score_view(*basis, previous, rho).visible_fraction >= score_view(*basis, best, rho).visible_fraction;
      return {keep ? previous : best, Proposer::Sampling};
    }
    case ViewMethod::Estimator: break;
  }
  if (settings.target_hysteresis && previous_target && chosen.iterations > 0) {
    // t0 is occluded: continue from the previous target (the spec's warm
    // start), which stays where it is while clear and otherwise moves to
    // the nearest clear view. While t0 is clear, t0 is the target.
    const std::optional<ViewEstimate> warm = kept ? kept : from_previous_target(*basis);
    if (is_free(warm->status)) return {warm->tf, Proposer::WarmStart};
  }
  // Without a free view, the spec's best iterate.
  return {chosen.tf, out.anticipated ? Proposer::Anticipated : Proposer::Estimate};
}

// RetreatSettings::look_ahead: the pursuit's view, or when the way there
// hides more of the object, a nearby view that sees more (most_visible_view)
// or the camera's own view (hold).
Candidate ViewLoop::Impl::look_ahead(const Frame& f, const Candidate& pursuit) const {
  const RetreatSettings& s = settings.retreat;
  // Only until t0 has been clear: what hides the object was there from the
  // start and stands still (a cage). What came in since may stand on the
  // way out of the valley the camera is in, where going on beats holding
  // (an arm that stopped over the object; the retreat still acts on a loss).
  if (!s.look_ahead || !pursuit.view || t0_was_clear) return pursuit;
  const double away = s.at;
  const Eigen::Vector3d& c = f.estimate.centroid;
  const double r = estimator.r_sphere;
  const Eigen::Vector3d from = (f.here - c).normalized();
  const auto score = [&](const Eigen::Vector3d& direction) {
    return score_view(f.field, c + r * direction, s.climb.occluder_radius).visible_fraction;
  };
  const double now = score(from);
  // How far the camera may go before a frame shows the loss and it stops:
  // at the speed limit for the frame's age and one period, then braking.
  const double v = settings.safety.max_linear_speed;
  const double a = settings.safety.max_linear_accel;
  const double reach = v * (std::max(f.age, 0.0) + f.dt) + v * v / (2.0 * a);
  // Whether the way to `goal` (3 points on the great circle, the last at
  // `reach`) loses what the look-ahead counts.
  const auto loses_on_the_way = [&](const Eigen::Vector3d& goal) {
    const Eigen::Vector3d to = (goal - c).normalized();
    const double angle = std::acos(std::clamp(from.dot(to), -1.0, 1.0));
    if (r * angle <= away || !(std::sin(angle) > 1e-9)) return false;  // there, or straight across: no one way
    double worst = now;
    for (int k = 1; k <= s.look_ahead_samples; ++k) {
      const double along = std::min(angle, reach / r) * k / s.look_ahead_samples;  // from `from` towards `to`
      worst = std::min(worst, score((std::sin(angle - along) * from + std::sin(along) * to) / std::sin(angle)));
    }
    return worst < (1.0 - s.drop) * now;
  };
  if (!loses_on_the_way(*pursuit.view)) return pursuit;
  // Climb to a nearby view that sees clearly more, if the way there keeps
  // what the camera sees (holding alone, it would stay wherever it
  // started); else hold.
  const Eigen::Vector3d climb = most_visible_view(f.field, f.here, {}, s.climb).view;
  if (loses_on_the_way(climb)) return {Eigen::Vector3d(c + r * from), Proposer::Here};
  return {climb, Proposer::Climb};
}

void ViewLoop::Impl::transition(Guard guard, LoopStep& out) {
  const std::vector<LoopTransition>& table = loop_transitions();
  const auto t = std::find_if(table.begin(), table.end(),
                              [&](const LoopTransition& x) { return x.from == mode && x.guard == guard; });
  if (t == table.end()) {
    throw std::logic_error(std::string("ViewLoop: no transition from ") + to_string(mode) + " by " + to_string(guard));
  }
  mode = t->to;
  out.guard = guard;
}

// Guard camera_cost_view (mode pursue), with the evidence it keeps: the view
// that showed the most in the last `memory`, and the frames in a row that
// showed `drop` less away from it. The loss must come from the
// camera's own motion: with the occluders as they were when that view
// showed the most, and those of this frame known to stand still (revealed
// by the motion: WorldModel::revealed_still), here shows less than there by
// `drop` too (occluders that moved in since cost the object wherever
// the camera is); and with this frame's occluders, that view must not show
// less than here (they came there too).
bool ViewLoop::Impl::camera_cost_view(const Frame& f) {
  const RetreatSettings& s = settings.retreat;
  const double keep = 1.0 - s.drop;
  if (best_seen) best_seen->age += f.dt;
  // What a view showed longer ago than `memory` is no evidence any more
  // (the occluders move): the current view starts again.
  if (!best_seen || f.shown >= best_seen->shown || !(best_seen->age <= s.memory)) {
    best_seen = seen_here(f);
    low_frames = 0;
    return false;
  }
  const bool away = (f.here - best_seen->position).norm() > s.at;
  low_frames = away && f.shown < keep * best_seen->shown ? low_frames + 1 : 0;
  if (low_frames < s.frames) return false;
  const Eigen::Vector3d& c = f.estimate.centroid;
  const double r = estimator.r_sphere;
  const double rho = s.climb.occluder_radius;
  const auto on_sphere = [&](const Eigen::Vector3d& p) { return Eigen::Vector3d(c + r * (p - c).normalized()); };
  const Eigen::Matrix3Xd still = world.revealed_still(best_seen->tracks);
  ViewProblem then = f.problem;
  then.occluders.resize(3, best_seen->occluders.cols() + still.cols());
  then.occluders << best_seen->occluders, still;
  const auto score_then = [&](const Eigen::Vector3d& p) {
    return score_view(then, c, r, on_sphere(p), rho).visible_fraction;
  };
  if (!(score_then(f.here) < keep * score_then(best_seen->position))) return false;
  return score_view(f.field, on_sphere(best_seen->position), rho).visible_fraction >=
         score_view(f.field, on_sphere(f.here), rho).visible_fraction;
}

// The mode machine in a frame that found the object (the retreat on).
void ViewLoop::Impl::found(const Frame& f, LoopStep& out) {
  const RetreatSettings& s = settings.retreat;
  const double keep = 1.0 - s.drop;
  if (f.estimate.iterations == 0) t0_was_clear = true;
  if (mode == LoopMode::WayBack || mode == LoopMode::Waiting || mode == LoopMode::Lost) {
    transition(Guard::ObjectFound, out);
  }
  if (mode == LoopMode::Hold) {
    const bool there = (f.here - held->position).norm() <= s.at;
    low_frames = there && f.shown < keep * held->shown ? low_frames + 1 : 0;
    Guard release = Guard::None;
    if (f.estimate.iterations == 0) {
      release = Guard::T0Clear;
    } else if (low_frames >= s.release_frames) {
      release = Guard::SceneChanged;
    }
    if (release == Guard::None) return;
    transition(release, out);
    held.reset();
    best_seen = seen_here(f);
    low_frames = 0;
    return;
  }
  if (camera_cost_view(f)) {
    transition(Guard::CameraCostView, out);
    held = best_seen;
    low_frames = 0;
  }
}

// The mode machine in a frame without the object (the retreat on).
void ViewLoop::Impl::lost(const Eigen::Vector3d& here, double dt, LoopStep& out) {
  if (mode == LoopMode::Pursue || mode == LoopMode::Lost) {
    if (best_seen) best_seen->age += dt;
    if (mode == LoopMode::Pursue) {
      if (best_seen && best_seen->age <= settings.retreat.memory) {
        transition(Guard::ObjectLost, out);
        held = best_seen;
        low_frames = 0;
      } else {
        transition(Guard::ObjectLostNoView, out);
      }
    }
  } else if (mode == LoopMode::Hold) {
    transition(Guard::ObjectLost, out);
  }
  const bool there = held && (here - held->position).norm() <= settings.retreat.at;
  if (mode == LoopMode::WayBack && there) transition(Guard::BackThere, out);
  if (mode == LoopMode::Waiting && !there) transition(Guard::AwayAgain, out);
}

LoopStep ViewLoop::Impl::step(const Observation& observation, double dt) {
  LoopStep out;
  estimator_calls = 0;
  reserve_estimator_memory(kReservedOcclusionPoints);  // once per thread
  auto start = Clock::now();
  const vpHomogeneousMatrix wMc = to_visp(observation.wMc);
  const Eigen::Vector3d here = observation.wMc.translation();
  // The estimator avoids the occluders seen and those presumed (last).
  std::optional<ViewProblem> problem = observation.problem;
  std::optional<OcclusionField> field;  // the occlusion field, once per frame
  const Eigen::Index seen = problem ? problem->occluders.cols() : 0;
  if (problem) {
    if (observation.presumed.cols() > 0) problem->occluders = observation.all_occluders();
    problem->camera = here;
    field.emplace(*problem, estimator.r_sphere);
    out.estimate = estimate_view_counted(*field, estimator, previous_view);
    if (out.estimate->status == ViewStatus::NoSupervoxels) out.estimate.reset();
    out.presumed_occluders = problem->occluders.cols() - seen;
  }
  // The world model, once per frame: the tracks of the occluders seen.
  out.tracks = world.update(observation.problem ? &observation.problem->occluders : nullptr, dt);

  // The retreat's modes need the estimator, a known shown area and retreat_drop > 0.
  const bool retreat = settings.method == ViewMethod::Estimator && settings.retreat.drop > 0.0;
  Candidate selected;
  if (out.estimate) {
    switch (out.estimate->status) {
      case ViewStatus::Converged: out.status = StepStatus::Converged; break;
      case ViewStatus::NotConverged:
      case ViewStatus::OutOfTime: out.status = StepStatus::NotConverged; break;
      default: out.status = StepStatus::NoOccluders; break;
    }
    const Candidate pursuit = pursue(*problem, *field, out);
    selected = pursuit;
    if (retreat && observation.shown_area) {
      const Frame f{*problem, *field, seen, *out.estimate, here, *observation.shown_area, dt, observation.age};
      found(f, out);
      if (mode == LoopMode::Pursue) selected = look_ahead(f, pursuit);
      if (mode == LoopMode::Hold) selected = {held->position, Proposer::BestSeen};
    } else {
      if (mode != LoopMode::Pursue) out.guard = Guard::ObjectFound;
      mode = LoopMode::Pursue;
    }
    previous_view = out.estimate->tf;
    previous_target = selected.view;
    last_centroid = out.estimate->centroid;
  } else if (retreat && last_centroid) {
    lost(here, dt, out);
    if (mode == LoopMode::WayBack) selected = {held->position, Proposer::BestSeen};
  } else {
    if (mode != LoopMode::Lost) out.guard = Guard::ObjectLostNoView;
    mode = LoopMode::Lost;
  }
  out.mode = mode;
  out.target = selected.view;
  out.proposer = selected.by;
  out.estimator_calls = estimator_calls;
  out.estimate_s = seconds_since(start);

  start = Clock::now();
  if (out.target) {
    out.command = controller.update(*out.target, *last_centroid, estimator.r_sphere, wMc, dt);
  }
  // Lost, the camera moves only on its way back.
  out.velocity = safety.filter(out.command, wMc, dt, out.estimate.has_value() || out.target.has_value(), observation.age);
  out.safety = safety.last_action();
  out.control_s = seconds_since(start);
  return out;
}

}  // namespace ofv::servo
