/**
 * \file metrics.h
 * \brief Per-step records of a closed-loop episode and the episode summary
 *        (`metrics.json` of `ofv simulate`, one row of `ofv compare`).
 *
 * Pure bookkeeping on std and Eigen: the runner fills a StepRecord per frame
 * from the simulator's ground truth and the pipeline's outputs.
 */
#pragma once

#include "ofv/perception/scores.h"
#include "ofv/servo/loop_status.h"

#include <Eigen/Geometry>

#include <iosfwd>
#include <optional>
#include <string>
#include <vector>

namespace ofv {

/// \brief Wall-clock time spent in each stage of one closed-loop step [s].
struct StageTimes {
  double render = 0.0;      ///< rendering the frame (a rehearsal: waiting for its live source)
  double perception = 0.0;  ///< the front end, or the simulator's ground-truth problem
  double estimate = 0.0;    ///< view selection (LoopStep::estimate_s)
  double control = 0.0;     ///< controller and safety filter (LoopStep::control_s)
  /// \brief The sum of the four stages [s].
  [[nodiscard]] double total() const { return render + perception + estimate + control; }
};

/**
 * \brief The camera pose the front end and the loop got in one frame, when
 *        it came from a pose source (setting `poses`: RGB-D odometry), against
 *        the true pose (StepRecord::wMc).
 */
struct PoseRecord {
  std::string source;  ///< the setting's word: odometry:icp, odometry:rgbd_icp, ...
  std::string status;  ///< the source's word for the frame: ok, first_frame, failed, implausible, degenerate
  /// False when the source could not tell the pose (the loop stopped for
  /// the frame: ofv::PoseStatus::Unknown, safety "pose unknown").
  bool known = true;
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();  ///< the pose used (world <- camera) [m]
  double translation_error = 0.0;  ///< |used - true| camera position [m]
  double rotation_error = 0.0;     ///< angle of the rotation from the true to the used orientation [deg]
};

/// \brief What happened in one frame period of an episode.
struct StepRecord {
  double time = 0.0;                                       ///< simulated time [s]
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();   ///< camera pose at the frame
  Eigen::Matrix<double, 6, 1> velocity = Eigen::Matrix<double, 6, 1>::Zero();  ///< sent to the robot (v, w), camera frame [m/s, rad/s]
  std::optional<Eigen::Vector3d> t0;  ///< estimator's initial view (none when no estimate)
  std::optional<Eigen::Vector3d> tf;  ///< estimator's final view
  std::optional<Eigen::Vector3d> target;  ///< the view the controller drove to (after hysteresis, or a baseline's)
  servo::StepStatus status = servo::StepStatus::ObjectLost;  ///< what the loop did with the frame
  servo::SafetyAction safety = servo::SafetyAction::None;    ///< what the safety filter did to the command
  int iterations = 0;                 ///< estimator push steps
  double visible_fraction = 0.0;      ///< true fraction of the object surface seen [0, 1]
  double angular_error_deg = 0.0;     ///< eq. 9 of the real camera against the ground-truth supervoxels [deg]
  double sphere_distance_error = 0.0; ///< |camera - true centroid| - r_sphere [m]
  Eigen::Vector3d true_centroid = Eigen::Vector3d::Zero();  ///< the object's surface centroid [m]
  int occluders_in_sphere = 0;        ///< ground truth: occluders inside the sphere
  int occluders_in_view = 0;          ///< ground truth: occluders the rendered frame shows
  int tracks = 0;                     ///< confirmed occluder tracks seen this frame
  double fastest_track_speed = 0.0;   ///< largest speed among them [m/s]
  int predicted_occluders = 0;        ///< predicted occluder points the target was chosen against
  servo::LoopMode mode = servo::LoopMode::Lost;     ///< the loop's mode after the frame (LoopStep::mode)
  servo::Guard guard = servo::Guard::None;          ///< the mode machine's transition in the frame, if any
  servo::Proposer proposer = servo::Proposer::None; ///< whose view the target is
  int estimator_calls = 0;            ///< estimate_view calls of the frame
  /// The front end's output against the frame's labels (ofv/perception/scores.h);
  /// all empty when the estimator's input is the simulator's ground truth.
  perception::PerceptionScores perception;
  StageTimes times;                   ///< compute time of this step
  /// The pose the loop got, when not the simulator's (setting `poses`);
  /// none when it was the true one (`wMc`).
  std::optional<PoseRecord> pose;
};

/// \brief One perception score over an episode's frames (those where it is defined).
struct ScoreSummary {
  int frames = 0;               ///< frames where the score is defined
  std::optional<double> mean;   ///< over those frames
  std::optional<double> worst;  ///< lowest precision or recall, largest error
  double worst_time = 0.0;      ///< when the worst was [s]
  /// The worst over the frames where at least half of the object is in
  /// view (true visible fraction >= 0.5), where the goals apply.
  std::optional<double> worst_half_visible;
};

/// \brief The perception block of an episode (`metrics.json` "perception").
struct PerceptionSummary {
  ScoreSummary object_precision, object_recall, occluder_precision, occluder_recall;
  /** \var object_precision
   *  \brief perception::PerceptionScores::object_precision over the episode.
   *  \var object_recall
   *  \brief perception::PerceptionScores::object_recall over the episode.
   *  \var occluder_precision
   *  \brief perception::PerceptionScores::occluder_precision over the episode.
   *  \var occluder_recall
   *  \brief perception::PerceptionScores::occluder_recall over the episode.
   */
  ScoreSummary centroid_error;  ///< [m]
  ScoreSummary hidden_error;    ///< [m]
  /// Frames where the front end lost the object while the true visible fraction was at least 0.5.
  int lost_half_visible = 0;
  /// \brief True when some frame was scored (full or labels perception).
  [[nodiscard]] bool scored() const { return object_recall.frames > 0; }
};

/// \brief One occlusion event: the visible fraction fell below the threshold.
struct OcclusionEvent {
  double onset = 0.0;                   ///< time the visibility fell below the threshold [s]
  std::optional<double> recovery_time;  ///< from the onset until it is back for good [s]; none if never
  /// When the occluder count in the sphere last rose, at or before the onset
  /// [s]: the warning the loop had. None when no occluder entered (one was
  /// there from the start, or the object left the image).
  std::optional<double> occluder_entered;
  /// When the count of occluders the sensor sees last rose, at or before the
  /// onset [s]: the warning full perception could have had. None when no
  /// occluder came into view (one was seen from the start).
  std::optional<double> occluder_in_view;
};

/// \brief The limit of an episode, from the hindsight planner (method
///        hindsight, sim::plan_hindsight; `metrics.json` "hindsight_bound").
///        The episode's mean visible fraction is what following the plan gave.
struct HindsightBound {
  double planned = 0.0;    ///< the planned path's mean visible fraction: the limit under the speed limit [0, 1]
  double unlimited = 0.0;  ///< the best view at each step on its own: the limit without a speed limit [0, 1]
  int views = 0;           ///< lattice views on the sphere
  int steps = 0;           ///< time steps
  double step = 0.0;       ///< time step [s]
  double spacing = 0.0;    ///< lattice spacing [m]
  long evaluations = 0;    ///< visibility evaluations made
  double plan_s = 0.0;     ///< planning time [s]
};

/// \brief The poses block of an episode (`metrics.json` "poses"): how far the
///        pose source's poses were from the truth.
struct PoseSummary {
  std::string source;  ///< PoseRecord::source
  /// Absolute trajectory error: RMS of the position errors after the rigid
  /// transform that puts the first used pose on the first true one
  /// (ofv::odometry::absolute_trajectory_error) [m]
  double ate = 0.0;
  double ate_max = 0.0;  ///< the largest of those errors [m]
  std::vector<std::pair<std::string, int>> status_counts;  ///< frames per status word (PoseRecord::status)
  int unknown = 0;  ///< frames the loop stopped for, the pose not known
  double max_translation_error = 0.0;  ///< the largest PoseRecord::translation_error (not aligned) [m]
  double max_translation_error_time = 0.0;  ///< when it was [s]
  double max_rotation_error = 0.0;     ///< the largest PoseRecord::rotation_error [deg]
};

/// \brief Summary of an episode.
struct EpisodeMetrics {
  int steps = 0;                        ///< frame periods (StepRecord) summarised
  double duration = 0.0;                ///< simulated [s]
  double mean_visible_fraction = 0.0;   ///< time-weighted mean of the true visible fraction [0, 1]
  double min_visible_fraction = 0.0;    ///< its lowest value over the steps [0, 1]
  double time_below_threshold = 0.0;    ///< simulated time with visibility < threshold [s]
  double visibility_threshold = 0.9;    ///< the `threshold` of summarise() [0, 1]
  std::vector<OcclusionEvent> occlusions;  ///< every occlusion event, in time order
  std::optional<double> max_recovery_time;   ///< worst recovery over events; none if one never recovered
  int unrecovered_occlusions = 0;       ///< events still going on at the end
  double mean_angular_error_deg = 0.0;  ///< time-weighted mean of StepRecord::angular_error_deg [deg]
  double path_length = 0.0;             ///< camera path [m]
  double max_sphere_distance_error = 0.0;  ///< max |distance to centroid - r_sphere| [m]
  double max_linear_speed = 0.0;        ///< [m/s]
  double max_angular_speed = 0.0;       ///< [rad/s]
  StageTimes mean_times;                ///< mean compute time per stage [s]
  StageTimes max_times;                 ///< worst step per stage [s]
  int estimator_iterations_max = 0;     ///< most push steps of one estimate
  double estimator_calls_mean = 0.0;    ///< estimate_view calls per frame, mean
  int estimator_calls_max = 0;          ///< estimate_view calls of the busiest frame
  std::vector<std::pair<std::string, int>> status_counts;  ///< steps per status
  std::vector<std::pair<std::string, int>> mode_counts;    ///< steps per loop mode (LoopMode)
  PerceptionSummary perception;  ///< empty (scored() false) with ground-truth perception
  std::optional<HindsightBound> hindsight;  ///< method hindsight only
  std::optional<PoseSummary> poses;  ///< when the steps carry a PoseRecord (setting `poses` not the simulator)
};

/**
 * \brief Summarises an episode.
 * \param steps  records in time order, one per frame period.
 * \param threshold  visibility counted as "in view" [0, 1].
 * \param hold   how long the visibility must stay back for an event to end [s].
 * Each step stands for the interval until the next one (the last for the
 * mean period). An occlusion event starts when the visibility falls below
 * `threshold` and ends at the first step from which it stays at or above the
 * threshold for `hold` seconds (or to the end): dips closer together than
 * that are one event. Its recovery time runs from the fall to that step.
 */
[[nodiscard]] EpisodeMetrics summarise(const std::vector<StepRecord>& steps,
                                       double threshold = 0.9, double hold = 0.2);

/// \brief The summary as `ofv simulate` and `ofv run` print it: a few indented lines.
[[nodiscard]] std::string episode_summary(const EpisodeMetrics& m);

/// \brief Header line of trajectory.csv.
[[nodiscard]] std::string trajectory_csv_header();
/// \brief One row of trajectory.csv (same columns as the header).
[[nodiscard]] std::string trajectory_csv_row(const StepRecord& step);

}  // namespace ofv
