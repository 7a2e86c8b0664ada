/**
 * \file estimator.h
 * \brief The occlusion-free view estimator of Cuiral-Zueco and López-Nicolás,
 *        "Dynamic Occlusion Handling for Real Time Object Perception",
 *        section III, as fixed by ESTIMATOR-SPEC.md.
 *
 * Pure geometry on Eigen: no I/O, no PCL, no ViSP. Every vector is in one
 * fixed frame (the world frame W), in metres.
 *
 * \code
 * ofv::ViewProblem problem;
 * problem.positions = ...;   // 3 x N supervoxel centroids v_n
 * problem.normals = ...;     // 3 x N normals p_n, towards the sensor side
 * problem.occluders = ...;   // 3 x B occluder points q_b
 * const ofv::ViewEstimate estimate = ofv::estimate_view(problem, ofv::EstimatorSettings{});
 * // estimate.tf: camera position on the sphere, looking at estimate.centroid
 * \endcode
 */
#pragma once

#include <Eigen/Core>

#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace ofv {

/// \brief How the initial view t0 averages the normals-to-sphere rays (spec §2).
enum class InitialView {
  SphericalMean,  ///< circular means of polar angle and azimuth about e1 (paper eqs. 4-5)
  VectorMean,     ///< normalised sum of the unit rays
};

/// \brief How the projected occlusion points push the iterate (spec §4).
enum class PushWeighting {
  Sum,              ///< v = sum (t_i - d_pi), the paper's reading
  InverseDistance,  ///< each term divided by its squared length: near points push hardest
};

/// \brief A named set of settings (spec §4, `preset`).
enum class Preset {
  Paper,        ///< the paper's printed reading
  AuthorsCode,  ///< the authors' public 2020 implementation: step r_seed/2, clearance 2 r_seed, 50 iterations
};

/// \brief Outcome of one estimate: the three of the iteration (spec §4), or
/// that there was nothing to estimate from.
enum class ViewStatus {
  Converged,     ///< t_f has no projected occlusion point within `clearance`
  NotConverged,  ///< max_iterations reached; t_f is the best visited iterate
  OutOfTime,     ///< time_budget ran out first; t_f is the best visited iterate
  NoOccluders,   ///< no valid occluder: t_f = t0
  /// No usable supervoxel (all skipped by spec §7) and no given centroid, so
  /// neither C nor a view exists: t0 = tf = the camera position if given, else
  /// zero, no angular errors. A closed loop treats it as the object lost;
  /// `ofv estimate` as a usage error (spec §8).
  NoSupervoxels,
};

/// \brief Which rule produced t0 after the spec's fallbacks (spec §2).
enum class InitialViewUsed { SphericalMean, VectorMean, Camera };

/**
 * \brief Fully resolved estimator settings. Lengths in metres.
 *
 * The defaults are the `paper` preset with r_seed = 0.02 m and
 * r_sphere = 0.5 m. To apply a preset with other radii, use
 * EstimatorParams::resolve().
 */
struct EstimatorSettings {
  double r_seed = 0.02;    ///< supervoxel seed resolution R_seed [m]
  double r_sphere = 0.5;   ///< radius of the solution sphere R_sphere [m]
  InitialView initial_view = InitialView::SphericalMean;  ///< how t0 averages the normal rays
  double clearance = 0.02;     ///< stop when no projected point is closer than this to t_i [m]
  double push_radius = 0.5;    ///< projected points closer than this push the iterate [m]
  PushWeighting push_weighting = PushWeighting::Sum;  ///< how the projected points push the iterate
  double step = 0.02;          ///< length of one push on the tangent plane [m]
  int max_iterations = 500;    ///< push steps before giving up (>= 0)
  bool warm_start = false;     ///< start from the previous frame's view instead of t0
  /// Wall time one estimate may take [s] (not the spec's: ofv's bound on
  /// work). When it runs out the iteration ends with the best visited
  /// iterate and status OutOfTime. The loop's frames take about 1 ms.
  double time_budget = 1.0;
};

/// Lengths (r_seed, r_sphere, clearance, push_radius, step) and input
/// coordinates beyond this are refused [m]: the arithmetic stays far from overflow.
inline constexpr double kMaxLength = 1e4;
/// More occlusion rays (usable supervoxels x occluders, spec §3) than this
/// are refused (24 bytes each: 240 MB): thin the supervoxels or occluders.
inline constexpr double kMaxOcclusionRays = 1e7;
/// Most push steps max_iterations may ask for (time_budget bounds the work too).
inline constexpr int kMaxIterations = 100000000;
/// \brief true for the statuses whose t_f is free of occlusion (converged, no occluders).
[[nodiscard]] inline bool is_free(ViewStatus s) { return s == ViewStatus::Converged || s == ViewStatus::NoOccluders; }

/**
 * \brief Settings as a user states them: a preset plus explicit overrides.
 *
 * resolve() applies the preset with the final r_seed and r_sphere, then the
 * explicit values, then validates (spec §4 `preset`, §7).
 */
struct EstimatorParams {
  Preset preset = Preset::Paper;  ///< the named set of settings the unset fields take
  std::optional<double> r_seed;    ///< R_seed [m]; unset: EstimatorSettings' default
  std::optional<double> r_sphere;  ///< R_sphere [m]; unset: EstimatorSettings' default
  std::optional<InitialView> initial_view;      ///< unset: EstimatorSettings' default
  std::optional<double> clearance;              ///< [m]; unset: the preset's (from r_seed)
  std::optional<double> push_radius;            ///< [m]; unset: the preset's (r_sphere)
  std::optional<PushWeighting> push_weighting;  ///< unset: EstimatorSettings' default
  std::optional<double> step;                   ///< [m]; unset: the preset's (from r_seed)
  std::optional<int> max_iterations;            ///< unset: the preset's (500 or 50)
  std::optional<bool> warm_start;               ///< unset: EstimatorSettings' default (false)
  std::optional<double> time_budget;            ///< [s]; unset: EstimatorSettings' default

  /// \brief The settings these parameters stand for.
  /// \throws std::invalid_argument naming the parameter and value that break spec §7.
  [[nodiscard]] EstimatorSettings resolve() const;
};

/// \brief Throws std::invalid_argument, naming the parameter and its value,
/// unless every length is finite, positive and at most kMaxLength,
/// max_iterations in [0, kMaxIterations] and time_budget in (0, 3600] s.
void validate(const EstimatorSettings& settings);

/**
 * \brief One frame's input to the estimator, in the world frame [m].
 *
 * Columns are points. Invalid supervoxels and occluders are skipped and
 * counted in the estimate (spec §7); invalid optional inputs throw.
 */
struct ViewProblem {
  Eigen::Matrix3Xd positions;  ///< 3 x N object supervoxel centroids v_n
  Eigen::Matrix3Xd normals;    ///< 3 x N supervoxel normals p_n (any length > 1e-12)
  Eigen::Matrix3Xd occluders;  ///< 3 x B occluder points q_b (may be empty)
  /// C; default: mean of every usable v_n (spec §7), also those at or outside the sphere.
  std::optional<Eigen::Vector3d> centroid;
  /// Columns e1, e2, e3, any length > 0, pairwise orthogonal (|cos| <= 1e-6);
  /// default: PCA of the same v_n as C (a supervoxel skipped by spec §1 loses
  /// its ray, never its part in C or the axes).
  std::optional<Eigen::Matrix3d> axes;
  std::optional<Eigen::Vector3d> camera;         ///< current camera position (t0's last fallback)
  std::optional<Eigen::Vector3d> previous_view;  ///< previous t_f, used with warm_start
};

/// \brief Mean and population standard deviation of an angular error [deg].
struct AngularErrorStats {
  double mean = 0.0;  ///< mean [deg]
  double std = 0.0;   ///< population standard deviation [deg]
};

/// \brief The estimator's result for one frame (spec §8), world frame [m].
struct ViewEstimate {
  Eigen::Vector3d t0 = Eigen::Vector3d::Zero();  ///< initial (occlusion-blind) view
  Eigen::Vector3d tf = Eigen::Vector3d::Zero();  ///< final (occlusion-free) view
  ViewStatus status = ViewStatus::NoOccluders;  ///< how the iteration ended
  int iterations = 0;  ///< push steps taken (0 when the start is clear)
  InitialViewUsed initial_view_used = InitialViewUsed::SphericalMean;  ///< the rule that gave t0
  int skipped_supervoxels = 0;  ///< non-finite, zero normal, or at/outside the sphere
  int skipped_occluders = 0;    ///< non-finite
  /// Angular error (eq. 9) of t0 and tf over the used rays; empty when no supervoxel is left.
  std::optional<AngularErrorStats> error_t0;
  std::optional<AngularErrorStats> error_tf;  ///< the same for t_f

  // Diagnostics.
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< C used
  Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();  ///< e1, e2, e3 used (columns)
  bool axes_from_world = false;   ///< PCA could not determine e1: world axes stood in
  double tf_to_t0_deg = 0.0;      ///< angle between t_f and t0 seen from C [deg]
  int occlusion_points = 0;       ///< N_C: occlusion-to-sphere points used
  int clearance_points = 0;       ///< projected points within `clearance` of t_f
  /// Every visited iterate, start first, when requested. When the iteration
  /// falls into an exact cycle, the path stops where the cycle closes (the
  /// rest would only repeat it) while `iterations` reports max_iterations.
  std::vector<Eigen::Vector3d> path;
};

/// \brief Options that do not change the estimate.
struct EstimateOptions {
  bool record_path = false;  ///< fill ViewEstimate::path
};

/// \brief What the estimator uses of a problem for a given C and R: the
///        supervoxels of spec §7 inside the sphere (§1) and the usable occluders.
struct UsableInput {
  Eigen::Matrix3Xd positions;  ///< 3 x N v_n [m]
  Eigen::Matrix3Xd normals;    ///< 3 x N unit normals p_n
  Eigen::Matrix3Xd rays;       ///< 3 x N s_n - C: where the normal leaves the sphere, from C [m]
  Eigen::Matrix3Xd occluders;  ///< 3 x B finite q_b [m]
};

/// \brief The supervoxels, rays and occluders the estimator would use with
///        centroid `centroid` and radius `r_sphere` (for baselines and metrics).
[[nodiscard]] UsableInput usable_input(const ViewProblem& problem, const Eigen::Vector3d& centroid, double r_sphere);

namespace detail {
struct FieldAccess;
}

/**
 * \brief One frame's problem prepared once for every estimate and view score
 *        made on it: the usable supervoxels and occluders (spec §7), C and
 *        the axes, the normals-to-sphere rays (§1) and the occlusion-to-sphere
 *        rays (§3), the part of the estimator that grows with supervoxels x
 *        occluders.
 *
 * A loop that estimates the same frame from several starts (the warm start
 * from its previous target, anticipated occluders) and scores views on it
 * (score_view(), most_visible_view()) builds one field per set of occluders
 * and hands it to each call. The field does not hold the problem's
 * previous_view: each estimate_view() call on it gives its own. Movable, not
 * copyable; immutable once built, so calls on one field may run on several
 * threads.
 */
class OcclusionField {
 public:
  /**
   * \param problem  the frame (world frame); its previous_view is only checked.
   * \param r_sphere R [m], finite and > 0; estimates on the field must use it.
   * \throws std::invalid_argument as estimate_view() does for the problem, or
   *         when the occlusion rays would be more than ofv handles (10^8).
   */
  OcclusionField(const ViewProblem& problem, double r_sphere);
  ~OcclusionField();
  OcclusionField(OcclusionField&&) noexcept;             ///< moves the prepared data
  OcclusionField& operator=(OcclusionField&&) noexcept;  ///< moves the prepared data
  OcclusionField(const OcclusionField&) = delete;
  OcclusionField& operator=(const OcclusionField&) = delete;

  /// R [m].
  [[nodiscard]] double r_sphere() const;
  /// Whether there is an object: a usable supervoxel or a given C. Without
  /// one, estimate_view() returns ViewStatus::NoSupervoxels.
  [[nodiscard]] bool has_object() const;
  /// C [m] (zero without an object).
  [[nodiscard]] const Eigen::Vector3d& centroid() const;
  /// The supervoxels inside the sphere with their rays, and the usable occluders.
  [[nodiscard]] const UsableInput& usable() const;
  /// N_C: the occlusion-to-sphere points.
  [[nodiscard]] int occlusion_points() const;

 private:
  friend struct detail::FieldAccess;
  struct Data;
  std::unique_ptr<Data> data_;
};

/**
 * \brief estimate_view() on a prepared field, warm-started (with
 *        EstimatorSettings::warm_start) from `previous_view`. Equal to
 *        estimate_view(problem, settings, options) with the field's problem
 *        and that previous_view; only the field's preparation is not counted in
 *        the time budget.
 * \throws std::invalid_argument on invalid settings, a settings.r_sphere other
 *         than the field's, a non-finite or far previous_view, and the errors
 *         of estimate_view() that depend on the start (t0's camera fallback,
 *         a warm start from C).
 */
[[nodiscard]] ViewEstimate estimate_view(const OcclusionField& field, const EstimatorSettings& settings,
                                         const std::optional<Eigen::Vector3d>& previous_view,
                                         const EstimateOptions& options = {});

/**
 * \brief Estimates the occlusion-free view for one frame (spec §1-§6).
 *
 * A frame with no usable supervoxel and no given centroid is an expected
 * outcome, not an error: status ViewStatus::NoSupervoxels, t0 = tf = the
 * camera position if given (else zero), iterations 0, no angular errors,
 * every supervoxel counted in skipped_supervoxels, the non-finite occluders in
 * skipped_occluders; the other fields keep their defaults.
 *
 * \param problem  the frame's supervoxels, occluders and optional inputs (world frame).
 * \param settings validated with validate().
 * \param options  diagnostics switches.
 * \throws std::invalid_argument on invalid input, with a message naming the
 *         field and the value: invalid settings, a non-finite, zero-length or
 *         non-orthogonal given axis, a non-finite optional point, mismatched positions and
 *         normals, the camera fallback of t0 (spec §2) reached without a
 *         camera or with the camera at C, or a warm start from a previous
 *         view at C.
 */
[[nodiscard]] ViewEstimate estimate_view(const ViewProblem& problem,
                                         const EstimatorSettings& settings,
                                         const EstimateOptions& options = {});

/**
 * \brief Prepares the calling thread's working memory for problems of up to
 *        `occlusion_points` occlusion points (supervoxels x occluders), 24
 *        bytes per point twice, mapped now. A real-time loop calls it before
 *        its first frame: otherwise the first frame with more points than
 *        any before faults in fresh memory, which took more time than the
 *        estimate itself (2.5 of 6 ms with 1.2·10^5 points, measured in the
 *        closed loop). Asking again for as much or less costs nothing; at
 *        most 3·10^6 points are prepared. Results do not depend on it.
 */
void reserve_estimator_memory(std::size_t occlusion_points);

/**
 * \brief Angle between two directions [rad], robust near 0 and pi.
 */
[[nodiscard]] double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b);

/**
 * \brief Point where the half-line origin + t dir, t > 0, leaves the sphere.
 * \pre origin strictly inside the sphere, dir non-zero (need not be unit).
 */
[[nodiscard]] Eigen::Vector3d sphere_exit(const Eigen::Vector3d& centre, double radius,
                                          const Eigen::Vector3d& origin,
                                          const Eigen::Vector3d& dir);

/// \name Enumeration words as used in scene files and on the command line.
/// \{
[[nodiscard]] const char* to_string(InitialView v);  ///< `spherical_mean` or `vector_mean`
/// `sum` or `inverse_distance`.
[[nodiscard]] const char* to_string(PushWeighting v);
/// `paper` or `authors_code`.
[[nodiscard]] const char* to_string(Preset v);
/// `converged`, `not_converged`, `out_of_time`, `no_occluders` or `no_supervoxels`.
[[nodiscard]] const char* to_string(ViewStatus v);
/// `spherical_mean`, `vector_mean` or `camera`.
[[nodiscard]] const char* to_string(InitialViewUsed v);
/// Parse a word; std::nullopt if it is not one of the listed words.
[[nodiscard]] std::optional<InitialView> parse_initial_view(const std::string& word);
/// The PushWeighting of `sum` or `inverse_distance`; std::nullopt for any other word.
[[nodiscard]] std::optional<PushWeighting> parse_push_weighting(const std::string& word);
/// The Preset of `paper` or `authors_code`; std::nullopt for any other word.
[[nodiscard]] std::optional<Preset> parse_preset(const std::string& word);
/// \}

}  // namespace ofv
