/**
 * \file episode.h
 * \brief One closed-loop episode: render the frame at the camera's pose →
 *        perception (full, or ground truth) → view selection (ofv's estimator
 *        or a baseline) → controller → the robot moves one frame period →
 *        next frame. Deterministic for a scenario, settings and seed.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/loop/baselines.h"
#include "ofv/loop/compare.h"
#include "ofv/loop/metrics.h"
#include "ofv/rgbd_frame.h"
#include "ofv/servo/controller.h"
#include "ofv/sim/scenario.h"

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

/// \brief Where the estimator's input comes from.
enum class PerceptionMode {
  Full,         ///< PCL front end on the rendered frame (needs ofv built with perception)
  GroundTruth,  ///< the simulator's ground-truth supervoxels and occluders
};

/**
 * \brief Everything an episode needs, resolved and validated.
 *
 * Built from a scenario and `name=value` settings (as `ofv simulate --set`
 * and the variants of `ofv compare` give them) by resolve_episode().
 */
struct EpisodeSetup {
  sim::Scenario scenario;
  EstimatorSettings estimator;
  ViewMethod method = ViewMethod::Estimator;
  SamplingSettings sampling;
  ControllerSettings controller;
  std::string robot = "camera";
  PerceptionMode perception = PerceptionMode::GroundTruth;
  double duration = 0.0;  ///< [s]
  /// Target continuity. Re-estimating from scratch every frame, a symmetric
  /// occlusion can make the target flip between two sides of an occluder and
  /// the camera dither between them. With this on, while t0 is occluded the
  /// target the camera follows is re-estimated from the previous target (the
  /// spec's warm start): it stays while clear and otherwise moves to the
  /// nearest clear view; once t0 is clear again, t0 is the target. The
  /// sampling planner keeps its previous view while it sees as much as the new
  /// best. The recorded t0 and tf stay the plain estimator's.
  bool target_hysteresis = true;
  /// The arms on ViSP's threaded simulators (ThreadedArm), one frame period
  /// of wall-clock time per step: a real-time demo, not exactly repeatable.
  bool real_time = false;
};

/// \brief Names accepted by resolve_episode() besides the estimator's settings.
[[nodiscard]] const std::vector<std::string>& episode_setting_names();

/**
 * \brief Applies `name=value` settings to a scenario: any estimator setting
 *        (lengths may be `r_seed` or `r_sphere`, meaning the scenario's
 *        value), `method`, `sampling_candidates`, `sampling_occluder_radius`,
 *        `controller` (law), `gain`, `max_linear_speed`, `max_angular_speed`,
 *        `target_filter`, `target_hysteresis` (true/false), `robot`, `real_time`
 *        (true/false), `perception`,
 *        `duration`, `seed` (k: the scenario's k-th random world, see sim::with_seed).
 * \throws std::invalid_argument naming the setting and the value.
 */
[[nodiscard]] EpisodeSetup resolve_episode(
    const sim::Scenario& scenario, const std::vector<std::pair<std::string, std::string>>& settings);

/// \brief What happened in one step, for pictures and progress.
struct StepDetail {
  const RgbdFrame* frame = nullptr;         ///< the rendered frame
  const ViewProblem* problem = nullptr;     ///< the estimator's input (nullptr when lost)
  const ViewEstimate* estimate = nullptr;   ///< nullptr when there was no estimate
  Eigen::Vector3d target = Eigen::Vector3d::Zero();  ///< chosen camera position
  Eigen::Vector3d true_centroid = Eigen::Vector3d::Zero();
};

/// \brief Called after every step; may be empty.
using StepObserver = std::function<void(const StepRecord&, const StepDetail&)>;

/// \brief Runs one episode.
/// \throws std::runtime_error when the loop cannot run (e.g. full perception not built).
[[nodiscard]] EpisodeOutcome run_episode(const EpisodeSetup& setup, const StepObserver& observer = {});

/// \brief The runner `ofv compare` uses: loads the spec's scenario, applies its
///        variant and seed, runs the episode.
[[nodiscard]] EpisodeRunner simulation_runner();

}  // namespace ofv
