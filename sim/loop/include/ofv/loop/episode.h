/**
 * \file episode.h
 * \brief One closed-loop episode: render the frame at the camera's pose →
 *        an ofv::Observation (perception full or labels, or the ground truth
 *        cut down to what a front end gives) → ofv::servo::ViewLoop (view selection,
 *        controller, safety filter) → the robot moves one frame period →
 *        next frame. Deterministic for a scenario, settings and seed.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/loop/compare.h"
#include "ofv/loop/metrics.h"
#include "ofv/perception/perception.h"
#include "ofv/pose_source.h"
#include "ofv/rgbd_frame.h"
#include "ofv/servo/robot.h"
#include "ofv/servo/robot_loop.h"
#include "ofv/servo/view_loop.h"
#include "ofv/settings_table.h"
#include "ofv/sim/hindsight.h"
#include "ofv/sim/scenario.h"

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

/// \brief Where the estimator's input comes from.
enum class PerceptionMode {
  Full,  ///< the front end on the rendered frame: what a robot gets
  /// The same front end with the rendered labels in place of segmentation
  /// and classification (PerceptionSettings::Classes::Labels): a perfect
  /// classifier of this sensor's frames, the limit of any front end.
  Labels,
  /// The simulator's ground-truth supervoxels and every occluder in the
  /// sphere, seen or not: beyond what the sensor shows.
  GroundTruth,
};
/// \brief The mode's word in settings and files: full, labels, ground-truth.
[[nodiscard]] const char* to_string(PerceptionMode mode);

/// \brief How full perception finds the object in the first frame.
enum class ObjectSelect {
  Labels,  ///< the scenario's object, as the first frame's labels show it (a user pointing it out)
  Auto,    ///< the front end's own choice: the colour-consistent cluster at the image centre
};
/// \brief The word in settings and files: labels, auto.
[[nodiscard]] const char* to_string(ObjectSelect select);

/// \brief Where the camera pose the front end and the loop get comes from (setting `poses`).
enum class PoseOrigin {
  /// The pose each frame comes with: in simulation the true one (the
  /// simulator's), in `ofv run` the robot's or the recording's (`simulator`, `robot`).
  Frame,
  /// RGB-D odometry (ofv::odometry, built with OpenCV's rgbd module) from
  /// the first frame's own pose (`odometry[:METHOD]`); the renderer and
  /// the metrics keep the true pose.
  Odometry,
};

/**
 * \brief Everything an episode needs, resolved and validated.
 *
 * Built from a scenario and `name=value` settings (as `ofv simulate --set`,
 * `ofv run --set` and the variants of `ofv compare` give them) by
 * resolve_episode().
 */
struct EpisodeSetup {
  sim::Scenario scenario;  ///< the world, already varied for `seed` (sim::with_seed)
  servo::LoopSettings loop;  ///< the per-frame policy: estimator, method, controller, safety
  servo::RobotKind robot = servo::RobotKind::Camera;  ///< what carries the camera (setting `robot`)
  PerceptionMode perception = PerceptionMode::Full;  ///< where the estimator's input comes from
  /// The front end's settings (perception full or labels) that users set
  /// (ofv::perception::perception_settings_table()); its sphere and seed resolution
  /// come from the estimator's.
  perception::PerceptionSettings front_end;
  ObjectSelect select = ObjectSelect::Labels;  ///< full perception, simulation only
  double duration = 0.0;  ///< [s]
  unsigned seed = 0;      ///< the scenario's k-th random world (sim::with_seed)
  /// Frames between capturing a frame and applying its command: the robot
  /// applies the command of frame k - latency during period k (zero
  /// velocity before the first one arrives). 0: the command applies during
  /// the period right after its frame, as if computing took no time.
  int latency = 0;
  /// The arms on ViSP's threaded simulators (ThreadedArm), one frame period
  /// of wall-clock time per step: a real-time demo, not exactly repeatable.
  bool real_time = false;
  /// Method hindsight: the planner's lattice spacing and time step (settings
  /// hindsight_spacing, hindsight_step, hindsight_segment); its speed limit is the loop's max_linear_speed.
  sim::HindsightSettings hindsight;
  PoseOrigin poses = PoseOrigin::Frame;  ///< setting `poses`
  /// With PoseOrigin::Odometry: OpenCV's method, a word of
  /// ofv::odometry::parse_method (icp, rgbd_icp, fast_icp, rgbd); empty for
  /// the odometry's default. (A word, not the odometry's enum: that
  /// component is optional.)
  std::string odometry_method;
  /// With PoseOrigin::Odometry: the odometry's other settings as set
  /// (settings `odometry_NAME`: NAME of ofv::odometry's table, and its value
  /// as text), in the order set; the odometry's defaults for the others.
  std::vector<std::pair<std::string, std::string>> odometry;
};

/**
 * \brief Every setting of an episode by name: the loop's
 *        (ofv::servo::loop_settings_table()), the front end's
 *        (ofv::perception::perception_settings_table()) and robot, perception, select,
 *        duration, seed, latency, real_time, hindsight_spacing, hindsight_step, hindsight_segment, poses. `ofv simulate`, `ofv run`, `ofv compare`, scenario
 *        `controller` sections and grids all read settings through it.
 */
[[nodiscard]] const SettingsTable<EpisodeSetup>& episode_settings_table();

/**
 * \brief Applies the scenario's own settings (its estimator and controller
 *        sections, robot, duration), then `name=value` settings in order,
 *        then validates.
 * \throws std::invalid_argument naming the setting and the value.
 */
[[nodiscard]] EpisodeSetup resolve_episode(
    const sim::Scenario& scenario, const std::vector<std::pair<std::string, std::string>>& settings);

/// \brief The front end's settings of an episode: the estimator's sphere
///        and seed resolution, the setup's front_end, labels as classes with
///        perception=labels (the object selection left as the default).
[[nodiscard]] perception::PerceptionSettings front_end_settings(const EpisodeSetup& setup);

/// \brief The words of setting `poses`, for messages: simulator, robot, odometry, odometry:icp, ...
inline constexpr const char* kPosesWords =
    "simulator, robot, odometry, odometry:icp, odometry:rgbd_icp, odometry:fast_icp, odometry:rgbd";

/// \brief The setting `poses` of a setup as a word: simulator, or odometry[:METHOD].
[[nodiscard]] std::string poses_word(const EpisodeSetup& setup);

/**
 * \brief The pose source of setting `poses`: empty for PoseOrigin::Frame (the
 *        frames' own poses), RGB-D odometry (ofv::odometry::odometry_pose_source,
 *        default odometry settings) for PoseOrigin::Odometry. A new source,
 *        with no frame seen yet, at each call.
 * \throws std::invalid_argument when odometry is asked for and ofv was built
 *         without it (OpenCV's rgbd module, opencv_contrib), naming the module.
 */
[[nodiscard]] PoseSource episode_pose_source(const EpisodeSetup& setup);

/// \brief What happened in one step, for pictures and progress.
struct StepDetail {
  const RgbdFrame* frame = nullptr;         ///< the rendered frame
  const Observation* observation = nullptr;  ///< what the loop was given
  const servo::LoopStep* step = nullptr;           ///< what the loop did (estimate, target, velocities)
};

/// \brief Called after every step; may be empty.
using StepObserver = std::function<void(const StepRecord&, const StepDetail&)>;

/// \brief Longest episode [s] (the setting `duration`: one day).
inline constexpr double kMaxEpisodeDuration = 86400.0;
/// \brief Most frames in one episode: kMaxEpisodeDuration at the scenarios' highest rate, 1000 Hz.
inline constexpr double kMaxEpisodeFrames = 86400.0 * 1000.0;

/**
 * \brief Runs one episode. With method hindsight, the path is planned first
 *        (sim::plan_hindsight, from the episode's start, r_sphere and
 *        max_linear_speed) and the loop follows it (ofv::servo::ViewLoop::follow:
 *        the plan's view and centroid one controller time constant plus the
 *        latency ahead); no perception runs, and the metrics carry the bounds.
 */
/// \throws std::invalid_argument naming `duration` or `rate` when the episode
///         is not finite or has more than kMaxEpisodeFrames frames (however
///         the setup was made); std::runtime_error when the loop cannot run
///         (e.g. full perception not built).
[[nodiscard]] EpisodeOutcome run_episode(const EpisodeSetup& setup, const StepObserver& observer = {});

/**
 * \brief Rehearses a deployment without hardware: the episode's arm on
 *        ViSP's threaded simulator (robot viper850 or afma6) in wall-clock
 *        time, a simulated sensor rendering the scenario live from the arm's
 *        current camera pose (sim::LiveSource), and the loop of `ofv run`
 *        (ofv::servo::run_on_robot) with its frame timing, stale frames and stop flag.
 * \param setup    the episode, with robot viper850 or afma6.
 * \param stop     a signal handler's flag, or nullptr.
 * \param observer sees every frame (e.g. to print the commands).
 * \return the episode, summarised from the simulator's ground truth at each frame.
 * \throws std::invalid_argument when the robot is not an arm.
 */
[[nodiscard]] EpisodeOutcome rehearse(const EpisodeSetup& setup, const volatile std::sig_atomic_t* stop,
                                      const std::function<void(const servo::RobotLoopFrame&)>& observer = {});

/// \brief The runner `ofv compare` uses: loads the spec's scenario, applies its
///        variant and seed, runs the episode.
[[nodiscard]] EpisodeRunner simulation_runner();

}  // namespace ofv
