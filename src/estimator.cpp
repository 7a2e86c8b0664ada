// The occlusion-free view estimator (ESTIMATOR-SPEC.md §1-§7).
#include "ofv/estimator.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace ofv {
namespace {

constexpr double kRadToDeg = 180.0 / 3.14159265358979323846;

// Thresholds fixed by the spec.
constexpr double kCircularMeanEps = 1e-9;   // §2: both sums of a circular mean below this
constexpr double kVectorMeanEps = 1e-9;     // §2: vector-mean sum shorter than this
constexpr double kCameraEps = 1e-12;        // §2: camera within this of C
constexpr double kPcaEps = 1e-9;            // §2: lambda1 - lambda2 <= eps * lambda1
constexpr double kCoincidentEps = 1e-9;     // §3: |q_b - v_n| below this
constexpr double kFarHemisphereEps = 1e-9;  // §4: d . w <= this has no gnomonic image
constexpr double kZeroPushEps = 1e-12;      // §4: |v| below this
constexpr double kParallelEps = 1e-9;       // §4: |e1 . w| >= 1 - this
constexpr double kMinNormal = 1e-12;        // §7: shorter normals are invalid

[[noreturn]] void usage_error(const std::string& what) { throw std::invalid_argument(what); }

std::string format_value(double v) {
  std::ostringstream s;
  s.precision(17);
  s << v;
  return s.str();
}

void require_positive(const char* name, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    usage_error(std::string("parameter '") + name + "' must be finite and positive, got " +
                format_value(value));
  }
}

void require_finite(const char* name, const Eigen::Vector3d& p) {
  if (!p.allFinite()) {
    usage_error(std::string("'") + name + "' must be finite, got [" + format_value(p.x()) + ", " +
                format_value(p.y()) + ", " + format_value(p.z()) + "]");
  }
}

// Circular mean of angles from their sine and cosine sums; empty when degenerate.
std::optional<double> circular_mean(double sum_sin, double sum_cos) {
  if (std::abs(sum_sin) < kCircularMeanEps && std::abs(sum_cos) < kCircularMeanEps) {
    return std::nullopt;
  }
  return std::atan2(sum_sin, sum_cos);
}

struct Axes {
  Eigen::Matrix3d e;  // columns e1, e2, e3
  bool determined = true;
  bool from_world = false;
};

// Object axes (spec §2): given axes normalised, else PCA of the points with the
// world axes standing in when PCA does not determine e1.
Axes object_axes(const ViewProblem& problem, const Eigen::Matrix3Xd& points) {
  Axes axes;
  if (problem.axes) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = problem.axes->col(k);
      const double len = e.norm();
      if (!e.allFinite() || !std::isfinite(len) || len <= 0.0) {
        usage_error("axis e" + std::to_string(k + 1) + " must be finite and non-zero, got [" +
                    format_value(e.x()) + ", " + format_value(e.y()) + ", " +
                    format_value(e.z()) + "]");
      }
      axes.e.col(k) = e / len;
    }
    return axes;
  }
  const Eigen::Index n = points.cols();
  if (n >= 2) {
    const Eigen::Vector3d mean = points.rowwise().mean();
    const Eigen::Matrix3Xd centred = points.colwise() - mean;
    const Eigen::Matrix3d cov = centred * centred.transpose() / static_cast<double>(n);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
    const Eigen::Vector3d& lambda = eig.eigenvalues();  // ascending
    if (lambda(2) - lambda(1) > kPcaEps * lambda(2)) {
      const Eigen::Vector3d e1 = eig.eigenvectors().col(2).normalized();
      const Eigen::Vector3d e2 = eig.eigenvectors().col(1).normalized();
      axes.e.col(0) = e1;
      axes.e.col(1) = e2;
      axes.e.col(2) = e1.cross(e2);
      return axes;
    }
  }
  axes.e.setIdentity();
  axes.determined = false;
  axes.from_world = true;
  return axes;
}

// Mean and population standard deviation of eq. 9 over the rays [deg].
std::optional<AngularErrorStats> angular_error(const Eigen::Matrix3Xd& rays,
                                               const Eigen::Vector3d& view_from_c) {
  const Eigen::Index n = rays.cols();
  if (n == 0) {
    return std::nullopt;
  }
  Eigen::ArrayXd err(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    err(k) = angle_between(rays.col(k), view_from_c) * kRadToDeg;
  }
  const double mean = err.mean();
  return AngularErrorStats{mean, std::sqrt((err - mean).square().mean())};
}

// Occlusion-to-sphere rays d = d_nb - C in structure-of-arrays form, so that
// one gnomonic projection of all of them is a single vectorisable loop.
struct OcclusionRays {
  std::vector<double> x, y, z;
  [[nodiscard]] std::size_t size() const { return x.size(); }
};

OcclusionRays occlusion_rays(const Eigen::Vector3d& c, double r, const Eigen::Matrix3Xd& v,
                             const Eigen::Matrix3Xd& q) {
  // All occluders at once per supervoxel, as Eigen arrays (vectorised).
  const Eigen::ArrayXd qx = q.row(0).transpose().array() - c.x();
  const Eigen::ArrayXd qy = q.row(1).transpose().array() - c.y();
  const Eigen::ArrayXd qz = q.row(2).transpose().array() - c.z();
  Eigen::ArrayXd ux(qx.size()), uy(qx.size()), uz(qx.size()), len(qx.size()), t(qx.size());

  OcclusionRays rays;
  const auto reserve = static_cast<std::size_t>(v.cols() * q.cols());
  rays.x.reserve(reserve);
  rays.y.reserve(reserve);
  rays.z.reserve(reserve);
  const double r2 = r * r;
  for (Eigen::Index n = 0; n < v.cols(); ++n) {
    const Eigen::Vector3d a = v.col(n) - c;  // v_n - C
    const double a_in = a.squaredNorm() - r2;  // < 0 inside the sphere
    // The half-line from v_n through q_b leaves the sphere at a + t u (from C).
    ux = qx - a.x();
    uy = qy - a.y();
    uz = qz - a.z();
    len = (ux.square() + uy.square() + uz.square()).sqrt();
    const Eigen::ArrayXd inv = (len >= kCoincidentEps).select(len, 1.0).inverse();
    ux *= inv;
    uy *= inv;
    uz *= inv;
    t = a.x() * ux + a.y() * uy + a.z() * uz;  // a . u
    t = (t.square() - a_in).sqrt() - t;
    for (Eigen::Index b = 0; b < qx.size(); ++b) {
      if (len(b) >= kCoincidentEps) {
        rays.x.push_back(a.x() + t(b) * ux(b));
        rays.y.push_back(a.y() + t(b) * uy(b));
        rays.z.push_back(a.z() + t(b) * uz(b));
      }
    }
  }
  return rays;
}

// What one gnomonic projection onto the plane tangent at t tells (spec §4).
struct Projection {
  int in_clearance = 0;                          // points with |d_pi - t| < clearance
  Eigen::Vector3d push = Eigen::Vector3d::Zero();  // v
};

// Compiled for AVX-512, AVX2 and baseline x86-64, picked at run time: the
// wider the vectors, the faster; only the reductions' summation order differs.
template <bool kInverse>
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__) && !defined(__SANITIZE_ADDRESS__)
__attribute__((target_clones("avx512f", "avx2", "default")))
#endif
Projection project_impl(const OcclusionRays& rays, const Eigen::Vector3d& t_from_c, double r,
                        double clearance, double push_radius) {
  const Eigen::Vector3d w = t_from_c.normalized();
  const double wx = w.x(), wy = w.y(), wz = w.z();
  const double tx = t_from_c.x(), ty = t_from_c.y(), tz = t_from_c.z();
  const double clear2 = clearance * clearance;
  const double push2 = push_radius * push_radius;
  const double* dx = rays.x.data();
  const double* dy = rays.y.data();
  const double* dz = rays.z.data();
  const auto n = static_cast<std::ptrdiff_t>(rays.size());
  // Counted in a double so that the loop vectorises (exact below 2^53).
  double count = 0.0;
  double vx = 0.0, vy = 0.0, vz = 0.0;
#pragma omp simd reduction(+ : count, vx, vy, vz)
  for (std::ptrdiff_t k = 0; k < n; ++k) {
    const double dw = dx[k] * wx + dy[k] * wy + dz[k] * wz;
    const double seen = dw > kFarHemisphereEps ? 1.0 : 0.0;
    const double scale = r / (dw > kFarHemisphereEps ? dw : 1.0);
    // d_pi - t, with d_pi = C + d R / (d . w)
    const double px = dx[k] * scale - tx;
    const double py = dy[k] * scale - ty;
    const double pz = dz[k] * scale - tz;
    const double dist2 = px * px + py * py + pz * pz;
    count += dist2 < clear2 ? seen : 0.0;
    double weight = dist2 < push2 ? seen : 0.0;
    if constexpr (kInverse) {
      weight /= dist2;
    }
    vx -= weight * px;
    vy -= weight * py;
    vz -= weight * pz;
  }
  Projection p;
  p.in_clearance = static_cast<int>(count);
  p.push = Eigen::Vector3d(vx, vy, vz);
  return p;
}

Projection project(const OcclusionRays& rays, const Eigen::Vector3d& t_from_c, double r,
                   const EstimatorSettings& s) {
  return s.push_weighting == PushWeighting::InverseDistance
             ? project_impl<true>(rays, t_from_c, r, s.clearance, s.push_radius)
             : project_impl<false>(rays, t_from_c, r, s.clearance, s.push_radius);
}

// t - d_pi for the projected point nearest to t (spec §4 fallback); zero if none.
Eigen::Vector3d away_from_nearest(const OcclusionRays& rays, const Eigen::Vector3d& t_from_c,
                                  double r) {
  const Eigen::Vector3d w = t_from_c.normalized();
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d away = Eigen::Vector3d::Zero();
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const Eigen::Vector3d d(rays.x[k], rays.y[k], rays.z[k]);
    const double dw = d.dot(w);
    if (dw <= kFarHemisphereEps) {
      continue;
    }
    const Eigen::Vector3d p = d * (r / dw) - t_from_c;
    const double dist2 = p.squaredNorm();
    if (dist2 < best) {
      best = dist2;
      away = -p;
    }
  }
  return away;
}

}  // namespace

double angle_between(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::atan2(a.cross(b).norm(), a.dot(b));
}

Eigen::Vector3d sphere_exit(const Eigen::Vector3d& centre, double radius,
                            const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) {
  const Eigen::Vector3d u = dir.normalized();
  const Eigen::Vector3d a = origin - centre;
  const double b = a.dot(u);
  const double c = a.squaredNorm() - radius * radius;  // < 0 inside
  const double t = -b + std::sqrt(b * b - c);
  return origin + t * u;
}

void validate(const EstimatorSettings& s) {
  require_positive("r_seed", s.r_seed);
  require_positive("r_sphere", s.r_sphere);
  require_positive("clearance", s.clearance);
  require_positive("push_radius", s.push_radius);
  require_positive("step", s.step);
  if (s.max_iterations < 0) {
    usage_error("parameter 'max_iterations' must be a non-negative integer, got " +
                std::to_string(s.max_iterations));
  }
}

EstimatorSettings EstimatorParams::resolve() const {
  EstimatorSettings s;
  s.r_seed = r_seed.value_or(s.r_seed);
  s.r_sphere = r_sphere.value_or(s.r_sphere);
  switch (preset) {
    case Preset::Paper:
      s.clearance = s.r_seed;
      s.push_radius = s.r_sphere;
      s.step = s.r_seed;
      s.max_iterations = 500;
      break;
    case Preset::AuthorsCode:
      s.clearance = 2.0 * s.r_seed;
      s.push_radius = s.r_sphere;
      s.step = s.r_seed / 2.0;
      s.max_iterations = 50;
      break;
  }
  s.initial_view = initial_view.value_or(s.initial_view);
  s.clearance = clearance.value_or(s.clearance);
  s.push_radius = push_radius.value_or(s.push_radius);
  s.push_weighting = push_weighting.value_or(s.push_weighting);
  s.step = step.value_or(s.step);
  s.max_iterations = max_iterations.value_or(s.max_iterations);
  s.warm_start = warm_start.value_or(s.warm_start);
  validate(s);
  return s;
}

ViewEstimate estimate_view(const ViewProblem& problem, const EstimatorSettings& settings,
                           const EstimateOptions& options) {
  validate(settings);
  if (problem.positions.cols() != problem.normals.cols()) {
    usage_error("supervoxel positions (" + std::to_string(problem.positions.cols()) +
                ") and normals (" + std::to_string(problem.normals.cols()) +
                ") differ in number");
  }
  if (problem.centroid) require_finite("centroid", *problem.centroid);
  if (problem.camera) require_finite("camera", *problem.camera);
  if (problem.previous_view) require_finite("previous_view", *problem.previous_view);

  const double r = settings.r_sphere;
  ViewEstimate est;

  // §7: drop supervoxels with non-finite data or no normal; normalise normals.
  const Eigen::Index n_in = problem.positions.cols();
  Eigen::Matrix3Xd pos(3, n_in);
  Eigen::Matrix3Xd nrm(3, n_in);
  Eigen::Index n_valid = 0;
  for (Eigen::Index k = 0; k < n_in; ++k) {
    const Eigen::Vector3d p = problem.positions.col(k);
    const Eigen::Vector3d nv = problem.normals.col(k);
    const double len = nv.norm();
    if (!p.allFinite() || !nv.allFinite() || !(len >= kMinNormal)) {
      continue;
    }
    pos.col(n_valid) = p;
    nrm.col(n_valid) = nv / len;
    ++n_valid;
  }
  pos.conservativeResize(3, n_valid);
  nrm.conservativeResize(3, n_valid);

  if (!problem.centroid && n_valid == 0) {
    usage_error("no usable supervoxel and no centroid given");
  }
  const Eigen::Vector3d c = problem.centroid ? *problem.centroid : Eigen::Vector3d(pos.rowwise().mean());
  est.centroid = c;

  // §1: supervoxels at or outside the sphere are skipped.
  Eigen::Matrix3Xd v(3, n_valid);
  Eigen::Matrix3Xd rays(3, n_valid);  // s_n - C
  Eigen::Index n = 0;
  for (Eigen::Index k = 0; k < n_valid; ++k) {
    if (!((pos.col(k) - c).norm() < r)) {
      continue;
    }
    v.col(n) = pos.col(k);
    rays.col(n) = sphere_exit(c, r, pos.col(k), nrm.col(k)) - c;
    ++n;
  }
  v.conservativeResize(3, n);
  rays.conservativeResize(3, n);
  est.skipped_supervoxels = static_cast<int>(n_in - n);

  const Axes axes = object_axes(problem, v);
  est.axes = axes.e;
  est.axes_from_world = axes.from_world;
  const Eigen::Vector3d e1 = axes.e.col(0), e2 = axes.e.col(1), e3 = axes.e.col(2);

  // §2: initial view t0.
  std::optional<Eigen::Vector3d> dir;
  if (settings.initial_view == InitialView::SphericalMean && axes.determined && n > 0) {
    double sin_theta = 0.0, cos_theta = 0.0, sin_phi = 0.0, cos_phi = 0.0;
    for (Eigen::Index k = 0; k < n; ++k) {
      const Eigen::Vector3d u = rays.col(k);
      const double phi = std::atan2(u.cross(e1).norm(), u.dot(e1));
      const double theta = std::atan2(u.dot(e3), u.dot(e2));
      sin_theta += std::sin(theta);
      cos_theta += std::cos(theta);
      sin_phi += std::sin(phi);
      cos_phi += std::cos(phi);
    }
    const std::optional<double> theta = circular_mean(sin_theta, cos_theta);
    const std::optional<double> phi = circular_mean(sin_phi, cos_phi);
    if (theta && phi) {
      dir = std::cos(*phi) * e1 +
            std::sin(*phi) * (std::cos(*theta) * e2 + std::sin(*theta) * e3);
      est.initial_view_used = InitialViewUsed::SphericalMean;
    }
  }
  if (!dir && n > 0) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (Eigen::Index k = 0; k < n; ++k) {
      sum += rays.col(k).normalized();
    }
    if (sum.norm() >= kVectorMeanEps) {
      dir = sum.normalized();
      est.initial_view_used = InitialViewUsed::VectorMean;
    }
  }
  if (!dir) {
    if (!problem.camera) {
      usage_error("the initial view falls back to the camera direction, but no camera is given");
    }
    const Eigen::Vector3d to_camera = *problem.camera - c;
    if (to_camera.norm() < kCameraEps) {
      usage_error("the initial view falls back to the camera direction, but the camera is at the centroid");
    }
    dir = to_camera.normalized();
    est.initial_view_used = InitialViewUsed::Camera;
  }
  est.t0 = c + r * *dir;

  // §7: occluders with a non-finite coordinate are skipped.
  Eigen::Matrix3Xd q(3, problem.occluders.cols());
  Eigen::Index b_count = 0;
  for (Eigen::Index k = 0; k < problem.occluders.cols(); ++k) {
    if (problem.occluders.col(k).allFinite()) {
      q.col(b_count++) = problem.occluders.col(k);
    }
  }
  q.conservativeResize(3, b_count);
  est.skipped_occluders = static_cast<int>(problem.occluders.cols() - b_count);

  // §4: the iteration.
  Eigen::Vector3d start = est.t0;
  if (settings.warm_start && problem.previous_view) {
    const Eigen::Vector3d from_c = *problem.previous_view - c;
    if (from_c.norm() < kCameraEps) {
      usage_error("'previous_view' is at the centroid: no direction to warm-start from");
    }
    start = c + r * from_c.normalized();
  }

  if (b_count == 0) {
    est.status = ViewStatus::NoOccluders;
    est.tf = est.t0;
    if (options.record_path) est.path.push_back(est.t0);
  } else {
    const OcclusionRays occ = occlusion_rays(c, r, v, q);
    est.occlusion_points = static_cast<int>(occ.size());
    const Eigen::Vector3d t0_from_c = est.t0 - c;

    Eigen::Vector3d t = start;
    Eigen::Vector3d best = start;
    int best_count = std::numeric_limits<int>::max();
    double best_angle = std::numeric_limits<double>::infinity();
    // The iteration is a deterministic map of t alone: once an iterate repeats
    // bit for bit, every later one is a repeat too, none clear and none better.
    // Brent's cycle detection finds that in O(1) memory, so that a huge
    // max_iterations on a cycling scene ends with the result it would reach.
    Eigen::Vector3d checkpoint = start;
    long steps_since_checkpoint = 0;
    long checkpoint_period = 1;
    bool cycling = false;
    for (int i = 0;; ++i) {
      const Eigen::Vector3d t_from_c = t - c;
      if (cycling) {
        est.status = ViewStatus::NotConverged;
        est.tf = best;
        est.iterations = settings.max_iterations;
        est.clearance_points = best_count;
        break;
      }
      if (options.record_path) est.path.push_back(t);
      const Projection proj = project(occ, t_from_c, r, settings);
      if (proj.in_clearance == 0) {
        est.status = ViewStatus::Converged;
        est.tf = t;
        est.iterations = i;
        est.clearance_points = 0;
        break;
      }
      const double angle = angle_between(t_from_c, t0_from_c);
      if (proj.in_clearance < best_count ||
          (proj.in_clearance == best_count && angle < best_angle)) {
        best = t;
        best_count = proj.in_clearance;
        best_angle = angle;
      }
      if (i == settings.max_iterations) {
        est.status = ViewStatus::NotConverged;
        est.tf = best;
        est.iterations = i;
        est.clearance_points = best_count;
        break;
      }
      Eigen::Vector3d push = proj.push;
      if (push.norm() < kZeroPushEps) {
        push = away_from_nearest(occ, t_from_c, r);
        if (push.norm() < kZeroPushEps) {
          const Eigen::Vector3d w = t_from_c.normalized();
          const Eigen::Vector3d axis = std::abs(e1.dot(w)) >= 1.0 - kParallelEps ? e2 : e1;
          push = axis - axis.dot(w) * w;
        }
      }
      const Eigen::Vector3d t_pi = t + settings.step * push.normalized();
      t = c + r * (t_pi - c).normalized();
      cycling = t == checkpoint;
      if (++steps_since_checkpoint == checkpoint_period) {
        checkpoint = t;
        checkpoint_period *= 2;
        steps_since_checkpoint = 0;
      }
    }
  }

  est.error_t0 = angular_error(rays, est.t0 - c);
  est.error_tf = angular_error(rays, est.tf - c);
  est.tf_to_t0_deg = angle_between(est.tf - c, est.t0 - c) * kRadToDeg;
  return est;
}

const char* to_string(InitialView v) {
  return v == InitialView::SphericalMean ? "spherical_mean" : "vector_mean";
}
const char* to_string(PushWeighting v) {
  return v == PushWeighting::Sum ? "sum" : "inverse_distance";
}
const char* to_string(Preset v) { return v == Preset::Paper ? "paper" : "authors_code"; }
const char* to_string(ViewStatus v) {
  switch (v) {
    case ViewStatus::Converged: return "converged";
    case ViewStatus::NotConverged: return "not_converged";
    case ViewStatus::NoOccluders: return "no_occluders";
    case ViewStatus::NoSupervoxels: return "no_supervoxels";
  }
  return "?";
}
const char* to_string(InitialViewUsed v) {
  switch (v) {
    case InitialViewUsed::SphericalMean: return "spherical_mean";
    case InitialViewUsed::VectorMean: return "vector_mean";
    case InitialViewUsed::Camera: return "camera";
  }
  return "?";
}

std::optional<InitialView> parse_initial_view(const std::string& word) {
  if (word == "spherical_mean") return InitialView::SphericalMean;
  if (word == "vector_mean") return InitialView::VectorMean;
  return std::nullopt;
}
std::optional<PushWeighting> parse_push_weighting(const std::string& word) {
  if (word == "sum") return PushWeighting::Sum;
  if (word == "inverse_distance") return PushWeighting::InverseDistance;
  return std::nullopt;
}
std::optional<Preset> parse_preset(const std::string& word) {
  if (word == "paper") return Preset::Paper;
  if (word == "authors_code") return Preset::AuthorsCode;
  return std::nullopt;
}

}  // namespace ofv
