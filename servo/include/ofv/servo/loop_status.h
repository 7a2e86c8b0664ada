/**
 * \file loop_status.h
 * \brief What the loop, its mode machine and its safety filter did with a
 *        frame (no ViSP types, so records and metrics can carry them).
 */
#pragma once

#include <vector>

namespace ofv::servo {

/// \brief What the loop did with one frame.
enum class StepStatus {
  Converged,     ///< the estimator found a clear view
  NotConverged,  ///< the estimator ran out of iterations: its best visited view
  NoOccluders,   ///< nothing occludes: t0
  ObjectLost,    ///< no object this frame (perception lost it, or no usable supervoxel): the robot stops
  BadFrame,      ///< the frame failed its checks and was skipped (run_on_robot): the robot stops
  Planned,       ///< method hindsight: the planned path's view (ViewLoop::follow)
};
/// \brief The status's word in files: converged, not_converged, no_occluders, object_lost, bad_frame, planned.
[[nodiscard]] const char* to_string(StepStatus status);

/// \brief What the safety filter did to a command.
enum class SafetyAction {
  None,               ///< passed untouched
  SpeedLimit,         ///< scaled down to the speed limits
  AccelerationLimit,  ///< changed less than asked, within the acceleration limits
  WorkspaceBound,     ///< motion out of the workspace removed
  InvalidCommand,     ///< non-finite command or period: stop
  ObjectLost,         ///< no object: stop
  StaleFrame,         ///< the frame is older than stale_timeout: stop
  BadFrame,           ///< the frame failed its checks and was skipped: stop
  /// The frame's camera pose is not known (ofv::Observation::pose: RGB-D
  /// odometry failed, found an implausible motion or a scene that cannot
  /// fix it): stop, as for a stale frame.
  PoseUnknown,
};
/// \brief The action's words in files ("" for None, "speed limit", "stale frame", "pose unknown" ...).
[[nodiscard]] const char* to_string(SafetyAction action);
/// \brief True for the actions that stop the robot.
[[nodiscard]] bool stops(SafetyAction action);

/**
 * \brief The loop's mode after a frame: the state of ViewLoop's mode machine.
 *
 * Pursue drives to the view the proposers give; WayBack drives back to
 * the view that showed the most of the object in the last 0.5 s when the
 * object is lost (the retreat); Waiting is back there with the object still
 * lost; Hold keeps that view once the object is found again; Lost stops
 * with no view to go back to.
 */
enum class LoopMode {
  Pursue,   ///< to the selected view (estimate, anticipated, warm start, look-ahead)
  Hold,     ///< found again after a loss: at the view that showed the most, until a guard releases it
  WayBack,  ///< the object lost: back to the view that showed the most of it
  Waiting,  ///< the object lost, back at that view: stopped, perception looks for it there
  Lost,     ///< the object lost with no recent view to go back to: stopped
};
/// \brief The word in files and on the terminal: pursue, hold, way_back, waiting, lost.
[[nodiscard]] const char* to_string(LoopMode mode);

/// \brief The guard of the mode machine that moved the loop in a frame.
enum class Guard {
  None,            ///< no transition
  T0Clear,         ///< hold → pursue: t0 is clear
  SceneChanged,    ///< hold → pursue: there, it keeps showing retreat_drop less than that view did
  ObjectLost,      ///< pursue | hold → way back: the object lost within 0.5 s of the view that showed the most, or while holding
  ObjectLostNoView,  ///< pursue → lost: the object lost with no such view
  BackThere,       ///< way back → waiting
  AwayAgain,       ///< waiting → way back
  ObjectFound,     ///< way back | waiting → hold; lost → pursue (then that mode's guards, the same frame)
};
/// \brief The word in files and on the terminal, e.g. object_lost, t0_clear.
[[nodiscard]] const char* to_string(Guard guard);

/// \brief One transition of the mode machine: in mode `from`, guard `guard` moves the loop to `to`.
struct LoopTransition {
  LoopMode from;  ///< the mode it leaves
  Guard guard;    ///< the guard that holds
  LoopMode to;    ///< the mode it enters
};
/// \brief Every transition of ViewLoop's mode machine; in a frame, the current
///        mode's guards are tried in this order and the first that holds is taken.
[[nodiscard]] const std::vector<LoopTransition>& loop_transitions();

/// \brief Which proposer's view the controller drives to.
enum class Proposer {
  None,         ///< no target: the camera stops (object lost, method static, back there)
  Estimate,     ///< the frame's estimate: t_f (t0 when clear)
  Anticipated,  ///< the estimate against the occluders' predicted positions too (anticipation=predict)
  WarmStart,    ///< continued from the previous target while t0 is occluded (target_hysteresis)
  Climb,        ///< look-ahead: a nearby view that sees clearly more (most_visible_view)
  Here,         ///< look-ahead: the camera's own view (it holds where it is)
  BestSeen,     ///< the view that showed the most of the object (modes way back and hold)
  InitialView,  ///< baseline method initial_view: t0
  Sampling,     ///< baseline method sampling
  Plan,         ///< method hindsight: the planned path (ViewLoop::follow)
};
/// \brief The word in files and on the terminal, e.g. estimate, warm_start.
[[nodiscard]] const char* to_string(Proposer proposer);

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using Guard [[deprecated("use ofv::servo::Guard")]] = servo::Guard;
using LoopMode [[deprecated("use ofv::servo::LoopMode")]] = servo::LoopMode;
using Proposer [[deprecated("use ofv::servo::Proposer")]] = servo::Proposer;
using SafetyAction [[deprecated("use ofv::servo::SafetyAction")]] = servo::SafetyAction;
using StepStatus [[deprecated("use ofv::servo::StepStatus")]] = servo::StepStatus;
using LoopTransition [[deprecated("use ofv::servo::LoopTransition")]] = servo::LoopTransition;
using servo::loop_transitions;
using servo::to_string;
}  // namespace ofv
/// \endcond
