/**
 * \file evaluation.h
 * \brief The TUM RGB-D benchmark's measures of a camera trajectory against
 *        ground truth (Sturm et al., "A Benchmark for the Evaluation of RGB-D
 *        SLAM Systems", IROS 2012): absolute trajectory error and relative
 *        pose error, and the TUM trajectory file writer.
 *
 * Poses are ofv::StampedPose (camera -> world, metres). The two
 * trajectories are associated by timestamp: each estimated pose with the
 * ground-truth pose nearest in time, within `max_time_difference`.
 *
 * \code
 * const auto truth = ofv::read_pose_file("recording/groundtruth.txt");
 * const auto estimate = ofv::read_pose_file("out/poses.txt");
 * const ofv::odometry::TrajectoryErrors e = ofv::odometry::trajectory_errors(estimate, truth);
 * std::cout << e.ate * 1000 << " mm\n";
 * \endcode
 */
#pragma once

#include "ofv/sources/sequence_files.h"

#include <string>
#include <utility>
#include <vector>

namespace ofv::odometry {

/// \brief Relative pose errors over pose pairs a fixed step apart.
struct RelativeErrors {
  long pairs = 0;                  ///< pairs compared
  double translation_rmse = 0.0;   ///< RMS of the translational error [m]
  double translation_max = 0.0;    ///< its largest [m]
  double rotation_rmse = 0.0;      ///< RMS of the rotational error [deg]
  double rotation_max = 0.0;       ///< its largest [deg]
};

/// \brief Every measure of one trajectory against its ground truth.
struct TrajectoryErrors {
  long poses = 0;            ///< associated poses
  double ate = 0.0;          ///< absolute trajectory error: RMS translation error after aligning the first pose [m]
  double ate_max = 0.0;      ///< its largest translation error [m]
  RelativeErrors per_frame;  ///< relative pose error between consecutive associated poses
  RelativeErrors per_second; ///< relative pose error between poses 1 s apart
};

/**
 * \brief Pairs (estimate index, truth index): each estimated pose with the
 *        ground-truth pose nearest in time, when within max_time_difference [s].
 * \pre both sorted by time.
 */
[[nodiscard]] std::vector<std::pair<std::size_t, std::size_t>> associate(
    const std::vector<StampedPose>& estimate, const std::vector<StampedPose>& truth,
    double max_time_difference = 0.02);

/**
 * \brief Absolute trajectory error: the estimate is moved by the rigid
 *        transform that puts its first associated pose on the ground
 *        truth's, then the RMS of the distances between the positions [m].
 * \return {RMSE, max} [m]; {0, 0} without associated poses.
 */
[[nodiscard]] std::pair<double, double> absolute_trajectory_error(const std::vector<StampedPose>& estimate,
                                                                  const std::vector<StampedPose>& truth,
                                                                  double max_time_difference = 0.02);

/**
 * \brief Relative pose error: for associated poses i and j, the error
 *        E = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j) (Q truth, P estimate), its
 *        translation's norm and its rotation's angle. j is i + `frames`
 *        when `seconds` <= 0, else the first pose at least `seconds` after i.
 */
[[nodiscard]] RelativeErrors relative_pose_error(const std::vector<StampedPose>& estimate,
                                                 const std::vector<StampedPose>& truth, int frames, double seconds,
                                                 double max_time_difference = 0.02);

/// \brief ATE, RPE per frame and per second at once.
[[nodiscard]] TrajectoryErrors trajectory_errors(const std::vector<StampedPose>& estimate,
                                                 const std::vector<StampedPose>& truth,
                                                 double max_time_difference = 0.02);

}  // namespace ofv::odometry
