/**
 * \file hindsight.h
 * \brief The limit of any view selection on a scenario: the camera path on
 *        the sphere that keeps the most of the object in view over the
 *        whole episode, planned from the simulator's knowledge of the
 *        future under the camera's speed limit (`method=hindsight`).
 *
 * Candidate views are a lattice of directions on the sphere of radius
 * r_sphere around the object's true centroid, which moves with the object:
 * view v at step i is c_i + r_sphere d_v. Time advances in steps of
 * `frames_per_step` frame periods. The value of view v at step i is the true
 * visible fraction of the object from there, looking at c_i
 * (sim::Renderer::visible_fractions(), the ray casting of the episode's
 * metrics). Moves: from view u at step i-1 to view v at step i when the
 * camera travels at most max_speed x the step between the two positions;
 * and straight moves of `segment_steps` steps from u to v along their great
 * circle at constant speed within that limit, each step in between scored
 * by the view nearest it (as each view stands for its cell of the sphere;
 * the planned path's values at those steps are then cast from where it is).
 * One-step moves alone lose speed to the lattice: within one step's reach
 * (1.67 cm at 0.5 m/s and 30 Hz) a 1 cm lattice has only its nearest ring,
 * so a camera crossing it moves at about 0.6 of its speed; a straight move of
 * 3 steps ends within half a spacing of where full speed would take it.
 * Dynamic programming over (step, view) gives the path with the largest sum
 * of values: exact for the lattice, the steps and these moves, not a
 * heuristic search. The camera starts where and as the scenario puts it and
 * turns towards the centroid at up to `max_turn_rate` (a view it could reach
 * before it could have turned to look at the centroid is scored as turned
 * so far; the unlimited bound's views look at it); off its sphere, it
 * reaches the sphere along the radius at full speed, or goes straight to a
 * lattice view in as few steps as its speed allows (up to 8 steps more than
 * the radius takes), the steps on the way scored where it is.
 *
 * The cost is at most views x steps visibility evaluations (each ray casts
 * the object's surface samples that face the view) plus views x (neighbours
 * + straight moves x segment_steps) x steps for the programme; far fewer
 * are made. A view keeps its value while no moving body comes near its cone
 * of sight to the object, so a still scene values each view once. A first
 * scan of the steps finds the best view at each (the unlimited bound): the
 * views best at the step before first, then the others in batches, each
 * only as far as it could beat the best so far (its rays stop once it
 * cannot, those to the samples it last found hidden first), until a view
 * sees all. Then the programme runs twice: keeping only the 64 best totals at
 * each step, which gives a path and its total; then keeping every state
 * whose total, with the best view's value at every step after it, can still
 * reach that total. No path through the others can beat the first one, so
 * the second programme is exact (the same plan as a programme over every
 * state); it values only the states it keeps, each only as far as it could
 * still reach the first total, and the views that stand for the straight
 * moves' steps from them. HindsightPlan records the views, the evaluations
 * made and the planning time.
 */
#pragma once

#include "ofv/sim/scenario.h"

#include <Eigen/Geometry>

#include <vector>

namespace ofv::sim {

/// \brief The discretisation and the camera limit of the hindsight planner.
struct HindsightSettings {
  /// Lattice spacing: each view stands for spacing² of the sphere's area [m].
  double spacing = 0.01;
  /// Frame periods per time step (the values are taken at the steps).
  int frames_per_step = 1;
  /// Steps of the straight moves at full speed between two views (1: none).
  int segment_steps = 3;
  /// The camera's speed limit [m/s] (the episode's max_linear_speed).
  double max_speed = 0.5;
  /// How fast the camera turns [rad/s] (the episode's max_angular_speed).
  double max_turn_rate = 1.5;
};

/// \brief A planned camera path and the bounds it gives.
struct HindsightPlan {
  double step = 0.0;                      ///< time step [s]
  std::vector<double> times;              ///< step times, from 0 [s]
  std::vector<Eigen::Vector3d> views;     ///< the planned camera position at each step (world) [m]
  std::vector<Eigen::Vector3d> centroids; ///< the object's true centroid at each step [m]
  std::vector<double> visible;            ///< the planned path's visible fraction at each step [0, 1]
  std::vector<double> best_visible;       ///< the best lattice view's at each step, on its own [0, 1]
  double bound = 0.0;            ///< mean of `visible`: the limit under the speed limit
  double unlimited_bound = 0.0;  ///< mean of `best_visible`: the limit without a speed limit
  int lattice_views = 0;         ///< views on the sphere
  long evaluations = 0;          ///< visibility evaluations, those stopped early included
  double seconds = 0.0;          ///< planning time (wall clock) [s]

  /// \brief The planned position at time t [s]: between two steps on the
  ///        great circle around the interpolated centroid, the last step's after the end.
  [[nodiscard]] Eigen::Vector3d view_at(double t) const;
  /// \brief The object's true centroid at time t, interpolated as view_at() [m].
  [[nodiscard]] Eigen::Vector3d centroid_at(double t) const;
};

/**
 * \brief Checks the planner's settings for an episode (plan_hindsight() does too).
 * \throws std::invalid_argument naming the setting (hindsight_spacing,
 *         hindsight_step, hindsight_segment) and the value: out of range, a spacing larger than
 *         the camera's move in one step (it could never move), or more than
 *         100000 views.
 */
void check_hindsight(const HindsightSettings& settings, double r_sphere, double duration, double rate);

/**
 * \brief Plans the best camera path of an episode in hindsight.
 * \param scenario  the world (already varied for its seed).
 * \param wMc_start the camera's pose at time 0 (its orientation sets the
 *                  views' roll: the least rotation that points it at the centroid).
 * \param r_sphere  the sphere's radius [m].
 * \param duration  the episode's length [s]; steps cover [0, duration].
 * \param settings  lattice spacing, time step, speed limit.
 * \throws std::invalid_argument as check_hindsight().
 */
[[nodiscard]] HindsightPlan plan_hindsight(const Scenario& scenario, const Eigen::Isometry3d& wMc_start,
                                           double r_sphere, double duration, const HindsightSettings& settings);

}  // namespace ofv::sim
