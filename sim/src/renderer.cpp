// Embree ray casting of a scenario: RGB-D frames, labels and ground truth.
#include "ofv/sim/renderer.h"
#include "bit_reversal.h"
#include "ofv/constants.h"
#include "sight_cone.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cmath>
#include <functional>
#include <limits>
#include <random>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace ofv::sim {

namespace {

constexpr double kDegToRad = kPi / 180.0;
// How far off its own surface's plane a visibility ray ends [m]: about 17
// times the single-precision rounding of coordinates around half a metre
// (6e-8 m), where the simulated scenes are.
constexpr double kSurfaceClearance = 1e-6;
// A holder is the object's (interacting) while its surface comes this near
// the object's; apart from it, an occluder like any other body [m].
constexpr double kHolderContact = 0.01;

// A point on a mesh: triangle and barycentric coordinates (stays on the
// surface when the mesh moves or deforms).
struct SurfaceSample {
  int triangle;
  float u, v;
};

std::vector<SurfaceSample> sample_surface(const TriangleMesh& m, int count, unsigned seed) {
  std::vector<double> cumulative;
  double total = 0.0;
  for (const auto& t : m.triangles) {
    total += 0.5 * (m.vertices[t[1]] - m.vertices[t[0]]).cross(m.vertices[t[2]] - m.vertices[t[0]]).cast<double>().norm();
    cumulative.push_back(total);
  }
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> uni(0.0, 1.0);
  std::vector<SurfaceSample> out;
  out.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    const double a = uni(rng) * total;
    const auto it = std::lower_bound(cumulative.begin(), cumulative.end(), a);
    const int tri = static_cast<int>(std::min<std::ptrdiff_t>(it - cumulative.begin(), static_cast<std::ptrdiff_t>(cumulative.size()) - 1));
    double u = uni(rng), v = uni(rng);
    if (u + v > 1.0) {
      u = 1.0 - u;
      v = 1.0 - v;
    }
    out.push_back({tri, static_cast<float>(u), static_cast<float>(v)});
  }
  return out;
}

struct WorldPoint {
  Eigen::Vector3d p, n;  // position, outward unit normal
};

// The outward unit normal of triangle t.
Eigen::Vector3d normal_of(const TriangleMesh& m, std::size_t t) {
  const auto& v = m.triangles[t];
  const Eigen::Vector3d a = m.vertices[v[0]].cast<double>();
  return (m.vertices[v[1]].cast<double>() - a).cross(m.vertices[v[2]].cast<double>() - a).normalized();
}

// Where sample s of m lies.
Eigen::Vector3d position_of(const TriangleMesh& m, const SurfaceSample& s) {
  const auto& t = m.triangles[static_cast<std::size_t>(s.triangle)];
  const Eigen::Vector3d a = m.vertices[t[0]].cast<double>(), b = m.vertices[t[1]].cast<double>(),
                        c = m.vertices[t[2]].cast<double>();
  return (1.0 - s.u - s.v) * a + s.u * b + s.v * c;
}

// Sample s of m, its triangle's normal given.
WorldPoint at(const TriangleMesh& m, const SurfaceSample& s, const Eigen::Vector3d& normal) {
  return {position_of(m, s), normal};
}

WorldPoint at(const TriangleMesh& m, const SurfaceSample& s) {
  return at(m, s, normal_of(m, static_cast<std::size_t>(s.triangle)));
}

std::uint16_t label_of(const Body& b, int occluder_index) {
  switch (b.role) {
    case Role::Object: return kLabelObject;
    case Role::Interacting: return kLabelInteracting;
    case Role::Background: return kLabelBackground;
    case Role::Occluder: return static_cast<std::uint16_t>(kLabelOccluder0 + occluder_index);
  }
  return kLabelNone;
}

// Cells of an r_seed grid: mean position and mean normal per cell (sums in
// the points' order), cells in the lexicographic order of their indices.
void grid_cells(const std::vector<WorldPoint>& pts, double cell, Eigen::Matrix3Xd& positions,
                Eigen::Matrix3Xd* normals) {
  using Key = std::array<long, 3>;
  struct Hash {
    std::size_t operator()(const Key& k) const {
      return static_cast<std::size_t>((static_cast<std::uint64_t>(k[0]) * 0x9E3779B97F4A7C15ull) ^
                                      (static_cast<std::uint64_t>(k[1]) * 0xC2B2AE3D27D4EB4Full) ^
                                      (static_cast<std::uint64_t>(k[2]) * 0x165667B19E3779F9ull));
    }
  };
  struct Cell {
    Key key;
    Eigen::Vector3d position = Eigen::Vector3d::Zero(), normal = Eigen::Vector3d::Zero();
    int count = 0;
  };
  std::vector<Cell> cells;
  std::unordered_map<Key, std::size_t, Hash> index;
  index.reserve(pts.size());
  for (const auto& w : pts) {
    const Key key{static_cast<long>(std::floor(w.p.x() / cell)), static_cast<long>(std::floor(w.p.y() / cell)),
                  static_cast<long>(std::floor(w.p.z() / cell))};
    const auto [it, inserted] = index.try_emplace(key, cells.size());
    if (inserted) cells.push_back({key});
    Cell& c = cells[it->second];
    c.position += w.p;
    c.normal += w.n;
    ++c.count;
  }
  std::sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.key < b.key; });
  positions.resize(3, static_cast<Eigen::Index>(cells.size()));
  if (normals != nullptr) normals->resize(3, static_cast<Eigen::Index>(cells.size()));
  for (std::size_t k = 0; k < cells.size(); ++k) {
    positions.col(static_cast<Eigen::Index>(k)) = cells[k].position / cells[k].count;
    if (normals != nullptr) normals->col(static_cast<Eigen::Index>(k)) = cells[k].normal.normalized();
  }
}

// Whether every vertex lies on the inner side of every triangle's plane
// (within a micrometre). Then the mesh lies in the half-space behind each of
// its triangles, so a segment from a point in front of a triangle to a point
// of it meets the mesh nowhere else.
bool convex(const TriangleMesh& m) {
  for (const auto& t : m.triangles) {
    const Eigen::Vector3d a = m.vertices[t[0]].cast<double>();
    const Eigen::Vector3d n = (m.vertices[t[1]].cast<double>() - a).cross(m.vertices[t[2]].cast<double>() - a);
    const double area = n.norm();
    if (!(area > 0.0)) continue;
    for (const Eigen::Vector3f& v : m.vertices) {
      if (n.dot(v.cast<double>() - a) > 1e-6 * area) return false;
    }
  }
  return true;
}

// Whether a convex mesh is the surface of its bounding box: its vertices
// on all eight corners and none elsewhere, its area the box's.
bool is_its_box(const TriangleMesh& m, const Eigen::AlignedBox3d& box) {
  unsigned corners = 0;
  for (const Eigen::Vector3f& p : m.vertices) {
    unsigned corner = 0;
    for (int j = 0; j < 3; ++j) {
      if (p[j] == static_cast<float>(box.max()[j])) {
        corner |= 1u << j;
      } else if (p[j] != static_cast<float>(box.min()[j])) {
        return false;
      }
    }
    corners |= 1u << corner;
  }
  const Eigen::Vector3d size = box.sizes();
  const double area = 2.0 * (size.x() * size.y() + size.y() * size.z() + size.z() * size.x());
  return corners == 0xFFu && std::abs(m.area() - area) <= 1e-6 * area;
}

// Runs rows(row0, row1) over bands of 8 rows of an image `height` rows high,
// in parallel (oneTBB, in the caller's task arena): a band has as much of
// the scene or of the empty sky above it as its neighbours.
void for_each_band(int height, const std::function<void(int, int)>& rows) {
  constexpr int kBand = 8;
  tbb::parallel_for(tbb::blocked_range<int>(0, (height + kBand - 1) / kBand), [&](const tbb::blocked_range<int>& r) {
    for (int b = r.begin(); b != r.end(); ++b) rows(b * kBand, std::min((b + 1) * kBand, height));
  });
}

// Depth as sensors and recordings store it, in 16-bit counts, so that a
// recorded episode replays bit for bit.
float quantised(float z) { return depth_from_units(depth_to_units(z, kTumDepthFactor), kTumDepthFactor); }

void quantise_depth(RgbdFrame& f, int row0, int row1) {
  const auto end = f.depth.begin() + static_cast<std::ptrdiff_t>(f.index(0, row1));
  for (auto z = f.depth.begin() + static_cast<std::ptrdiff_t>(f.index(0, row0)); z != end; ++z) *z = quantised(*z);
}

// SplitMix64's output function (Steele, Lea and Flood 2014): a bijection of
// 64-bit words whose outputs for consecutive inputs pass BigCrush.
constexpr std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
constexpr std::uint64_t kGolden = 0x9E3779B97F4A7C15ull;

// A standard normal draw from 32 random bits by its inverse distribution
// function: the quantiles at 2^16 + 1 equally likely points, linear between
// neighbours (the low 16 bits choose the interval, the next 16 the place in
// it), scaled to unit variance. Draws reach 4.3 sigma; the table is built
// once (a few milliseconds), each draw is one look-up.
class NormalByQuantiles {
 public:
  NormalByQuantiles() : q_(kPoints) {
    // Upper-tail probability of point j, and Newton on 0.5 erfc(x / sqrt 2)
    // from the neighbour's quantile outwards (the middle one is 0).
    const double n = kPoints;
    double x = 0.0;
    for (int j = kPoints / 2 + 1; j < kPoints; ++j) {
      const double tail = (n - 0.5 - j) / n;
      for (int it = 0; it < 50; ++it) {
        const double step = (0.5 * std::erfc(x / std::sqrt(2.0)) - tail) / (std::exp(-0.5 * x * x) / std::sqrt(2.0 * kPi));
        x += step;
        if (std::abs(step) < 1e-13 * (1.0 + x)) break;
      }
      q_[static_cast<std::size_t>(j)] = x;
      q_[static_cast<std::size_t>(kPoints - 1 - j)] = -x;
    }
    // Variance of the piecewise-uniform draw: (a^2 + ab + b^2) / 3 per interval.
    double second_moment = 0.0;
    for (std::size_t i = 0; i + 1 < q_.size(); ++i) {
      const double a = q_[i], b = q_[i + 1];
      second_moment += (a * a + a * b + b * b) / 3.0;
    }
    const double scale = 1.0 / std::sqrt(second_moment / (kPoints - 1));
    for (double& v : q_) v *= scale;
  }
  [[nodiscard]] double operator()(std::uint32_t bits) const {
    const std::size_t i = bits & 0xFFFFu;
    const double f = static_cast<double>(bits >> 16) * (1.0 / 65536.0);
    return q_[i] + f * (q_[i + 1] - q_[i]);
  }

 private:
  static constexpr int kPoints = (1 << 16) + 1;
  std::vector<double> q_;
};

const NormalByQuantiles& standard_normal() {
  static const NormalByQuantiles table;
  return table;
}

// A uniform draw in [0, 1) from the low 24 bits.
double uniform24(std::uint64_t bits) { return static_cast<double>(bits & 0xFFFFFFu) * (1.0 / 16777216.0); }

// Depth noise and dropouts (NoiseModel) of rows [row0, row1), quantised:
// `clean` is the depth before noise, `grazing` 1 where the ray meets the
// surface more obliquely than the model's grazing angle, `dropout` the
// drop-out probability of each label's own (dark or shiny) surface. Every
// pixel's draws come from a hash of (seed, frame, pixel): counter-based,
// so a frame is the same whatever the threads and whatever the other pixels.
void add_noise(RgbdFrame& f, int row0, int row1, const std::vector<std::uint8_t>& grazing,
               const std::vector<float>& clean, const NoiseModel& m, std::uint64_t seed, long frame_index,
               const std::vector<double>& dropout) {
  const CameraIntrinsics& k = f.intrinsics;
  const NormalByQuantiles& gauss = standard_normal();
  const std::uint64_t frame_key = mix64(mix64(seed) + static_cast<std::uint64_t>(frame_index));
  // Plain pointers: the byte loads and stores would otherwise make the
  // compiler load each vector's data pointer again at every pixel.
  const float* const in = clean.data();
  const std::uint8_t* const grazes = grazing.data();
  const std::uint16_t* const labels = f.labels.data();
  float* const out = f.depth.data();
  const double* const dark_of = dropout.data();
  const std::size_t dark_labels = dropout.size();
  const int width = k.width, height = k.height;
  const double edge_jump = m.edge_jump, depth_sigma = m.depth_sigma, edge_dropout = m.edge_dropout;
  for (int v = row0; v < row1; ++v) {
    const std::size_t row = f.index(0, v);
    for (int u = 0; u < width; ++u) {
      const std::size_t i = row + static_cast<std::size_t>(u);
      const float z = in[i];
      if (z <= 0.0f) continue;
      // Right, left, down, up, as far as the image goes.
      const auto jumps = [&](std::size_t j) { return in[j] <= 0.0f || std::abs(in[j] - z) > edge_jump; };
      const bool edge = (u + 1 < width && jumps(i + 1)) || (u > 0 && jumps(i - 1)) ||
                        (v + 1 < height && jumps(i + static_cast<std::size_t>(width))) ||
                        (v > 0 && jumps(i - static_cast<std::size_t>(width)));
      // Bits 0-31: the Gaussian; 32-55: the edge's drop-out; a second word
      // for a dark or shiny body's own drop-outs.
      const std::uint64_t bits = mix64(frame_key + kGolden * (static_cast<std::uint64_t>(i) + 1));
      const double noise_z = gauss(static_cast<std::uint32_t>(bits)) * depth_sigma * z * z;
      const double dark = labels[i] < dark_labels ? dark_of[labels[i]] : 0.0;
      if (grazes[i] != 0 || (edge && uniform24(bits >> 32) < edge_dropout) ||
          (dark > 0.0 && uniform24(mix64(bits)) < dark)) {
        out[i] = 0.0f;
      } else {
        out[i] = quantised(static_cast<float>(z + noise_z));
      }
    }
  }
}

}  // namespace

struct Renderer::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  std::vector<TriangleMesh> world;               // per body, at the current time
  std::vector<std::uint16_t> labels;             // per body, at the current time (a holder's: set_time())
  std::vector<std::uint16_t> apart_label;        // per body: a holder's label while it does not touch the object
  std::vector<double> dropout;                   // per label: Body::dropout
  std::vector<std::vector<SurfaceSample>> samples;  // per body
  int object = 0;
  std::vector<char> rigid_convex;             // per body (a convex object hides none of its facing samples)
  std::vector<Eigen::AlignedBox3d> boxes;     // per body, at the current time
  std::vector<char> solid_box;                // per body: convex, its vertices its box's corners (set_time())
  std::vector<int> ray_order;  // the object's samples, neighbours on its surface next to each other (order_rays())

  ~Impl() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }

  // Whether body b is an occluder at the current time: one of the
  // scenario's, or a holder apart from the object.
  [[nodiscard]] bool occluder_now(std::size_t b) const { return labels[b] >= kLabelOccluder0; }

  // Whether body b's surface comes within kHolderContact of the object's
  // at the current time: their surface samples, those of each within that
  // of the other's bounding box.
  [[nodiscard]] bool touches_object(std::size_t b) const {
    const auto obj = static_cast<std::size_t>(object);
    const auto grown = [](const Eigen::AlignedBox3d& box) {
      return Eigen::AlignedBox3d(box.min().array() - kHolderContact, box.max().array() + kHolderContact);
    };
    if (!boxes[b].intersects(grown(boxes[obj]))) return false;
    const auto near_box = [&](std::size_t body, const Eigen::AlignedBox3d& box) {
      std::vector<Eigen::Vector3d> near;
      for (const SurfaceSample& x : samples[body]) {
        const Eigen::Vector3d p = position_of(world[body], x);
        if (box.contains(p)) near.push_back(p);
      }
      return near;
    };
    const std::vector<Eigen::Vector3d> mine = near_box(b, grown(boxes[obj]));
    const std::vector<Eigen::Vector3d> its = near_box(obj, grown(boxes[b]));
    return std::any_of(mine.begin(), mine.end(), [&](const Eigen::Vector3d& p) {
      return std::any_of(its.begin(), its.end(),
                         [&](const Eigen::Vector3d& q) { return (q - p).squaredNorm() <= kHolderContact * kHolderContact; });
    });
  }

  // The object's surface samples at the current time.
  [[nodiscard]] std::vector<WorldPoint> object_points() const {
    const TriangleMesh& m = world[static_cast<std::size_t>(object)];
    std::vector<WorldPoint> points;
    points.reserve(samples[static_cast<std::size_t>(object)].size());
    for (const auto& s : samples[static_cast<std::size_t>(object)]) points.push_back(at(m, s));
    return points;
  }

  // The object's surface samples in ray_order (neighbours on the surface
  // next to each other, so that the rays of one packet of visible_fraction()
  // run close together through the scene), and a ball that holds them.
  struct Samples {
    std::vector<WorldPoint> points;
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    double radius = 0.0;
  };
  [[nodiscard]] Samples object_samples() const {
    const TriangleMesh& m = world[static_cast<std::size_t>(object)];
    const auto& all = samples[static_cast<std::size_t>(object)];
    Samples out;
    out.points.reserve(ray_order.size());
    Eigen::AlignedBox3d box;
    for (const int k : ray_order) {
      out.points.push_back(at(m, all[static_cast<std::size_t>(k)]));
      box.extend(out.points.back().p);
    }
    out.centre = box.center();
    for (const WorldPoint& w : out.points) out.radius = std::max(out.radius, (w.p - out.centre).norm());
    return out;
  }
  // Sets ray_order: the object's samples in Morton order of their place at time 0.
  void order_rays() {
    const std::vector<WorldPoint> points = object_points();
    Eigen::AlignedBox3d box;
    for (const WorldPoint& w : points) box.extend(w.p);
    const Eigen::Vector3d size = box.sizes().cwiseMax(1e-9);
    std::vector<std::pair<std::uint64_t, int>> keyed;
    keyed.reserve(points.size());
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Eigen::Vector3d q = ((points[k].p - box.min()).cwiseQuotient(size) * 1023.0).cwiseMax(0.0).cwiseMin(1023.0);
      std::uint64_t key = 0;
      for (int bit = 9; bit >= 0; --bit) {
        for (int a = 0; a < 3; ++a) key = (key << 1) | ((static_cast<std::uint64_t>(q[a]) >> bit) & 1u);
      }
      keyed.emplace_back(key, static_cast<int>(k));
    }
    std::sort(keyed.begin(), keyed.end());
    ray_order.clear();
    for (const auto& [key, k] : keyed) ray_order.push_back(k);
  }

  // Whether a body other than the object may lie on a segment from o to the
  // object's samples: unless a plane of its box has o strictly on one side and
  // the object's box on the other, or its box's ball misses the cone from o
  // around the samples' ball (or lies beyond their far side).
  [[nodiscard]] bool others_in_the_way(const Samples& target, const Eigen::Vector3d& o) const {
    const Eigen::AlignedBox3d& object_box = boxes[static_cast<std::size_t>(object)];
    const detail::SightCone cone(o, target.centre, target.radius);
    if (cone.length() <= target.radius) return true;
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      if (static_cast<int>(b) == object) continue;
      const Eigen::AlignedBox3d& box = boxes[b];
      bool apart = false;
      for (int k = 0; k < 3 && !apart; ++k) {
        // The camera strictly on its side of the plane, the object on or behind it.
        apart = (o[k] < box.min()[k] && object_box.max()[k] <= box.min()[k]) ||
                (o[k] > box.max()[k] && object_box.min()[k] >= box.max()[k]);
      }
      if (!apart && cone.may_meet(box.center(), 0.5 * box.diagonal().norm())) return true;
    }
    return false;
  }

  // Whether every segment from o to the object passes through a body that is
  // its own bounding box: o beyond the box's face on one axis, the object's
  // box before its opposite face, and the segments from o to the object's box
  // corners crossing the near face's plane inside that face (with a margin far
  // above rounding). The object's box holds its samples, and the crossings of
  // the segments to them lie in the hull of the corners' crossings.
  [[nodiscard]] bool behind_a_box(const Eigen::Vector3d& o) const {
    constexpr double kMargin = 1e-6;  // [m]
    const Eigen::AlignedBox3d& object_box = boxes[static_cast<std::size_t>(object)];
    for (std::size_t b = 0; b < boxes.size(); ++b) {
      if (!solid_box[b] || static_cast<int>(b) == object) continue;
      const Eigen::AlignedBox3d& box = boxes[b];
      for (int k = 0; k < 3; ++k) {
        double face = 0.0;
        if (o[k] > box.max()[k] && object_box.max()[k] < box.min()[k] - kMargin) {
          face = box.max()[k];
        } else if (o[k] < box.min()[k] && object_box.min()[k] > box.max()[k] + kMargin) {
          face = box.min()[k];
        } else {
          continue;
        }
        bool inside = true;
        for (int corner = 0; corner < 8 && inside; ++corner) {
          const Eigen::Vector3d c = object_box.corner(static_cast<Eigen::AlignedBox3d::CornerType>(corner));
          const Eigen::Vector3d q = o + (face - o[k]) / (c[k] - o[k]) * (c - o);
          for (int j = 0; j < 3; ++j) {
            if (j != k && (q[j] < box.min()[j] + kMargin || q[j] > box.max()[j] - kMargin)) inside = false;
          }
        }
        if (inside) return true;
      }
    }
    return false;
  }

  // The fraction of the samples facing a camera at wMc that it sees: in its
  // image, within its depth range and with nothing in between. No ray is
  // cast where the answer is known: a body that is its own box across every
  // line of sight (none seen), or a convex object with no other body in the
  // way (every facing sample in view seen). Where only a fraction of at
  // least `at_least` matters, the samples in *missed (a bitset: those an
  // earlier call found not seen) go first, then the others in blocks spread
  // over the surface, and the rays stop once fewer than that can be seen:
  // the fraction that could still be seen is returned, below `at_least`,
  // with *exact false; then *missed becomes the samples this call found not
  // seen (it is left as it was where no threshold matters).
  [[nodiscard]] double visible_fraction(const Samples& target, const Eigen::Isometry3d& wMc,
                                        const SensorSettings& sensor,
                                        double at_least = -std::numeric_limits<double>::infinity(),
                                        bool* exact = nullptr, std::vector<std::uint64_t>* missed = nullptr) const {
    if (exact != nullptr) *exact = true;
    const Eigen::Vector3d o = wMc.translation();
    const Eigen::Isometry3d cMw = wMc.inverse();
    const CameraIntrinsics& k = sensor.intrinsics;
    const int total = static_cast<int>(target.points.size());
    const auto words = static_cast<std::size_t>((total + 63) / 64);
    // When the samples' ball lies in the image and the depth range (by far
    // more than rounding), so does every sample: no need to project each.
    const Eigen::Vector3d b = cMw * target.centre;
    const double r = target.radius + 1e-6;
    const auto clear_of = [&](double f, double c, double side, double along, double depth) {
      return f * along + c * depth >= r * std::hypot(f, c) && side * depth - f * along >= r * std::hypot(f, side);
    };
    const bool all_in_view = b.z() - r >= sensor.min_depth && b.z() + r <= sensor.max_depth &&
                             clear_of(k.fx, k.cx, k.width - 1.0 - k.cx, b.x(), b.z()) &&
                             clear_of(k.fy, k.cy, k.height - 1.0 - k.cy, b.y(), b.z());
    if (behind_a_box(o)) return 0.0;
    const bool cast = rigid_convex[static_cast<std::size_t>(object)] == 0 || others_in_the_way(target, o);
    if (!cast && all_in_view) {  // every facing sample is seen
      const bool any = std::any_of(target.points.begin(), target.points.end(),
                                   [&](const WorldPoint& w) { return w.n.dot(o - w.p) > 0.0; });
      return any ? 1.0 : 0.0;
    }
    // Rays from the camera to the facing samples in view, 16 to a packet,
    // neighbours on the surface together. Where a threshold matters, the
    // samples missed before go first and the others follow in blocks taken
    // in bit-reversed order, spread over the surface so that an occlusion
    // anywhere shows early; the rays stop once the fraction that could still
    // be seen, every sample not yet looked at taken as facing and seen, is
    // below the threshold.
    constexpr int kPacket = 16, kBlock = 64;
    const int blocks = (total + kBlock - 1) / kBlock;
    const bool bounded = at_least > 0.0 && cast;
    // Which samples were missed before and which have been looked at: only
    // where a threshold matters.
    const bool track = bounded && missed != nullptr;
    thread_local std::vector<std::uint64_t> earlier, done;
    if (track) {
      earlier.assign(words, 0);
      for (std::size_t w = 0; w < std::min(words, missed->size()); ++w) earlier[w] = (*missed)[w];
      missed->assign(words, 0);
      done.assign(words, 0);
    }
    const int bits = bounded ? detail::bits_for(static_cast<std::size_t>(blocks)) : 0;
    int facing = 0, not_seen = 0, looked_at = 0;
    const auto found = [&](int sample) {
      ++not_seen;
      if (track) (*missed)[static_cast<std::size_t>(sample) / 64] |= std::uint64_t{1} << (sample % 64);
    };
    alignas(64) int valid[kPacket];
    int lane_sample[kPacket];
    RTCRay16 ray{};
    for (int j = 0; j < kPacket; ++j) {
      ray.org_x[j] = static_cast<float>(o.x());
      ray.org_y[j] = static_cast<float>(o.y());
      ray.org_z[j] = static_cast<float>(o.z());
      ray.mask[j] = 0xFFFFFFFFu;
      ray.time[j] = 0.0f;
      ray.flags[j] = 0;
    }
    int filled = 0;
    auto trace = [&] {
      if (filled == 0) return;
      for (int j = filled; j < kPacket; ++j) valid[j] = 0;
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      rtcOccluded16(valid, scene, &context, &ray);
      for (int j = 0; j < filled; ++j) {
        if (ray.tfar[j] < 0.0f) found(lane_sample[j]);
      }
      filled = 0;
    };
    const auto look_at = [&](int sample) {
      if (track) done[static_cast<std::size_t>(sample) / 64] |= std::uint64_t{1} << (sample % 64);
      ++looked_at;
      const WorldPoint& w = target.points[static_cast<std::size_t>(sample)];
      const double towards = w.n.dot(o - w.p);
      if (towards <= 0.0) return;
      ++facing;
      if (!all_in_view) {
        const Eigen::Vector3d pc = cMw * w.p;
        const double u = k.fx * pc.x() / pc.z() + k.cx, v = k.fy * pc.y() / pc.z() + k.cy;
        if (pc.z() < sensor.min_depth || pc.z() > sensor.max_depth || u < 0.0 || v < 0.0 || u > k.width - 1.0 ||
            v > k.height - 1.0) {
          found(sample);
          return;
        }
      }
      if (!cast) return;
      const Eigen::Vector3d d = w.p - o;
      valid[filled] = -1;
      lane_sample[filled] = sample;
      ray.dir_x[filled] = static_cast<float>(d.x());
      ray.dir_y[filled] = static_cast<float>(d.y());
      ray.dir_z[filled] = static_cast<float>(d.z());
      ray.tnear[filled] = 0.0f;
      // Stop short of the point itself, where the ray is still kSurfaceClearance
      // off its surface's plane: a ray that grazes the surface (the camera
      // within a hair of its plane) would otherwise meet the surface it ends on.
      const double short_of = std::max(1e-4, kSurfaceClearance / towards);
      ray.tfar[filled] = static_cast<float>(std::max(0.0, 1.0 - short_of));
      if (++filled == kPacket) trace();
    };
    // The fraction that could still be seen, every sample not yet looked at
    // taken as facing and seen; whether it is below at_least once the rays
    // on their way are traced (then the value is that bound).
    const auto could_see = [&]() {
      const int could_face = facing + total - looked_at;
      return could_face > 0 ? static_cast<double>(could_face - not_seen) / could_face : 0.0;
    };
    const auto can_stop = [&]() {
      trace();
      if (could_see() >= at_least) return false;
      if (exact != nullptr) *exact = looked_at == total;
      return true;
    };
    if (track) {
      for (std::size_t w = 0; w < words; ++w) {
        for (int bit = 0; bit < 64 && earlier[w] != 0; ++bit) {
          const int sample = static_cast<int>(w * 64) + bit;
          if ((earlier[w] >> bit & 1u) == 0 || sample >= total) continue;
          look_at(sample);
          if (filled == 0 && can_stop()) return could_see();  // a packet has just gone
        }
      }
      if (can_stop()) return could_see();
    }
    for (int p = 0; p < (bounded ? 1 << bits : blocks); ++p) {
      const int q = bounded ? static_cast<int>(detail::bit_reversed(static_cast<std::size_t>(p), bits)) : p;
      if (q >= blocks) continue;
      for (int sample = q * kBlock; sample < std::min(total, (q + 1) * kBlock); ++sample) {
        if (!track || (done[static_cast<std::size_t>(sample) / 64] >> (sample % 64) & 1u) == 0) look_at(sample);
      }
      if (bounded && can_stop()) return could_see();
    }
    trace();
    return facing > 0 ? static_cast<double>(facing - not_seen) / facing : 0.0;
  }
};

Renderer::Renderer(const Scenario& scenario, int surface_samples)
    : scenario_(scenario), impl_(std::make_unique<Impl>()) {
  // Embree's defaults: with TBB tasking, a "threads=N" configuration sets a
  // process-wide tbb::global_control, so "threads=1" made every TBB loop of
  // the process (ofv compare's episodes, the hindsight planner's views) serial
  // while a renderer lived.
  impl_->device = rtcNewDevice(nullptr);
  if (impl_->device == nullptr) throw std::runtime_error("Embree: cannot create a device");
  const auto occluders = static_cast<int>(std::count_if(scenario_.bodies.begin(), scenario_.bodies.end(),
                                                        [](const Body& b) { return b.role == Role::Occluder; }));
  int occluder = 0, holder = 0;
  for (std::size_t k = 0; k < scenario_.bodies.size(); ++k) {
    const Body& b = scenario_.bodies[k];
    impl_->labels.push_back(label_of(b, b.role == Role::Occluder ? occluder++ : 0));
    // A holder apart from the object is an occluder, numbered after the scenario's.
    impl_->apart_label.push_back(b.role == Role::Interacting
                                     ? static_cast<std::uint16_t>(kLabelOccluder0 + occluders + holder++)
                                     : impl_->labels.back());
    for (const std::uint16_t label : {impl_->labels.back(), impl_->apart_label.back()}) {
      if (impl_->dropout.size() <= label) impl_->dropout.resize(label + 1u, 0.0);
      impl_->dropout[label] = std::max(impl_->dropout[label], b.dropout);
    }
    if (b.role == Role::Object) impl_->object = static_cast<int>(k);
    impl_->rigid_convex.push_back(!b.deformable() && convex(b.mesh) ? 1 : 0);
    const int n = b.role == Role::Object ? surface_samples
                                         : std::clamp(static_cast<int>(b.mesh.area() / (0.004 * 0.004)), 200, 20000);
    impl_->samples.push_back(sample_surface(b.mesh, n, 7919u * static_cast<unsigned>(k + 1)));
  }
  set_time(0.0);
  impl_->order_rays();
}

Renderer::~Renderer() = default;

void Renderer::set_time(double t) {
  if (t == time_) return;
  time_ = t;
  if (impl_->scene != nullptr) rtcReleaseScene(impl_->scene);
  impl_->scene = rtcNewScene(impl_->device);
  // Medium: builds about as fast as low for these few thousand triangles,
  // and traces faster (the planner casts millions of rays into one scene).
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_MEDIUM);
  impl_->world.clear();
  impl_->boxes.clear();
  impl_->solid_box.clear();
  for (std::size_t k = 0; k < scenario_.bodies.size(); ++k) {
    impl_->world.push_back(scenario_.bodies[k].world_mesh(t));
    const TriangleMesh& m = impl_->world.back();
    Eigen::AlignedBox3d& box = impl_->boxes.emplace_back();
    for (const Eigen::Vector3f& p : m.vertices) box.extend(p.cast<double>());
    impl_->solid_box.push_back(impl_->rigid_convex[k] != 0 && is_its_box(m, box) ? 1 : 0);
    RTCGeometry g = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                          3 * sizeof(float), m.vertices.size()));
    for (std::size_t i = 0; i < m.vertices.size(); ++i) {
      v[3 * i] = m.vertices[i].x();
      v[3 * i + 1] = m.vertices[i].y();
      v[3 * i + 2] = m.vertices[i].z();
    }
    auto* idx = static_cast<unsigned*>(rtcSetNewGeometryBuffer(g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                               3 * sizeof(unsigned), m.triangles.size()));
    for (std::size_t i = 0; i < m.triangles.size(); ++i) {
      for (int j = 0; j < 3; ++j) idx[3 * i + static_cast<std::size_t>(j)] = static_cast<unsigned>(m.triangles[i][j]);
    }
    rtcCommitGeometry(g);
    rtcAttachGeometryByID(impl_->scene, g, static_cast<unsigned>(k));
    rtcReleaseGeometry(g);
  }
  rtcCommitScene(impl_->scene);
  for (std::size_t k = 0; k < scenario_.bodies.size(); ++k) {
    if (scenario_.bodies[k].role == Role::Interacting) {
      impl_->labels[k] = impl_->touches_object(k) ? std::uint16_t{kLabelInteracting} : impl_->apart_label[k];
    }
  }
}

RenderedFrame Renderer::render(const Eigen::Isometry3d& wMc, long frame_index) const {
  return render(wMc, frame_index, scenario_.sensor.intrinsics, scenario_.sensor.noise.enabled);
}

RenderedFrame Renderer::render(const Eigen::Isometry3d& wMc, long frame_index,
                               const CameraIntrinsics& k, bool noise) const {
  RenderedFrame out;
  render(wMc, frame_index, k, noise, out);
  return out;
}

void Renderer::render(const Eigen::Isometry3d& wMc, long frame_index, const CameraIntrinsics& k, bool noise,
                      RenderedFrame& out) const {
  // Embree takes a ray that is not finite for a programming error and
  // aborts: such a pose (from a faulty driver) is refused here.
  if (!wMc.matrix().allFinite()) throw std::invalid_argument("renderer: the camera pose is not finite");
  RgbdFrame& f = out.frame;
  f.timestamp = time_;
  f.intrinsics = k;
  f.wMc = wMc;
  const auto pixels = static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height);
  f.depth.assign(pixels, 0.0f);
  f.rgb.assign(3 * pixels, 0);
  f.labels.assign(pixels, kLabelNone);
  f.object_centroid = object_centroid();
  // Scratch kept by each thread that calls render, so a loop of frames
  // reuses it. (The workers below use the caller's, through these references.)
  thread_local std::vector<std::uint8_t> grazing_scratch;
  thread_local std::vector<float> clean_scratch;
  std::vector<std::uint8_t>& grazing = grazing_scratch;
  std::vector<float>& clean = clean_scratch;
  grazing.assign(pixels, 0);
  const SensorSettings& sensor = scenario_.sensor;
  const float cos_grazing = static_cast<float>(std::cos(sensor.noise.grazing_deg * kDegToRad));
  const Eigen::Matrix3d R = wMc.linear();
  const Eigen::Vector3d o = wMc.translation();

  // The ray of pixel (u, v) is R (x_u, y_v, 1) with x_u = (u - cx) / fx,
  // y_v = (v - cy) / fy: the columns' products R.col(0) x_u are made once,
  // and each pixel adds in the same order as the product would,
  // (R.col(0) x_u + R.col(1) y_v) + R.col(2), so the rays are bit for bit
  // those of the product.
  std::vector<Eigen::Vector3d> column_term(static_cast<std::size_t>(k.width));
  for (int u = 0; u < k.width; ++u) column_term[static_cast<std::size_t>(u)] = R.col(0) * ((u - k.cx) / k.fx);
  const Eigen::Vector3d last = R.col(2);
  // Coherent rays of 16 neighbouring pixels are traced as one packet.
  for_each_band(k.height, [&](int row0, int row1) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
    constexpr int kPacket = 16;
    alignas(64) int valid[kPacket];
    RTCRayHit16 rh;
    // What Embree reads and never writes, set once.
    for (int j = 0; j < kPacket; ++j) {
      rh.ray.org_x[j] = static_cast<float>(o.x());
      rh.ray.org_y[j] = static_cast<float>(o.y());
      rh.ray.org_z[j] = static_cast<float>(o.z());
      rh.ray.tnear[j] = static_cast<float>(sensor.min_depth);
      rh.ray.mask[j] = 0xFFFFFFFFu;
      rh.ray.time[j] = 0.0f;
      rh.ray.flags[j] = 0;
    }
    const float tfar = static_cast<float>(sensor.max_depth);
    // Plain pointers: the byte stores would otherwise make the compiler
    // load each vector's data pointer again at every pixel.
    float* const depth = f.depth.data();
    std::uint8_t* const grazes = grazing.data();
    std::uint16_t* const labels = f.labels.data();
    std::uint8_t* const rgb = f.rgb.data();
    const std::uint16_t* const body_label = impl_->labels.data();
    const Body* const bodies = scenario_.bodies.data();
    for (int v = row0; v < row1; ++v) {
      const Eigen::Vector3d row_term = R.col(1) * ((v - k.cy) / k.fy);
      for (int u0 = 0; u0 < k.width; u0 += kPacket) {
        for (int j = 0; j < kPacket; ++j) {
          const int u = u0 + j;
          valid[j] = u < k.width ? -1 : 0;
          // Camera ray with unit Z, so the hit distance is the depth Z.
          const Eigen::Vector3d d = (column_term[static_cast<std::size_t>(std::min(u, k.width - 1))] + row_term) + last;
          rh.ray.dir_x[j] = static_cast<float>(d.x());
          rh.ray.dir_y[j] = static_cast<float>(d.y());
          rh.ray.dir_z[j] = static_cast<float>(d.z());
          rh.ray.tfar[j] = tfar;
          rh.hit.geomID[j] = RTC_INVALID_GEOMETRY_ID;
        }
        rtcIntersect16(valid, impl_->scene, &context, &rh);
        for (int j = 0; j < kPacket && u0 + j < k.width; ++j) {
          const unsigned geom = rh.hit.geomID[j];
          if (geom == RTC_INVALID_GEOMETRY_ID) continue;
          const std::size_t i = f.index(u0 + j, v);
          const Eigen::Vector3d ng(rh.hit.Ng_x[j], rh.hit.Ng_y[j], rh.hit.Ng_z[j]);
          const Eigen::Vector3d d(rh.ray.dir_x[j], rh.ray.dir_y[j], rh.ray.dir_z[j]);
          const double c = std::abs(ng.normalized().dot(d.normalized()));
          depth[i] = rh.ray.tfar[j];
          grazes[i] = static_cast<float>(c) < cos_grazing ? 1 : 0;
          labels[i] = body_label[geom];
          const Eigen::Vector3f colour = bodies[geom].colour;
          const float shade = static_cast<float>(0.35 + 0.65 * c);
          for (int ch = 0; ch < 3; ++ch) {
            rgb[3 * i + static_cast<std::size_t>(ch)] =
                static_cast<std::uint8_t>(std::clamp(255.0f * colour[ch] * shade, 0.0f, 255.0f));
          }
        }
      }
    }
  });
  // Noise needs the clean depth of the neighbour rows, so it is a second
  // pass over the rows.
  if (noise) {
    clean = f.depth;
    for_each_band(k.height, [&](int row0, int row1) {
      add_noise(f, row0, row1, grazing, clean, sensor.noise, scenario_.seed, frame_index, impl_->dropout);
    });
  } else {
    for_each_band(k.height, [&](int row0, int row1) { quantise_depth(f, row0, row1); });
  }
}

ObjectTruth Renderer::truth(const Eigen::Isometry3d& wMc, double r_sphere) const {
  ObjectTruth t;
  t.centroid = object_centroid();
  t.visible_fraction = impl_->visible_fraction(impl_->object_samples(), wMc, scenario_.sensor);
  for (std::size_t b = 0; b < scenario_.bodies.size(); ++b) {
    if (!impl_->occluder_now(b)) continue;
    const auto& verts = impl_->world[b].vertices;
    const bool inside = std::any_of(verts.begin(), verts.end(), [&](const Eigen::Vector3f& v) {
      return (v.cast<double>() - t.centroid).norm() < r_sphere;
    });
    t.occluders_in_sphere += inside ? 1 : 0;
  }
  return t;
}

Eigen::Vector3d Renderer::object_centroid() const {
  const TriangleMesh& m = impl_->world[static_cast<std::size_t>(impl_->object)];
  const auto& samples = impl_->samples[static_cast<std::size_t>(impl_->object)];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& s : samples) sum += position_of(m, s);
  return sum / static_cast<double>(samples.size());
}

std::vector<Eigen::Vector3d> Renderer::object_surface() const {
  const std::vector<WorldPoint> samples = impl_->object_points();
  std::vector<Eigen::Vector3d> points(samples.size());
  std::transform(samples.begin(), samples.end(), points.begin(), [](const WorldPoint& w) { return w.p; });
  return points;
}

std::vector<double> Renderer::visible_fractions(const std::vector<Eigen::Isometry3d>& poses) const {
  std::vector<char> exact;
  return visible_fractions(poses, std::vector<double>(poses.size(), -std::numeric_limits<double>::infinity()), exact);
}

std::vector<double> Renderer::visible_fractions(const std::vector<Eigen::Isometry3d>& poses,
                                                const std::vector<double>& at_least, std::vector<char>& exact,
                                                std::vector<std::vector<std::uint64_t>>* missed) const {
  if (at_least.size() != poses.size() || (missed != nullptr && missed->size() != poses.size())) {
    throw std::invalid_argument("renderer: " + std::to_string(at_least.size()) + " thresholds and " +
                                std::to_string(missed != nullptr ? missed->size() : poses.size()) +
                                " sets of samples for " + std::to_string(poses.size()) + " poses");
  }
  for (const Eigen::Isometry3d& wMc : poses) {
    if (!wMc.matrix().allFinite()) throw std::invalid_argument("renderer: a camera pose is not finite");
  }
  const Impl::Samples samples = impl_->object_samples();
  std::vector<double> fractions(poses.size());
  exact.assign(poses.size(), 1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, poses.size()), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) {
      bool whole = true;
      fractions[i] = impl_->visible_fraction(samples, poses[i], scenario_.sensor, at_least[i], &whole,
                                             missed != nullptr ? &(*missed)[i] : nullptr);
      exact[i] = whole ? 1 : 0;
    }
  });
  return fractions;
}

int occluders_seen(const std::vector<std::uint16_t>& labels) {
  std::vector<bool> seen;
  int count = 0;
  for (const std::uint16_t label : labels) {
    if (label < kLabelOccluder0) continue;
    const std::size_t k = label - kLabelOccluder0;
    if (k >= seen.size()) seen.resize(k + 1, false);
    if (!seen[k]) {
      seen[k] = true;
      ++count;
    }
  }
  return count;
}

ViewProblem Renderer::ground_truth_object(const Eigen::Isometry3d& wMc, double r_seed) const {
  const Eigen::Vector3d o = wMc.translation();
  const std::size_t obj = static_cast<std::size_t>(impl_->object);
  std::vector<WorldPoint> facing;
  facing.reserve(impl_->samples[obj].size());
  for (const auto& s : impl_->samples[obj]) {
    const WorldPoint w = at(impl_->world[obj], s);
    if (w.n.dot(o - w.p) > 0.0) facing.push_back(w);
  }
  ViewProblem p;
  grid_cells(facing, r_seed, p.positions, &p.normals);
  p.camera = o;
  return p;
}

ViewProblem Renderer::ground_truth_problem(const Eigen::Isometry3d& wMc, double r_seed,
                                           double r_sphere, double obb_margin) const {
  ViewProblem p = ground_truth_object(wMc, r_seed);
  const Eigen::Vector3d o = wMc.translation();
  // The augmented OBB from all of the object's surface.
  const std::size_t obj = static_cast<std::size_t>(impl_->object);
  Eigen::Matrix3Xd all(3, static_cast<Eigen::Index>(impl_->samples[obj].size()));
  Eigen::Index n = 0;
  for (const auto& s : impl_->samples[obj]) all.col(n++) = position_of(impl_->world[obj], s);
  const Eigen::Vector3d mean = all.rowwise().mean();
  const Eigen::Matrix3Xd centred = all.colwise() - mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(centred * centred.transpose());
  const Eigen::Matrix3d axes = eig.eigenvectors();
  const Eigen::Vector3d half = (axes.transpose() * centred).cwiseAbs().rowwise().maxCoeff().array() + obb_margin;
  const Eigen::Vector3d c = p.positions.cols() > 0 ? Eigen::Vector3d(p.positions.rowwise().mean()) : mean;

  // Everything but the object and its holder while it touches the object
  // (inside the augmented OBB anyway): the occluders (a holder apart from
  // the object is one) and the table, as the paper's classification would;
  // not the bodies wholly outside the sphere.
  std::vector<std::size_t> bodies;
  std::size_t samples = 0;
  for (std::size_t b = 0; b < scenario_.bodies.size(); ++b) {
    const Role role = scenario_.bodies[b].role;
    if ((!impl_->occluder_now(b) && role != Role::Background) || impl_->boxes[b].exteriorDistance(c) > r_sphere + 1e-9) {
      continue;
    }
    bodies.push_back(b);
    samples += impl_->samples[b].size();
  }
  std::vector<WorldPoint> occluding;
  occluding.reserve(samples);
  std::vector<Eigen::Vector3d> normals;  // of the body's triangles, each made once
  for (const std::size_t b : bodies) {
    const TriangleMesh& m = impl_->world[b];
    normals.resize(m.triangles.size());
    for (std::size_t t = 0; t < m.triangles.size(); ++t) normals[t] = normal_of(m, t);
    for (const auto& s : impl_->samples[b]) {
      const WorldPoint w = at(m, s, normals[static_cast<std::size_t>(s.triangle)]);
      if (w.n.dot(o - w.p) <= 0.0) continue;  // the sensor sees only this side
      const bool in_obb = ((axes.transpose() * (w.p - mean)).cwiseAbs().array() <= half.array()).all();
      if (!in_obb && (w.p - c).norm() < r_sphere) occluding.push_back(w);
    }
  }
  grid_cells(occluding, r_seed, p.occluders, nullptr);
  return p;
}

}  // namespace ofv::sim
