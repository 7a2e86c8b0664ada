/**
 * \file view_loop.h
 * \brief The per-frame policy of ofv, once for simulation and robots:
 *        problem + camera pose → view selection (the estimator or a
 *        baseline) → target continuity → controller → safety filter →
 *        camera twist and a typed status.
 *
 * Every caller uses it: the simulated episode (ofv::run_episode), `ofv run`
 * on hardware or recordings (ofv::servo::run_on_robot), the tutorials. Perception
 * (or the simulator's ground truth) comes before it as an ofv::Observation,
 * the robot after it.
 *
 * \code
 * ofv::servo::LoopSettings settings;                      // documented defaults
 * ofv::servo::loop_settings_table().set(settings, "gain", "6");
 * ofv::servo::ViewLoop loop(settings);
 * while (...) {
 *   ofv::Observation seen = observer.observe(frame);  // ofv::perception::PerceptionObserver, or your own
 *   seen.age = frame_age;
 *   const ofv::servo::LoopStep s = loop.step(seen, dt);
 *   robot.step(s.velocity, dt);
 * }
 * \endcode
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/observation.h"
#include "ofv/occluder_tracker.h"
#include "ofv/servo/controller.h"
#include "ofv/servo/loop_status.h"
#include "ofv/servo/safety.h"
#include "ofv/settings_table.h"
#include "ofv/view_methods.h"

#include <Eigen/Core>
#include <visp3/core/vpColVector.h>
#include <visp3/core/vpHomogeneousMatrix.h>

#include <memory>
#include <optional>
#include <vector>

/**
 * \namespace ofv::servo
 * \brief The ViSP side (component `servo`): the occlusion-free view as a ViSP
 *        feature, the view controller, robots, the safety filter and the
 *        per-frame loop (ViewLoop, run_on_robot). The names of ofv 0.1 in
 *        `ofv` (`ofv::ViewLoop`, ...) remain for one release as deprecated aliases.
 */
namespace ofv::servo {

/// \brief How the loop looks ahead at moving occluders.
enum class Anticipation {
  Off,      ///< the paper's reactive method: the view moves once occlusion rays reach it
  Predict,  ///< also avoid where the tracked occluders will be over the horizon
};
/// \brief The word in settings and files: off, predict.
[[nodiscard]] const char* to_string(Anticipation a);

/**
 * \brief Anticipation of moving occluders (Anticipation::Predict).
 *
 * The occluders are tracked (ofv::OccluderTracker). Each frame, the points
 * of every confirmed track moving faster than `min_speed` are copied to
 * where the track's velocity takes them after horizon x k / samples,
 * k = 1..samples; the copies inside the sphere join the frame's occluders
 * and the estimator (unchanged, the spec's) runs on that problem, from the
 * view the frame's own estimate found (the spec's warm start). The view
 * so keeps clear of the occluders' path over the horizon, and the camera
 * leaves before the object is covered. When the predicted problem has no
 * free view, the loop falls back to the frame's own (reactive) estimate.
 */
struct AnticipationSettings {
  Anticipation mode = Anticipation::Predict;  ///< off, or predict
  double horizon = 0.8;    ///< how far ahead [s]
  int samples = 2;         ///< predicted copies over the horizon
  double min_speed = 0.15; ///< slower tracks are taken as still [m/s]
};

/**
 * \brief The retreat (ViewLoop's modes way back, waiting and hold) and the
 *        look-ahead (mode pursue); both need the frame's shown area
 *        (Observation::shown_area).
 *
 * Way back: the loop remembers the camera position that showed the most of
 * the object in the last `memory`; when perception loses the object within
 * `memory` of that frame, the camera drives back there (within `at`) and
 * stops until the object is found again. Found again, it holds that view
 * until t0 is clear or, there, `release_frames` frames in a row show `drop`
 * less of the object than that view did (the scene changed).
 *
 * Look-ahead, until t0 has been clear in some frame (what hides the object
 * was there from the start and stands still, like a cage; a view can look
 * free only because the sensor does not see the occluders behind the ones
 * in front): the camera does not go on towards its target when, on the way
 * (`look_ahead_samples` points on the great circle, the last as far as it
 * can travel before a frame shows a loss and it stops: max_linear_speed x
 * (frame age + one period) plus the braking distance), score_view with the
 * frame's occluders shows `drop` less of the object than here; it climbs to
 * a nearby view that sees clearly more (most_visible_view with `climb`) if
 * the way there keeps what it sees, else it holds where it is. Once t0 has
 * been clear, what hides the object came in and may stand on the way out
 * (an arm stopped over the object), where holding would keep the camera there.
 */
struct RetreatSettings {
  double drop = 0.1;       ///< setting retreat_drop: the loss that counts, a fraction; 0 = retreat and look-ahead off
  double memory = 0.5;     ///< what a view showed counts as evidence this long [s]
  double at = 0.01;        ///< the camera is at a view within this distance [m]
  int release_frames = 6;  ///< at the held view, this many frames showing `drop` less end the hold
  bool look_ahead = true;  ///< setting look_ahead
  int look_ahead_samples = 3;  ///< points scored on the way
  MostVisibleSettings climb;   ///< the look-ahead's climb; its margin is setting look_ahead_margin
};

/// \brief Every setting of the loop; ofv::servo::loop_settings_table() names them.
struct LoopSettings {
  EstimatorParams estimator;                  ///< the spec's settings (preset + explicit values)
  ViewMethod method = ViewMethod::Estimator;  ///< how the target view is chosen
  SamplingSettings sampling;                  ///< for ViewMethod::Sampling
  ControllerSettings controller;             ///< the law, gain and speed limits
  /// The last filter before the robot. Its speed limits are set together
  /// with the controller's by the table's `max_linear_speed` and
  /// `max_angular_speed`.
  SafetySettings safety;
  /// Target continuity. Re-estimating from scratch every frame, a symmetric
  /// occlusion can make the target flip between two sides of an occluder and
  /// the camera dither between them. With this on, while t0 is occluded the
  /// target is re-estimated from the previous target (the spec's warm
  /// start): it stays while clear and otherwise moves to the nearest clear
  /// view; once t0 is clear again, t0 is the target. The sampling planner
  /// keeps its previous view while it sees as much as the new best.
  bool target_hysteresis = true;
  AnticipationSettings anticipation;  ///< how the loop looks ahead at moving occluders
  TrackerSettings tracker;           ///< the occluder tracks anticipation uses
  RetreatSettings retreat;           ///< modes way back, waiting and hold, and the look-ahead of mode pursue
};

/**
 * \brief The loop's settings by name: the estimator's (ofv::estimator_settings_table()),
 *        then the view method and sampling, the controller, the target's
 *        continuity, anticipation and the occluder tracks, the retreat and
 *        look-ahead, and the safety filter (`ofv settings` lists them,
 *        docs/settings.md is generated from it).
 */
[[nodiscard]] const SettingsTable<LoopSettings>& loop_settings_table();


/// \brief The loop's output for one frame. World frame [m]; twists in the camera frame.
struct LoopStep {
  StepStatus status = StepStatus::ObjectLost;  ///< what the frame came to
  std::optional<ViewEstimate> estimate;   ///< the estimator's result (none when the object is lost)
  std::optional<Eigen::Vector3d> target;  ///< the view the controller drives to (none: hold still)
  LoopMode mode = LoopMode::Lost;         ///< the mode after this frame
  Guard guard = Guard::None;              ///< the last transition this frame took, if any
  Proposer proposer = Proposer::None;     ///< whose view the target is
  vpColVector command = vpColVector(6, 0.0);   ///< the controller's twist [m/s, rad/s]
  vpColVector velocity = vpColVector(6, 0.0);  ///< after the safety filter: send this to the robot
  SafetyAction safety = SafetyAction::None;    ///< what the safety filter did
  std::vector<OccluderTrack> tracks;  ///< the occluder tracks after this frame (confirmed or not)
  /// The estimate on the frame's occluders plus the predicted ones
  /// (anticipation on, something moving, a free view found): warm-started
  /// from the frame's view (estimate->tf), or, when that view is not clear
  /// of the predicted occluders and the previous target is, from the
  /// previous target.
  std::optional<ViewEstimate> anticipated;
  Eigen::Index predicted_occluders = 0;  ///< predicted points added to the problem
  /// Occluders presumed, not seen (Observation::presumed).
  Eigen::Index presumed_occluders = 0;
  int estimator_calls = 0;  ///< estimate_view calls this frame
  double estimate_s = 0.0;  ///< compute time of view selection [s]
  double control_s = 0.0;   ///< compute time of controller and filter [s]
};

/**
 * \brief The per-frame policy. One instance per episode or run: it keeps
 *        the world model (occluder tracks), the mode machine's state, the
 *        previous view and target, the controller's task and the safety
 *        filter's previous command.
 *
 * Each frame, in order (docs/architecture.md, "The per-frame policy"):
 * the world model is updated with the occluders seen; the proposers give
 * candidate views (the estimate, the anticipated one, the warm start from
 * the previous target, the look-ahead's climb or hold, the best view seen);
 * the mode machine moves by its named guards (ofv::servo::Guard: one transition a
 * frame, after the object was found or lost again one more); the
 * selector picks the mode's view; the controller and the safety filter
 * turn it into a twist. Movable, not copyable.
 */
class ViewLoop {
 public:
  /// \throws std::invalid_argument naming a setting out of range.
  explicit ViewLoop(const LoopSettings& settings);
  ~ViewLoop();
  ViewLoop(ViewLoop&&) noexcept;             ///< moves the loop and its state
  ViewLoop& operator=(ViewLoop&&) noexcept;  ///< moves the loop and its state
  ViewLoop(const ViewLoop&) = delete;
  ViewLoop& operator=(const ViewLoop&) = delete;

  /**
   * \param observation what the frame shows (ofv::Observer): the problem
   *                  (none when the object is lost; its camera and
   *                  previous_view are set here), the presumed occluders
   *                  (the estimator avoids them, the occluder tracks leave
   *                  them out), the shown area (unknown: the loop never
   *                  retreats, RetreatSettings::drop), the camera
   *                  pose when the frame was taken and the frame's age when
   *                  the command is sent (older than the stale timeout: stop).
   * \param dt        time since the previous frame, and the period the command
   *                  will be applied for [s].
   * \throws std::logic_error with method hindsight, which follow() drives.
   */
  [[nodiscard]] LoopStep step(const Observation& observation, double dt);

  /**
   * \brief Drives to a view chosen outside the loop (method hindsight: the
   *        planned path) through the loop's controller and safety filter;
   *        no view selection, world model or modes (the mode is pursue).
   * \param target   the camera position to drive to (world) [m].
   * \param centroid the point the camera looks at (world) [m].
   * \param wMc      the camera's pose when the frame was taken.
   * \param age      the frame's age when the command is sent [s] (as Observation::age).
   * \param dt       as step().
   * \param within   0: the loop's controller approaches the target as it
   *                 approaches a view it chose. Positive: the time in which
   *                 to reach it [s]: the same control law with gain 1/within,
   *                 not adaptive, no target filter, so that a path given in
   *                 advance at the path's time + within is tracked, not
   *                 approached (a moving target is otherwise lagged or cut across).
   */
  [[nodiscard]] LoopStep follow(const Eigen::Vector3d& target, const Eigen::Vector3d& centroid,
                                const Eigen::Isometry3d& wMc, double age, double dt, double within = 0.0);

  /// \brief The robot was stopped outside the loop (a watchdog, a skipped
  ///        frame): the next command starts from rest within the
  ///        acceleration limits.
  void robot_stopped();
  /// \brief The mode the last frame left the loop in.
  [[nodiscard]] LoopMode mode() const;

  /// \brief Forgets all it learnt: previous view and target, command, occluder tracks, mode (a new run).
  void reset();

  /// \brief The settings it was made with.
  [[nodiscard]] const LoopSettings& settings() const;
  /// \brief The resolved estimator settings (preset applied).
  [[nodiscard]] const EstimatorSettings& estimator() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using ViewLoop [[deprecated("use ofv::servo::ViewLoop")]] = servo::ViewLoop;
using Anticipation [[deprecated("use ofv::servo::Anticipation")]] = servo::Anticipation;
using AnticipationSettings [[deprecated("use ofv::servo::AnticipationSettings")]] = servo::AnticipationSettings;
using LoopSettings [[deprecated("use ofv::servo::LoopSettings")]] = servo::LoopSettings;
using LoopStep [[deprecated("use ofv::servo::LoopStep")]] = servo::LoopStep;
using RetreatSettings [[deprecated("use ofv::servo::RetreatSettings")]] = servo::RetreatSettings;
using servo::loop_settings_table;
using servo::to_string;
}  // namespace ofv
/// \endcond
