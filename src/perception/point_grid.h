// Internal: points hashed on a uniform grid, for the neighbour queries of the
// adjacency graph and of tracking.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cstdint>
#include <vector>

namespace ofv::perception::detail {

/// A grid cell's key: 21 bits per axis (+-8 km at 8 mm cells).
inline std::uint64_t cell_key(const Eigen::Vector3i& c) {
  const auto k = [](int x) {
    return static_cast<std::uint64_t>(static_cast<std::int64_t>(x) + (std::int64_t{1} << 20)) & 0x1FFFFFu;
  };
  return k(c.x()) | (k(c.y()) << 21) | (k(c.z()) << 42);
}

/// Points hashed on a uniform grid: "is any point within r of p" in O(1).
class PointGrid {
 public:
  /// Hashes `points` (kept by reference: they must outlive the queries) on
  /// cells of edge `cell` [m].
  void build(const std::vector<Eigen::Vector3f>& points, double cell) {
    inv_cell_ = static_cast<float>(1.0 / cell);
    entries_.clear();
    entries_.reserve(points.size());
    points_ = &points;
    for (std::size_t i = 0; i < points.size(); ++i) {
      entries_.push_back({key(cell_of(points[i])), static_cast<int>(i)});
    }
    std::sort(entries_.begin(), entries_.end(),
              [](const Entry& a, const Entry& b) { return a.key < b.key; });
  }

  /// True if a point j within `radius` (<= the cell size) of p has accept(j).
  template <typename Accept>
  [[nodiscard]] bool any_within(const Eigen::Vector3f& p, float radius, Accept&& accept) const {
    const float r2 = radius * radius;
    bool found = false;
    for_each_near(p, [&](int j) {
      found =
          found || (((*points_)[static_cast<std::size_t>(j)] - p).squaredNorm() <= r2 && accept(j));
    });
    return found;
  }

  /// Calls f(j) for every point j within the 27 cells around p.
  template <typename F>
  void for_each_near(const Eigen::Vector3f& p, F&& f) const {
    const Eigen::Vector3i c = cell_of(p);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint64_t k = key(c + Eigen::Vector3i(dx, dy, dz));
          auto it =
              std::lower_bound(entries_.begin(), entries_.end(), k,
                               [](const Entry& e, std::uint64_t value) { return e.key < value; });
          for (; it != entries_.end() && it->key == k; ++it) {
            f(it->index);
          }
        }
      }
    }
  }

 private:
  struct Entry {
    std::uint64_t key;
    int index;
  };
  [[nodiscard]] Eigen::Vector3i cell_of(const Eigen::Vector3f& p) const {
    return (p * inv_cell_).array().floor().cast<int>();
  }
  static std::uint64_t key(const Eigen::Vector3i& c) { return cell_key(c); }
  float inv_cell_ = 1.0f;
  std::vector<Entry> entries_;
  const std::vector<Eigen::Vector3f>* points_ = nullptr;
};

}  // namespace ofv::perception::detail
