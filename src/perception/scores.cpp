// Perception scores against a frame's ground-truth labels (scores.h).
#include "ofv/perception/scores.h"

#include "ofv/perception/cloud.h"
#include "parallel.h"
#include "point_grid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

namespace ofv::perception {

namespace {

std::optional<double> ratio(std::size_t part, std::size_t whole) {
  if (whole == 0) return std::nullopt;
  return static_cast<double>(part) / static_cast<double>(whole);
}

bool is_occluder(std::uint16_t label) { return label >= kPixelOccluder0; }

// Distance from p to the nearest of `samples` (hashed in `grid`, cells of
// `cell`); the whole set when none is within the 27 cells around p.
double nearest_distance(const detail::PointGrid& grid, const std::vector<Eigen::Vector3f>& samples,
                        const Eigen::Vector3f& p) {
  float best = std::numeric_limits<float>::infinity();
  grid.for_each_near(p, [&](int j) { best = std::min(best, (samples[static_cast<std::size_t>(j)] - p).squaredNorm()); });
  if (!std::isfinite(best)) {
    for (const Eigen::Vector3f& s : samples) best = std::min(best, (s - p).squaredNorm());
  }
  return std::sqrt(static_cast<double>(best));
}

}  // namespace

struct VoxelLabels::Index {
  detail::CellMap cells;
};

VoxelLabels::VoxelLabels(const RgbdFrame& frame, double voxel, int stride, double max_depth) {
  check_frame(frame);
  if (frame.labels.empty()) {
    throw std::invalid_argument("perception scores: the frame has no labels (only the simulator and ofv's "
                                "own recordings carry them)");
  }
  if (!(voxel > 0.0) || stride < 1) {
    throw std::invalid_argument("voxel labels: voxel " + std::to_string(voxel) + " m and stride " +
                                std::to_string(stride) + ": expected a positive voxel and a stride >= 1");
  }
  inv_voxel_ = static_cast<float>(1.0 / voxel);
  const CameraIntrinsics& k = frame.intrinsics;
  const Eigen::Matrix3f wRc = frame.wMc.linear().cast<float>();
  const Eigen::Vector3f wtc = frame.wMc.translation().cast<float>();
  auto index = std::make_shared<Index>();
  index->cells.reset(frame.depth.size() / static_cast<std::size_t>(stride * stride * 8));
  // Votes per cell: (label, count), the first kInline in place (a cell
  // shows one or two labels), any more in `more`.
  constexpr int kInline = 4;
  struct Votes {
    std::array<std::pair<std::uint16_t, int>, kInline> inline_votes{};
    int size = 0;
  };
  std::vector<Votes> votes;
  std::unordered_map<std::size_t, std::vector<std::pair<std::uint16_t, int>>> more;
  std::vector<int> counts;
  // Each sampled pixel's point and cell, the rows in parallel; then the
  // votes in the pixels' order (the cells' sums as one loop would add them).
  const int rows = (k.height + stride - 1) / stride, columns = (k.width + stride - 1) / stride;
  constexpr std::uint64_t kNoPoint = ~std::uint64_t{0};
  // Scratch kept by the calling thread (a frame's worth of pages each call
  // otherwise; the workers below use the caller's, through these
  // references), and each column's and row's ray slope, made once.
  thread_local std::vector<std::uint64_t> keys_scratch;
  thread_local std::vector<Eigen::Vector3f> points_scratch;
  thread_local std::vector<float> slope_x_scratch, slope_y_scratch;
  std::vector<std::uint64_t>& keys = keys_scratch;
  std::vector<Eigen::Vector3f>& points = points_scratch;
  std::vector<float>& slope_x = slope_x_scratch;
  std::vector<float>& slope_y = slope_y_scratch;
  keys.assign(static_cast<std::size_t>(rows) * static_cast<std::size_t>(columns), kNoPoint);
  points.resize(keys.size());
  slope_x.resize(static_cast<std::size_t>(columns));
  slope_y.resize(static_cast<std::size_t>(rows));
  for (int c = 0; c < columns; ++c) slope_x[static_cast<std::size_t>(c)] = static_cast<float>((c * stride - k.cx) / k.fx);
  for (int r = 0; r < rows; ++r) slope_y[static_cast<std::size_t>(r)] = static_cast<float>((r * stride - k.cy) / k.fy);
  detail::for_each_index(static_cast<std::size_t>(rows), 8, [&](std::size_t row) {
    const int v = static_cast<int>(row) * stride;
    const float* const depth = frame.depth.data() + frame.index(0, v);
    for (int u = 0; u < k.width; u += stride) {
      const float z = depth[u];
      if (!(z > 0.0f) || !std::isfinite(z) || z > static_cast<float>(max_depth)) continue;
      const Eigen::Vector3f pc(slope_x[static_cast<std::size_t>(u / stride)] * z, slope_y[row] * z, z);
      const std::size_t at = row * static_cast<std::size_t>(columns) + static_cast<std::size_t>(u / stride);
      points[at] = wRc * pc + wtc;
      keys[at] = detail::cell_key(detail::cell_of(points[at], inv_voxel_));
    }
  });
  std::uint64_t last_key = kNoPoint;  // neighbouring pixels mostly share a cell
  std::size_t current = 0;  // its cell
  for (int v = 0; v < k.height; v += stride) {
    for (int u = 0; u < k.width; u += stride) {
      const std::size_t i = frame.index(u, v);
      const std::size_t at = static_cast<std::size_t>(v / stride) * static_cast<std::size_t>(columns) +
                             static_cast<std::size_t>(u / stride);
      const std::uint64_t key = keys[at];
      if (key == kNoPoint) continue;
      const Eigen::Vector3f& pw = points[at];
      if (key != last_key) {
        int& cell = index->cells.find_or_insert(key);
        if (cell < 0) {
          cell = static_cast<int>(cells_.size());
          cells_.emplace_back();
          votes.emplace_back();
          counts.push_back(0);
        }
        last_key = key;
        current = static_cast<std::size_t>(cell);
      }
      const std::size_t c = current;
      cells_[c].mean += pw;
      ++counts[c];
      Votes& vote = votes[c];
      const std::uint16_t label = frame.labels[i];
      const auto in_place = vote.inline_votes.begin() + vote.size;
      const auto found = std::find_if(vote.inline_votes.begin(), in_place, [label](const auto& x) { return x.first == label; });
      if (found != in_place) {
        ++found->second;
      } else if (vote.size < kInline) {
        *in_place = {label, 1};
        ++vote.size;
      } else {
        auto& rest = more[c];
        const auto it = std::find_if(rest.begin(), rest.end(), [label](const auto& x) { return x.first == label; });
        if (it == rest.end()) {
          rest.emplace_back(label, 1);
        } else {
          ++it->second;
        }
      }
    }
  }
  // The most votes; a tie goes to the smaller label (deterministic).
  const auto fewer = [](const auto& a, const auto& b) {
    return a.second < b.second || (a.second == b.second && a.first > b.first);
  };
  for (std::size_t c = 0; c < cells_.size(); ++c) {
    cells_[c].mean /= static_cast<float>(counts[c]);
    const Votes& vote = votes[c];
    auto best = *std::max_element(vote.inline_votes.begin(), vote.inline_votes.begin() + vote.size, fewer);
    if (vote.size == kInline) {
      if (const auto it = more.find(c); it != more.end()) {
        best = std::max(best, *std::max_element(it->second.begin(), it->second.end(), fewer), fewer);
      }
    }
    cells_[c].label = best.first;
  }
  index_ = std::move(index);
}

int VoxelLabels::find(const Eigen::Vector3f& p) const {
  const Eigen::Vector3i c = detail::cell_of(p, inv_voxel_);
  if (const int at = index_->cells.find(detail::cell_key(c)); at >= 0) return at;
  int best = -1;
  float best_d2 = std::numeric_limits<float>::infinity();
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const int at = index_->cells.find(detail::cell_key(c + Eigen::Vector3i(dx, dy, dz)));
        if (at < 0) continue;
        const float d2 = (cells_[static_cast<std::size_t>(at)].mean - p).squaredNorm();
        if (d2 < best_d2) {
          best_d2 = d2;
          best = at;
        }
      }
    }
  }
  return best;
}

std::uint16_t VoxelLabels::label_at(const Eigen::Vector3f& p) const {
  const int c = find(p);
  return c < 0 ? std::uint16_t{kPixelNone} : cells_[static_cast<std::size_t>(c)].label;
}

PerceptionScores score_perception(const RgbdFrame& frame, const PerceptionResult& result,
                                  const PerceptionTruth& truth, const PerceptionSettings& settings) {
  const VoxelLabels cells(frame, settings.supervoxels.voxel_resolution, settings.cloud.pixel_stride, settings.max_depth);
  const std::vector<VoxelLabels::Cell>& all = cells.cells();
  PerceptionScores s;
  const auto r2 = static_cast<float>(truth.r_sphere * truth.r_sphere);
  const Eigen::Vector3f centre = truth.centroid.value_or(Eigen::Vector3d::Zero()).cast<float>();
  const auto in_sphere = [&](const Eigen::Vector3f& p) { return truth.centroid && (p - centre).squaredNorm() < r2; };
  for (const VoxelLabels::Cell& c : all) {
    s.object_cells += c.label == kPixelObject ? 1u : 0u;
    s.occluder_cells += is_occluder(c.label) && in_sphere(c.mean) ? 1u : 0u;
  }

  // Precision: each of the front end's voxels against its cell. Recall: a
  // true cell is found when a voxel of the class lies within one voxel edge
  // of its points' mean (PCL's voxels are re-gridded means: fewer than the cells).
  std::vector<Eigen::Vector3f> object_points, occluder_points;
  std::size_t object_voxels = 0, object_right = 0, occluder_voxels = 0, occluder_right = 0;
  const bool lost = result.status == TrackingStatus::Lost;
  const auto class_of = [&](std::size_t i) {
    return result.supervoxels[static_cast<std::size_t>(result.voxel_owner[i])].label;
  };
  std::vector<std::uint16_t> truth_of(lost ? 0 : result.voxels.size(), kPixelNone);  // each voxel's cell's label
  detail::for_each_index(truth_of.size(), 256, [&](std::size_t i) {
    if (class_of(i) == SupervoxelClass::Object || class_of(i) == SupervoxelClass::Occluder) {
      truth_of[i] = cells.label_at(result.voxels[i]);
    }
  });
  for (std::size_t i = 0; i < truth_of.size(); ++i) {
    const SupervoxelClass cls = class_of(i);
    if (cls != SupervoxelClass::Object && cls != SupervoxelClass::Occluder) continue;
    const std::uint16_t label = truth_of[i];
    if (cls == SupervoxelClass::Object) {
      ++object_voxels;
      object_right += label == kPixelObject ? 1u : 0u;
      object_points.push_back(result.voxels[i]);
    } else {
      occluder_points.push_back(result.voxels[i]);
      if (label == kPixelSupport) continue;
      ++occluder_voxels;
      occluder_right += is_occluder(label) ? 1u : 0u;
    }
  }
  const double voxel = settings.supervoxels.voxel_resolution;
  detail::PointGrid object_grid, occluder_grid;
  object_grid.build(object_points, voxel);
  occluder_grid.build(occluder_points, voxel);
  const auto near = [voxel](const detail::PointGrid& grid, const Eigen::Vector3f& p) {
    return grid.any_within(p, static_cast<float>(voxel), [](int) { return true; });
  };
  std::vector<char> found(all.size(), 0);  // 1: an object cell found, 2: an occluder cell found
  detail::for_each_index(all.size(), 256, [&](std::size_t i) {
    const VoxelLabels::Cell& c = all[i];
    if (c.label == kPixelObject && near(object_grid, c.mean)) found[i] = 1;
    if (is_occluder(c.label) && in_sphere(c.mean) && near(occluder_grid, c.mean)) found[i] = 2;
  });
  const auto object_found = static_cast<std::size_t>(std::count(found.begin(), found.end(), 1));
  const auto occluder_found = static_cast<std::size_t>(std::count(found.begin(), found.end(), 2));
  s.object_precision = ratio(object_right, object_voxels);
  s.object_recall = ratio(object_found, s.object_cells);
  s.occluder_precision = ratio(occluder_right, occluder_voxels);
  s.occluder_recall = ratio(occluder_found, s.occluder_cells);
  if (lost) return s;

  if (truth.centroid) s.centroid_error = (result.centroid - *truth.centroid).norm();
  if (!truth.surface.empty() && !result.hidden.empty()) {
    std::vector<Eigen::Vector3f> samples;
    samples.reserve(truth.surface.size());
    for (const Eigen::Vector3d& p : truth.surface) samples.push_back(p.cast<float>());
    detail::PointGrid grid;
    grid.build(samples, settings.supervoxels.voxel_resolution);
    double sum = 0.0;
    for (const Eigen::Vector3f& p : result.hidden) sum += nearest_distance(grid, samples, p);
    s.hidden_voxels = result.hidden.size();
    s.hidden_error = sum / static_cast<double>(result.hidden.size());
  }
  return s;
}

double labelled_shown_area(const RgbdFrame& frame, const PerceptionSettings& settings) {
  const double voxel = settings.supervoxels.voxel_resolution;
  const VoxelLabels cells(frame, voxel, settings.cloud.pixel_stride, settings.max_depth);
  const auto object = std::count_if(cells.cells().begin(), cells.cells().end(),
                                    [](const VoxelLabels::Cell& c) { return c.label == kPixelObject; });
  return static_cast<double>(object) * voxel * voxel;
}

}  // namespace ofv::perception
