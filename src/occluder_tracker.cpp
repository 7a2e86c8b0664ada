// Occluder clusters followed by constant-velocity Kalman filters.
#include "ofv/occluder_tracker.h"

#include "ofv/settings_table.h"

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <numeric>
#include <optional>
#include <stdexcept>
#include <string>
#include <tuple>
#include <unordered_map>

namespace ofv {

namespace {

// Union-find with path halving.
int find_root(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    auto& p = parent[static_cast<std::size_t>(i)];
    p = parent[static_cast<std::size_t>(p)];
    i = p;
  }
  return i;
}

using Cell = std::array<std::int64_t, 3>;

struct CellHash {
  std::size_t operator()(const Cell& c) const noexcept {
    return std::hash<std::int64_t>{}((c[0] * 73856093) ^ (c[1] * 19349663) ^ (c[2] * 83492791));
  }
};

void require(bool ok, const char* name, double value, const char* what) {
  if (!ok) {
    throw std::invalid_argument(std::string("tracker setting '") + name + "' must be " + what + ", got " +
                                format_number(value));
  }
}

// Nearest of `points` to `q`: the smallest index of those at the least
// squared distance, as a scan of every point finds it, from a search that
// looks only at the points whose x is within that distance (`by_x`: the
// indices of `points` sorted by x). Returns the squared distance, or
// `within2` when no point is closer than that (then `nearest` is 0).
double nearest_by_x(const Eigen::Matrix3Xd& points, const std::vector<Eigen::Index>& by_x, const Eigen::Vector3d& q,
                    Eigen::Index& nearest, double within2 = std::numeric_limits<double>::infinity()) {
  double best = within2;
  nearest = 0;
  const auto first_right = std::lower_bound(by_x.begin(), by_x.end(), q.x(),
                                            [&](Eigen::Index i, double x) { return points(0, i) < x; });
  const auto consider = [&](Eigen::Index i) {
    const double dx = points(0, i) - q.x();
    if (dx * dx > best) return false;  // so is every point further along x
    const double d2 = (points.col(i) - q).squaredNorm();
    if (d2 < best || (d2 == best && i < nearest)) {
      best = d2;
      nearest = i;
    }
    return true;
  };
  for (auto it = first_right; it != by_x.end() && consider(*it); ++it) {
  }
  for (auto it = first_right; it != by_x.begin() && consider(*(it - 1)); --it) {
  }
  return best;
}

// The column indices of `points` sorted by x, for nearest_by_x.
std::vector<Eigen::Index> indices_by_x(const Eigen::Matrix3Xd& points) {
  std::vector<Eigen::Index> by_x(static_cast<std::size_t>(points.cols()));
  std::iota(by_x.begin(), by_x.end(), Eigen::Index{0});
  std::sort(by_x.begin(), by_x.end(), [&](Eigen::Index i, Eigen::Index j) { return points(0, i) < points(0, j); });
  return by_x;
}

// A translation taking last frame's points onto this frame's, and how well
// it fits: the fraction of the points tried that found a partner closer
// than the trim, and the root mean square distance of those pairs.
struct Registration {
  Eigen::Vector3d shift = Eigen::Vector3d::Zero();
  double overlap = 0.0;
  double rms = 0.0;
};

// Translation taking `before` onto `after`: a few iterations of
// translation-only ICP from `guess`, each matching every point of `after`
// (at most `max_points`, evenly spread) with its nearest neighbour in the shifted
// `before` and moving by the median residual (per axis) of the pairs closer
// than `trim`. The median ignores the points that appear or vanish at the
// edge of what is seen. None when fewer than half the points (or fewer than
// 3) find a partner: the shapes do not overlap enough to register.
std::optional<Registration> register_translation(const Eigen::Matrix3Xd& before, const std::vector<Eigen::Index>& by_x,
                                                 const Eigen::Matrix3Xd& after, const Eigen::Vector3d& guess,
                                                 double trim, std::size_t max_points) {
  const auto n_after = static_cast<std::size_t>(after.cols());
  const std::size_t stride = std::max<std::size_t>(1, n_after / max_points);
  const double trim2 = trim * trim;
  Eigen::Vector3d d = guess;
  std::array<std::vector<double>, 3> residuals;
  Registration result;
  for (int iteration = 0; iteration < 9; ++iteration) {
    for (auto& r : residuals) r.clear();
    int tried = 0;
    double sum2 = 0.0;
    for (std::size_t k = 0; k < n_after; k += stride, ++tried) {
      const Eigen::Vector3d q = after.col(static_cast<Eigen::Index>(k)) - d;
      Eigen::Index nearest = 0;
      const double best = nearest_by_x(before, by_x, q, nearest, trim2);
      if (best >= trim2) continue;
      sum2 += best;
      for (std::size_t a = 0; a < 3; ++a) residuals[a].push_back(q(static_cast<Eigen::Index>(a)) - before(static_cast<Eigen::Index>(a), nearest));
    }
    const auto pairs = static_cast<int>(residuals[0].size());
    if (pairs < 3 || 2 * pairs < tried) return std::nullopt;
    result.shift = d;
    result.overlap = static_cast<double>(pairs) / tried;
    result.rms = std::sqrt(sum2 / pairs);
    if (iteration == 8) break;  // the fit of the last step, measured
    Eigen::Vector3d step;
    for (std::size_t a = 0; a < 3; ++a) {
      auto& r = residuals[a];
      const auto mid = r.begin() + static_cast<std::ptrdiff_t>(r.size() / 2);
      std::nth_element(r.begin(), mid, r.end());
      step(static_cast<Eigen::Index>(a)) = *mid;
    }
    d += step;
    if (step.norm() < 1e-5) iteration = 7;  // converged: measure its fit
  }
  return result;
}

// The translation of an occluder from last frame's points to this frame's,
// registered from each of `starts`; of those that register, the best
// overlap wins, then (within 5 % of overlap) the smallest rms distance,
// then (within 20 % + 1 mm of it) the smallest motion. ICP keeps its start
// along the directions a shape cannot tell (a capsule whose ends are not
// seen, along its axis; a plane within itself; a grid by one spacing),
// where every start fits as well: what cannot be seen to move is taken
// as still (a stopped hand, a table, an arm growing into view would
// otherwise keep the motion of the start). When too few of this frame's
// points find last frame's (the part seen has grown: a table coming into
// view), last frame's points are registered onto this frame's instead.
std::optional<Eigen::Vector3d> track_motion(const Eigen::Matrix3Xd& before, const Eigen::Matrix3Xd& after,
                                            const std::vector<Eigen::Vector3d>& starts, double trim) {
  constexpr std::size_t kChoosePoints = 64;   // points tried from every start
  constexpr std::size_t kRefinePoints = 256;  // from the chosen one
  const auto best_of = [&](const Eigen::Matrix3Xd& from, const Eigen::Matrix3Xd& to, double sign)
      -> std::optional<Eigen::Vector3d> {
    const std::vector<Eigen::Index> by_x = indices_by_x(from);
    std::vector<Registration> found;
    for (std::size_t k = 0; k < starts.size(); ++k) {
      const bool repeated = std::any_of(starts.begin(), starts.begin() + static_cast<std::ptrdiff_t>(k),
                                        [&](const Eigen::Vector3d& s) { return (s - starts[k]).norm() < 0.005; });
      if (repeated) continue;
      if (auto r = register_translation(from, by_x, to, sign * starts[k], trim, kChoosePoints)) found.push_back(*r);
    }
    if (found.empty()) return std::nullopt;
    double overlap = 0.0;
    for (const auto& r : found) overlap = std::max(overlap, r.overlap);
    double rms = std::numeric_limits<double>::infinity();
    for (const auto& r : found) {
      if (r.overlap >= overlap - 0.05) rms = std::min(rms, r.rms);
    }
    std::optional<Eigen::Vector3d> chosen;
    for (const auto& r : found) {
      if (r.overlap < overlap - 0.05 || r.rms > 1.2 * rms + 1e-3) continue;
      if (!chosen || r.shift.norm() < chosen->norm()) chosen = r.shift;
    }
    if (!chosen) return std::nullopt;
    // Refined from the chosen start with more points.
    const auto refined = register_translation(from, by_x, to, *chosen, trim, kRefinePoints);
    return sign * (refined ? refined->shift : *chosen);
  };
  if (auto forward = best_of(before, after, 1.0)) return forward;
  return best_of(after, before, -1.0);
}

// The normal of a cluster that is a wide plane (a table): points spread
// more than `width` (standard deviation) along two axes and less than a
// tenth of that along the third. Such a plane's motion within itself cannot
// be seen (the aperture problem): what changes is only which part of it is
// seen (cut by the sphere, the image, the object's box), so only the motion
// along its normal is measured.
std::optional<Eigen::Vector3d> wide_plane_normal(const Eigen::Matrix3Xd& points, double width) {
  if (points.cols() < 3) return std::nullopt;
  const Eigen::Vector3d mean = points.rowwise().mean();
  const Eigen::Matrix3Xd centred = points.colwise() - mean;
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(centred * centred.transpose() /
                                                          static_cast<double>(points.cols()));
  const Eigen::Vector3d spread = eig.eigenvalues().cwiseMax(0.0).cwiseSqrt();  // increasing
  if (!(spread(1) > width && spread(0) < 0.1 * spread(1))) return std::nullopt;
  return Eigen::Vector3d(eig.eigenvectors().col(0));
}

// A wide plane (a table) and what touches it or comes within
// `link_distance` of it (a hand reaching down to it, an arm sweeping over
// it) make one cluster, and a wide plane's motion is measured only along
// its normal: the hand would be taken as still. Such a cluster is cut into
// the plane and the rest. The plane: a least-squares plane refitted three
// times to the points within `band` of the last (the plane has most of
// the points, so the first fit is near it); it must be a wide plane
// (wide_plane_normal) and hold kPlaneShare of the points. The rest is
// clustered again; parts of fewer than kMinPart points (a plane's ragged
// edge) stay with the plane.
void split_planes(std::vector<std::vector<int>>& clusters, const Eigen::Matrix3Xd& points, double link_distance) {
  constexpr std::size_t kMinCluster = 30;
  constexpr double kPlaneShare = 0.6;
  constexpr std::size_t kMinPart = 3;
  const double band = 0.3 * link_distance;
  const std::size_t n_clusters = clusters.size();
  for (std::size_t c = 0; c < n_clusters; ++c) {
    std::vector<int>& cluster = clusters[c];
    if (cluster.size() < kMinCluster) continue;
    std::vector<int> inside = cluster;
    for (int round = 0; round < 4 && inside.size() >= 3; ++round) {
      const Eigen::Matrix3Xd part = points(Eigen::all, inside);
      const Eigen::Vector3d mean = part.rowwise().mean();
      const Eigen::Matrix3Xd centred = part.colwise() - mean;
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(centred * centred.transpose());
      const Eigen::Vector3d normal = eig.eigenvectors().col(0);
      inside.clear();
      for (const int i : cluster) {
        if (std::abs(normal.dot(points.col(i) - mean)) <= band) inside.push_back(i);
      }
    }
    if (static_cast<double>(inside.size()) < kPlaneShare * static_cast<double>(cluster.size()) ||
        inside.size() == cluster.size() || !wide_plane_normal(points(Eigen::all, inside), 0.5 * link_distance)) {
      continue;
    }
    std::vector<int> rest;
    std::set_difference(cluster.begin(), cluster.end(), inside.begin(), inside.end(), std::back_inserter(rest));
    const Eigen::Matrix3Xd rest_points = points(Eigen::all, rest);
    std::vector<std::vector<int>> parts;
    for (const std::vector<int>& part : cluster_points(rest_points, link_distance)) {
      if (part.size() < kMinPart) {
        for (const int k : part) inside.push_back(rest[static_cast<std::size_t>(k)]);
        continue;
      }
      parts.emplace_back();
      for (const int k : part) parts.back().push_back(rest[static_cast<std::size_t>(k)]);
    }
    if (parts.empty()) continue;
    std::sort(inside.begin(), inside.end());
    cluster = std::move(inside);
    for (auto& part : parts) clusters.push_back(std::move(part));
  }
}

// The normal of each cluster whose motion is measured along it only: a
// wide plane (wide_plane_normal), or a piece of one, all of whose points
// lie within `band` of a wide plane of this frame (a table seen in pieces
// past the object, whose part in view changes as the camera moves: small,
// it would otherwise take that change for motion within the plane).
std::vector<std::optional<Eigen::Vector3d>> plane_normals(const std::vector<std::vector<int>>& clusters,
                                                          const Eigen::Matrix3Xd& points, double link_distance) {
  const double band = 0.3 * link_distance;
  std::vector<std::optional<Eigen::Vector3d>> normals;
  std::vector<std::pair<Eigen::Vector3d, double>> planes;  // normal, offset
  for (const std::vector<int>& c : clusters) {
    const Eigen::Matrix3Xd part = points(Eigen::all, c);
    normals.push_back(wide_plane_normal(part, 0.5 * link_distance));
    if (normals.back()) planes.emplace_back(*normals.back(), normals.back()->dot(part.rowwise().mean()));
  }
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    if (normals[c]) continue;
    for (const auto& plane : planes) {
      const bool on = std::all_of(clusters[c].begin(), clusters[c].end(), [&](int i) {
        return std::abs(plane.first.dot(points.col(i)) - plane.second) <= band;
      });
      if (on) {
        normals[c] = plane.first;
        break;
      }
    }
  }
  return normals;
}

// Clusters that join occluders followed apart until now (a hand reaching the
// table, two hands touching) are cut back into them, each part then owned by
// its track. Each point of such a cluster goes to the track of the nearest
// point of the tracks' predictions (the points seen last frame moved by the
// track's velocity); a track claims a cluster when at least kMinClaim of
// the cluster's points lie within `link` of its prediction, and a cluster
// claimed by two tracks or more is cut between those. `owner[k]`: the track
// of cluster k when it came from such a cut, else -1.
constexpr int kMinClaim = 3;

void split_merged(const std::vector<OccluderTrack>& tracks, double period, double link,
                  std::vector<std::vector<int>>& clusters, const Eigen::Matrix3Xd& points,
                  std::vector<int>& owner) {
  owner.assign(clusters.size(), -1);
  Eigen::Index total = 0;
  int seen = 0;
  for (const OccluderTrack& t : tracks) {
    total += t.points.cols();
    seen += t.points.cols() > 0 ? 1 : 0;
  }
  if (seen < 2) return;
  Eigen::Matrix3Xd predicted(3, total);
  std::vector<int> track_of(static_cast<std::size_t>(total));
  std::vector<Eigen::AlignedBox3d> box(tracks.size());  // of each prediction, grown by link
  Eigen::Index m = 0;
  for (std::size_t t = 0; t < tracks.size(); ++t) {
    const Eigen::Index n = tracks[t].points.cols();
    predicted.middleCols(m, n) = tracks[t].points.colwise() + period * tracks[t].velocity;
    std::fill_n(track_of.begin() + m, n, static_cast<int>(t));
    if (n > 0) {
      box[t] = Eigen::AlignedBox3d(predicted.middleCols(m, n).rowwise().minCoeff(),
                                   predicted.middleCols(m, n).rowwise().maxCoeff());
      box[t].extend(box[t].min() - Eigen::Vector3d::Constant(link)).extend(box[t].max() + Eigen::Vector3d::Constant(link));
    }
    m += n;
  }
  const std::vector<Eigen::Index> by_x = indices_by_x(predicted);
  const double link2 = link * link;
  const std::size_t n_clusters = clusters.size();
  for (std::size_t c = 0; c < n_clusters; ++c) {
    Eigen::AlignedBox3d extent;
    for (const int i : clusters[c]) extent.extend(Eigen::Vector3d(points.col(i)));
    if (std::count_if(box.begin(), box.end(), [&](const Eigen::AlignedBox3d& b) { return b.intersects(extent); }) < 2) {
      continue;  // no two predictions come near it
    }
    std::vector<int> nearest_track;  // per point of the cluster
    std::unordered_map<int, int> claims;
    nearest_track.reserve(clusters[c].size());
    for (const int i : clusters[c]) {
      Eigen::Index nearest = 0;
      const double d2 = nearest_by_x(predicted, by_x, points.col(i), nearest);
      const int t = track_of[static_cast<std::size_t>(nearest)];
      nearest_track.push_back(t);
      if (d2 < link2) ++claims[t];
    }
    std::vector<int> claimants;
    for (const auto& [t, n] : claims) {
      if (n >= kMinClaim) claimants.push_back(t);
    }
    if (claimants.size() < 2) continue;
    std::sort(claimants.begin(), claimants.end());
    const auto claimant = [&](int t) {
      const auto it = std::lower_bound(claimants.begin(), claimants.end(), t);
      return it != claimants.end() && *it == t ? it - claimants.begin() : -1;
    };
    // A point whose nearest track does not claim the cluster goes to the
    // nearest of the claimants' predicted points (searched in those alone).
    std::vector<Eigen::Index> claimed_by_x;
    std::vector<std::vector<int>> parts(claimants.size());
    for (std::size_t k = 0; k < clusters[c].size(); ++k) {
      const int i = clusters[c][k];
      auto part = claimant(nearest_track[k]);
      if (part < 0) {
        if (claimed_by_x.empty()) {
          std::copy_if(by_x.begin(), by_x.end(), std::back_inserter(claimed_by_x),
                       [&](Eigen::Index j) { return claimant(track_of[static_cast<std::size_t>(j)]) >= 0; });
        }
        Eigen::Index nearest = 0;
        nearest_by_x(predicted, claimed_by_x, points.col(i), nearest);
        part = claimant(track_of[static_cast<std::size_t>(nearest)]);
      }
      parts[static_cast<std::size_t>(part)].push_back(i);
    }
    bool first = true;
    for (std::size_t k = 0; k < claimants.size(); ++k) {
      if (parts[k].empty()) continue;
      if (first) {
        clusters[c] = std::move(parts[k]);
        owner[c] = claimants[k];
        first = false;
      } else {
        clusters.push_back(std::move(parts[k]));
        owner.push_back(claimants[k]);
      }
    }
  }
}

}  // namespace

void validate(const TrackerSettings& s) {
  require(std::isfinite(s.link_distance) && s.link_distance > 0.0 && s.link_distance <= 1.0, "link_distance",
          s.link_distance, "in (0, 1] m");
  require(std::isfinite(s.gate) && s.gate > 0.0 && s.gate <= 10.0, "gate", s.gate, "in (0, 10] m");
  require(std::isfinite(s.accel_noise) && s.accel_noise > 0.0 && s.accel_noise <= 1000.0, "accel_noise",
          s.accel_noise, "in (0, 1000] m/s^2");
  require(std::isfinite(s.measurement_noise) && s.measurement_noise > 0.0 && s.measurement_noise <= 1.0,
          "measurement_noise", s.measurement_noise, "in (0, 1] m");
  require(std::isfinite(s.initial_speed_sigma) && s.initial_speed_sigma > 0.0 && s.initial_speed_sigma <= 100.0,
          "initial_speed_sigma", s.initial_speed_sigma, "in (0, 100] m/s");
  require(s.confirm_hits >= 1 && s.confirm_hits <= 1000, "confirm_hits", s.confirm_hits, "in [1, 1000]");
  require(s.max_misses >= 0 && s.max_misses <= 1000, "max_misses", s.max_misses, "in [0, 1000]");
}

double OccluderTrack::position_sigma() const { return std::sqrt(std::max(0.0, covariance(0, 0))); }
double OccluderTrack::speed_sigma() const { return std::sqrt(std::max(0.0, covariance(1, 1))); }

std::vector<std::vector<int>> cluster_points(const Eigen::Matrix3Xd& points, double link_distance) {
  const int n = static_cast<int>(points.cols());
  std::vector<int> parent(static_cast<std::size_t>(n));
  std::iota(parent.begin(), parent.end(), 0);
  const auto unite = [&](int i, int j) {
    const int ri = find_root(parent, i);
    const int rj = find_root(parent, j);
    if (ri != rj) parent[static_cast<std::size_t>(std::max(ri, rj))] = std::min(ri, rj);
  };
  // Grid of cell edge link_distance / 2. Two points of one cell are
  // closer than link_distance (the cell's diagonal is 0.87 of it), so a cell
  // is linked whole; linked points are at most two cells apart along each
  // axis, and two cells need one linked pair, looked for only while they
  // are not yet in one cluster. The clusters are those of linking every
  // pair closer than link_distance. Points too far out for a cell index
  // (2^52 edges) are compared with every point.
  const double edge = 0.5 * link_distance;
  const double link2 = link_distance * link_distance;
  const auto close = [&](int i, int j) { return (points.col(i) - points.col(j)).squaredNorm() < link2; };
  std::vector<Cell> cell_of(static_cast<std::size_t>(n));
  std::vector<int> far;
  std::vector<char> finite(static_cast<std::size_t>(n), 0);  // 1: finite, 2: finite and in a cell
  Cell low{}, high{};
  bool any = false;
  for (int i = 0; i < n; ++i) {
    if (!points.col(i).allFinite()) continue;
    finite[static_cast<std::size_t>(i)] = 1;
    const Eigen::Vector3d index = (points.col(i) / edge).array().floor();
    if (!(index.cwiseAbs().maxCoeff() < 0x1p52)) {
      far.push_back(i);
      continue;
    }
    finite[static_cast<std::size_t>(i)] = 2;
    Cell& c = cell_of[static_cast<std::size_t>(i)];
    for (std::size_t a = 0; a < 3; ++a) {
      c[a] = static_cast<std::int64_t>(index(static_cast<Eigen::Index>(a)));
      low[a] = any ? std::min(low[a], c[a]) : c[a];
      high[a] = any ? std::max(high[a], c[a]) : c[a];
    }
    any = true;
  }
  // Cell ids in order of their first point: a dense table over the points'
  // box (padded by the two neighbouring cells) where it is small, a hash
  // map otherwise.
  constexpr std::int64_t kDenseCells = std::int64_t{1} << 22;
  std::array<std::int64_t, 3> size{};
  std::int64_t volume = 1;
  for (std::size_t a = 0; a < 3 && any; ++a) {
    size[a] = high[a] - low[a] + 5;
    volume = size[a] > kDenseCells ? kDenseCells + 1 : std::min(kDenseCells + 1, volume * size[a]);
  }
  const bool dense = any && volume <= kDenseCells;
  std::vector<int> dense_id(dense ? static_cast<std::size_t>(volume) : 0, -1);
  std::unordered_map<Cell, int, CellHash> hashed_id;
  const auto slot = [&](const Cell& c) -> int* {
    if (!dense) {
      const auto it = hashed_id.find(c);
      return it == hashed_id.end() ? nullptr : &it->second;
    }
    std::int64_t k = 0;
    for (std::size_t a = 0; a < 3; ++a) k = k * size[a] + (c[a] - low[a] + 2);
    return &dense_id[static_cast<std::size_t>(k)];
  };
  std::vector<Cell> cells;
  std::vector<std::vector<int>> members;
  for (int i = 0; i < n; ++i) {
    if (finite[static_cast<std::size_t>(i)] != 2) continue;  // not finite, or far
    const Cell& c = cell_of[static_cast<std::size_t>(i)];
    int* id = slot(c);
    if (id == nullptr) id = &hashed_id.emplace(c, -1).first->second;
    if (*id < 0) {
      *id = static_cast<int>(cells.size());
      cells.push_back(c);
      members.emplace_back();
    } else {
      unite(members[static_cast<std::size_t>(*id)].front(), i);
    }
    members[static_cast<std::size_t>(*id)].push_back(i);
  }
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const Cell& c = cells[k];
    const std::vector<int>& here = members[k];
    for (std::int64_t dx = -2; dx <= 2; ++dx) {
      for (std::int64_t dy = -2; dy <= 2; ++dy) {
        for (std::int64_t dz = -2; dz <= 2; ++dz) {
          const Cell other{c[0] + dx, c[1] + dy, c[2] + dz};
          if (other <= c) continue;  // each pair of cells once
          const int* id = slot(other);
          if (id == nullptr || *id < 0) continue;
          const std::vector<int>& there = members[static_cast<std::size_t>(*id)];
          if (find_root(parent, here.front()) == find_root(parent, there.front())) continue;
          const auto linked = [&] {
            for (const int i : here) {
              for (const int j : there) {
                if (close(i, j)) return true;
              }
            }
            return false;
          };
          if (linked()) unite(here.front(), there.front());
        }
      }
    }
  }
  for (const int i : far) {
    for (int j = 0; j < n; ++j) {
      if (j != i && finite[static_cast<std::size_t>(j)] && close(i, j)) unite(i, j);
    }
  }
  // Roots are each cluster's smallest index, so clusters come in order of their first point.
  std::vector<std::vector<int>> clusters;
  std::vector<int> index_of_root(static_cast<std::size_t>(n), -1);
  for (int i = 0; i < n; ++i) {
    if (!finite[static_cast<std::size_t>(i)]) continue;
    const int r = find_root(parent, i);
    int& k = index_of_root[static_cast<std::size_t>(r)];
    if (k < 0) {
      k = static_cast<int>(clusters.size());
      clusters.emplace_back();
    }
    clusters[static_cast<std::size_t>(k)].push_back(i);
  }
  return clusters;
}

OccluderTracker::OccluderTracker(const TrackerSettings& settings) : settings_(settings) { validate(settings_); }

void OccluderTracker::reset() {
  tracks_.clear();
  next_id_ = 0;
  started_ = false;
}

void OccluderTracker::predict(double dt) {
  // x' = F x, P' = F P F^T + Q with F = [1 dt; 0 1] and the discrete
  // white-noise acceleration Q = q [dt^4/4 dt^3/2; dt^3/2 dt^2], q = accel_noise^2.
  Eigen::Matrix2d f;
  f << 1.0, dt, 0.0, 1.0;
  const double q = settings_.accel_noise * settings_.accel_noise;
  Eigen::Matrix2d noise;
  noise << 0.25 * dt * dt * dt * dt, 0.5 * dt * dt * dt, 0.5 * dt * dt * dt, dt * dt;
  for (OccluderTrack& t : tracks_) {
    t.position += dt * t.velocity;
    t.covariance = f * t.covariance * f.transpose() + q * noise;
    t.centroid += dt * t.velocity;
  }
}

const std::vector<OccluderTrack>& OccluderTracker::coast(double dt) {
  return update(Eigen::Matrix3Xd(3, 0), dt);
}

const std::vector<OccluderTrack>& OccluderTracker::update(const Eigen::Matrix3Xd& occluders, double dt) {
  double period = 0.0;
  if (started_) {
    period = dt;
    if (!(std::isfinite(dt) && dt > 0.0)) {
      throw std::invalid_argument("occluder tracker: time since the previous frame must be positive, got " +
                                  format_number(dt));
    }
    predict(dt);
  }
  started_ = true;

  std::vector<std::vector<int>> clusters = cluster_points(occluders, settings_.link_distance);
  split_planes(clusters, occluders, settings_.link_distance);
  std::vector<int> owner;
  split_merged(tracks_, period, settings_.link_distance, clusters, occluders, owner);
  const std::vector<std::optional<Eigen::Vector3d>> normals = plane_normals(clusters, occluders, settings_.link_distance);
  std::vector<Eigen::Vector3d> centroids;
  centroids.reserve(clusters.size());
  for (const auto& c : clusters) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    for (const int i : c) sum += occluders.col(i);
    centroids.emplace_back(sum / static_cast<double>(c.size()));
  }

  // The parts of a cut cluster go to their tracks; then greedy association,
  // nearest pair first, within the gate.
  std::vector<int> cluster_of(tracks_.size(), -1);
  std::vector<char> used(centroids.size(), 0);
  for (std::size_t c = 0; c < owner.size(); ++c) {
    if (owner[c] < 0) continue;
    cluster_of[static_cast<std::size_t>(owner[c])] = static_cast<int>(c);
    used[c] = 1;
  }
  std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    const double gate = settings_.gate;
    for (std::size_t c = 0; c < centroids.size(); ++c) {
      const double d = (centroids[c] - tracks_[t].centroid).norm();
      if (d < gate) pairs.emplace_back(d, t, c);
    }
  }
  std::sort(pairs.begin(), pairs.end());
  for (const auto& [d, t, c] : pairs) {
    if (cluster_of[t] >= 0 || used[c]) continue;
    cluster_of[t] = static_cast<int>(c);
    used[c] = 1;
  }

  // Measurement update: H = [1 0], R = measurement_noise^2.
  const double r = settings_.measurement_noise * settings_.measurement_noise;
  std::vector<OccluderTrack> kept;
  for (std::size_t t = 0; t < tracks_.size(); ++t) {
    OccluderTrack& track = tracks_[t];
    if (cluster_of[t] < 0) {
      track.points.resize(3, 0);
      if (++track.misses <= settings_.max_misses) kept.push_back(std::move(track));
      continue;
    }
    const auto c = static_cast<std::size_t>(cluster_of[t]);
    // The measurement: where the points seen last frame have moved to
    // (registration), not the centroid, which also moves when the visible
    // part of an occluder changes (entering the sphere, the camera moving).
    // The registration starts from the predicted motion, from none, and
    // from the centroid's (before the track has a velocity, points about
    // one spacing apart would otherwise register one spacing short:
    // aliasing); see track_motion. A track missed last frame has no points:
    // the centroid's offset from its prediction stands for the position's.
    const Eigen::Matrix3Xd now = occluders(Eigen::all, clusters[c]);
    std::optional<Eigen::Vector3d> moved;
    const std::optional<Eigen::Vector3d>& plane = normals[c];
    bool registered = true;
    if (track.points.cols() > 0) {
      // A wide plane, or a piece of one, registers from no motion alone:
      // only the motion along its normal counts.
      const Eigen::Vector3d centroid_shift = centroids[c] - (track.centroid - period * track.velocity);
      std::vector<Eigen::Vector3d> starts{Eigen::Vector3d::Zero()};
      if (!plane) starts.insert(starts.end(), {period * track.velocity, centroid_shift});
      moved = track_motion(track.points, now, starts, settings_.link_distance);
      registered = moved.has_value();
      if (moved && plane) moved = plane->dot(*moved) * *plane;
    }
    if (!registered) {
      // The shapes do not overlap either way (the occluder turned, or the
      // part seen changed whole): its motion is unknown, and the centroid's
      // jump is none. The track starts again here, with its id.
      track.position = track.centroid = centroids[c];
      track.velocity.setZero();
      track.covariance << r, 0.0, 0.0, settings_.initial_speed_sigma * settings_.initial_speed_sigma;
      track.points = now;
      track.hits = 1;
      track.misses = 0;
      kept.push_back(std::move(track));
      continue;
    }
    const Eigen::Vector3d measured = moved ? Eigen::Vector3d(track.position - period * track.velocity + *moved)
                                           : Eigen::Vector3d(track.position + centroids[c] - track.centroid);
    track.centroid = centroids[c];
    const Eigen::Vector2d gain = track.covariance.col(0) / (track.covariance(0, 0) + r);
    const Eigen::Vector3d innovation = measured - track.position;
    track.position += gain(0) * innovation;
    track.velocity += gain(1) * innovation;
    const Eigen::Matrix2d i_kh = Eigen::Matrix2d::Identity() - gain * Eigen::RowVector2d(1.0, 0.0);
    track.covariance = i_kh * track.covariance;
    track.covariance = 0.5 * (track.covariance + track.covariance.transpose()).eval();
    // A plane's motion within itself is not seen: none, not what the track
    // had before (a piece of table seen in a frame without the rest of it,
    // then joined by the rest).
    if (plane) track.velocity = plane->dot(track.velocity) * *plane;
    track.points = now;
    ++track.hits;
    track.misses = 0;
    track.confirmed = track.confirmed || track.hits >= settings_.confirm_hits;
    kept.push_back(std::move(track));
  }
  for (std::size_t c = 0; c < centroids.size(); ++c) {
    if (used[c]) continue;
    OccluderTrack track;
    track.id = next_id_++;
    track.position = track.centroid = centroids[c];
    track.covariance << r, 0.0, 0.0, settings_.initial_speed_sigma * settings_.initial_speed_sigma;
    track.points = occluders(Eigen::all, clusters[c]);
    track.hits = 1;
    track.confirmed = settings_.confirm_hits <= 1;
    kept.push_back(std::move(track));
  }
  std::sort(kept.begin(), kept.end(), [](const OccluderTrack& a, const OccluderTrack& b) { return a.id < b.id; });
  tracks_ = std::move(kept);
  return tracks_;
}

bool is_moving(const OccluderTrack& track, double min_speed) {
  return track.confirmed && track.points.cols() > 0 && track.velocity.norm() > min_speed;
}

Eigen::Matrix3Xd predicted_occluders(const std::vector<OccluderTrack>& tracks, const std::vector<double>& times,
                                     double min_speed) {
  Eigen::Index count = 0;
  for (const OccluderTrack& t : tracks) {
    count += is_moving(t, min_speed) ? t.points.cols() * static_cast<Eigen::Index>(times.size()) : 0;
  }
  Eigen::Matrix3Xd out(3, count);
  Eigen::Index k = 0;
  for (const OccluderTrack& t : tracks) {
    if (!is_moving(t, min_speed)) continue;
    for (const double tau : times) {
      out.middleCols(k, t.points.cols()) = t.points.colwise() + tau * t.velocity;
      k += t.points.cols();
    }
  }
  return out;
}

bool is_still(const OccluderTrack& track, double min_speed) {
  return track.confirmed && track.points.cols() > 0 && !(track.velocity.norm() > min_speed);
}

Eigen::Matrix3Xd still_occluders(const std::vector<OccluderTrack>& tracks, double min_speed) {
  Eigen::Index count = 0;
  for (const OccluderTrack& t : tracks) count += is_still(t, min_speed) ? t.points.cols() : 0;
  Eigen::Matrix3Xd out(3, count);
  Eigen::Index k = 0;
  for (const OccluderTrack& t : tracks) {
    if (!is_still(t, min_speed)) continue;
    out.middleCols(k, t.points.cols()) = t.points;
    k += t.points.cols();
  }
  return out;
}

}  // namespace ofv
