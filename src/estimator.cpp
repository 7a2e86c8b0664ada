// The occlusion-free view estimator, in the order of ESTIMATOR-SPEC.md:
// inputs and their hygiene (Inputs, §7), normals-to-sphere rays (§1), the
// initial view (§2), occlusion-to-sphere rays (§3), the iteration (§4) and the
// angular errors (§6). estimate_view() at the bottom reads as that sequence.
#include "estimator_errors.h"
#include "point_kernel.h"
#include "ofv/constants.h"
#include "ofv/estimator.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <limits>
#include <memory>
#include <vector>

namespace ofv {
namespace {

using detail::format_value;
using detail::usage_error;

constexpr double kRadToDeg = 180.0 / kPi;

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
constexpr double kAxesOrthogonalEps = 1e-6;  // given axes: |cos| between two of them above this is refused

// ---------------------------------------------------------------------------
// Inputs and §7: what the estimator may use.

void require_finite(const char* name, const std::optional<Eigen::Vector3d>& p) {
  if (p && !p->allFinite()) {
    usage_error(std::string("'") + name + "' must be finite, got " + format_value(*p));
  }
}

// Extreme but finite coordinates (non-finite ones are §7's to skip).
void require_in_range(const std::string& name, const Eigen::Matrix3Xd& m) {
  for (Eigen::Index k = 0; k < m.cols(); ++k) {
    for (int i = 0; i < 3; ++i) {
      if (std::isfinite(m(i, k)) && std::abs(m(i, k)) > kMaxLength) {
        usage_error(name + " " + std::to_string(k) + " has a coordinate beyond " + format_value(kMaxLength) +
                    " m: " + format_value(Eigen::Vector3d(m.col(k))));
      }
    }
  }
}

// The optional inputs and §7's hygiene: these are usage errors, thrown before
// any work so that a bad frame never half-succeeds.
void check_problem(const ViewProblem& problem) {
  if (problem.positions.cols() != problem.normals.cols()) {
    usage_error("supervoxel positions (" + std::to_string(problem.positions.cols()) +
                ") and normals (" + std::to_string(problem.normals.cols()) +
                ") differ in number");
  }
  require_finite("centroid", problem.centroid);
  require_finite("camera", problem.camera);
  require_finite("previous_view", problem.previous_view);
  require_in_range("supervoxel position", problem.positions);
  require_in_range("supervoxel normal", problem.normals);
  require_in_range("occluder", problem.occluders);
  for (const auto& [name, p] : {std::pair{"centroid", &problem.centroid}, std::pair{"camera", &problem.camera},
                                std::pair{"previous_view", &problem.previous_view}}) {
    if (*p) require_in_range(name, **p);
  }
  if (problem.axes) {  // §2: a zero-length or non-finite given axis
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = problem.axes->col(k);
      const double len = e.norm();
      if (!e.allFinite() || !std::isfinite(len) || len <= 0.0) {
        usage_error("axis e" + std::to_string(k + 1) + " must be finite and non-zero, got " +
                    format_value(e));
      }
    }
    // They are a frame (§2 projects on e2, e3 and measures angles from e1):
    // pairwise orthogonal once normalised, to kAxesOrthogonalEps.
    const Eigen::Matrix3d e = problem.axes->colwise().normalized();
    for (int a = 0; a < 3; ++a) {
      for (int b = a + 1; b < 3; ++b) {
        const double cos_ab = e.col(a).dot(e.col(b));
        if (!(std::abs(cos_ab) <= kAxesOrthogonalEps)) {
          usage_error("axes e" + std::to_string(a + 1) + " and e" + std::to_string(b + 1) +
                      " must be orthogonal, the cosine of their angle is " + format_value(cos_ab));
        }
      }
    }
  }
}

// Supervoxels v_n with their unit normals p_n, one per column.
struct Supervoxels {
  Eigen::Matrix3Xd v;
  Eigen::Matrix3Xd p;
  [[nodiscard]] Eigen::Index size() const { return v.cols(); }
};

// §7: supervoxels with a non-finite coordinate or normal, or a normal shorter
// than 1e-12, are dropped; the others' normals are normalised.
Supervoxels usable_supervoxels(const ViewProblem& problem) {
  const Eigen::Index n_in = problem.positions.cols();
  Supervoxels s;
  s.v.resize(3, n_in);
  s.p.resize(3, n_in);
  Eigen::Index n = 0;
  for (Eigen::Index k = 0; k < n_in; ++k) {
    const Eigen::Vector3d v = problem.positions.col(k);
    const Eigen::Vector3d p = problem.normals.col(k);
    const double len = p.norm();
    if (!v.allFinite() || !p.allFinite() || !(len >= kMinNormal)) {
      continue;
    }
    s.v.col(n) = v;
    s.p.col(n) = p / len;
    ++n;
  }
  s.v.conservativeResize(3, n);
  s.p.conservativeResize(3, n);
  return s;
}

// §7: occluders with a non-finite coordinate are dropped.
Eigen::Matrix3Xd usable_occluders(const Eigen::Matrix3Xd& occluders) {
  Eigen::Matrix3Xd q(3, occluders.cols());
  Eigen::Index b = 0;
  for (Eigen::Index k = 0; k < occluders.cols(); ++k) {
    if (occluders.col(k).allFinite()) {
      q.col(b++) = occluders.col(k);
    }
  }
  q.conservativeResize(3, b);
  return q;
}

// C and the object axes e1, e2, e3 (columns of e).
struct ObjectFrame {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  Eigen::Matrix3d e = Eigen::Matrix3d::Identity();
  bool determined = true;   // e1 is known: given, or PCA separates lambda1 from lambda2
  bool from_world = false;  // the world axes stand in for undetermined PCA axes
};

// Inputs and §2: given axes normalised (checked by check_inputs), else PCA of
// `points`, with the world axes standing in when PCA does not determine e1
// (N <= 1, or lambda1 - lambda2 <= 1e-9 lambda1).
ObjectFrame object_axes(const ViewProblem& problem, const Eigen::Matrix3Xd& points) {
  ObjectFrame frame;
  if (problem.axes) {
    for (int k = 0; k < 3; ++k) {
      const Eigen::Vector3d e = problem.axes->col(k);
      frame.e.col(k) = e / e.norm();
    }
    return frame;
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
      frame.e.col(0) = e1;
      frame.e.col(1) = e2;
      frame.e.col(2) = e1.cross(e2);
      return frame;
    }
  }
  frame.e.setIdentity();
  frame.determined = false;
  frame.from_world = true;
  return frame;
}

// Inputs: C (given, or the mean of `points`) and the axes, from the usable
// supervoxels' positions `points` (3 x N, N >= 1 unless C is given).
ObjectFrame object_frame(const ViewProblem& problem, const Eigen::Matrix3Xd& points) {
  ObjectFrame frame = object_axes(problem, points);
  frame.c = problem.centroid ? *problem.centroid : Eigen::Vector3d(points.rowwise().mean());
  return frame;
}

// ---------------------------------------------------------------------------
// §1: normals-to-sphere rays (eq. 3).

// §1: s_n is where v_n + t p_n, t > 0, leaves the sphere; supervoxels at or
// outside the sphere (|v_n - C| >= R) have no ray and are skipped.
// The rays u_n = s_n - C of the supervoxels kept, no occluders yet.
UsableInput normals_to_sphere_rays(const Supervoxels& s, const Eigen::Vector3d& c, double r) {
  UsableInput rays;
  rays.positions.resize(3, s.size());
  rays.normals.resize(3, s.size());
  rays.rays.resize(3, s.size());
  Eigen::Index n = 0;
  for (Eigen::Index k = 0; k < s.size(); ++k) {
    if (!((s.v.col(k) - c).norm() < r)) {
      continue;
    }
    rays.positions.col(n) = s.v.col(k);
    rays.normals.col(n) = s.p.col(k);
    rays.rays.col(n) = sphere_exit(c, r, s.v.col(k), s.p.col(k)) - c;
    ++n;
  }
  rays.positions.conservativeResize(3, n);
  rays.normals.conservativeResize(3, n);
  rays.rays.conservativeResize(3, n);
  return rays;
}

// ---------------------------------------------------------------------------
// §2: the initial view t0 (eqs. 4, 5) and its fallbacks.

// Circular mean of angles from their sine and cosine sums; empty when degenerate.
std::optional<double> circular_mean(double sum_sin, double sum_cos) {
  if (std::abs(sum_sin) < kCircularMeanEps && std::abs(sum_cos) < kCircularMeanEps) {
    return std::nullopt;
  }
  return std::atan2(sum_sin, sum_cos);
}

// §2 `spherical_mean`: circular means of the polar angle about e1 and of the
// azimuth from e2 towards e3; empty when either is degenerate.
std::optional<Eigen::Vector3d> spherical_mean_direction(const Eigen::Matrix3Xd& u,
                                                        const Eigen::Matrix3d& e) {
  const Eigen::Vector3d e1 = e.col(0), e2 = e.col(1), e3 = e.col(2);
  double sin_theta = 0.0, cos_theta = 0.0, sin_phi = 0.0, cos_phi = 0.0;
  for (Eigen::Index k = 0; k < u.cols(); ++k) {
    const Eigen::Vector3d un = u.col(k);
    const double phi = std::atan2(un.cross(e1).norm(), un.dot(e1));
    const double theta = std::atan2(un.dot(e3), un.dot(e2));
    sin_theta += std::sin(theta);
    cos_theta += std::cos(theta);
    sin_phi += std::sin(phi);
    cos_phi += std::cos(phi);
  }
  const std::optional<double> theta = circular_mean(sin_theta, cos_theta);
  const std::optional<double> phi = circular_mean(sin_phi, cos_phi);
  if (!theta || !phi) {
    return std::nullopt;
  }
  return std::cos(*phi) * e1 + std::sin(*phi) * (std::cos(*theta) * e2 + std::sin(*theta) * e3);
}

// §2 `vector_mean`: unit(sum unit(u_n)); empty when the sum is shorter than 1e-9.
std::optional<Eigen::Vector3d> vector_mean_direction(const Eigen::Matrix3Xd& u) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (Eigen::Index k = 0; k < u.cols(); ++k) {
    sum += u.col(k).normalized();
  }
  if (sum.norm() < kVectorMeanEps) {
    return std::nullopt;
  }
  return sum.normalized();
}

// §2, last fallback: the direction from C to the current camera. Reaching it
// without a camera, or with the camera at C, is a usage error.
Eigen::Vector3d camera_direction(const std::optional<Eigen::Vector3d>& camera,
                                 const Eigen::Vector3d& c) {
  if (!camera) {
    usage_error("the initial view falls back to the camera direction, but no camera is given");
  }
  const Eigen::Vector3d to_camera = *camera - c;
  if (to_camera.norm() < kCameraEps) {
    usage_error(
        "the initial view falls back to the camera direction, but the camera is at the centroid");
  }
  return to_camera.normalized();
}

struct InitialViewChoice {
  Eigen::Vector3d t0;
  InitialViewUsed used;
};

// §2: t0 = C + R dir, dir from the chosen rule, falling back from
// spherical_mean (needs e1 determined and N > 0) to vector_mean (N > 0) to
// the camera.
InitialViewChoice initial_view(const Eigen::Matrix3Xd& u, const ObjectFrame& object,
                               const std::optional<Eigen::Vector3d>& camera, double r,
                               InitialView rule) {
  const Eigen::Vector3d& c = object.c;
  if (rule == InitialView::SphericalMean && object.determined && u.cols() > 0) {
    if (const auto dir = spherical_mean_direction(u, object.e)) {
      return {c + r * *dir, InitialViewUsed::SphericalMean};
    }
  }
  if (u.cols() > 0) {
    if (const auto dir = vector_mean_direction(u)) {
      return {c + r * *dir, InitialViewUsed::VectorMean};
    }
  }
  return {c + r * camera_direction(camera, c), InitialViewUsed::Camera};
}

// ---------------------------------------------------------------------------
// §3: occlusion-to-sphere rays.

// The point kernels (point_kernel.h) round every operation on its own.

// §4 sums the projected points in kLanes interleaved partial sums (see
// sum_projection); storage is padded to whole rows of kLanes points.
constexpr std::size_t kLanes = 8;

// The largest buffers a thread keeps for reuse: 3·10^6 points, 72 MB.
constexpr std::size_t kMaxKeptPoints = 3'000'000;

// Buffers of freed PointRows kept for the next ones on the same thread: a
// loop's frames would otherwise map, fault in and unmap the same megabytes
// of fresh pages once per estimate (half the time of a frame's estimate with
// ~10^5 occlusion points, measured in the closed loop). The two largest are
// kept, up to kMaxKept doubles each: a one-off huge problem's memory is freed.
class BufferCache {
 public:
  // The smallest kept buffer of at least `size` doubles, else a new one.
  std::unique_ptr<double[]> take(std::size_t size, std::size_t& capacity) {
    Slot* fit = nullptr;
    for (Slot& s : slots_) {
      if (s.buffer && s.size >= size && (!fit || s.size < fit->size)) fit = &s;
    }
    if (fit) {
      capacity = fit->size;
      fit->size = 0;
      return std::move(fit->buffer);
    }
    capacity = size + size / 2;  // room to grow: fewer fresh buffers while problems grow
    return std::unique_ptr<double[]>(new double[capacity]);
  }
  // Makes sure the two slots hold buffers of at least `size` doubles,
  // written once so that their pages are mapped. A thread's high-water
  // mark: asking again for as much or less does nothing.
  void reserve(std::size_t size) {
    if (size <= reserved_) return;
    reserved_ = std::min(size, kMaxKept);
    for (Slot& s : slots_) {
      if (s.size >= reserved_) continue;
      s.buffer.reset(new double[reserved_]);
      std::fill(s.buffer.get(), s.buffer.get() + reserved_, 0.0);
      s.size = reserved_;
    }
  }
  void give(std::unique_ptr<double[]> buffer, std::size_t size) {
    Slot* smallest = &slots_[0];
    for (Slot& s : slots_) {
      if (s.size < smallest->size) smallest = &s;
    }
    if (size > smallest->size && size <= kMaxKept) {
      smallest->buffer = std::move(buffer);
      smallest->size = size;
    }
  }

 private:
  static constexpr std::size_t kMaxKept = 3 * kMaxKeptPoints;
  struct Slot {
    std::unique_ptr<double[]> buffer;
    std::size_t size = 0;
  };
  Slot slots_[2];
  std::size_t reserved_ = 0;
};

BufferCache& buffer_cache() {
  thread_local BufferCache cache;
  return cache;
}

// Points d = d_nb - C in structure-of-arrays form, kLanes per row: point k is
// at index k, its partial sum is k % kLanes. The tail of the last row is
// padded with d = 0, which lies in the far hemisphere (d . w = 0) of every
// iterate and so is ignored by §4 exactly as the spec ignores such points.
// One buffer, not zero-filled (every slot read is written first), reused
// from the thread's BufferCache.
struct PointRows {
  std::unique_ptr<double[]> buffer;
  std::size_t buffer_size = 0;
  double* x = nullptr;
  double* y = nullptr;
  double* z = nullptr;
  std::size_t rows = 0;
  std::size_t capacity_rows = 0;

  PointRows() = default;
  PointRows(PointRows&&) noexcept = default;
  PointRows& operator=(PointRows&&) = delete;
  PointRows(const PointRows&) = delete;
  PointRows& operator=(const PointRows&) = delete;
  ~PointRows() {
    if (buffer) buffer_cache().give(std::move(buffer), buffer_size);
  }

  // Room for n_rows rows, contents undefined; rows is set to n_rows.
  void reserve_rows(std::size_t n_rows) {
    if (n_rows > capacity_rows) {
      if (buffer) buffer_cache().give(std::move(buffer), buffer_size);
      buffer = buffer_cache().take(3 * n_rows * kLanes, buffer_size);
      capacity_rows = buffer_size / (3 * kLanes);
      x = buffer.get();
      y = x + capacity_rows * kLanes;
      z = y + capacity_rows * kLanes;
    }
    rows = n_rows;
  }
};

// Occlusion-to-sphere rays: the N_C points in (n, b) order, pairs with
// coincident v_n and q_b left out.
struct OcclusionRays {
  PointRows points;
  std::size_t count = 0;  // N_C
  [[nodiscard]] std::size_t size() const { return count; }
};

// §3 for one supervoxel a = v_n - C (a_in = |a|^2 - R^2 < 0) and every
// occluder q_b - C: where the half-line from v_n through q_b leaves the
// sphere, from C, written to out[b]; len[b] = |q_b - v_n|.
OFV_POINT_KERNEL
void sphere_exits(const double* qx, const double* qy, const double* qz, std::size_t n_q,
                  double ax, double ay, double az, double a_in, double* ox, double* oy,
                  double* oz, double* len) {
#pragma omp simd
  for (std::size_t b = 0; b < n_q; ++b) {
    double ux = qx[b] - ax;
    double uy = qy[b] - ay;
    double uz = qz[b] - az;
    const double l = std::sqrt(ux * ux + uy * uy + uz * uz);
    const double inv = 1.0 / (l >= kCoincidentEps ? l : 1.0);
    ux *= inv;
    uy *= inv;
    uz *= inv;
    double t = ax * ux + ay * uy + az * uz;  // a . u
    t = std::sqrt(t * t - a_in) - t;         // a + t u is on the sphere, t > 0
    ox[b] = ax + t * ux;
    oy[b] = ay + t * uy;
    oz[b] = az + t * uz;
    len[b] = l;
  }
}

// §3: for every pair (n, b) with |q_b - v_n| >= 1e-9, where the half-line from
// v_n through q_b leaves the sphere.
OcclusionRays occlusion_rays(const Eigen::Vector3d& c, double r, const Eigen::Matrix3Xd& v,
                             const Eigen::Matrix3Xd& q) {
  const auto n_q = static_cast<std::size_t>(q.cols());
  std::vector<double> qc(4 * n_q);  // q_b - C by coordinate, then |q_b - v_n|
  double* qx = qc.data();
  double* qy = qx + n_q;
  double* qz = qy + n_q;
  double* len = qz + n_q;
  for (std::size_t b = 0; b < n_q; ++b) {
    const auto col = static_cast<Eigen::Index>(b);
    qx[b] = q(0, col) - c.x();
    qy[b] = q(1, col) - c.y();
    qz[b] = q(2, col) - c.z();
  }
  OcclusionRays rays;
  const std::size_t n_max = static_cast<std::size_t>(v.cols()) * n_q;
  const std::size_t n_rows = (n_max + kLanes - 1) / kLanes;
  rays.points.reserve_rows(n_rows);
  double* ox = rays.points.x;
  double* oy = rays.points.y;
  double* oz = rays.points.z;
  const double r2 = r * r;
  std::size_t k = 0;  // the next row is written from here on
  for (Eigen::Index n = 0; n < v.cols(); ++n) {
    const Eigen::Vector3d a = v.col(n) - c;    // v_n - C
    const double a_in = a.squaredNorm() - r2;  // < 0 inside the sphere
    sphere_exits(qx, qy, qz, n_q, a.x(), a.y(), a.z(), a_in, ox + k, oy + k, oz + k, len);
    // Drop the coincident pairs (rare) by moving the rest of this row down.
    if (std::all_of(len, len + n_q, [](double l) { return l >= kCoincidentEps; })) {
      k += n_q;
      continue;
    }
    std::size_t kept = k;
    for (std::size_t b = 0; b < n_q; ++b) {
      if (len[b] >= kCoincidentEps) {
        ox[kept] = ox[k + b];
        oy[kept] = oy[k + b];
        oz[kept] = oz[k + b];
        ++kept;
      }
    }
    k = kept;
  }
  // Zero the tail of the last row and the rows the dropped pairs left.
  std::fill(ox + k, ox + n_rows * kLanes, 0.0);
  std::fill(oy + k, oy + n_rows * kLanes, 0.0);
  std::fill(oz + k, oz + n_rows * kLanes, 0.0);
  rays.count = k;
  rays.points.rows = (k + kLanes - 1) / kLanes;
  return rays;
}

// ---------------------------------------------------------------------------
// §4: the iteration (eqs. 6-8).

// §4 `warm_start`: C + R unit(previous_view - C) when on and given, else t0.
Eigen::Vector3d iteration_start(const std::optional<Eigen::Vector3d>& previous_view,
                                const EstimatorSettings& settings, const Eigen::Vector3d& c,
                                const Eigen::Vector3d& t0) {
  if (!settings.warm_start || !previous_view) {
    return t0;
  }
  const Eigen::Vector3d from_c = *previous_view - c;
  if (from_c.norm() < kCameraEps) {
    usage_error("'previous_view' is at the centroid: no direction to warm-start from");
  }
  return c + settings.r_sphere * from_c.normalized();
}

// What one gnomonic projection onto the plane tangent at t tells (spec §4).
struct Projection {
  int in_clearance = 0;                            // points with |d_pi - t| < clearance
  Eigen::Vector3d push = Eigen::Vector3d::Zero();  // v
};

// Per-lane partial sums of one projection (count, v).
struct LaneSums {
  double count[kLanes] = {}, vx[kLanes] = {}, vy[kLanes] = {}, vz[kLanes] = {};
};

// §4 projection, stop-test count and push terms of `rows` rows of points, one
// pass. Each term is computed as the spec writes it (d_pi - t with d_pi = C +
// d R / (d . w), compared squared), and added to the partial sum of its lane,
// in row order.
template <bool kInverse>
OFV_POINT_KERNEL void project_rows(const double* dx, const double* dy, const double* dz,
                                   std::size_t rows, double wx, double wy, double wz, double tx,
                                   double ty, double tz, double r, double clear2, double push2,
                                   LaneSums* sums) {
  double count[kLanes] = {}, vx[kLanes] = {}, vy[kLanes] = {}, vz[kLanes] = {};
  for (std::size_t row = 0; row < rows; ++row) {
    const std::size_t o = row * kLanes;
#pragma omp simd
    for (std::size_t l = 0; l < kLanes; ++l) {
      const double x = dx[o + l], y = dy[o + l], z = dz[o + l];
      const double dw = x * wx + y * wy + z * wz;
      const double seen = dw > kFarHemisphereEps ? 1.0 : 0.0;
      const double scale = r / (dw > kFarHemisphereEps ? dw : 1.0);
      // d_pi - t, with d_pi = C + d R / (d . w)
      const double px = x * scale - tx;
      const double py = y * scale - ty;
      const double pz = z * scale - tz;
      const double dist2 = px * px + py * py + pz * pz;
      count[l] += dist2 < clear2 ? seen : 0.0;
      double weight = dist2 < push2 ? seen : 0.0;
      if constexpr (kInverse) {
        weight /= dist2;
      }
      vx[l] -= weight * px;
      vy[l] -= weight * py;
      vz[l] -= weight * pz;
    }
  }
  for (std::size_t l = 0; l < kLanes; ++l) {
    sums->count[l] = count[l];
    sums->vx[l] = vx[l];
    sums->vy[l] = vy[l];
    sums->vz[l] = vz[l];
  }
}

// The documented summation order of v (spec §4 allows any): the term of point
// k goes to partial sum k % 8, added in increasing k; the partial sums are
// then added as ((s0 + s1) + (s2 + s3)) + ((s4 + s5) + (s6 + s7)). Points that
// are not in J contribute an exact zero, so leaving them out of a partial sum
// (pruning, below) does not change it; and since the lanes are fixed, neither
// does the vector width of the machine. The count is exact in any order.
double combine(const double (&s)[kLanes]) {
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// §4: gnomonic projection onto the plane tangent at t of the points `pts`.
Projection project(const PointRows& pts, const Eigen::Vector3d& t_from_c, double r,
                   const EstimatorSettings& s) {
  const Eigen::Vector3d w = t_from_c.normalized();
  const double clear2 = s.clearance * s.clearance;
  const double push2 = s.push_radius * s.push_radius;
  LaneSums sums;
  const auto run = s.push_weighting == PushWeighting::InverseDistance ? project_rows<true>
                                                                      : project_rows<false>;
  run(pts.x, pts.y, pts.z, pts.rows, w.x(), w.y(), w.z(), t_from_c.x(),
      t_from_c.y(), t_from_c.z(), r, clear2, push2, &sums);
  Projection p;
  p.in_clearance = static_cast<int>(combine(sums.count));
  p.push = Eigen::Vector3d(combine(sums.vx), combine(sums.vy), combine(sums.vz));
  return p;
}

// How many of the n points are closer than sqrt(keep2) to t.
OFV_POINT_KERNEL std::size_t count_within(const double* x, const double* y, const double* z,
                                          std::size_t n, double tx, double ty, double tz,
                                          double keep2) {
  std::size_t kept = 0;
#pragma omp simd reduction(+ : kept)
  for (std::size_t k = 0; k < n; ++k) {
    const double ex = x[k] - tx, ey = y[k] - ty, ez = z[k] - tz;
    kept += ex * ex + ey * ey + ez * ez < keep2 ? 1 : 0;
  }
  return kept;
}

// Copies the points of `rows` rows closer than sqrt(keep2) to t into kx, ky,
// kz, each lane's in order into the same lane; lane_rows[l] = how many lane l
// kept. Row by row, in memory order: the kept points are near each other (one
// supervoxel's rays through one occluder cluster), so most rows keep none.
OFV_POINT_KERNEL void keep_within(const double* x, const double* y, const double* z, std::size_t rows,
                                  double tx, double ty, double tz, double keep2, double* kx, double* ky,
                                  double* kz, std::size_t (&lane_rows)[kLanes]) {
  std::fill(lane_rows, lane_rows + kLanes, std::size_t{0});
  for (std::size_t row = 0; row < rows; ++row) {
    const std::size_t first = row * kLanes;
    unsigned in = 0;
    for (std::size_t l = 0; l < kLanes; ++l) {
      const double ex = x[first + l] - tx, ey = y[first + l] - ty, ez = z[first + l] - tz;
      in |= (ex * ex + ey * ey + ez * ez < keep2 ? 1u : 0u) << l;
    }
    for (std::size_t l = 0; in != 0; ++l, in >>= 1) {
      if ((in & 1u) == 0) continue;
      const std::size_t to = lane_rows[l]++ * kLanes + l;
      kx[to] = x[first + l];
      ky[to] = y[first + l];
      kz[to] = z[first + l];
    }
  }
}

// Pruning. A point d on the sphere at angle a < 90 deg from w projects at
// distance R tan(a) from t; beyond 90 deg it has no image. So a point is
// counted in the clearance disc or in J only if tan(a) < rho / R, rho =
// max(clearance, push_radius): only if its chord to t - C, 2 R sin(a/2), is
// below reach = 2 R sin(atan(rho / R) / 2). The terms of the others are exact
// zeros. The margins (relative 1e-9, absolute 1e-9 R) cover the rounding of
// the stored points and iterates off the sphere (~1e-16 R) and of the
// computed distances.
//
// The kept set is chosen at an iterate t_k with `slack` to spare, and stays
// valid while the iterate is within `slack` of t_k (triangle inequality), so
// one selection serves several iterations. When it would keep most points,
// all points are used (copying would cost more than it saves).
class PrunedPoints {
 public:
  PrunedPoints(const OcclusionRays& all, const EstimatorSettings& s)
      : all_(all), r_(s.r_sphere) {
    const double rho = std::max(s.clearance, s.push_radius);
    const double reach = 2.0 * r_ * std::sin(0.5 * std::atan(rho / r_));
    slack_ = std::max(4.0 * s.step, 0.25 * reach);
    keep_radius_ = reach * (1.0 + 1e-9) + 1e-9 * r_ + slack_;
    // Every chord is at most 2R: then nothing can ever be left out.
    never_ = keep_radius_ >= 2.0 * r_ * (1.0 - 1e-9) || all.points.rows < 4;
  }

  // The points that may count or push at the iterate t - C.
  const PointRows& at(const Eigen::Vector3d& t_from_c) {
    if (never_) return all_.points;
    if (!valid_ || !((t_from_c - centre_).norm() * (1.0 + 1e-9) + 1e-9 * r_ <= slack_)) {
      select(t_from_c);
    }
    return use_all_ ? all_.points : kept_;
  }

 private:
  void select(const Eigen::Vector3d& t_from_c) {
    centre_ = t_from_c;
    valid_ = true;
    const PointRows& a = all_.points;
    const double keep2 = keep_radius_ * keep_radius_;
    const std::size_t n = a.rows * kLanes;
    const double* x = a.x;
    const double* y = a.y;
    const double* z = a.z;
    const double tx = t_from_c.x(), ty = t_from_c.y(), tz = t_from_c.z();
    use_all_ = count_within(x, y, z, n, tx, ty, tz, keep2) * 2 > n;
    if (use_all_) return;
    // Each lane keeps its own points in order, so each partial sum of §4
    // meets the same non-zero terms in the same order.
    std::size_t lane_rows[kLanes];
    kept_.reserve_rows(a.rows);
    keep_within(x, y, z, a.rows, tx, ty, tz, keep2, kept_.x, kept_.y, kept_.z, lane_rows);
    kept_.rows = *std::max_element(lane_rows, lane_rows + kLanes);
    for (std::size_t l = 0; l < kLanes; ++l) {  // pad with d = 0 (no image)
      for (std::size_t m = lane_rows[l]; m < kept_.rows; ++m) {
        kept_.x[m * kLanes + l] = kept_.y[m * kLanes + l] = kept_.z[m * kLanes + l] = 0.0;
      }
    }
  }

  const OcclusionRays& all_;
  double r_;
  double slack_ = 0.0;
  double keep_radius_ = 0.0;
  bool never_ = false;
  bool valid_ = false;
  bool use_all_ = true;
  Eigen::Vector3d centre_ = Eigen::Vector3d::Zero();
  PointRows kept_;
};

// t - d_pi for the projected point nearest to t (spec §4 fallback); zero if none.
// Scans every point: the nearest may be outside the push disc.
Eigen::Vector3d away_from_nearest(const OcclusionRays& rays, const Eigen::Vector3d& t_from_c,
                                  double r) {
  const Eigen::Vector3d w = t_from_c.normalized();
  double best = std::numeric_limits<double>::infinity();
  Eigen::Vector3d away = Eigen::Vector3d::Zero();
  const PointRows& pts = rays.points;
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const double dw = pts.x[k] * w.x() + pts.y[k] * w.y() + pts.z[k] * w.z();
    if (dw <= kFarHemisphereEps) {
      continue;
    }
    const double scale = r / dw;
    const Eigen::Vector3d p(pts.x[k] * scale - t_from_c.x(), pts.y[k] * scale - t_from_c.y(),
                            pts.z[k] * scale - t_from_c.z());
    const double dist2 = p.x() * p.x() + p.y() * p.y() + p.z() * p.z();
    if (dist2 < best) {
      best = dist2;
      away = -p;
    }
  }
  return away;
}

// §4 push direction (not normalised): v, or when |v| < 1e-12 away from the
// nearest projected point, or when that coincides with t_i along e1 projected
// on the tangent plane (e2 if e1 is parallel to w).
Eigen::Vector3d push_direction(const Projection& proj, const OcclusionRays& rays,
                               const Eigen::Vector3d& t_from_c, double r,
                               const Eigen::Matrix3d& e) {
  Eigen::Vector3d push = proj.push;
  if (push.norm() < kZeroPushEps) {
    push = away_from_nearest(rays, t_from_c, r);
    if (push.norm() < kZeroPushEps) {
      const Eigen::Vector3d w = t_from_c.normalized();
      const Eigen::Vector3d e1 = e.col(0), e2 = e.col(1);
      const Eigen::Vector3d axis = std::abs(e1.dot(w)) >= 1.0 - kParallelEps ? e2 : e1;
      push = axis - axis.dot(w) * w;
    }
  }
  return push;
}

// §4 step (eq. 7) on the tangent plane, then back to the sphere (eq. 8).
Eigen::Vector3d step_on_sphere(const Eigen::Vector3d& t, const Eigen::Vector3d& push,
                               const Eigen::Vector3d& c, double r, double step) {
  const Eigen::Vector3d t_pi = t + step * push.normalized();
  return c + r * (t_pi - c).normalized();
}

// §4 `not_converged`: the visited iterate with the fewest points inside the
// clearance disc, ties broken by the smallest angle to t0.
class BestIterate {
 public:
  explicit BestIterate(const Eigen::Vector3d& start) : t_(start) {}
  void consider(const Eigen::Vector3d& t, int in_clearance, double angle_to_t0) {
    if (in_clearance < count_ || (in_clearance == count_ && angle_to_t0 < angle_)) {
      t_ = t;
      count_ = in_clearance;
      angle_ = angle_to_t0;
    }
  }
  [[nodiscard]] const Eigen::Vector3d& t() const { return t_; }
  [[nodiscard]] int count() const { return count_; }

 private:
  Eigen::Vector3d t_;
  int count_ = std::numeric_limits<int>::max();
  double angle_ = std::numeric_limits<double>::infinity();
};

// The iteration is a deterministic map of t alone: once an iterate repeats bit
// for bit, every later one is a repeat too, none clear and none better.
// Brent's cycle detection finds that in O(1) memory, so that a huge
// max_iterations on a cycling scene ends with the result it would reach.
class CycleDetector {
 public:
  explicit CycleDetector(const Eigen::Vector3d& start) : checkpoint_(start) {}
  // True when t repeats an earlier iterate.
  bool repeats(const Eigen::Vector3d& t) {
    const bool cycling = t == checkpoint_;
    if (++steps_since_checkpoint_ == period_) {
      checkpoint_ = t;
      period_ *= 2;
      steps_since_checkpoint_ = 0;
    }
    return cycling;
  }

 private:
  Eigen::Vector3d checkpoint_;
  long steps_since_checkpoint_ = 0;
  long period_ = 1;
};

using Clock = std::chrono::steady_clock;

struct IterationResult {
  Eigen::Vector3d tf;
  ViewStatus status;
  int iterations;
  int clearance_points;
};

// §4: from `start`, project, stop when clear, else push, step and go back to
// the sphere, for at most max_iterations steps. Appends every visited iterate
// to `path` when given.
IterationResult iterate(const OcclusionRays& occ, const Eigen::Vector3d& start,
                        const Eigen::Vector3d& t0, const ObjectFrame& object,
                        const EstimatorSettings& settings, Clock::time_point deadline,
                        std::vector<Eigen::Vector3d>* path) {
  const Eigen::Vector3d& c = object.c;
  const double r = settings.r_sphere;
  const Eigen::Vector3d t0_from_c = t0 - c;
  Eigen::Vector3d t = start;
  BestIterate best(start);
  CycleDetector cycle(start);
  PrunedPoints points(occ, settings);
  bool cycling = false;
  for (int i = 0;; ++i) {
    if (cycling) {
      return {best.t(), ViewStatus::NotConverged, settings.max_iterations, best.count()};
    }
    if (path) path->push_back(t);
    const Eigen::Vector3d t_from_c = t - c;
    const Projection proj = project(points.at(t_from_c), t_from_c, r, settings);
    if (proj.in_clearance == 0) {
      return {t, ViewStatus::Converged, i, 0};
    }
    best.consider(t, proj.in_clearance, angle_between(t_from_c, t0_from_c));
    if (i == settings.max_iterations) {
      return {best.t(), ViewStatus::NotConverged, i, best.count()};
    }
    if (i % 8 == 7 && Clock::now() > deadline) {
      return {best.t(), ViewStatus::OutOfTime, i, best.count()};
    }
    const Eigen::Vector3d push = push_direction(proj, occ, t_from_c, r, object.e);
    t = step_on_sphere(t, push, c, r, settings.step);
    cycling = cycle.repeats(t);
  }
}

// ---------------------------------------------------------------------------
// §6: angular error (eq. 9).

// Mean and population standard deviation of eq. 9 over the rays [deg]; empty
// when there is no ray.
std::optional<AngularErrorStats> angular_error(const Eigen::Matrix3Xd& u,
                                               const Eigen::Vector3d& view_from_c) {
  const Eigen::Index n = u.cols();
  if (n == 0) {
    return std::nullopt;
  }
  Eigen::ArrayXd err(n);
  for (Eigen::Index k = 0; k < n; ++k) {
    err(k) = angle_between(u.col(k), view_from_c) * kRadToDeg;
  }
  const double mean = err.mean();
  return AngularErrorStats{mean, std::sqrt((err - mean).square().mean())};
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

struct OcclusionField::Data {
  double r = 0.0;
  std::optional<Eigen::Vector3d> camera;
  bool has_object = false;
  ObjectFrame object;
  UsableInput usable;  // §1's rays and §7's occluders
  int skipped_supervoxels = 0;
  int skipped_occluders = 0;
  std::optional<OcclusionRays> occlusion;  // §3, none without occluders
};

OcclusionField::OcclusionField(const ViewProblem& problem, double r_sphere) : data_(std::make_unique<Data>()) {
  if (!(r_sphere > 0.0) || !std::isfinite(r_sphere)) {
    usage_error("r_sphere must be finite and > 0, got " + format_value(r_sphere));
  }
  check_problem(problem);
  Data& d = *data_;
  d.r = r_sphere;
  d.camera = problem.camera;
  // Inputs, §7: C and the axes describe the whole object, so they come from
  // every usable supervoxel, also those §1 then skips for lying at or outside
  // the sphere (which is judged against this C).
  const Supervoxels supervoxels = usable_supervoxels(problem);
  d.has_object = problem.centroid || supervoxels.size() > 0;
  d.usable.occluders = usable_occluders(problem.occluders);
  d.skipped_occluders = static_cast<int>(problem.occluders.cols() - d.usable.occluders.cols());
  if (!d.has_object) {
    d.skipped_supervoxels = static_cast<int>(problem.positions.cols());
    return;
  }
  d.object = object_frame(problem, supervoxels.v);
  // §1: normals-to-sphere rays.
  d.usable = normals_to_sphere_rays(supervoxels, d.object.c, r_sphere);
  d.usable.occluders = usable_occluders(problem.occluders);
  d.skipped_supervoxels = static_cast<int>(problem.positions.cols() - d.usable.positions.cols());
  // §3: occlusion-to-sphere rays.
  const Eigen::Index n_v = d.usable.positions.cols();
  const Eigen::Index n_q = d.usable.occluders.cols();
  const double n_rays = static_cast<double>(n_v) * static_cast<double>(n_q);
  if (n_rays > kMaxOcclusionRays) {
    usage_error(std::to_string(n_v) + " supervoxels x " + std::to_string(n_q) + " occluders make " +
                format_value(n_rays) + " occlusion rays, more than the " + format_value(kMaxOcclusionRays) +
                " ofv handles: thin the supervoxels or the occluders");
  }
  if (n_q > 0) d.occlusion.emplace(occlusion_rays(d.object.c, r_sphere, d.usable.positions, d.usable.occluders));
}

OcclusionField::~OcclusionField() = default;
OcclusionField::OcclusionField(OcclusionField&&) noexcept = default;
OcclusionField& OcclusionField::operator=(OcclusionField&&) noexcept = default;
double OcclusionField::r_sphere() const { return data_->r; }
bool OcclusionField::has_object() const { return data_->has_object; }
const Eigen::Vector3d& OcclusionField::centroid() const { return data_->object.c; }
const UsableInput& OcclusionField::usable() const { return data_->usable; }
int OcclusionField::occlusion_points() const { return data_->occlusion ? static_cast<int>(data_->occlusion->size()) : 0; }

namespace detail {

struct FieldAccess {
  static const OcclusionField::Data& data(const OcclusionField& field) { return *field.data_; }
};

}  // namespace detail

namespace {

ViewEstimate estimate_on(const OcclusionField& field, const EstimatorSettings& settings,
                         const std::optional<Eigen::Vector3d>& previous_view, const EstimateOptions& options,
                         Clock::time_point deadline) {
  const auto& d = detail::FieldAccess::data(field);
  ViewEstimate est;
  est.skipped_supervoxels = d.skipped_supervoxels;
  est.skipped_occluders = d.skipped_occluders;
  if (!d.has_object) {
    // No usable supervoxel and no C given: nothing to look at. The camera
    // stays where it is (t0 = tf = camera, or zero without one).
    est.status = ViewStatus::NoSupervoxels;
    est.t0 = est.tf = d.camera.value_or(Eigen::Vector3d::Zero());
    return est;
  }
  const double r = settings.r_sphere;
  const Eigen::Vector3d& c = d.object.c;
  est.centroid = c;
  est.axes = d.object.e;
  est.axes_from_world = d.object.from_world;
  const Eigen::Matrix3Xd& u = d.usable.rays;

  // §2: initial view t0.
  const InitialViewChoice initial = initial_view(u, d.object, d.camera, r, settings.initial_view);
  est.t0 = initial.t0;
  est.initial_view_used = initial.used;

  // §4: the iteration.
  const Eigen::Vector3d start = iteration_start(previous_view, settings, c, est.t0);
  if (d.usable.occluders.cols() == 0) {
    est.status = ViewStatus::NoOccluders;
    est.tf = est.t0;
    if (options.record_path) est.path.push_back(est.t0);
  } else {
    est.occlusion_points = static_cast<int>(d.occlusion->size());
    const IterationResult it =
        iterate(*d.occlusion, start, est.t0, d.object, settings, deadline, options.record_path ? &est.path : nullptr);
    est.tf = it.tf;
    est.status = it.status;
    est.iterations = it.iterations;
    est.clearance_points = it.clearance_points;
  }

  // §6: angular errors.
  est.error_t0 = angular_error(u, est.t0 - c);
  est.error_tf = angular_error(u, est.tf - c);
  est.tf_to_t0_deg = angle_between(est.tf - c, est.t0 - c) * kRadToDeg;
  // Geometry never lies: a view is finite and on the sphere.
  for (const Eigen::Vector3d* t : {&est.t0, &est.tf}) {
    if (!t->allFinite() || std::abs((*t - c).norm() - r) > 1e-6 * r) {
      throw std::logic_error("estimate_view: a view off the sphere (" + format_value(*t) + ", radius " +
                             format_value(r) + " around " + format_value(c) + "): please report this input");
    }
  }
  return est;
}

Clock::time_point deadline_after(const EstimatorSettings& settings) {
  return Clock::now() +
         std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(settings.time_budget));
}

}  // namespace

ViewEstimate estimate_view(const OcclusionField& field, const EstimatorSettings& settings,
                           const std::optional<Eigen::Vector3d>& previous_view, const EstimateOptions& options) {
  const Clock::time_point deadline = deadline_after(settings);
  validate(settings);
  if (settings.r_sphere != field.r_sphere()) {
    usage_error("r_sphere " + format_value(settings.r_sphere) + " differs from the occlusion field's " +
                format_value(field.r_sphere()));
  }
  require_finite("previous_view", previous_view);
  if (previous_view) require_in_range("previous_view", *previous_view);
  return estimate_on(field, settings, previous_view, options, deadline);
}

ViewEstimate estimate_view(const ViewProblem& problem, const EstimatorSettings& settings,
                           const EstimateOptions& options) {
  const Clock::time_point deadline = deadline_after(settings);
  validate(settings);
  const OcclusionField field(problem, settings.r_sphere);
  return estimate_on(field, settings, problem.previous_view, options, deadline);
}

void reserve_estimator_memory(std::size_t occlusion_points) {
  const std::size_t rows = (std::min(occlusion_points, kMaxKeptPoints) + kLanes - 1) / kLanes;
  buffer_cache().reserve(3 * rows * kLanes);
}

UsableInput usable_input(const ViewProblem& problem, const Eigen::Vector3d& centroid, double r_sphere) {
  UsableInput input = normals_to_sphere_rays(usable_supervoxels(problem), centroid, r_sphere);
  input.occluders = usable_occluders(problem.occluders);
  return input;
}

}  // namespace ofv
