/**
 * \file robot_loop.h
 * \brief The closed loop on a robot: frames from a sensor or a recording →
 *        an ofv::Observer (the perception front end, ofv::perception::PerceptionObserver)
 *        → ofv::servo::ViewLoop → the robot, until the source ends or a stop is requested. `ofv run`, the rehearsal on ViSP's threaded
 *        simulators and the real-robot tutorial use it.
 */
#pragma once

#include "ofv/frame_source.h"
#include "ofv/observation.h"
#include "ofv/pose_source.h"
#include "ofv/servo/robot.h"
#include "ofv/servo/view_loop.h"

#include <csignal>
#include <functional>
#include <limits>
#include <optional>
#include <string>

namespace ofv::servo {

/// \brief How run_on_robot() treats its source and robot.
struct RobotLoopOptions {
  /// The frame's camera pose is the robot's when the frame arrives (a live
  /// eye-in-hand sensor); otherwise the frame carries its pose (recordings,
  /// the simulated sensor).
  bool pose_from_robot = false;
  /// When set, the pose the front end and the loop get: called with each
  /// frame (its pose the robot's with pose_from_robot, else its own) and
  /// the object as the front end found it in the previous frame (ofv::object_hint),
  /// before the observer; a pose it marks not ok makes the frame's
  /// Observation::pose Unknown, and the loop stops for it. RGB-D odometry:
  /// ofv::odometry::odometry_pose_source(). Frames skipped as bad do not reach it.
  PoseSource pose_source;
  /// A frame's age is the wall-clock time since it arrived (live sources);
  /// otherwise the gap to the previous frame's timestamp (recordings).
  bool wall_clock_age = false;
  /// Step the robot with each command (false: a dry run that only reports them).
  bool move_robot = true;
  /// With move_robot: a thread that sends the robot a zero velocity when no
  /// command came within the safety filter's `stale_timeout` after one that
  /// moved it (a source or a perception that stalls), and ends the run when
  /// a command to the robot does not return within its period plus that
  /// timeout (drivers may wait out the period to keep the cadence). Every robot call of
  /// the run then goes through one lock.
  bool watchdog = true;
  /// Stop after this much source time [s].
  double max_duration = std::numeric_limits<double>::infinity();
  /// Period of the first frame when the source does not say [s].
  double first_period = 1.0 / 30.0;
  /// A frame the source cannot read (ofv::BadFrame: a short read) or the
  /// observer refuses (std::invalid_argument: a depth image of the wrong
  /// size, a pose that is not a rigid transform, ...) is skipped with a
  /// stop; the run ends after more than this many in a row ...
  int max_bad_frames_in_row = kMaxBadFramesInRow;
  /// ... or more than this many in the last 60 s.
  int max_bad_frames_per_minute = kMaxBadFramesPerMinute;
  /// When set, stop as soon as it reads non-zero (a signal handler's flag).
  const volatile std::sig_atomic_t* stop = nullptr;
};

/// \brief One frame of run_on_robot(), for printing and recording.
struct RobotLoopFrame {
  long index = 0;                    ///< frames before this one in the run
  const RgbdFrame* frame = nullptr;  ///< the frame as read (its pose the robot's with pose_from_robot)
  /// With a pose source: what it said for this frame (the pose the loop got
  /// is the observation's); nullptr without one, or for a bad frame.
  const FramePose* pose = nullptr;
  const Observation* observation = nullptr;  ///< what the loop was given (its age set)
  const LoopStep* step = nullptr;  ///< what the loop decided and sent
  std::string bad_frame;  ///< why the frame was skipped (empty: it was not); step->status is then BadFrame
  double dt = 0.0;         ///< period the command is applied for [s] (0 with a timestamp that does not increase)
  double frame_age = 0.0;  ///< [s]
  double source_s = 0.0;      ///< time spent waiting for and reading the frame [s]
  double perception_s = 0.0;  ///< compute time of the observer (perception) [s]
};

/// \brief How a run ended.
struct RobotLoopSummary {
  long frames = 0;       ///< frames read and answered with a command
  long lost = 0;         ///< frames without the object
  long pose_unknown = 0;  ///< frames whose pose the pose source could not tell (RobotLoopOptions::pose_source)
  long bad_frames = 0;   ///< frames skipped for failing their checks
  bool stopped = false;  ///< ended by the stop flag
  long watchdog_stops = 0;  ///< zero velocities the watchdog sent between frames
};

/**
 * \brief Runs the loop until the source ends, `max_duration` passes or the
 *        stop flag is raised; then, when it moves the robot, sends a zero
 *        velocity (also when an exception leaves it), so the robot is left at rest.
 *
 * A frame older than the stale timeout, a timestamp that does not increase
 * or is not finite, a lost object or a pose the pose source could not tell
 * gives a zero velocity for that frame;
 * the robot is never sent a period that is not finite and >= 0 (0 with
 * such a stop), and a non-finite timestamp is not the next frame's time base.
 * \param source   the frames, read until it ends
 * \param observer makes each frame's observation (ofv::perception::PerceptionObserver on
 *                 a sensor; in a rehearsal, the simulator's cut-down truth).
 * \param robot    what carries the camera; sent each command
 * \param settings the loop's settings (ofv::servo::ViewLoop)
 * \param options  how the source and the robot are treated
 * \param on_frame sees every frame after its command is sent; may be empty.
 * \throws std::invalid_argument for invalid settings (method hindsight among them); whatever the source,
 *         observer or robot throw at run time but the observer's refusals of
 *         single frames; std::runtime_error when a command to the robot did
 *         not return within its period plus `stale_timeout` (watchdog), or
 *         after too many bad frames (naming the last one's reason).
 */
RobotLoopSummary run_on_robot(FrameSource& source, Observer& observer, CameraRobot& robot,
                              const LoopSettings& settings, const RobotLoopOptions& options,
                              const std::function<void(const RobotLoopFrame&)>& on_frame = {});

/// \brief Why run_on_robot() (and `ofv run`) refuse method hindsight.
inline constexpr const char* kHindsightIsSimulationOnly =
    "setting method = hindsight plans from the simulator's knowledge of the whole episode: it runs in ofv simulate "
    "and ofv compare, not on a robot, a recording or a rehearsal";

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using servo::run_on_robot;
using RobotLoopFrame [[deprecated("use ofv::servo::RobotLoopFrame")]] = servo::RobotLoopFrame;
using RobotLoopOptions [[deprecated("use ofv::servo::RobotLoopOptions")]] = servo::RobotLoopOptions;
using RobotLoopSummary [[deprecated("use ofv::servo::RobotLoopSummary")]] = servo::RobotLoopSummary;
}  // namespace ofv
/// \endcond
