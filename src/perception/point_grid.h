// Internal: points hashed on a uniform grid, for the neighbour queries of the
// adjacency graph and of tracking.
#pragma once

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace ofv::perception::detail {

/// A grid cell's key from its indices: 21 bits per axis (+-8 km at 8 mm cells).
inline std::uint64_t cell_key(std::int64_t x, std::int64_t y, std::int64_t z) {
  const auto k = [](std::int64_t i) { return static_cast<std::uint64_t>(i + (std::int64_t{1} << 20)) & 0x1FFFFFu; };
  return k(x) | (k(y) << 21) | (k(z) << 42);
}
inline std::uint64_t cell_key(const Eigen::Vector3i& c) { return cell_key(c.x(), c.y(), c.z()); }
/// The indices of the cell of edge 1 / inv_edge that holds p (within 32 bits
/// for the front end's settings: voxel_resolution >= 0.1 mm, max_depth <= 1e4 m).
inline Eigen::Vector3i cell_of(const Eigen::Vector3f& p, float inv_edge) {
  return (p * inv_edge).array().floor().cast<int>();
}
/// The key of the cell of edge 1 / inv_edge that holds p (through 64-bit
/// integers: no voxel size overflows the conversion).
inline std::uint64_t cell_key(const Eigen::Vector3f& p, float inv_edge) {
  const auto index = [inv_edge](float x) { return static_cast<std::int64_t>(std::floor(x * inv_edge)); };
  return cell_key(index(p.x()), index(p.y()), index(p.z()));
}

/// Cells (keys of cell_key()) to indices: open addressing, linear probing
/// (a key and its index share a cache line); doubles when half full.
class CellMap {
 public:
  /// Empties the map, sized for `count` keys (it grows past them).
  void reset(std::size_t count) {
    std::size_t size = 16;
    int bits = 4;
    for (; size < 2 * count; ++bits) size *= 2;
    mask_ = size - 1;
    shift_ = 64 - bits;
    slots_.assign(size, Slot{});
    size_ = 0;
  }
  /// The index stored for `key`, to be set by the caller when it is new (-1).
  /// The reference holds until the next insertion.
  int& find_or_insert(std::uint64_t key) {
    if (2 * (size_ + 1) > slots_.size()) grow();
    std::size_t i = slot(key);
    while (slots_[i].key != key && slots_[i].key != kEmpty) i = (i + 1) & mask_;
    if (slots_[i].key == kEmpty) {
      slots_[i].key = key;
      ++size_;
    }
    return slots_[i].value;
  }
  /// The index stored for `key`, or -1.
  [[nodiscard]] int find(std::uint64_t key) const {
    if (slots_.empty()) return -1;
    for (std::size_t i = slot(key);; i = (i + 1) & mask_) {
      if (slots_[i].key == key) return slots_[i].value;
      if (slots_[i].key == kEmpty) return -1;
    }
  }

 private:
  static constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // never a cell_key (63 bits)
  struct Slot {
    std::uint64_t key = kEmpty;
    int value = -1;
  };
  // Fibonacci hashing: the product's top bits depend on all of the key's (z too).
  [[nodiscard]] std::size_t slot(std::uint64_t key) const {
    return static_cast<std::size_t>((key * 0x9E3779B97F4A7C15ull) >> shift_);
  }
  void grow() {
    const std::vector<Slot> old = std::move(slots_);
    reset(std::max<std::size_t>(old.size(), 8));  // twice the slots
    for (const Slot& s : old) {
      if (s.key != kEmpty) find_or_insert(s.key) = s.value;
    }
  }
  std::size_t mask_ = 0;
  int shift_ = 64;
  std::size_t size_ = 0;  // keys stored
  std::vector<Slot> slots_;
};

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
    first_.reset(entries_.size());
    for (std::size_t i = 0; i < entries_.size(); ++i) {
      if (i == 0 || entries_[i].key != entries_[i - 1].key) first_.find_or_insert(entries_[i].key) = static_cast<int>(i);
    }
  }

  /// True if a point j within `radius` (<= the cell size) of p has accept(j)
  /// (without side effects: the search stops at the first such point, p's
  /// own cell first).
  template <typename Accept>
  [[nodiscard]] bool any_within(const Eigen::Vector3f& p, float radius, Accept&& accept) const {
    const float r2 = radius * radius;
    const Eigen::Vector3i c = cell_of(p);
    const auto in_cell = [&](const Eigen::Vector3i& cell) {
      const std::uint64_t k = key(cell);
      const int first = first_.find(k);
      if (first < 0) return false;
      for (auto i = static_cast<std::size_t>(first); i < entries_.size() && entries_[i].key == k; ++i) {
        const int j = entries_[i].index;
        if (((*points_)[static_cast<std::size_t>(j)] - p).squaredNorm() <= r2 && accept(j)) return true;
      }
      return false;
    };
    if (in_cell(c)) return true;
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          if ((dx != 0 || dy != 0 || dz != 0) && in_cell(c + Eigen::Vector3i(dx, dy, dz))) return true;
        }
      }
    }
    return false;
  }

  /// Calls f(j) for every point j within the 27 cells around p.
  template <typename F>
  void for_each_near(const Eigen::Vector3f& p, F&& f) const {
    const Eigen::Vector3i c = cell_of(p);
    for (int dz = -1; dz <= 1; ++dz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const std::uint64_t k = key(c + Eigen::Vector3i(dx, dy, dz));
          const int first = first_.find(k);
          if (first < 0) continue;
          for (auto i = static_cast<std::size_t>(first); i < entries_.size() && entries_[i].key == k; ++i) {
            f(entries_[i].index);
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
  [[nodiscard]] Eigen::Vector3i cell_of(const Eigen::Vector3f& p) const { return detail::cell_of(p, inv_cell_); }
  static std::uint64_t key(const Eigen::Vector3i& c) { return cell_key(c); }
  float inv_cell_ = 1.0f;
  std::vector<Entry> entries_;  // sorted by key
  CellMap first_;               // key -> its first entry
  const std::vector<Eigen::Vector3f>* points_ = nullptr;
};

}  // namespace ofv::perception::detail
