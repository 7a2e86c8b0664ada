// The per-frame policy: view selection, target continuity, control, safety.
#include "ofv/servo/view_loop.h"

#include "ofv/estimator_settings.h"
#include "ofv/servo/target_pose.h"
#include "world_model.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

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

// A view and who proposed it (no view: the camera stops).
struct Candidate {
  std::optional<Eigen::Vector3d> view;
  Proposer by = Proposer::None;
};

}  // namespace

struct ViewLoop::Impl {
  explicit Impl(const LoopSettings& s)
      : settings(s),
        estimator(s.estimator.resolve()),
        controller(s.controller),
        safety(s.safety),
        world(s.tracker, s.anticipation.min_speed) {
    if (settings.sampling.candidates < 1 || !(settings.sampling.occluder_radius > 0.0)) {
      throw std::invalid_argument("sampling settings: candidates must be >= 1 and occluder_radius positive");
    }
    const RetreatSettings& r = settings.retreat;
    if (!(r.drop >= 0.0 && r.drop <= 1.0) || !(r.memory > 0.0) || !(r.at >= 0.0) || r.release_frames < 1 ||
        r.look_ahead_samples < 1 || !(r.climb.step_deg > 0.0) || !(r.climb.margin >= 0.0) ||
        !(r.climb.occluder_radius > 0.0)) {
      throw std::invalid_argument(
          "retreat settings: drop in [0, 1], memory > 0 s, at and climb.margin >= 0, release_frames and "
          "look_ahead_samples >= 1, climb.step_deg and climb.occluder_radius > 0");
    }
  }

  // A camera position (world), how much of the object it showed and how
  // long ago that was [s].
  struct SeenView {
    Eigen::Vector3d position;
    double shown = 0.0;
    double age = 0.0;
  };

  // What one frame brings to the stages after the world model.
  struct Frame {
    const OcclusionField& field;  // of the frame's problem: seen and presumed occluders
    const ViewEstimate& estimate;
    Eigen::Vector3d here;
    double shown;  // [m²]
    double dt, age;
  };

  LoopStep step(const Observation& observation, double dt);

  // --- proposers
  ViewEstimate estimate_view_counted(const OcclusionField& field, const EstimatorSettings& settings,
                                     const std::optional<Eigen::Vector3d>& start);
  std::optional<ViewEstimate> from_previous_target(const OcclusionField& field);
  Candidate pursue(const ViewProblem& problem, const OcclusionField& field, LoopStep& out);
  Candidate look_ahead(const Frame& f, const Candidate& pursuit) const;
  // --- the mode machine
  void transition(Guard guard, LoopStep& out);
  void remember(const Frame& f);
  void release(const Frame& f, LoopStep& out);
  void lost(const Eigen::Vector3d& here, double dt, LoopStep& out);

  LoopSettings settings;
  EstimatorSettings estimator;
  ViewController controller;
  std::optional<ViewController> tracker;  // follow()'s with a time to reach its target
  SafetyFilter safety;
  WorldModel world;
  int estimator_calls = 0;
  LoopMode mode = LoopMode::Lost;
  std::optional<Eigen::Vector3d> previous_view, previous_target;
  std::optional<Eigen::Vector3d> last_centroid;  // C of the last frame that found the object
  std::optional<SeenView> best_seen;  // the view that showed the most of the object (modes way back, hold: the target)
  int low_frames = 0;                 // mode hold: frames in a row showing much less than best_seen there
  bool t0_was_clear = false;          // t0 was clear in some frame since the start
};

ViewLoop::ViewLoop(const LoopSettings& settings) : impl_(std::make_unique<Impl>(settings)) {}
ViewLoop::~ViewLoop() = default;
ViewLoop::ViewLoop(ViewLoop&&) noexcept = default;
ViewLoop& ViewLoop::operator=(ViewLoop&&) noexcept = default;
LoopStep ViewLoop::step(const Observation& observation, double dt) {
  if (impl_->settings.method == ViewMethod::Hindsight) {
    throw std::logic_error("method hindsight follows a path planned in simulation: use ViewLoop::follow");
  }
  return impl_->step(observation, dt);
}

LoopStep ViewLoop::follow(const Eigen::Vector3d& target, const Eigen::Vector3d& centroid, const Eigen::Isometry3d& wMc,
                          double age, double dt, double within) {
  if (!(std::isfinite(within) && within >= 0.0)) {
    throw std::invalid_argument("ViewLoop::follow: the time to reach the target must be finite and >= 0, got " +
                                format_number(within));
  }
  LoopStep out;
  const auto start = Clock::now();
  out.status = StepStatus::Planned;
  out.mode = impl_->mode = LoopMode::Pursue;
  out.proposer = Proposer::Plan;
  out.target = target;
  const vpHomogeneousMatrix pose = to_visp(wMc);
  ViewController* controller = &impl_->controller;
  if (within > 0.0) {
    if (!impl_->tracker || impl_->tracker->settings().gain != 1.0 / within) {
      ControllerSettings c = impl_->settings.controller;
      c.gain = 1.0 / within;
      c.adaptive_gain = false;
      c.target_filter = 0.0;
      impl_->tracker.emplace(c);
    }
    controller = &*impl_->tracker;
  }
  out.command = controller->update(target, centroid, impl_->estimator.r_sphere, pose, dt);
  out.velocity = impl_->safety.filter(out.command, pose, dt, true, age);
  out.safety = impl_->safety.last_action();
  out.control_s = seconds_since(start);
  return out;
}
void ViewLoop::robot_stopped() { impl_->safety.reset(); }
LoopMode ViewLoop::mode() const { return impl_->mode; }
void ViewLoop::reset() { impl_ = std::make_unique<Impl>(impl_->settings); }
const LoopSettings& ViewLoop::settings() const { return impl_->settings; }
const EstimatorSettings& ViewLoop::estimator() const { return impl_->estimator; }

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
    case ViewMethod::Hindsight:  // follow() drives it; step() refuses it
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

// Mode pursue (the retreat on): the view that showed the most in the last
// `memory`, for the way back (what a view showed longer ago is no evidence
// any more: the occluders move).
void ViewLoop::Impl::remember(const Frame& f) {
  if (best_seen) best_seen->age += f.dt;
  if (!best_seen || f.shown >= best_seen->shown || !(best_seen->age <= settings.retreat.memory)) {
    best_seen = SeenView{f.here, f.shown};
  }
}

// Mode hold, found again at best_seen after a loss: it stays there until t0
// is clear, or until, there, `release_frames` frames in a row show `drop`
// less than that view did (the scene changed).
void ViewLoop::Impl::release(const Frame& f, LoopStep& out) {
  const RetreatSettings& s = settings.retreat;
  const bool there = (f.here - best_seen->position).norm() <= s.at;
  low_frames = there && f.shown < (1.0 - s.drop) * best_seen->shown ? low_frames + 1 : 0;
  if (f.estimate.iterations == 0) {
    transition(Guard::T0Clear, out);
  } else if (low_frames >= s.release_frames) {
    transition(Guard::SceneChanged, out);
  } else {
    return;
  }
  best_seen.reset();  // pursue starts again from here
}

// The mode machine in a frame without the object (the retreat on).
void ViewLoop::Impl::lost(const Eigen::Vector3d& here, double dt, LoopStep& out) {
  if (best_seen) best_seen->age += dt;
  if (mode == LoopMode::Pursue) {
    const bool recent = best_seen && best_seen->age <= settings.retreat.memory;
    transition(recent ? Guard::ObjectLost : Guard::ObjectLostNoView, out);
  } else if (mode == LoopMode::Hold) {
    transition(Guard::ObjectLost, out);
  }
  const bool there = best_seen && (here - best_seen->position).norm() <= settings.retreat.at;
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
    if (mode != LoopMode::Pursue && mode != LoopMode::Hold) {
      transition(Guard::ObjectFound, out);
      low_frames = 0;
    }
    selected = pursue(*problem, *field, out);
    if (retreat && observation.shown_area) {
      const Frame f{*field, *out.estimate, here, *observation.shown_area, dt, observation.age};
      if (f.estimate.iterations == 0) t0_was_clear = true;
      if (mode == LoopMode::Hold) release(f, out);
      if (mode == LoopMode::Pursue) {
        remember(f);
        selected = look_ahead(f, selected);
      }
    }
    if (mode == LoopMode::Hold) selected = {best_seen->position, Proposer::BestSeen};
    previous_view = out.estimate->tf;
    previous_target = selected.view;
    last_centroid = out.estimate->centroid;
  } else if (retreat && last_centroid) {
    lost(here, dt, out);
    if (mode == LoopMode::WayBack) selected = {best_seen->position, Proposer::BestSeen};
  } else if (mode == LoopMode::Pursue) {
    transition(Guard::ObjectLostNoView, out);
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
  out.velocity = safety.filter(out.command, wMc, dt, out.estimate.has_value() || out.target.has_value(), observation.age,
                               observation.pose == PoseStatus::Known);
  out.safety = safety.last_action();
  out.control_s = seconds_since(start);
  return out;
}

}  // namespace ofv::servo
