// View selection methods besides the estimator (baselines).
#include "ofv/view_methods.h"
#include "ofv/constants.h"
#include "point_kernel.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>

namespace ofv {

namespace {

constexpr double kRadToDeg = 180.0 / kPi;

// Eq. 9 averaged over the usable rays [deg]; 0 without any.
double mean_error_deg(const UsableInput& u, const Eigen::Vector3d& c, const Eigen::Vector3d& view) {
  double error = 0.0;
  for (Eigen::Index i = 0; i < u.rays.cols(); ++i) error += angle_between(u.rays.col(i), view - c);
  return u.rays.cols() > 0 ? error / static_cast<double>(u.rays.cols()) * kRadToDeg : 0.0;
}

// Whether one of the n occluders (by coordinate) lies closer than sqrt(rho2)
// to the segment from p to p + seg (len2 = |seg|^2): |rel - t seg|, rel =
// o - p, t = rel . seg / len2 clamped to [0, 1], summed as Eigen sums a
// Vector3d's dot product and squared norm, (x + y) + z, so that the result
// is that of the plain Eigen expression.
OFV_POINT_KERNEL bool any_near_segment(const double* x, const double* y, const double* z, std::size_t n,
                                       double px, double py, double pz, double sx, double sy, double sz,
                                       double len2, double rho2) {
  int near = 0;
#pragma omp simd reduction(| : near)
  for (std::size_t b = 0; b < n; ++b) {
    const double rx = x[b] - px, ry = y[b] - py, rz = z[b] - pz;
    double t = ((rx * sx + ry * sy) + rz * sz) / len2;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    const double dx = rx - t * sx, dy = ry - t * sy, dz = rz - t * sz;
    near |= (dx * dx + dy * dy) + dz * dz < rho2 ? 1 : 0;
  }
  return near != 0;
}

ScoredView score(const UsableInput& u, const Eigen::Vector3d& c,
                 const Eigen::Vector3d& view, double rho) {
  ScoredView s;
  s.view = view;
  const Eigen::Index n = u.positions.cols();
  if (n == 0) return s;
  // The occluders by coordinate, tested in blocks: a blocked line of sight
  // stops at its first block with a hit.
  constexpr std::size_t kBlock = 64;
  const auto m = static_cast<std::size_t>(u.occluders.cols());
  const Eigen::Matrix<double, Eigen::Dynamic, 3> o = u.occluders.transpose();
  const double rho2 = rho * rho;
  int seen = 0;
  for (Eigen::Index i = 0; i < n; ++i) {
    const Eigen::Vector3d p = u.positions.col(i);
    const Eigen::Vector3d seg = view - p;
    if (u.normals.col(i).dot(seg) <= 0.0) continue;
    const double len2 = seg.squaredNorm();
    bool blocked = false;
    for (std::size_t b = 0; b < m && !blocked; b += kBlock) {
      blocked = any_near_segment(o.col(0).data() + b, o.col(1).data() + b, o.col(2).data() + b,
                                 std::min(kBlock, m - b), p.x(), p.y(), p.z(), seg.x(), seg.y(), seg.z(),
                                 len2, rho2);
    }
    seen += blocked ? 0 : 1;
  }
  s.visible_fraction = static_cast<double>(seen) / static_cast<double>(n);
  s.mean_error_deg = mean_error_deg(u, c, view);
  return s;
}

ScoredView sample_best(const UsableInput& u, const Eigen::Vector3d& centroid, double r_sphere,
                       const SamplingSettings& sampling) {
  if (!(sampling.occluder_radius > 0.0) || !std::isfinite(sampling.occluder_radius)) {
    throw std::invalid_argument("sampling occluder_radius must be finite and positive");
  }
  const Eigen::Matrix3Xd dirs = fibonacci_directions(sampling.candidates);
  ScoredView best;
  best.visible_fraction = -1.0;
  for (Eigen::Index k = 0; k < dirs.cols(); ++k) {
    const ScoredView s =
        score(u, centroid, centroid + r_sphere * dirs.col(k), sampling.occluder_radius);
    if (s.visible_fraction > best.visible_fraction ||
        (s.visible_fraction == best.visible_fraction && s.mean_error_deg < best.mean_error_deg)) {
      best = s;
    }
  }
  return best;
}

ScoredView most_visible(const UsableInput& u, const Eigen::Vector3d& centroid, double r_sphere,
                        const Eigen::Vector3d& current, const std::vector<Eigen::Vector3d>& others,
                        const MostVisibleSettings& settings) {
  const auto on_sphere = [&](const Eigen::Vector3d& p) -> Eigen::Vector3d {
    const Eigen::Vector3d d = p - centroid;
    return d.norm() > 1e-12 ? Eigen::Vector3d(centroid + r_sphere * d.normalized()) : centroid + r_sphere * Eigen::Vector3d::UnitZ();
  };
  const Eigen::Vector3d here = on_sphere(current);
  const ScoredView held = score(u, centroid, here, settings.occluder_radius);
  ScoredView best = held;
  const auto consider = [&](const Eigen::Vector3d& view) {
    const ScoredView s = score(u, centroid, on_sphere(view), settings.occluder_radius);
    if (s.visible_fraction > best.visible_fraction ||
        (s.visible_fraction == best.visible_fraction && s.mean_error_deg < best.mean_error_deg)) {
      best = s;
    }
  };
  // Eight neighbours: rotate `here` about two tangent axes by step_deg.
  const Eigen::Vector3d w = (here - centroid).normalized();
  const Eigen::Vector3d a = w.unitOrthogonal();
  const Eigen::Vector3d b = w.cross(a);
  const double step = settings.step_deg * kPi / 180.0;
  for (int k = 0; k < 8; ++k) {
    const double phi = kPi / 4.0 * k;
    const Eigen::Vector3d tangent = std::cos(phi) * a + std::sin(phi) * b;
    consider(centroid + r_sphere * (std::cos(step) * w + std::sin(step) * tangent));
  }
  for (const Eigen::Vector3d& o : others) consider(o);
  return best.visible_fraction >= held.visible_fraction + settings.margin ? best : held;
}

}  // namespace

const char* to_string(ViewMethod m) {
  switch (m) {
    case ViewMethod::Estimator: return "estimator";
    case ViewMethod::Static: return "static";
    case ViewMethod::InitialView: return "initial_view";
    case ViewMethod::Sampling: return "sampling";
    case ViewMethod::Hindsight: return "hindsight";
  }
  return "?";
}

Eigen::Matrix3Xd fibonacci_directions(int n) {
  if (n < 1) throw std::invalid_argument("candidate count must be >= 1, got " + std::to_string(n));
  Eigen::Matrix3Xd d(3, n);
  const double golden = kPi * (3.0 - std::sqrt(5.0));
  for (int k = 0; k < n; ++k) {
    const double z = 1.0 - (2.0 * k + 1.0) / n;
    const double rho = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = golden * k;
    d.col(k) << rho * std::cos(phi), rho * std::sin(phi), z;
  }
  return d;
}

ScoredView score_view(const ViewProblem& problem, const Eigen::Vector3d& centroid, double r_sphere,
                      const Eigen::Vector3d& view, double occluder_radius) {
  return score(usable_input(problem, centroid, r_sphere), centroid, view, occluder_radius);
}

ScoredView score_view(const OcclusionField& field, const Eigen::Vector3d& view, double occluder_radius) {
  return score(field.usable(), field.centroid(), view, occluder_radius);
}

double mean_angular_error_deg(const ViewProblem& problem, const Eigen::Vector3d& centroid, double r_sphere,
                              const Eigen::Vector3d& view) {
  return mean_error_deg(usable_input(problem, centroid, r_sphere), centroid, view);
}

ScoredView sample_best_view(const ViewProblem& problem, const Eigen::Vector3d& centroid,
                            double r_sphere, const SamplingSettings& sampling) {
  return sample_best(usable_input(problem, centroid, r_sphere), centroid, r_sphere, sampling);
}

ScoredView sample_best_view(const OcclusionField& field, const SamplingSettings& sampling) {
  return sample_best(field.usable(), field.centroid(), field.r_sphere(), sampling);
}

ScoredView most_visible_view(const ViewProblem& problem, const Eigen::Vector3d& centroid, double r_sphere,
                             const Eigen::Vector3d& current, const std::vector<Eigen::Vector3d>& others,
                             const MostVisibleSettings& settings) {
  return most_visible(usable_input(problem, centroid, r_sphere), centroid, r_sphere, current, others, settings);
}

ScoredView most_visible_view(const OcclusionField& field, const Eigen::Vector3d& current,
                             const std::vector<Eigen::Vector3d>& others, const MostVisibleSettings& settings) {
  return most_visible(field.usable(), field.centroid(), field.r_sphere(), current, others, settings);
}

}  // namespace ofv
