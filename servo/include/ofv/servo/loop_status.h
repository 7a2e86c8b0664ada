/**
 * \file loop_status.h
 * \brief What the loop and its safety filter did with a frame (no ViSP
 *        types, so records and metrics can carry them).
 */
#pragma once

namespace ofv {

/// \brief What the loop did with one frame.
enum class StepStatus {
  Converged,     ///< the estimator found a clear view
  NotConverged,  ///< the estimator ran out of iterations: its best visited view
  NoOccluders,   ///< nothing occludes: t0
  ObjectLost,    ///< no object this frame (perception lost it, or no usable supervoxel): the robot stops
};
/// \brief The status's word in files: converged, not_converged, no_occluders, object_lost.
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
};
/// \brief The action's words in files ("" for None, "speed limit", "stale frame" ...).
[[nodiscard]] const char* to_string(SafetyAction action);
/// \brief True for the actions that stop the robot.
[[nodiscard]] bool stops(SafetyAction action);

}  // namespace ofv
