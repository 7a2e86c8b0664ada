/**
 * \file view_methods.h
 * \brief View selection: ofv's estimator and what it is compared against.
 *
 * The closed loop (ofv::servo::ViewLoop) picks the camera's target view with one of
 * these methods:
 * - the occlusion-free view estimator (estimator.h, ESTIMATOR-SPEC);
 * - a static camera (never moves);
 * - the occlusion-blind initial view t0 (the authors' previous method);
 * - a sampling next-best-view planner: candidate views spread evenly on the
 *   sphere (a Fibonacci lattice), each scored by ray casting the object's
 *   supervoxels against the occluders and by normal alignment; the best one
 *   is taken. This is what a user of NBV planners would try instead.
 *
 * Pure geometry on Eigen, on the estimator's own ViewProblem, so that every
 * method sees exactly the same input.
 */
#pragma once

#include "ofv/estimator.h"

#include <string>
#include <vector>

namespace ofv {

/// \brief The view-selection methods of the closed loop.
enum class ViewMethod {
  Estimator,  ///< ofv's occlusion-free view (t_f)
  Static,     ///< keep the camera where it is
  InitialView,  ///< occlusion-blind t0
  Sampling,   ///< best of many candidate views on the sphere
  /// The best path in hindsight, planned before the episode from the
  /// simulator's knowledge of the future (sim::plan_hindsight): the limit
  /// of any method, simulation only (the loop follows it, ofv::servo::ViewLoop::follow).
  Hindsight,
};

/// \brief The method's word in settings and files: estimator, static, initial_view, sampling, hindsight.
[[nodiscard]] const char* to_string(ViewMethod m);

/// \brief `n` unit directions spread evenly on the sphere (Fibonacci lattice).
[[nodiscard]] Eigen::Matrix3Xd fibonacci_directions(int n);

/// \brief Settings of the sampling planner.
struct SamplingSettings {
  int candidates = 2000;         ///< candidate views on the sphere
  double occluder_radius = 0.015;  ///< an occluder point blocks rays passing closer than this [m]
};

/// \brief A scored view.
struct ScoredView {
  Eigen::Vector3d view = Eigen::Vector3d::Zero();  ///< camera position on the sphere (world) [m]
  double visible_fraction = 0.0;  ///< supervoxels whose line of sight misses every occluder [0, 1]
  double mean_error_deg = 0.0;    ///< mean angular error (eq. 9) over the supervoxels [deg]
};

/**
 * \brief Scores a camera position: the fraction of the usable supervoxels
 *        (spec §1, §7) it sees past the occluders, each occluder a ball of
 *        radius `occluder_radius`, and its mean angular error (eq. 9).
 *        Supervoxels facing away (normal . (view - v) <= 0) count as unseen.
 * \param problem  the frame's supervoxels and occluders (world frame).
 * \param centroid C of the problem (ViewEstimate::centroid) [m].
 * \param r_sphere radius of the sphere [m].
 * \param view     the camera position to score (world frame) [m].
 * \param occluder_radius radius of each occluder point's ball [m].
 */
[[nodiscard]] ScoredView score_view(const ViewProblem& problem, const Eigen::Vector3d& centroid,
                                    double r_sphere, const Eigen::Vector3d& view,
                                    double occluder_radius);
/// \brief score_view() on a prepared field: its supervoxels, occluders and C.
[[nodiscard]] ScoredView score_view(const OcclusionField& field, const Eigen::Vector3d& view,
                                    double occluder_radius);

/**
 * \brief Mean angular error (eq. 9, spec §6) of a camera position: the angle,
 *        seen from `centroid`, between the camera and each usable
 *        supervoxel's normal-to-sphere ray [deg]; 0 without usable supervoxels.
 */
[[nodiscard]] double mean_angular_error_deg(const ViewProblem& problem, const Eigen::Vector3d& centroid,
                                            double r_sphere, const Eigen::Vector3d& view);

/**
 * \brief The sampling next-best-view planner: the candidate with the largest
 *        visible fraction, ties broken by the smallest mean angular error.
 */
[[nodiscard]] ScoredView sample_best_view(const ViewProblem& problem,
                                          const Eigen::Vector3d& centroid, double r_sphere,
                                          const SamplingSettings& sampling);
/// \brief sample_best_view() on a prepared field: its supervoxels, occluders, C and R.
[[nodiscard]] ScoredView sample_best_view(const OcclusionField& field, const SamplingSettings& sampling);

/// \brief Settings of most_visible_view().
struct MostVisibleSettings {
  double step_deg = 8.0;          ///< neighbours of the current view, this far from it seen from C [deg]
  double margin = 0.05;           ///< a view must see this much more of the object than the current one
  double occluder_radius = 0.02;  ///< an occluder point blocks lines of sight passing closer than this [m]
};

/**
 * \brief A view that sees clearly more, nearby (ofv::servo::ViewLoop's look-ahead climbs there): scores (score_view) the
 *        current view, its 8 neighbours at `step_deg` around it and the
 *        `others`, all on the sphere, and returns the one that sees the
 *        largest fraction of the object, but the current view unless that
 *        one sees at least `margin` more. Climbing this way the camera
 *        moves only towards clearly better views and otherwise holds still,
 *        never towards a gap that only an edge of the object shows through.
 * \param problem  the frame's supervoxels and occluders (world frame).
 * \param centroid C of the problem [m].
 * \param r_sphere radius of the sphere [m].
 * \param current the camera's position (projected on the sphere) [m].
 * \param others  further candidate positions (projected on the sphere) [m].
 * \param settings `step_deg`, `margin` and `occluder_radius` are used.
 */
[[nodiscard]] ScoredView most_visible_view(const ViewProblem& problem, const Eigen::Vector3d& centroid,
                                           double r_sphere, const Eigen::Vector3d& current,
                                           const std::vector<Eigen::Vector3d>& others,
                                           const MostVisibleSettings& settings);
/// \brief most_visible_view() on a prepared field: its supervoxels, occluders, C and R.
[[nodiscard]] ScoredView most_visible_view(const OcclusionField& field, const Eigen::Vector3d& current,
                                           const std::vector<Eigen::Vector3d>& others,
                                           const MostVisibleSettings& settings);

}  // namespace ofv
