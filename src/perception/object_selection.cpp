// The first frame: the support plane, then the object picked by a box, an
// image selection, or (by default) as the cluster at the image centre.
#include "front_end.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace ofv::perception {

namespace {

/// Clusters of the supervoxels with keep[i] of one colour: neighbours join,
/// nearest in chromaticity first, when the two clusters' mean chromaticities
/// (weighted by voxels) are within max_chroma (any two when max_chroma <= 0).
/// Comparing clusters, not single supervoxels, keeps a chain of mixed
/// supervoxels along a border (the case's blue, blue-skin, the hand's skin)
/// from joining two objects step by small step.
std::vector<std::vector<int>> colour_clusters(const std::vector<SupervoxelInfo>& supervoxels,
                                              const std::vector<std::pair<int, int>>& neighbours,
                                              const std::vector<char>& keep, double max_chroma) {
  const std::size_t n = supervoxels.size();
  std::vector<int> parent(n);
  std::vector<Eigen::Vector3f> chroma_sum(n);
  std::vector<float> weight(n);
  for (std::size_t i = 0; i < n; ++i) {
    parent[i] = static_cast<int>(i);
    weight[i] = static_cast<float>(std::max(supervoxels[i].voxel_count, 1));
    chroma_sum[i] = weight[i] * chromaticity(supervoxels[i].colour);
  }
  const auto find = [&parent](int i) {
    while (parent[static_cast<std::size_t>(i)] != i) {
      parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
      i = parent[static_cast<std::size_t>(i)];
    }
    return i;
  };
  struct Edge {
    float difference;
    int a, b;
  };
  std::vector<Edge> edges;
  for (const auto& [a, b] : neighbours) {
    if (!keep[static_cast<std::size_t>(a)] || !keep[static_cast<std::size_t>(b)]) continue;
    edges.push_back({(chromaticity(supervoxels[static_cast<std::size_t>(a)].colour) -
                      chromaticity(supervoxels[static_cast<std::size_t>(b)].colour))
                         .norm(),
                     std::min(a, b), std::max(a, b)});
  }
  std::sort(edges.begin(), edges.end(), [](const Edge& x, const Edge& y) {
    return std::tie(x.difference, x.a, x.b) < std::tie(y.difference, y.a, y.b);
  });
  for (const Edge& e : edges) {
    const auto ra = static_cast<std::size_t>(find(e.a));
    const auto rb = static_cast<std::size_t>(find(e.b));
    if (ra == rb) continue;
    if (max_chroma > 0.0 &&
        (chroma_sum[ra] / weight[ra] - chroma_sum[rb] / weight[rb]).norm() > static_cast<float>(max_chroma)) {
      continue;
    }
    parent[ra] = static_cast<int>(rb);
    chroma_sum[rb] += chroma_sum[ra];
    weight[rb] += weight[ra];
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

/// True when p (world frame) projects onto a mask pixel or into the rectangle.
bool in_image_selection(const RgbdFrame& frame, const Eigen::Isometry3d& cMw, const Eigen::Vector3d& p,
                        const ObjectSelection& sel) {
  const auto px = detail::project(frame, cMw, p);
  if (!px) return false;
  const int u = static_cast<int>(std::lround(px->x()));
  const int v = static_cast<int>(std::lround(px->y()));
  const CameraIntrinsics& k = frame.intrinsics;
  if (u < 0 || v < 0 || u >= k.width || v >= k.height) return false;
  if (!sel.mask.empty()) return sel.mask.size() == frame.depth.size() && sel.mask[frame.index(u, v)] != 0;
  return sel.rect.contains(Eigen::Vector2i(u, v));
}

/// True when p (world frame) is inside the selection: the box
/// (Mode::Box), or the mask or rectangle it projects onto (Mode::Image).
bool in_selection(const RgbdFrame& frame, const Eigen::Isometry3d& cMw, const Eigen::Vector3d& p,
                  const ObjectSelection& sel) {
  return sel.mode == ObjectSelection::Mode::Box ? sel.box.contains(p) : in_image_selection(frame, cMw, p, sel);
}

/// ObjectSelection::Mode::Box and Mode::Image: the supervoxels off the plane
/// whose centroid is inside the selection (in_selection()).
std::vector<char> select_inside(const RgbdFrame& frame, const std::vector<SupervoxelInfo>& supervoxels,
                                const std::vector<char>& off_plane, const ObjectSelection& sel) {
  std::vector<char> object(supervoxels.size(), 0);
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  for (std::size_t i = 0; i < supervoxels.size(); ++i) {
    object[i] = off_plane[i] && in_selection(frame, cMw, supervoxels[i].centroid, sel) ? 1 : 0;
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
    object_chroma += chromaticity(supervoxels[static_cast<std::size_t>(i)].colour);
  }
  object_chroma /= static_cast<float>(cluster.size());
  const auto limit = static_cast<float>(max_chroma);
  std::vector<Eigen::Vector3f> foreign_sum(n, Eigen::Vector3f::Zero());
  std::vector<int> foreign_count(n, 0);
  for (const auto& [a, b] : neighbours) {
    for (const auto& [x, y] : {std::pair{a, b}, std::pair{b, a}}) {
      const Eigen::Vector3f cy = chromaticity(supervoxels[static_cast<std::size_t>(y)].colour);
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
        const Eigen::Vector3f c = chromaticity(supervoxels[xi].colour);
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

/// The world point seen at the pixel with depth nearest the image centre
/// (the principal point: what the camera points at; rings of growing
/// radius, within the image); none without depth.
std::optional<Eigen::Vector3f> centre_point(const RgbdFrame& frame) {
  const CameraIntrinsics& k = frame.intrinsics;
  const int cu = std::clamp(static_cast<int>(std::lround(k.cx)), 0, k.width - 1);
  const int cv = std::clamp(static_cast<int>(std::lround(k.cy)), 0, k.height - 1);
  const int rings = std::max(k.width, k.height);
  for (int ring = 0; ring <= rings; ++ring) {
    std::optional<std::pair<int, int>> found;
    int found_d2 = std::numeric_limits<int>::max();
    const auto consider = [&](int du, int dv) {
      const int u = cu + du, v = cv + dv;
      if (u < 0 || v < 0 || u >= k.width || v >= k.height || du * du + dv * dv >= found_d2) return;
      const float z = frame.depth[frame.index(u, v)];
      if (!(z > 0.0f) || !std::isfinite(z)) return;
      found = {u, v};
      found_d2 = du * du + dv * dv;
    };
    for (int d = -ring; d <= ring; ++d) {  // the ring's pixels: its rows, then the rest of its columns
      consider(d, -ring);
      if (ring > 0) consider(d, ring);
      if (std::abs(d) < ring) {
        consider(-ring, d);
        consider(ring, d);
      }
    }
    if (!found) continue;
    const auto [u, v] = *found;
    const double z = frame.depth[frame.index(u, v)];
    const Eigen::Vector3d pc((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
    return (frame.wMc * pc).cast<float>();
  }
  return std::nullopt;
}

/// ObjectSelection::Mode::Auto: of the clusters of adjacent, colour-consistent
/// supervoxels off the plane, the one the camera points at (centre_point()),
/// grown into its boundary supervoxels; none when no cluster is large enough.
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
  // Clusters of one colour: a hand holding the object in the first frame is
  // adjacent to it but of another colour.
  const double max_chroma = t.max_chroma_distance;
  const auto clusters = colour_clusters(supervoxels, neighbours, off_plane, max_chroma);
  // What the camera points at: the surface seen at the valid pixel nearest
  // the image centre, and the cluster with a voxel nearest it. (A cluster's
  // mean would do for a compact object, not for one around another: the
  // object seen around the hand held in front of it.)
  const std::optional<Eigen::Vector3f> aim = centre_point(frame);
  if (!aim) return object;
  std::vector<int> cluster_of(n, -1);
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    if (static_cast<int>(clusters[c].size()) < t.min_cluster_supervoxels) continue;
    for (int i : clusters[c]) cluster_of[static_cast<std::size_t>(i)] = static_cast<int>(c);
  }
  float best = std::numeric_limits<float>::infinity();
  const std::vector<int>* chosen = nullptr;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const int c = cluster_of[static_cast<std::size_t>(r.voxel_owner[i])];
    const float d = (r.voxels[i] - *aim).squaredNorm();
    if (c >= 0 && d < best) {
      best = d;
      chosen = &clusters[static_cast<std::size_t>(c)];
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

void Perception::Impl::fit_support_plane(const RgbdFrame& frame, const PerceptionResult& r) {
  const std::size_t n = r.supervoxels.size();
  // The support is what the selection is not: with a box, a rectangle or a
  // mask, the plane is fitted to the points outside it. Fitted to all, the
  // dominant plane of a case seen face on above a strip of table was the
  // case's face, and the object was nothing but plane.
  const ObjectSelection& sel = settings.selection;
  std::vector<Eigen::Vector3f> outside;
  const std::vector<Eigen::Vector3f>* points = &cloud.points;
  if (sel.mode != ObjectSelection::Mode::Auto) {
    const Eigen::Isometry3d cMw = frame.wMc.inverse();
    for (const Eigen::Vector3f& p : cloud.points) {
      if (!in_selection(frame, cMw, p.cast<double>(), sel)) outside.push_back(p);
    }
    points = &outside;
  }
  const auto min_inliers = static_cast<std::size_t>(0.2 * static_cast<double>(points->size()));
  plane = detail::fit_dominant_plane(*points, settings.tracking.plane_distance, std::max<std::size_t>(min_inliers, 3));
  if (plane) {
    Eigen::Vector3f sum = Eigen::Vector3f::Zero();
    int count = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (on_plane(r.supervoxels[i])) {
        sum += chromaticity(r.supervoxels[i].colour);
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
  fit_support_plane(frame, r);
  std::vector<char> off_plane(n);
  for (std::size_t i = 0; i < n; ++i) {
    off_plane[i] = on_plane(r.supervoxels[i]) ? 0 : 1;
  }

  const ObjectSelection& sel = settings.selection;
  std::vector<char> object;
  std::string if_none;
  switch (sel.mode) {
    case ObjectSelection::Mode::Box:
      object = select_inside(frame, r.supervoxels, off_plane, sel);
      if_none = "no supervoxel inside the selection box";
      break;
    case ObjectSelection::Mode::Image:
      object = select_inside(frame, r.supervoxels, off_plane, sel);
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

  // The voxels of the selection that may enter the object state: not the
  // plane's own under the object's foot, nor those of a selected supervoxel
  // whose chromaticity is nearer a touching unselected supervoxel's than
  // their own supervoxel's. A supervoxel at the object's border can hold a
  // few voxels of what touches it (a holding hand); remembered, they would
  // make the hand look like the object in the next frame, and the object
  // would grow into it.
  std::vector<std::vector<int>> foreign(n);
  for (const auto& [a, b] : sv.touching) {
    const auto ua = static_cast<std::size_t>(a), ub = static_cast<std::size_t>(b);
    if (object[ua] && !object[ub] && off_plane[ub]) foreign[ua].push_back(b);
    if (object[ub] && !object[ua] && off_plane[ua]) foreign[ub].push_back(a);
  }
  voxel_matched.resize(r.voxels.size());
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    const Eigen::Vector3f c = chromaticity(sv.colours[i]);
    const float own = (chromaticity(r.supervoxels[owner].colour) - c).norm();
    const bool foreign_colour = std::any_of(foreign[owner].begin(), foreign[owner].end(), [&](int f) {
      return (chromaticity(r.supervoxels[static_cast<std::size_t>(f)].colour) - c).norm() < own;
    });
    voxel_matched[i] = !plane_voxel(r.voxels[i], sv.colours[i]) && !foreign_colour ? 1 : 0;
  }
  return object;
}

}  // namespace ofv::perception
