// ofv's supervoxel stage: VCCS on the voxel grid (the algorithm is described
// in vccs.h). No PCL here.
#include "vccs.h"

#include "parallel.h"
#include "point_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <numeric>
#include <optional>
#include <vector>

namespace ofv::perception::detail {

namespace {

/// The unit eigenvector of a covariance's smallest eigenvalue, or nothing
/// when the points lie on a line or a point (l1 l2 <= 1e-6 trace^2: the
/// middle eigenvalue vanishes against the largest). The adjugate of C has the eigenvalues
/// l1 l2, l0 l2, l0 l1 on the same eigenvectors: its largest column is
/// already near the wanted axis, and two products with it converge as
/// (l0 / l1)^2 per step. A few multiplications where Eigen's direct 3x3
/// solver takes about 100 ns (trigonometric functions).
std::optional<Eigen::Vector3d> smallest_axis(const Eigen::Matrix3d& c) {
  Eigen::Matrix3d adj;
  adj(0, 0) = c(1, 1) * c(2, 2) - c(1, 2) * c(1, 2);
  adj(1, 1) = c(0, 0) * c(2, 2) - c(0, 2) * c(0, 2);
  adj(2, 2) = c(0, 0) * c(1, 1) - c(0, 1) * c(0, 1);
  adj(0, 1) = adj(1, 0) = c(0, 2) * c(1, 2) - c(0, 1) * c(2, 2);
  adj(0, 2) = adj(2, 0) = c(0, 1) * c(1, 2) - c(0, 2) * c(1, 1);
  adj(1, 2) = adj(2, 1) = c(0, 1) * c(0, 2) - c(0, 0) * c(1, 2);
  Eigen::Index k = 0;
  const double largest = adj.colwise().squaredNorm().maxCoeff(&k);
  const double trace = c.trace();
  // largest ~ (l1 l2)^2 <= 1e-12 trace^4 when l1 <= 1e-6 l2 (a line), or no spread at all.
  if (!(largest > 1e-12 * trace * trace * trace * trace) || !std::isfinite(largest)) return std::nullopt;
  Eigen::Vector3d v = adj.col(k) / std::sqrt(largest);
  for (int step = 0; step < 2; ++step) v = (adj * v).normalized();
  if (!v.allFinite()) return std::nullopt;
  return v;
}

/// A voxel, or a supervoxel's centre: what the distance compares.
struct Feature {
  Eigen::Vector3f position = Eigen::Vector3f::Zero();
  Eigen::Vector3f colour = Eigen::Vector3f::Zero();
  Eigen::Vector3f normal = Eigen::Vector3f::Zero();  // unit, or zero (none)
};

struct Weights {
  float normal, colour, spatial, inv_seed;
  [[nodiscard]] float distance(const Feature& s, const Feature& v) const {
    return normal * (1.0f - std::abs(s.normal.dot(v.normal))) + colour * (s.colour - v.colour).norm() / 255.0f +
           spatial * (s.position - v.position).norm() * inv_seed;
  }
};

/// The voxels: features, cells and 26-neighbour lists (CSR).
struct Voxels {
  std::vector<Feature> features;
  std::vector<Eigen::Vector3i> cells;
  std::vector<int> first;       // neighbours of i: neighbours[first[i] .. first[i + 1])
  std::vector<int> neighbours;
  CellMap map;  // every occupied cell -> its voxel (two cells for a merged one)
  std::vector<std::pair<Eigen::Vector3i, int>> owners;  // every occupied cell and its voxel
  // Scratch, kept from frame to frame for its capacity.
  using Moments = Eigen::Matrix<double, 10, 1>;
  std::vector<int> points, fill, survivor, index;
  std::vector<char> paired;
  std::vector<std::vector<std::pair<int, int>>> pairs;  // found by each range of cells
  std::vector<Moments> own, ring;

  void build(const WorldCloud& cloud, float inv_voxel) {
    // Voxels in the order of their first point; points sharing a cell averaged.
    map.reset(cloud.points.size());
    features.clear();
    cells.clear();
    points.clear();  // per voxel
    for (std::size_t i = 0; i < cloud.points.size(); ++i) {
      const Eigen::Vector3i c = cell_of(cloud.points[i], inv_voxel);
      int& slot = map.find_or_insert(cell_key(c));
      if (slot < 0) {
        slot = static_cast<int>(features.size());
        features.push_back({cloud.points[i], cloud.colours[i], Eigen::Vector3f::Zero()});
        cells.push_back(c);
        points.push_back(1);
        continue;
      }
      Feature& f = features[static_cast<std::size_t>(slot)];
      f.position += cloud.points[i];
      f.colour += cloud.colours[i];
      ++points[static_cast<std::size_t>(slot)];
    }
    for (std::size_t i = 0; i < features.size(); ++i) {
      if (points[i] == 1) continue;
      features[i].position /= static_cast<float>(points[i]);
      features[i].colour /= static_cast<float>(points[i]);
    }
    merge_split_patches(1.0f / inv_voxel);
    const std::size_t n = features.size();
    // Half of the 26 offsets find each pair once, from every cell of a
    // voxel; the lists get both ends.
    static const std::array<Eigen::Vector3i, 13> kForward = [] {
      std::array<Eigen::Vector3i, 13> out;
      std::size_t k = 0;
      for (int dz = -1; dz <= 1; ++dz) {
        for (int dy = -1; dy <= 1; ++dy) {
          for (int dx = -1; dx <= 1; ++dx) {
            if (dz > 0 || (dz == 0 && (dy > 0 || (dy == 0 && dx > 0)))) out[k++] = Eigen::Vector3i(dx, dy, dz);
          }
        }
      }
      return out;
    }();
    // Each pair is found once per pair of their cells (ranges of cells in
    // parallel), counted, filled at both ends; then each list sorted
    // (ascending, the order growth offers them in, whatever order the pairs
    // came in) and its repeats (a joined voxel's two cells) dropped.
    collect_in_parallel(owners.size(), pairs, [&](std::size_t o, std::vector<std::pair<int, int>>& found) {
      const auto& [c, i] = owners[o];
      for (const Eigen::Vector3i& d : kForward) {
        const int j = map.find(cell_key(c + d));
        if (j >= 0 && j != i) found.emplace_back(i, j);
      }
    });
    first.assign(n + 1, 0);
    for (const auto& found : pairs) {
      for (const auto& [i, j] : found) {
        ++first[static_cast<std::size_t>(i) + 1];
        ++first[static_cast<std::size_t>(j) + 1];
      }
    }
    for (std::size_t i = 0; i < n; ++i) first[i + 1] += first[i];
    neighbours.resize(static_cast<std::size_t>(first[n]));
    fill.assign(first.begin(), first.end() - 1);
    for (const auto& found : pairs) {
      for (const auto& [i, j] : found) {
        neighbours[static_cast<std::size_t>(fill[static_cast<std::size_t>(i)]++)] = j;
        neighbours[static_cast<std::size_t>(fill[static_cast<std::size_t>(j)]++)] = i;
      }
    }
    for_each_index(n, 1024, [&](std::size_t i) {
      const auto begin = neighbours.begin() + first[i];
      const auto end = neighbours.begin() + first[i + 1];
      for (auto a = begin + 1; a < end; ++a) {  // insertion sort: a few tens at most
        const int x = *a;
        auto b = a;
        for (; b != begin && *(b - 1) > x; --b) *b = *(b - 1);
        *b = x;
      }
      fill[i] = static_cast<int>(std::unique(begin, end) - begin);  // the list's length
    });
    int kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const int from = first[i];
      first[i] = kept;
      for (int a = 0; a < fill[i]; ++a) neighbours[static_cast<std::size_t>(kept++)] = neighbours[static_cast<std::size_t>(from + a)];
    }
    first[n] = kept;
    neighbours.resize(static_cast<std::size_t>(kept));
  }

  /// A surface lying along a cell face (a cloth facing the camera at a
  /// cell's boundary) leaves its points on both sides of it, as its noise
  /// decides from frame to frame: two voxels, face neighbours, whose means
  /// are closer than 0.4 voxel across that face, where the surface elsewhere
  /// gives one. Each such pair becomes one voxel (the two means and colours
  /// averaged; both cells lead to it), so that a patch of surface counts
  /// once in what is taken over voxels (C, the axes, the supervoxels' sizes)
  /// wherever the grid cuts it. A surface crossing a column of cells at a
  /// slope s splits it into halves s / 2 apart: the pairs joined are those of
  /// surfaces within 39 degrees of the face; steeper ones (45 degrees and
  /// more) keep a voxel per cell. Halves of other colours are two surfaces
  /// touching, not one. A voxel joins at most one other.
  void merge_split_patches(float voxel) {
    // Two surfaces that touch (a finger on a case) differ in colour more than one surface's noise.
    constexpr float kSameColour = 25.0f;  // RGB distance, of 441 at most
    const std::size_t n = features.size();
    survivor.resize(n);  // the voxel each one becomes
    std::iota(survivor.begin(), survivor.end(), 0);
    paired.assign(n, 0);
    for (std::size_t i = 0; i < n; ++i) {
      for (int axis = 0; axis < 3 && !paired[i]; ++axis) {
        const int j = map.find(cell_key(cells[i] + Eigen::Vector3i::Unit(axis)));
        if (j < 0 || paired[static_cast<std::size_t>(j)]) continue;
        Feature& a = features[i];
        const Feature& b = features[static_cast<std::size_t>(j)];
        if (std::abs(a.position(axis) - b.position(axis)) >= 0.4f * voxel ||
            (a.colour - b.colour).norm() >= kSameColour) {
          continue;
        }
        a.position = 0.5f * (a.position + b.position);
        a.colour = 0.5f * (a.colour + b.colour);
        paired[i] = paired[static_cast<std::size_t>(j)] = 1;
        survivor[static_cast<std::size_t>(j)] = static_cast<int>(i);
      }
    }
    // Survivors keep their order; every cell leads to its voxel's new index.
    index.assign(n, -1);
    int kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (survivor[i] == static_cast<int>(i)) index[i] = kept++;
    }
    owners.clear();
    for (std::size_t i = 0; i < n; ++i) {
      const int to = index[static_cast<std::size_t>(survivor[i])];
      map.find_or_insert(cell_key(cells[i])) = to;
      owners.emplace_back(cells[i], to);
    }
    for (std::size_t i = 0; i < n; ++i) {  // in place: index[i] <= i
      if (index[i] < 0) continue;
      features[static_cast<std::size_t>(index[i])] = features[i];
      cells[static_cast<std::size_t>(index[i])] = cells[i];
    }
    features.resize(static_cast<std::size_t>(kept));
    cells.resize(static_cast<std::size_t>(kept));
  }

  /// True when more than `count` voxels (voxel i among them) lie within
  /// `radius` of voxel i; stops counting as soon as there are.
  [[nodiscard]] bool more_within(int i, float radius, float voxel, double count) const {
    const Feature& f = features[static_cast<std::size_t>(i)];
    const Eigen::Vector3i& c = cells[static_cast<std::size_t>(i)];
    const int reach = static_cast<int>(std::ceil(radius / voxel));
    int found = 1;
    if (found > count) return true;
    for (int dz = -reach; dz <= reach; ++dz) {
      for (int dy = -reach; dy <= reach; ++dy) {
        for (int dx = -reach; dx <= reach; ++dx) {
          if (dx == 0 && dy == 0 && dz == 0) continue;
          const int j = map.find(cell_key(c + Eigen::Vector3i(dx, dy, dz)));
          if (j >= 0 && j != i && (features[static_cast<std::size_t>(j)].position - f.position).norm() <= radius &&
              ++found > count) {
            return true;
          }
        }
      }
    }
    return false;
  }

  /// Step 2: each voxel's normal from its two rings of neighbours, counted
  /// as VCCS does: the voxel, each neighbour, and each neighbour's
  /// neighbours (a voxel once per path to it). Moments [1, x, y, z, xx, xy,
  /// xz, yy, yz, zz] summed over one ring, then over the ring of those sums.
  void compute_normals(const Eigen::Vector3f& camera) {
    const std::size_t n = features.size();
    if (n == 0) return;
    const Eigen::Vector3f origin = features[0].position;  // small numbers: no cancellation
    own.resize(n);
    ring.resize(n);
    // Each voxel's sums are its own: the three passes run over ranges of voxels in parallel.
    for_each_index(n, 512, [&](std::size_t i) {
      const Eigen::Vector3d p = (features[i].position - origin).cast<double>();
      own[i] << 1.0, p.x(), p.y(), p.z(), p.x() * p.x(), p.x() * p.y(), p.x() * p.z(), p.y() * p.y(),
          p.y() * p.z(), p.z() * p.z();
    });
    for_each_index(n, 512, [&](std::size_t i) {  // the voxel and its neighbours
      ring[i] = own[i];
      for (int a = first[i]; a < first[i + 1]; ++a) ring[i] += own[static_cast<std::size_t>(neighbours[static_cast<std::size_t>(a)])];
    });
    // The voxel, and for each neighbour: itself and its neighbours.
    for_each_index(n, 512, [&](std::size_t i) {
      Moments m = own[i];
      for (int a = first[i]; a < first[i + 1]; ++a) m += ring[static_cast<std::size_t>(neighbours[static_cast<std::size_t>(a)])];
      Feature& f = features[i];
      f.normal.setZero();
      if (m(0) < 3.0) return;
      const Eigen::Vector3d mean = m.segment<3>(1) / m(0);
      Eigen::Matrix3d covariance;
      covariance << m(4), m(5), m(6), m(5), m(7), m(8), m(6), m(8), m(9);
      covariance = covariance / m(0) - mean * mean.transpose();
      const std::optional<Eigen::Vector3d> axis = smallest_axis(covariance);
      if (!axis) return;
      Eigen::Vector3f normal = axis->cast<float>();
      if (normal.dot(camera - f.position) < 0.0f) normal = -normal;
      f.normal = normal;
    });
  }
};

/// A supervoxel while it grows.
struct Growing {
  Feature centre;
  std::vector<int> voxels;
};

}  // namespace

struct Vccs::Scratch {
  Voxels v;
  CellMap seed_cells;
  std::vector<int> candidates;  // per seed cell, its voxel so far
  std::vector<float> candidate_distance;
  std::vector<Growing> growing;
  std::vector<int> owner;
  std::vector<float> best;
  std::vector<int> taken, listed, offered, renumber, seen, touching;
};

Vccs::Vccs() : scratch_(std::make_unique<Scratch>()) {}
Vccs::~Vccs() = default;
Vccs::Vccs(Vccs&&) noexcept = default;
Vccs& Vccs::operator=(Vccs&&) noexcept = default;

void Vccs::run(const WorldCloud& cloud, const SupervoxelSettings& settings, const Eigen::Vector3d& camera,
               SupervoxelOutput& out) {
  out.clear();
  if (cloud.points.empty()) return;
  const auto voxel = static_cast<float>(settings.voxel_resolution);
  const auto seed = static_cast<float>(settings.seed_resolution);
  const Eigen::Vector3f eye = camera.cast<float>();

  auto& [v, seed_cells, candidates, candidate_distance, growing, owner, best, taken, listed, offered, renumber,
         seen, touching] = *scratch_;

  // 1-2. Voxels, neighbours, normals.
  v.build(cloud, 1.0f / voxel);
  v.compute_normals(eye);
  const std::size_t n = v.features.size();

  // 3. Seeds: per cell of edge R_seed, the voxel nearest its centre (the
  // first such voxel on a tie), cells in the order of their first voxel.
  seed_cells.reset(n);
  candidates.clear();
  candidate_distance.clear();
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3i c = cell_of(v.features[i].position, 1.0f / seed);
    const Eigen::Vector3f centre = (c.cast<float>() + Eigen::Vector3f::Constant(0.5f)) * seed;
    const float d = (v.features[i].position - centre).squaredNorm();
    int& slot = seed_cells.find_or_insert(cell_key(c));
    if (slot < 0) {
      slot = static_cast<int>(candidates.size());
      candidates.push_back(static_cast<int>(i));
      candidate_distance.push_back(d);
    } else if (d < candidate_distance[static_cast<std::size_t>(slot)]) {
      candidates[static_cast<std::size_t>(slot)] = static_cast<int>(i);
      candidate_distance[static_cast<std::size_t>(slot)] = d;
    }
  }
  const float search = 0.5f * seed;
  const double min_count = 0.05 * M_PI * static_cast<double>(search) * search / (static_cast<double>(voxel) * voxel);
  growing.clear();
  owner.assign(n, -1);
  best.assign(n, std::numeric_limits<float>::infinity());
  for (const int s : candidates) {
    if (!v.more_within(s, search, voxel, min_count)) continue;
    const Feature& f = v.features[static_cast<std::size_t>(s)];
    owner[static_cast<std::size_t>(s)] = static_cast<int>(growing.size());
    best[static_cast<std::size_t>(s)] = 0.0f;
    growing.push_back({f, {s}});
  }

  // 4. Growth.
  const Weights w{static_cast<float>(settings.normal_importance), static_cast<float>(settings.colour_importance),
                  static_cast<float>(settings.spatial_importance), 1.0f / seed};
  const int depth = static_cast<int>(1.8f * seed / voxel);
  listed.assign(n, 0);  // the last round whose compaction kept the voxel
  // A voxel a supervoxel's turn offered and did not take has the same
  // distance and best on its next offer in that turn: it is offered once.
  offered.assign(n, 0);
  int turn = 0;
  for (int round = 1; round < depth; ++round) {
    for (std::size_t s = 0; s < growing.size(); ++s) {
      Growing& g = growing[s];
      const int self = static_cast<int>(s);
      ++turn;
      taken.clear();
      for (const int i : g.voxels) {
        if (owner[static_cast<std::size_t>(i)] != self) continue;  // taken by another this round
        for (int a = v.first[static_cast<std::size_t>(i)]; a < v.first[static_cast<std::size_t>(i) + 1]; ++a) {
          const auto j = static_cast<std::size_t>(v.neighbours[static_cast<std::size_t>(a)]);
          if (owner[j] == self || offered[j] == turn) continue;
          offered[j] = turn;
          const float d = w.distance(g.centre, v.features[j]);
          if (d < best[j]) {
            best[j] = d;
            owner[j] = self;
            taken.push_back(static_cast<int>(j));
          }
        }
      }
      g.voxels.insert(g.voxels.end(), taken.begin(), taken.end());
    }
    // New centres; supervoxels left empty are dropped (their indices move).
    // A supervoxel's list keeps each voxel it owns once (one it lost and took
    // back this round is listed twice).
    renumber.assign(growing.size(), -1);
    std::size_t kept = 0;
    for (std::size_t s = 0; s < growing.size(); ++s) {
      Growing& g = growing[s];
      const int self = static_cast<int>(s);
      g.voxels.erase(std::remove_if(g.voxels.begin(), g.voxels.end(),
                                    [&](int i) {
                                      const auto k = static_cast<std::size_t>(i);
                                      if (owner[k] != self || listed[k] == round) return true;
                                      listed[k] = round;
                                      return false;
                                    }),
                     g.voxels.end());
      if (g.voxels.empty()) continue;
      Feature c;
      for (const int i : g.voxels) {
        const Feature& f = v.features[static_cast<std::size_t>(i)];
        c.position += f.position;
        c.colour += f.colour;
        c.normal += f.normal;
      }
      const float inv = 1.0f / static_cast<float>(g.voxels.size());
      c.position *= inv;
      c.colour *= inv;
      const float length = c.normal.norm();
      c.normal = length > 0.0f ? Eigen::Vector3f(c.normal / length) : Eigen::Vector3f::Zero();
      g.centre = c;
      renumber[s] = static_cast<int>(kept);
      if (kept != s) growing[kept] = std::move(g);
      ++kept;
    }
    growing.resize(kept);
    for (int& o : owner) {
      if (o >= 0) o = renumber[static_cast<std::size_t>(o)];
    }
  }

  // 5. Output.
  out.supervoxels.reserve(growing.size());
  out.voxels.reserve(n);
  out.colours.reserve(n);
  out.owner.reserve(n);
  for (std::size_t s = 0; s < growing.size(); ++s) {
    const Growing& g = growing[s];
    SupervoxelInfo info;
    info.centroid = g.centre.position.cast<double>();
    info.colour = g.centre.colour;
    info.voxel_count = static_cast<int>(g.voxels.size());
    Eigen::Vector3d normal = g.centre.normal.cast<double>();
    if (normal.norm() > 0.5) {
      if (normal.dot(camera - info.centroid) < 0.0) normal = -normal;
      info.normal = normal.normalized();
      info.normal_valid = true;
    } else {
      info.normal = (camera - info.centroid).normalized();
      info.normal_valid = false;
    }
    out.supervoxels.push_back(info);
    for (const int i : g.voxels) {
      out.voxels.push_back(v.features[static_cast<std::size_t>(i)].position);
      out.colours.push_back(v.features[static_cast<std::size_t>(i)].colour);
      out.owner.push_back(static_cast<int>(s));
    }
  }
  seen.assign(growing.size(), -1);  // the last supervoxel that listed this one
  for (std::size_t a = 0; a < growing.size(); ++a) {
    touching.clear();
    for (const int i : growing[a].voxels) {
      for (int k = v.first[static_cast<std::size_t>(i)]; k < v.first[static_cast<std::size_t>(i) + 1]; ++k) {
        const int b = owner[static_cast<std::size_t>(v.neighbours[static_cast<std::size_t>(k)])];
        if (b > static_cast<int>(a) && seen[static_cast<std::size_t>(b)] != static_cast<int>(a)) {
          seen[static_cast<std::size_t>(b)] = static_cast<int>(a);
          touching.push_back(b);
        }
      }
    }
    std::sort(touching.begin(), touching.end());
    for (const int b : touching) out.touching.emplace_back(static_cast<int>(a), b);
  }
}

void vccs_supervoxels(const WorldCloud& cloud, const SupervoxelSettings& settings, const Eigen::Vector3d& camera,
                      SupervoxelOutput& out) {
  Vccs().run(cloud, settings, camera, out);
}

}  // namespace ofv::perception::detail
