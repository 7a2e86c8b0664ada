// The first frame: the support plane, then the object picked by a box, an
// image selection, or (by default) as the cluster nearest the image centre.
#include "front_end.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace ofv::perception {

namespace {

using detail::chroma;

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

/// ObjectSelection::Mode::Box: the supervoxels off the plane whose centroid is in `box`.
std::vector<char> select_in_box(const std::vector<SupervoxelInfo>& supervoxels,
                                const std::vector<char>& off_plane,
                                const Eigen::AlignedBox3d& box) {
  std::vector<char> object(supervoxels.size(), 0);
  for (std::size_t i = 0; i < supervoxels.size(); ++i) {
    object[i] = off_plane[i] && box.contains(supervoxels[i].centroid) ? 1 : 0;
  }
  return object;
}

/// ObjectSelection::Mode::Image: the supervoxels off the plane whose centroid
/// projects onto a mask pixel or into the rectangle.
std::vector<char> select_in_image(const RgbdFrame& frame,
                                  const std::vector<SupervoxelInfo>& supervoxels,
                                  const std::vector<char>& off_plane, const ObjectSelection& sel) {
  std::vector<char> object(supervoxels.size(), 0);
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const CameraIntrinsics& k = frame.intrinsics;
  for (std::size_t i = 0; i < supervoxels.size(); ++i) {
    if (!off_plane[i]) {
      continue;
    }
    const auto px = detail::project(frame, cMw, supervoxels[i].centroid);
    if (!px) {
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
  return object;
}

/// Boundary supervoxels mix the object's colour with a foreign neighbour's
/// (the table at its foot, the holding hand) and fall outside the colour-
/// consistent cluster. One touching the object joins it when its
/// chromaticity is nearer the object's mean than the mean of its foreign
/// neighbours (those not of the object's colour); repeated until nothing
/// joins. A supervoxel of a foreign colour is nearest its own kind and
/// never joins.
void grow_into_boundary(const std::vector<SupervoxelInfo>& supervoxels,
                        const std::vector<std::pair<int, int>>& neighbours,
                        const std::vector<char>& off_plane, const std::vector<int>& cluster,
                        double max_chroma, std::vector<char>& object) {
  const std::size_t n = supervoxels.size();
  Eigen::Vector3f object_chroma = Eigen::Vector3f::Zero();
  for (int i : cluster) {
    object_chroma += chroma(supervoxels[static_cast<std::size_t>(i)].colour);
  }
  object_chroma /= static_cast<float>(cluster.size());
  const auto limit = static_cast<float>(max_chroma);
  std::vector<Eigen::Vector3f> foreign_sum(n, Eigen::Vector3f::Zero());
  std::vector<int> foreign_count(n, 0);
  for (const auto& [a, b] : neighbours) {
    for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
      const Eigen::Vector3f cy = chroma(supervoxels[static_cast<std::size_t>(y)].colour);
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
        if (object[xi] || !object[static_cast<std::size_t>(y)] || !off_plane[xi]) {
          continue;
        }
        const Eigen::Vector3f c = chroma(supervoxels[xi].colour);
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
}

/// ObjectSelection::Mode::Auto: the cluster of adjacent, colour-consistent
/// supervoxels off the plane nearest the image centre, grown into its
/// boundary supervoxels; none when no cluster is large enough.
std::vector<char> select_cluster(const RgbdFrame& frame, const PerceptionResult& r,
                                 const std::vector<std::pair<int, int>>& touching,
                                 const std::vector<char>& off_plane, const TrackingSettings& t) {
  const std::vector<SupervoxelInfo>& supervoxels = r.supervoxels;
  const std::size_t n = supervoxels.size();
  std::vector<char> object(n, 0);
  // Neighbours: within R_adj (the paper's graph) or touching (PCL's voxel
  // adjacency, which also links supervoxels grown larger than R_adj).
  std::vector<std::pair<int, int>> neighbours = r.adjacency;
  neighbours.insert(neighbours.end(), touching.begin(), touching.end());
  // Clusters grow only across colour-consistent edges: a hand holding the
  // object in the first frame is adjacent to it but of another colour.
  std::vector<std::pair<int, int>> edges;
  const double max_chroma = t.max_chroma_distance;
  for (const auto& [a, b] : neighbours) {
    if (max_chroma <= 0.0 || (chroma(supervoxels[static_cast<std::size_t>(a)].colour) -
                              chroma(supervoxels[static_cast<std::size_t>(b)].colour))
                                     .norm() <= max_chroma) {
      edges.emplace_back(a, b);
    }
  }
  const auto clusters = components(n, edges, off_plane);
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const CameraIntrinsics& k = frame.intrinsics;
  double best = std::numeric_limits<double>::infinity();
  const std::vector<int>* chosen = nullptr;
  for (const auto& cluster : clusters) {
    if (static_cast<int>(cluster.size()) < t.min_cluster_supervoxels) {
      continue;
    }
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int i : cluster) {
      mean += supervoxels[static_cast<std::size_t>(i)].centroid;
    }
    mean /= static_cast<double>(cluster.size());
    const auto px = detail::project(frame, cMw, mean);
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
    return object;
  }
  for (int i : *chosen) {
    object[static_cast<std::size_t>(i)] = 1;
  }
  if (max_chroma > 0.0) {
    grow_into_boundary(supervoxels, neighbours, off_plane, *chosen, max_chroma, object);
  }
  return object;
}

}  // namespace

void Perception::Impl::fit_support_plane(const PerceptionResult& r) {
  const std::size_t n = r.supervoxels.size();
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
}

std::vector<char> Perception::Impl::select(const RgbdFrame& frame, const PerceptionResult& r,
                                           std::string& why) {
  const std::size_t n = r.supervoxels.size();
  // The support plane: its supervoxels are never object, whatever the selection.
  fit_support_plane(r);
  std::vector<char> off_plane(n);
  for (std::size_t i = 0; i < n; ++i) {
    off_plane[i] = on_plane(r.supervoxels[i]) ? 0 : 1;
  }

  const ObjectSelection& sel = settings.selection;
  std::vector<char> object;
  std::string if_none;
  switch (sel.mode) {
    case ObjectSelection::Mode::Box:
      object = select_in_box(r.supervoxels, off_plane, sel.box);
      if_none = "no supervoxel inside the selection box";
      break;
    case ObjectSelection::Mode::Image:
      object = select_in_image(frame, r.supervoxels, off_plane, sel);
      if_none = "no supervoxel inside the image selection";
      break;
    case ObjectSelection::Mode::Auto:
      object = select_cluster(frame, r, sv.touching, off_plane, settings.tracking);
      if_none = "no cluster of at least " +
                std::to_string(settings.tracking.min_cluster_supervoxels) +
                " supervoxels off the dominant plane";
      break;
  }
  if (std::none_of(object.begin(), object.end(), [](char c) { return c != 0; })) {
    why = if_none;
  }

  // Every voxel of the selection may enter the object state, except the
  // plane's own under the object's foot.
  voxel_matched.resize(r.voxels.size());
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    voxel_matched[i] = plane_voxel(r.voxels[i], sv.colours[i]) ? 0 : 1;
  }
  return object;
}

}  // namespace ofv::perception
