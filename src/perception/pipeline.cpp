// The perception front end: frame -> supervoxels -> tracked object -> OBB -> ViewProblem.
#include "ofv/perception/perception.h"

#include "pcl_stages.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ofv {

const char* to_string(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::Initialised:
      return "initialised";
    case TrackingStatus::Tracking:
      return "tracking";
    case TrackingStatus::Lost:
      return "lost";
  }
  return "?";
}

const char* to_string(SupervoxelClass label) {
  switch (label) {
    case SupervoxelClass::Object:
      return "object";
    case SupervoxelClass::Interacting:
      return "interacting";
    case SupervoxelClass::Occluder:
      return "occluder";
    case SupervoxelClass::Background:
      return "background";
  }
  return "?";
}

namespace {

void require(bool ok, const char* name, double value, const char* expected) {
  if (!ok) {
    throw std::invalid_argument(std::string("perception setting ") + name + " = " +
                                std::to_string(value) + ": expected " + expected);
  }
}

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

/// Points hashed on a uniform grid: "is any point within r of p" in O(1).
class PointGrid {
 public:
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
  static std::uint64_t key(const Eigen::Vector3i& c) {
    const auto k = [](int x) {
      return static_cast<std::uint64_t>(static_cast<std::int64_t>(x) + (std::int64_t{1} << 20)) &
             0x1FFFFFu;
    };
    return k(c.x()) | (k(c.y()) << 21) | (k(c.z()) << 42);
  }
  float inv_cell_ = 1.0f;
  std::vector<Entry> entries_;
  const std::vector<Eigen::Vector3f>* points_ = nullptr;
};

/// Pixel of world point p in the frame's camera; nullopt behind the camera.
std::optional<Eigen::Vector2d> project(const RgbdFrame& frame, const Eigen::Isometry3d& cMw,
                                       const Eigen::Vector3d& p, double* depth = nullptr) {
  const Eigen::Vector3d pc = cMw * p;
  if (!(pc.z() > 1e-6)) {
    return std::nullopt;
  }
  if (depth != nullptr) {
    *depth = pc.z();
  }
  const CameraIntrinsics& k = frame.intrinsics;
  return Eigen::Vector2d(k.fx * pc.x() / pc.z() + k.cx, k.fy * pc.y() / pc.z() + k.cy);
}

/// True when world point p cannot be seen in the frame: out of the image, or
/// behind a surface nearer the camera by more than `tolerance` [m].
bool hidden(const RgbdFrame& frame, const Eigen::Isometry3d& cMw, const Eigen::Vector3d& p,
            double tolerance) {
  double z = 0.0;
  const auto px = project(frame, cMw, p, &z);
  if (!px) return true;
  const int u = static_cast<int>(std::lround(px->x()));
  const int v = static_cast<int>(std::lround(px->y()));
  const CameraIntrinsics& k = frame.intrinsics;
  if (u < 0 || v < 0 || u >= k.width || v >= k.height) return true;
  const float observed = frame.depth[frame.index(u, v)];
  return std::isfinite(observed) && observed > 0.0f && static_cast<double>(observed) < z - tolerance;
}

/// Colour without brightness: R, G, B over their sum (shading-invariant).
Eigen::Vector3f chroma(const Eigen::Vector3f& rgb) { return rgb / std::max(rgb.sum(), 1.0f); }

/// Connected components of the vertices with keep[i], over `edges`.
std::vector<std::vector<int>> components(std::size_t n,
                                         const std::vector<std::pair<int, int>>& edges,
                                         const std::vector<char>& keep) {
  std::vector<int> parent(n);
  for (std::size_t i = 0; i < n; ++i) {
    parent[i] = static_cast<int>(i);
  }
  const auto find = [&parent](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
      parent[static_cast<std::size_t>(i)] =
          parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
      i = parent[static_cast<std::size_t>(i)];
    }
    return i;
  };
  for (const auto& [a, b] : edges) {
    if (keep[static_cast<std::size_t>(a)] && keep[static_cast<std::size_t>(b)]) {
      parent[static_cast<std::size_t>(find(a))] = find(b);
    }
  }
  std::vector<int> slot(n, -1);
  std::vector<std::vector<int>> out;
  for (std::size_t i = 0; i < n; ++i) {
    if (!keep[i]) {
      continue;
    }
    const auto root = static_cast<std::size_t>(find(static_cast<int>(i)));
    if (slot[root] < 0) {
      slot[root] = static_cast<int>(out.size());
      out.emplace_back();
    }
    out[static_cast<std::size_t>(slot[root])].push_back(static_cast<int>(i));
  }
  return out;
}

}  // namespace

void validate(const PerceptionSettings& s) {
  const SupervoxelSettings& sv = s.supervoxels;
  require(positive(sv.voxel_resolution), "voxel_resolution", sv.voxel_resolution, "> 0 [m]");
  require(positive(sv.seed_resolution) && sv.seed_resolution >= sv.voxel_resolution,
          "seed_resolution", sv.seed_resolution, ">= voxel_resolution [m]");
  require(std::isfinite(sv.colour_importance) && sv.colour_importance >= 0.0, "colour_importance",
          sv.colour_importance, ">= 0");
  require(std::isfinite(sv.spatial_importance) && sv.spatial_importance >= 0.0,
          "spatial_importance", sv.spatial_importance, ">= 0");
  require(std::isfinite(sv.normal_importance) && sv.normal_importance >= 0.0, "normal_importance",
          sv.normal_importance, ">= 0");
  require(sv.adjacency_alpha >= 1.0 && sv.adjacency_alpha <= 1.5, "adjacency_alpha",
          sv.adjacency_alpha, "in [1, 1.5] (paper eq. 1)");
  const TrackingSettings& t = s.tracking;
  require(positive(t.max_motion), "max_motion", t.max_motion, "> 0 [m]");
  require(t.min_near_fraction > 0.0 && t.min_near_fraction <= 1.0, "min_near_fraction",
          t.min_near_fraction, "in (0, 1]");
  require(t.min_kept_fraction >= 0.0 && t.min_kept_fraction <= 1.0, "min_kept_fraction",
          t.min_kept_fraction, "in [0, 1]");
  require(std::isfinite(t.max_chroma_distance), "max_chroma_distance", t.max_chroma_distance,
          "a finite number (<= 0: off)");
  require(positive(t.plane_distance), "plane_distance", t.plane_distance, "> 0 [m]");
  require(t.min_cluster_supervoxels >= 1, "min_cluster_supervoxels", t.min_cluster_supervoxels,
          ">= 1");
  require(t.occlusion_memory_frames >= 0, "occlusion_memory_frames", t.occlusion_memory_frames,
          ">= 0");
  require(s.cloud.pixel_stride >= 1, "pixel_stride", s.cloud.pixel_stride, ">= 1");
  require(positive(s.r_sphere), "r_sphere", s.r_sphere, "> 0 [m]");
  require(std::isfinite(s.crop_margin) && s.crop_margin >= 0.0, "crop_margin", s.crop_margin,
          ">= 0 [m]");
  require(positive(s.max_depth), "max_depth", s.max_depth, "> 0 [m]");
  require(std::isfinite(s.obb_margin) && s.obb_margin >= 0.0, "obb_margin", s.obb_margin,
          ">= 0 [m]");
  if (s.selection.mode == ObjectSelection::Mode::Box && s.selection.box.isEmpty()) {
    throw std::invalid_argument("perception selection: mode box needs a non-empty box");
  }
  if (s.selection.mode == ObjectSelection::Mode::Image && s.selection.mask.empty() &&
      s.selection.rect.isEmpty()) {
    throw std::invalid_argument("perception selection: mode image needs a rectangle or a mask");
  }
}

struct Perception::Impl {
  explicit Impl(const PerceptionSettings& s) : settings(s), builder(cloud_settings(s)) {}

  static CloudSettings cloud_settings(const PerceptionSettings& s) {
    CloudSettings c = s.cloud;
    c.voxel_resolution = s.supervoxels.voxel_resolution;
    return c;
  }

  PerceptionSettings settings;
  CloudBuilder builder;
  WorldCloud cloud;
  detail::SupervoxelOutput sv;
  PointGrid grid;  // reused for adjacency and tracking
  std::vector<Eigen::Vector3f> centroids;
  std::vector<Eigen::Vector3d> object_cloud;  // classify(): visible + hidden object voxels

  // Object state carried from frame to frame (world frame).
  bool initialised = false;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3f> memory;  // object voxels: seen now, or hidden behind something
  std::vector<Eigen::Vector3f> memory_chroma;  // chromaticity of each memory voxel
  std::vector<int> memory_age;                 // frames since the voxel was last seen
  struct Vertex {
    Eigen::Vector3d centroid, normal;
    int age = 0;  // frames since it was last seen
  };
  std::vector<Vertex> vertex_memory;  // object supervoxels: seen now, or hidden behind something
  std::size_t initial_voxels = 0;              // object voxels in the first frame (seen whole)
  std::optional<Eigen::Vector4d> plane;        // dominant (support) plane found in the first frame
  Eigen::Vector3f plane_chroma = Eigen::Vector3f::Zero();  // its mean chromaticity

  /// True for a voxel of the support plane: on it, and of its colour.
  [[nodiscard]] bool plane_voxel(const Eigen::Vector3f& p, const Eigen::Vector3f& rgb) const {
    return plane &&
           std::abs(plane->head<3>().cast<float>().dot(p) + static_cast<float>((*plane)(3))) <=
               static_cast<float>(settings.tracking.plane_distance) &&
           (settings.tracking.max_chroma_distance <= 0.0 ||
            (chroma(rgb) - plane_chroma).norm() <=
                static_cast<float>(settings.tracking.max_chroma_distance));
  }
  // Per voxel of the current frame: may it enter the object state? In
  // tracking only voxels that matched the state themselves do, so the
  // foreign voxels of a mixed boundary supervoxel (a hand's, the table's)
  // never become object and cannot pull their neighbours in next frame.
  std::vector<char> voxel_matched;

  /// True for a supervoxel lying on the support plane: centroid on it and
  /// normal within 60 degrees of the plane's. The foot of an object standing
  /// on the plane is near it too, but faces another way; supervoxels that
  /// straddle the foot and the plane have normals in between and go with
  /// the plane.
  [[nodiscard]] bool on_plane(const SupervoxelInfo& s) const {
    return plane &&
           std::abs(plane->head<3>().dot(s.centroid) + (*plane)(3)) <=
               settings.tracking.plane_distance &&
           std::abs(plane->head<3>().dot(s.normal)) >= std::cos(M_PI / 3.0);
  }

  PerceptionResult process(const RgbdFrame& frame);
  void adjacency(PerceptionResult& r);
  std::vector<char> select(const RgbdFrame& frame, const PerceptionResult& r, std::string& why);
  std::vector<char> track(const PerceptionResult& r);
  void remember(const RgbdFrame& frame, const PerceptionResult& r, const std::vector<char>& object);
  void classify(PerceptionResult& r, const std::vector<char>& object);
};

PerceptionResult Perception::Impl::process(const RgbdFrame& frame) {
  const auto start = std::chrono::steady_clock::now();
  PerceptionResult r;
  r.wMc = frame.wMc;
  const Eigen::Vector3d camera = frame.wMc.translation();

  // 1. Cloud: crop to the sphere around the last centroid (or the user box).
  auto stage = std::chrono::steady_clock::now();
  CropVolume crop;
  crop.max_depth = settings.max_depth;
  const double crop_radius = settings.r_sphere + settings.crop_margin;
  if (initialised) {
    crop.centre = centroid;
    crop.radius = crop_radius;
  } else if (settings.selection.mode == ObjectSelection::Mode::Box) {
    crop.centre = settings.selection.box.center();
    crop.radius = crop_radius + 0.5 * settings.selection.box.diagonal().norm();
  }
  builder.build(frame, crop, cloud);
  r.counts.valid_pixels = cloud.valid_pixels;
  r.counts.cropped_points = cloud.cropped_points;
  r.counts.voxels = cloud.points.size();
  r.timings.cloud = ms_since(stage);

  // 2. Supervoxels.
  stage = std::chrono::steady_clock::now();
  detail::cluster_supervoxels(cloud, settings.supervoxels, camera, sv);
  r.supervoxels = sv.supervoxels;
  r.voxels = sv.voxels;
  r.voxel_owner = sv.owner;
  r.counts.supervoxels = r.supervoxels.size();
  r.timings.supervoxels = ms_since(stage);

  stage = std::chrono::steady_clock::now();
  adjacency(r);
  r.timings.adjacency = ms_since(stage);

  // 3. Object: selection in the first frame, tracking afterwards.
  stage = std::chrono::steady_clock::now();
  std::vector<char> object;
  std::string why;
  if (!initialised) {
    object = select(frame, r, why);
    voxel_matched.resize(r.voxels.size());
    for (std::size_t i = 0; i < r.voxels.size(); ++i) {
      voxel_matched[i] = plane_voxel(r.voxels[i], sv.colours[i]) ? 0 : 1;
    }
  } else {
    object = track(r);
  }
  std::size_t object_voxels = 0;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    object_voxels += object[static_cast<std::size_t>(r.voxel_owner[i])] ? 1u : 0u;
  }
  bool lost = object_voxels == 0;
  if (lost && why.empty()) {
    why = "no supervoxel near the object's last state";
  }
  if (!lost && initialised &&
      static_cast<double>(object_voxels) <
          settings.tracking.min_kept_fraction * static_cast<double>(initial_voxels)) {
    lost = true;
    why = std::to_string(object_voxels) + " object voxels found, fewer than " +
          std::to_string(settings.tracking.min_kept_fraction) + " x the " +
          std::to_string(initial_voxels) + " of the first frame";
  }
  if (lost) {
    r.status = TrackingStatus::Lost;
    r.message = why;
  } else {
    r.status = initialised ? TrackingStatus::Tracking : TrackingStatus::Initialised;
    if (!initialised) {
      initial_voxels = object_voxels;
      initialised = true;
    }
    remember(frame, r, object);
  }
  r.timings.tracking = ms_since(stage);

  // 4. Classification and the estimator's input.
  stage = std::chrono::steady_clock::now();
  if (!lost) {
    classify(r, object);
    centroid = r.centroid;
  }
  r.timings.classify = ms_since(stage);
  r.timings.total = ms_since(start);
  return r;
}

void Perception::Impl::adjacency(PerceptionResult& r) {
  const double r_adj = settings.supervoxels.adjacency_alpha * settings.supervoxels.seed_resolution;
  centroids.clear();
  for (const SupervoxelInfo& s : r.supervoxels) {
    centroids.push_back(s.centroid.cast<float>());
  }
  grid.build(centroids, r_adj);
  const auto r2 = static_cast<float>(r_adj * r_adj);
  for (std::size_t i = 0; i < centroids.size(); ++i) {
    grid.for_each_near(centroids[i], [&](int j) {
      if (static_cast<std::size_t>(j) > i &&
          (centroids[static_cast<std::size_t>(j)] - centroids[i]).squaredNorm() <= r2) {
        r.adjacency.emplace_back(static_cast<int>(i), j);
      }
    });
  }
  r.counts.adjacency_edges = r.adjacency.size();
}

std::vector<char> Perception::Impl::select(const RgbdFrame& frame, const PerceptionResult& r,
                                           std::string& why) {
  const std::size_t n = r.supervoxels.size();
  std::vector<char> object(n, 0);
  const ObjectSelection& sel = settings.selection;
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const CameraIntrinsics& k = frame.intrinsics;
  // The support plane: a plane holding at least a fifth of the points.
  const auto min_inliers = static_cast<std::size_t>(0.2 * static_cast<double>(cloud.points.size()));
  plane = detail::fit_dominant_plane(cloud.points, settings.tracking.plane_distance,
                                     std::max<std::size_t>(min_inliers, 3));
  if (plane) {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (on_plane(r.supervoxels[i])) {
        sum += chroma(r.supervoxels[i].colour);
        ++count;
      }
    }
    plane_chroma = count > 0 ? Eigen::Vector3f(sum / static_cast<float>(count))
                             : Eigen::Vector3f::Constant(-10.0f);  // matches no colour
  }
  switch (sel.mode) {
    case ObjectSelection::Mode::Box:
      for (std::size_t i = 0; i < n; ++i) {
        object[i] =
            sel.box.contains(r.supervoxels[i].centroid) && !on_plane(r.supervoxels[i]) ? 1 : 0;
      }
      if (std::none_of(object.begin(), object.end(), [](char c) { return c != 0; })) {
        why = "no supervoxel inside the selection box";
      }
      return object;
    case ObjectSelection::Mode::Image:
      for (std::size_t i = 0; i < n; ++i) {
        const auto px = project(frame, cMw, r.supervoxels[i].centroid);
        if (!px || on_plane(r.supervoxels[i])) {
          continue;
        }
        const int u = static_cast<int>(std::lround(px->x()));
        const int v = static_cast<int>(std::lround(px->y()));
        if (u < 0 || v < 0 || u >= k.width || v >= k.height) {
          continue;
        }
        if (!sel.mask.empty()) {
          object[i] = sel.mask.size() == frame.depth.size() && sel.mask[frame.index(u, v)] != 0;
        } else {
          object[i] = sel.rect.contains(Eigen::Vector2i(u, v)) ? 1 : 0;
        }
      }
      if (std::none_of(object.begin(), object.end(), [](char c) { return c != 0; })) {
        why = "no supervoxel inside the image selection";
      }
      return object;
    case ObjectSelection::Mode::Auto:
      break;
  }

  // Default: drop the dominant plane, then take the cluster of adjacent
  // supervoxels nearest the image centre.
  std::vector<char> keep(n, 1);
  for (std::size_t i = 0; i < n; ++i) {
    keep[i] = on_plane(r.supervoxels[i]) ? 0 : 1;
  }
  // Neighbours: within R_adj (the paper's graph) or touching (PCL's voxel
  // adjacency, which also links supervoxels grown larger than R_adj).
  std::vector<std::pair<int, int>> neighbours = r.adjacency;
  neighbours.insert(neighbours.end(), sv.touching.begin(), sv.touching.end());
  // Clusters grow only across colour-consistent edges: a hand holding the
  // object in the first frame is adjacent to it but of another colour.
  std::vector<std::pair<int, int>> edges;
  const double max_chroma = settings.tracking.max_chroma_distance;
  for (const auto& [a, b] : neighbours) {
    if (max_chroma <= 0.0 || (chroma(r.supervoxels[static_cast<std::size_t>(a)].colour) -
                              chroma(r.supervoxels[static_cast<std::size_t>(b)].colour))
                                     .norm() <= max_chroma) {
      edges.emplace_back(a, b);
    }
  }
  const auto clusters = components(n, edges, keep);
  double best = std::numeric_limits<double>::infinity();
  const std::vector<int>* chosen = nullptr;
  for (const auto& cluster : clusters) {
    if (static_cast<int>(cluster.size()) < settings.tracking.min_cluster_supervoxels) {
      continue;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i : cluster) {
      mean += r.supervoxels[static_cast<std::size_t>(i)].centroid;
    }
    mean /= static_cast<double>(cluster.size());
    const auto px = project(frame, cMw, mean);
    if (!px) {
      continue;
    }
    const double dist = (*px - Eigen::Vector2d(k.cx, k.cy)).norm();
    if (dist < best) {
      best = dist;
      chosen = &cluster;
    }
  }
  if (chosen == nullptr) {
    why = "no cluster of at least " + std::to_string(settings.tracking.min_cluster_supervoxels) +
          " supervoxels off the dominant plane";
    return object;
  }
  for (int i : *chosen) {
    object[static_cast<std::size_t>(i)] = 1;
  }
  if (max_chroma <= 0.0) {
    return object;
  }
  // Boundary supervoxels mix the object's colour with a foreign neighbour's
  // (the table at its foot, the holding hand) and fall outside the colour-
  // consistent cluster. One touching the object joins it when its
  // chromaticity is nearer the object's mean than the mean of its foreign
  // neighbours (those not of the object's colour); repeated until nothing
  // joins. A supervoxel of a foreign colour is nearest its own kind and
  // never joins.
  Eigen::Vector3f object_chroma = Eigen::Vector3f::Zero();
  for (int i : *chosen) {
    object_chroma += chroma(r.supervoxels[static_cast<std::size_t>(i)].colour);
  }
  object_chroma /= static_cast<float>(chosen->size());
  const auto limit = static_cast<float>(max_chroma);
  std::vector<Eigen::Vector3f> foreign_sum(n, Eigen::Vector3f::Zero());
  std::vector<int> foreign_count(n, 0);
  for (const auto& [a, b] : neighbours) {
    for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
      const Eigen::Vector3f cy = chroma(r.supervoxels[static_cast<std::size_t>(y)].colour);
      if ((cy - object_chroma).norm() > limit) {
        foreign_sum[static_cast<std::size_t>(x)] += cy;
        ++foreign_count[static_cast<std::size_t>(x)];
      }
    }
  }
  for (bool grew = true; grew;) {
    grew = false;
    for (const auto& [a, b] : neighbours) {
      for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
        const auto xi = static_cast<std::size_t>(x);
        if (object[xi] || !object[static_cast<std::size_t>(y)] || !keep[xi]) {
          continue;
        }
        const Eigen::Vector3f c = chroma(r.supervoxels[xi].colour);
        const bool nearer_object =
            foreign_count[xi] == 0
                ? (c - object_chroma).norm() <= limit
                : (c - object_chroma).norm() <
                      (c - foreign_sum[xi] / static_cast<float>(foreign_count[xi])).norm();
        if (nearer_object) {
          object[xi] = 1;
          grew = true;
        }
      }
    }
  }
  return object;
}

std::vector<char> Perception::Impl::track(const PerceptionResult& r) {
  const std::size_t n = r.supervoxels.size();
  const TrackingSettings& t = settings.tracking;
  grid.build(memory, t.max_motion);
  std::vector<int> near(n, 0);
  voxel_matched.assign(r.voxels.size(), 0);
  const auto radius = static_cast<float>(t.max_motion);
  const auto max_chroma = static_cast<float>(t.max_chroma_distance);
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    const Eigen::Vector3f c = chroma(sv.colours[i]);
    const bool is_near =
        !plane_voxel(r.voxels[i], sv.colours[i]) &&
        grid.any_within(r.voxels[i], radius, [&](int j) {
          return max_chroma <= 0.0f ||
                 (memory_chroma[static_cast<std::size_t>(j)] - c).norm() <= max_chroma;
        });
    near[owner] += is_near ? 1 : 0;
    voxel_matched[i] = is_near ? 1 : 0;
  }
  std::vector<char> object(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    object[i] =
        static_cast<double>(near[i]) >=
                    t.min_near_fraction * static_cast<double>(r.supervoxels[i].voxel_count) &&
                !on_plane(r.supervoxels[i])
            ? 1
            : 0;
  }
  return object;
}

void Perception::Impl::remember(const RgbdFrame& frame, const PerceptionResult& r,
                                const std::vector<char>& object) {
  // Old object voxels now hidden behind something nearer the camera (or out
  // of the image) stay in the state for a while, so that the object's
  // occluded part is recognised when it reappears.
  std::vector<Eigen::Vector3f> next;
  std::vector<Eigen::Vector3f> next_chroma;
  std::vector<int> next_age;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    if (object[owner] && voxel_matched[i]) {
      next.push_back(r.voxels[i]);
      next_chroma.push_back(chroma(sv.colours[i]));
      next_age.push_back(0);
    }
  }
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const double tolerance = settings.tracking.max_motion;
  const int max_age = settings.tracking.occlusion_memory_frames;
  for (std::size_t i = 0; i < memory.size(); ++i) {
    if (memory_age[i] + 1 <= max_age && hidden(frame, cMw, memory[i].cast<double>(), tolerance)) {
      next.push_back(memory[i]);
      next_chroma.push_back(memory_chroma[i]);
      next_age.push_back(memory_age[i] + 1);
    }
  }
  memory.swap(next);
  memory_chroma.swap(next_chroma);
  memory_age.swap(next_age);

  // The same for the object's supervoxels (the estimator's vertices). A
  // remembered vertex goes when it shows again or a seen one takes its place.
  std::vector<Vertex> vertices;
  for (std::size_t i = 0; i < r.supervoxels.size(); ++i) {
    if (object[i] && r.supervoxels[i].normal_valid) {
      vertices.push_back({r.supervoxels[i].centroid, r.supervoxels[i].normal, 0});
    }
  }
  const std::size_t seen = vertices.size();
  const double spacing = 0.5 * settings.supervoxels.seed_resolution;
  for (const Vertex& m : vertex_memory) {
    if (m.age + 1 > max_age || !hidden(frame, cMw, m.centroid, tolerance)) continue;
    const bool replaced = std::any_of(vertices.begin(), vertices.begin() + static_cast<std::ptrdiff_t>(seen),
                                      [&](const Vertex& v) { return (v.centroid - m.centroid).norm() < spacing; });
    if (!replaced) vertices.push_back({m.centroid, m.normal, m.age + 1});
  }
  vertex_memory.swap(vertices);
}

void Perception::Impl::classify(PerceptionResult& r, const std::vector<char>& object) {
  const std::size_t n = r.supervoxels.size();
  // The object's voxel cloud: what is seen of it, plus the remembered voxels
  // of its part hidden behind something nearer the camera, so that an
  // occluder does not drag C, the axes and the OBB towards the visible part.
  object_cloud.clear();
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    if (object[static_cast<std::size_t>(r.voxel_owner[i])]) {
      object_cloud.push_back(r.voxels[i].cast<double>());
    }
  }
  r.counts.object_voxels = object_cloud.size();
  for (std::size_t i = 0; i < memory.size(); ++i) {
    if (memory_age[i] > 0) {
      object_cloud.push_back(memory[i].cast<double>());
    }
  }
  r.counts.hidden_voxels = object_cloud.size() - r.counts.object_voxels;

  // C and the PCA axes.
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : object_cloud) {
    c += p;
  }
  c /= static_cast<double>(object_cloud.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : object_cloud) {
    cov += (p - c) * (p - c).transpose();
  }
  cov /= static_cast<double>(object_cloud.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Matrix3d axes;
  axes.col(0) = eig.eigenvectors().col(2);  // largest variance
  axes.col(1) = eig.eigenvectors().col(1);
  axes.col(2) = axes.col(0).cross(axes.col(1));
  r.centroid = c;
  r.axes = axes;

  // Augmented OBB: extents of the object cloud along the axes, plus the margin.
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d& p : object_cloud) {
    const Eigen::Vector3d local = axes.transpose() * (p - c);
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
  }
  r.obb.axes = axes;
  r.obb.centre = c + axes * (0.5 * (lo + hi));
  r.obb.half_extents = 0.5 * (hi - lo) + Eigen::Vector3d::Constant(settings.obb_margin);

  // Labels (paper II-B) and the estimator's input.
  std::vector<int> vertices;
  std::vector<int> occluders;
  for (std::size_t i = 0; i < n; ++i) {
    SupervoxelInfo& s = r.supervoxels[i];
    if (object[i]) {
      s.label = SupervoxelClass::Object;
      ++r.counts.object;
      if (s.normal_valid) {
        vertices.push_back(static_cast<int>(i));
      }
    } else if (!settings.support_plane_occludes && on_plane(s)) {
      s.label = SupervoxelClass::Background;
    } else if (r.obb.contains(s.centroid)) {
      s.label = SupervoxelClass::Interacting;
      ++r.counts.interacting;
    } else if ((s.centroid - c).norm() < settings.r_sphere) {
      s.label = SupervoxelClass::Occluder;
      ++r.counts.occluders;
      occluders.push_back(static_cast<int>(i));
    } else {
      s.label = SupervoxelClass::Background;
    }
  }
  ViewProblem& p = r.problem;
  p.positions.resize(3, static_cast<Eigen::Index>(vertices.size()));
  p.normals.resize(3, static_cast<Eigen::Index>(vertices.size()));
  for (std::size_t j = 0; j < vertices.size(); ++j) {
    const SupervoxelInfo& s = r.supervoxels[static_cast<std::size_t>(vertices[j])];
    p.positions.col(static_cast<Eigen::Index>(j)) = s.centroid;
    p.normals.col(static_cast<Eigen::Index>(j)) = s.normal;
  }
  if (settings.tracking.hidden_vertices) {
    // The object's remembered supervoxels now hidden: the estimator keeps
    // them in view too, not only the part that is still seen.
    Eigen::Index k = p.positions.cols();
    for (const Vertex& m : vertex_memory) {
      k += m.age > 0 ? 1 : 0;
    }
    p.positions.conservativeResize(3, k);
    p.normals.conservativeResize(3, k);
    k = static_cast<Eigen::Index>(vertices.size());
    for (const Vertex& m : vertex_memory) {
      if (m.age == 0) continue;
      p.positions.col(k) = m.centroid;
      p.normals.col(k) = m.normal;
      ++k;
    }
    r.counts.hidden_vertices = static_cast<std::size_t>(k) - vertices.size();
  }
  p.occluders.resize(3, static_cast<Eigen::Index>(occluders.size()));
  for (std::size_t j = 0; j < occluders.size(); ++j) {
    p.occluders.col(static_cast<Eigen::Index>(j)) =
        r.supervoxels[static_cast<std::size_t>(occluders[j])].centroid;
  }
  p.centroid = c;
  p.axes = axes;
  p.camera = r.wMc.translation();
}

Perception::Perception(const PerceptionSettings& settings) {
  validate(settings);
  impl_ = std::make_unique<Impl>(settings);
}
Perception::~Perception() = default;
Perception::Perception(Perception&&) noexcept = default;
Perception& Perception::operator=(Perception&&) noexcept = default;

PerceptionResult Perception::process(const RgbdFrame& frame) { return impl_->process(frame); }

void Perception::reset() {
  impl_->initialised = false;
  impl_->memory.clear();
  impl_->memory_chroma.clear();
  impl_->memory_age.clear();
  impl_->vertex_memory.clear();
  impl_->initial_voxels = 0;
  impl_->plane.reset();
}

const PerceptionSettings& Perception::settings() const { return impl_->settings; }

}  // namespace ofv
