// Internal: the state Perception carries from frame to frame, and its stages,
// one file each along the frame's path:
//   pipeline.cpp          the per-frame sequence (cloud, supervoxels, adjacency, ...)
//   supervoxels.cpp       PCL's supervoxels (supervoxels=pcl); vccs.cpp: ofv's own (supervoxels=ofv, the default)
//   object_selection.cpp  the first frame: support plane, then the object by box, image or cluster
//   object_memory.cpp     later frames: the object found near its remembered voxels, its
//                         motion; the memory updated, hidden voxels kept (and moved) for a while
//   classify.cpp          PCA, augmented OBB, interacting / occluders, the ViewProblem
//                         (with vertices from the hidden voxels)
#pragma once

#include "ofv/perception/cloud.h"
#include "ofv/constants.h"
#include "ofv/perception/perception.h"

#include "pcl_stages.h"
#include "vccs.h"
#include "point_grid.h"

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

namespace ofv::perception {

namespace detail {

/// Two colours alike: their chromaticities within max_chroma (<= 0: any).
inline bool alike(const Eigen::Vector3f& a, const Eigen::Vector3f& b, double max_chroma) {
  return max_chroma <= 0.0 || static_cast<double>((chromaticity(a) - chromaticity(b)).norm()) <= max_chroma;
}

/// Pixel of world point p in the frame's camera; nullopt behind the camera.
inline std::optional<Eigen::Vector2d> project(const RgbdFrame& frame, const Eigen::Isometry3d& cMw,
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

/// World point seen at pixel (u, v) with depth `depth` [m] (project()'s inverse).
inline Eigen::Vector3d unproject(const RgbdFrame& frame, double u, double v, double depth) {
  const CameraIntrinsics& k = frame.intrinsics;
  return frame.wMc * Eigen::Vector3d((u - k.cx) * depth / k.fx, (v - k.cy) * depth / k.fy, depth);
}

/// What the frame shows of world point p.
enum class Sight {
  Shown,    ///< its pixel's depth is at p or behind it
  Hidden,   ///< out of the image, or behind a surface nearer the camera by more than the tolerance
  NoDepth,  ///< its pixel has no depth (a drop-out, or a sensor's shadow next to an occluding edge)
};

/// Where world point p falls in a frame: its pixel, its depth in that
/// camera [m] and the depth the frame measured at the pixel (not finite, or
/// 0: none). nullopt behind the camera or out of the image.
struct Look {
  int u = 0;
  int v = 0;
  double z = 0.0;
  float observed = 0.0f;
  [[nodiscard]] bool measured() const { return std::isfinite(observed) && observed > 0.0f; }
};

inline std::optional<Look> look(const RgbdFrame& frame, const Eigen::Isometry3d& cMw, const Eigen::Vector3d& p) {
  Look l;
  const auto px = project(frame, cMw, p, &l.z);
  if (!px) return std::nullopt;
  l.u = static_cast<int>(std::lround(px->x()));
  l.v = static_cast<int>(std::lround(px->y()));
  const CameraIntrinsics& k = frame.intrinsics;
  if (l.u < 0 || l.v < 0 || l.u >= k.width || l.v >= k.height) return std::nullopt;
  l.observed = frame.depth[frame.index(l.u, l.v)];
  return l;
}

inline Sight sight(const RgbdFrame& frame, const Eigen::Isometry3d& cMw, const Eigen::Vector3d& p,
                   double tolerance) {
  const auto l = look(frame, cMw, p);
  if (!l) return Sight::Hidden;
  if (!l->measured()) return Sight::NoDepth;
  return static_cast<double>(l->observed) < l->z - tolerance ? Sight::Hidden : Sight::Shown;
}

/// The frame's voxels grouped by supervoxel and hashed: which supervoxels
/// come within a distance of one another, voxel to voxel (eq. 1's adjacency
/// measures between centroids, which misses a broken strip of voxels and a
/// long body touching another at one end).
class VoxelContacts {
 public:
  /// Hashes the voxels of the supervoxels j with keep(j) (the only ones
  /// for_each() visits and finds).
  template <typename Keep>
  void build(const PerceptionResult& r, double radius, Keep&& keep) {
    radius2_ = static_cast<float>(radius * radius);
    points_.clear();
    owners_.clear();
    first_.assign(r.supervoxels.size() + 1, 0);
    for (std::size_t i = 0; i < r.voxels.size(); ++i) {
      const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
      if (keep(owner)) ++first_[owner + 1];
    }
    for (std::size_t j = 0; j + 1 < first_.size(); ++j) first_[j + 1] += first_[j];
    points_.resize(static_cast<std::size_t>(first_.back()));
    owners_.resize(points_.size());
    next_.assign(first_.begin(), first_.end() - 1);
    for (std::size_t i = 0; i < r.voxels.size(); ++i) {
      const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
      if (!keep(owner)) continue;
      const auto at = static_cast<std::size_t>(next_[owner]++);
      points_[at] = r.voxels[i];  // grouped by supervoxel: points_[first_[j] .. first_[j + 1])
      owners_[at] = static_cast<int>(owner);
    }
    grid_.build(points_, radius);
  }

  /// Calls f(y) for every kept supervoxel y with a voxel within the
  /// distance of one of x's (y repeats, once per such pair of voxels; x
  /// itself too).
  template <typename F>
  void for_each(std::size_t x, F&& f) const {
    for_each_pair(x, [&](std::size_t y, const Eigen::Vector3f&, const Eigen::Vector3f&) { f(y); });
  }

  /// Calls f(y, p, q) for every voxel p of x and q of a kept supervoxel y
  /// within the distance of each other.
  template <typename F>
  void for_each_pair(std::size_t x, F&& f) const {
    for (int m = first_[x]; m < first_[x + 1]; ++m) {
      const Eigen::Vector3f& p = points_[static_cast<std::size_t>(m)];
      grid_.for_each_near(p, [&](int j) {
        const Eigen::Vector3f& q = points_[static_cast<std::size_t>(j)];
        if ((q - p).squaredNorm() <= radius2_) f(static_cast<std::size_t>(owners_[static_cast<std::size_t>(j)]), p, q);
      });
    }
  }

 private:
  float radius2_ = 0.0f;
  std::vector<Eigen::Vector3f> points_;  // the kept voxels, grouped by supervoxel
  std::vector<int> owners_;              // the supervoxel of each
  std::vector<int> first_;               // supervoxel j's: points_[first_[j] .. first_[j + 1])
  std::vector<int> next_;                // build()'s fill positions
  PointGrid grid_;
};

}  // namespace detail

struct Perception::Impl {
  explicit Impl(const PerceptionSettings& s) : settings(s), builder(cloud_settings(s)) {}

  static CloudSettings cloud_settings(const PerceptionSettings& s) {
    CloudSettings c = s.cloud;
    c.voxel_resolution = s.supervoxels.voxel_resolution;
    return c;
  }

  PerceptionSettings settings;

  // Buffers reused from frame to frame.
  CloudBuilder builder;
  WorldCloud cloud;
  detail::SupervoxelOutput sv;
  detail::Vccs vccs;
  detail::PointGrid grid;  // for adjacency and tracking
  std::vector<std::vector<std::pair<int, int>>> adjacency_found;  // adjacency(): per range of supervoxels
  std::vector<Eigen::Vector3f> centroids;
  std::vector<Eigen::Vector3d> object_cloud;  // classify(): visible + hidden object voxels
  std::vector<Eigen::Vector3f> object_points;  // the same, hashed in object_grid (interacting elements)
  detail::PointGrid object_grid;
  // Classes::Labels: the frame's label of each supervoxel (split_by_labels()).
  std::vector<std::uint16_t> supervoxel_labels;
  // Per voxel of the current frame: may it enter the object state? In
  // tracking only voxels that matched the state themselves do, so the
  // foreign voxels of a mixed boundary supervoxel (a hand's, the table's)
  // never become object and cannot pull their neighbours in next frame.
  std::vector<char> voxel_matched;
  std::vector<char> voxel_revealed;  // revealed object surface (grow_revealed()), remembered
  // Per voxel of the current frame that track() matched: the chromaticity
  // of the memory voxel it matched, which it is remembered with (empty:
  // every voxel is remembered with its own).
  std::vector<Eigen::Vector3f> voxel_anchor;
  detail::VoxelContacts contacts;    // grow_revealed(), classify(): which supervoxels come near one another
  // object_motion(): the frame's object voxels (hashed), normals and
  // chromaticities, and the voxels on the object's own outline with the
  // outline's outward normal, of this frame and of the previous one.
  std::vector<Eigen::Vector3f> moved;
  std::vector<Eigen::Vector3f> moved_normals;
  detail::PointGrid moved_grid;
  std::vector<Eigen::Vector3f> moved_chroma;
  std::vector<Eigen::Vector3f> outline, outline_normals;
  // Where an occluder cuts the seen object (object_motion()): the last
  // surface point, the outline's outward direction, the surface's
  // chromaticity there, and how much nearer the camera the occluder is [m].
  struct Cut {
    Eigen::Vector3f point, outward, chroma;
    double gap;
  };
  std::vector<Cut> cuts;
  detail::PointGrid around;  // behind_occluders(): the seen voxels near a cut
  std::vector<Eigen::Vector3d> near_cut;
  std::vector<Eigen::Vector3f> previous_outline, previous_outline_normals;
  detail::PointGrid outline_grid;

  // Object state carried from frame to frame (world frame).
  bool initialised = false;
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
  std::vector<Eigen::Vector3f> memory;  // object voxels: seen now, or hidden behind something
  std::vector<Eigen::Vector3f> memory_chroma;  // chromaticity of each memory voxel
  std::vector<int> memory_age;                 // frames since the voxel was last seen
  std::vector<Eigen::Vector3f> memory_normal;  // its supervoxel's normal then (0: none)
  detail::PointGrid seen_grid;                 // the frame's object voxels (remember())
  std::vector<Eigen::Vector3f> holder;  // holder_body: the holder's voxels when last seen (grow_holder())
  int holder_age = 0;                   // frames since the holder was last seen
  struct Grip {  // taken_by_hand(): the touching body's voxels when it first touched the object
    std::vector<Eigen::Vector3f> still;  // where they were
    std::vector<Eigen::Vector3f> moved;  // carried by the object's motion since
    void clear() {
      still.clear();
      moved.clear();
    }
  } grip;
  detail::PointGrid holder_grid;
  detail::PointGrid base_grid;  // grow_holder(): the holder's body, for its base on the plane
  // classify(): the previous frame's occluder voxels off the support plane,
  // but for those of bodies that touched the object without coming as
  // occluders (`native`, grow_holder()); hashed in foreign_grid by
  // grow_holder(): what touches the object after coming as an occluder
  // stays one.
  std::vector<Eigen::Vector3f> foreign_voxels;
  detail::PointGrid foreign_grid;
  std::vector<char> native;  // per supervoxel of the frame (grow_holder())
  std::size_t initial_voxels = 0;        // object voxels in the first frame (seen whole)
  bool incomplete = false;  // the first frame showed an occluder cutting the object (behind_occluders())
  RgbdFrame previous;  // the previous frame's depth, pose and intrinsics (no colour), with grow_revealed: grow_revealed()
  std::optional<Eigen::Vector4d> plane;  // dominant (support) plane found in the first frame
  Eigen::Vector3f plane_chroma = Eigen::Vector3f::Zero();  // its mean chromaticity

  /// True for a voxel of the support plane: on it, and of its colour.
  [[nodiscard]] bool plane_voxel(const Eigen::Vector3f& p, const Eigen::Vector3f& rgb) const {
    return plane &&
           std::abs(plane->head<3>().cast<float>().dot(p) + static_cast<float>((*plane)(3))) <=
               static_cast<float>(settings.tracking.plane_distance) &&
           (settings.tracking.max_chroma_distance <= 0.0 ||
            (chromaticity(rgb) - plane_chroma).norm() <=
                static_cast<float>(settings.tracking.max_chroma_distance));
  }

  /// True for a supervoxel lying on the support plane: centroid on it and
  /// normal within 60 degrees of the plane's. The foot of an object standing
  /// on the plane is near it too, but faces another way; supervoxels that
  /// straddle the foot and the plane have normals in between and go with
  /// the plane.
  [[nodiscard]] bool on_plane(const SupervoxelInfo& s) const {
    return plane &&
           std::abs(plane->head<3>().dot(s.centroid) + (*plane)(3)) <=
               settings.tracking.plane_distance &&
           std::abs(plane->head<3>().dot(s.normal)) >= std::cos(kPi / 3.0);
  }

  // The stages, in the order process() runs them.

  /// pipeline.cpp: the whole frame.
  PerceptionResult process(const RgbdFrame& frame);
  /// pipeline.cpp: r.adjacency, the pairs of supervoxels within R_adj (paper eq. 1).
  void adjacency(PerceptionResult& r);
  /// object_selection.cpp: the first frame's object supervoxels (1 = object);
  /// fits the support plane and sets voxel_matched. `why` says why none is found.
  std::vector<char> select(const RgbdFrame& frame, const PerceptionResult& r, std::string& why);
  /// object_selection.cpp: the support plane (RANSAC: a plane holding a
  /// fifth of the cloud outside the selection, or of the whole cloud with
  /// Mode::Auto) and its colour; supervoxels on it are never object.
  void fit_support_plane(const RgbdFrame& frame, const PerceptionResult& r);
  /// labelled.cpp (Classes::Labels): every supervoxel cut where the frame's
  /// labels change; supervoxel_labels holds each piece's label.
  void split_by_labels(const RgbdFrame& frame);
  /// labelled.cpp (tracking): the voxels of an object supervoxel that are not
  /// the object's cut off, pieces after the supervoxels: those of the
  /// support plane (plane_voxel()), and those that neither match the
  /// remembered object (voxel_matched) nor were revealed and are unlike the
  /// colour its matched voxels remember (voxel_anchor; twice
  /// max_chroma_distance). Whether one was.
  bool split_off_others(const RgbdFrame& frame, const std::vector<char>& object);
  /// labelled.cpp: sv's supervoxels replaced by pieces: `owner` each voxel's
  /// piece, `whole` each piece's supervoxel before; a piece's centroid,
  /// colour and count from its voxels, its normal its own where it is a flat
  /// part of its supervoxel (else the supervoxel's).
  void cut_supervoxels(const RgbdFrame& frame, std::vector<int> owner, const std::vector<int>& whole);
  /// labelled.cpp (Classes::Labels): the supervoxels labelled object (the
  /// first frame also fits the support plane); sets voxel_matched.
  std::vector<char> labelled_object(const RgbdFrame& frame, const PerceptionResult& r);
  /// object_memory.cpp: a later frame's object supervoxels, those near the
  /// remembered object voxels; sets voxel_matched.
  std::vector<char> track(const RgbdFrame& frame, const PerceptionResult& r);
  /// The nearest memory voxel of chromaticity c (within max_chroma_distance)
  /// within radius (<= the cell of `grid`, built on `memory`) of p; -1: none.
  [[nodiscard]] int remembered_match(const Eigen::Vector3f& p, float radius, const Eigen::Vector3f& c) const;
  [[nodiscard]] bool remembered_near(const Eigen::Vector3f& p, float radius, const Eigen::Vector3f& c) const {
    return remembered_match(p, radius, c) >= 0;
  }
  /// Grows `object` over surface the previous frame could not see (TrackingSettings::grow_revealed).
  void grow_revealed(const RgbdFrame& frame, const PerceptionResult& r, const std::vector<int>& near,
                     std::vector<char>& object);
  /// pipeline.cpp: r.status and r.message from the object found; the first
  /// frame found also sets the state's start (initialised, initial_voxels).
  void set_status(const RgbdFrame& frame, PerceptionResult& r, const std::vector<char>& object, std::string why);
  /// The memory voxels whose normal faces the frame's camera (or that have
  /// none) and whose pixel has a depth, nearer or not: as many object
  /// voxels as the view could show (the sensor measures no surface seen
  /// too obliquely).
  [[nodiscard]] std::size_t remembered_in_view(const RgbdFrame& frame) const;
  /// object_memory.cpp: the object's rigid motion from the previous frame
  /// to this one (world frame), from its visible voxels matched against the
  /// memory; identity when it cannot be told (TrackingSettings::follow_motion).
  /// Also finds the frame's outline and its cuts (`cuts`).
  Eigen::Isometry3d object_motion(const RgbdFrame& frame, const PerceptionResult& r,
                                  const std::vector<char>& object);
  /// object_memory.cpp: the memory updated with the frame's object; its
  /// hidden part moved by object_motion() first; then behind_occluders().
  void remember(const RgbdFrame& frame, PerceptionResult& r, const std::vector<char>& object);
  /// object_memory.cpp: the object presumed to go on behind the occluders
  /// that cut it, as hidden memory voxels (PerceptionSettings::behind_occluders);
  /// sets r.counts.presumed_voxels.
  void behind_occluders(const RgbdFrame& frame, PerceptionResult& r);
  /// classify.cpp: C, axes, OBB, labels and r.problem.
  void classify(const RgbdFrame& frame, PerceptionResult& r, const std::vector<char>& object);
  /// holder_body: marks interacting the holder's body beyond the box (PerceptionSettings::holder_body).
  void grow_holder(const PerceptionResult& r, const std::vector<char>& object, const Eigen::Vector3d& c,
                   std::vector<char>& interacting);
  /// classify.cpp: whether the bodies `toucher` (touching the object, not
  /// its holder) have moved with the object since they first touched it.
  bool taken_by_hand(const PerceptionResult& r, const std::vector<char>& toucher);
  /// classify.cpp: occluder points beyond the image border, where the
  /// occluders the border cuts continue (PerceptionSettings::beyond_view),
  /// appended to r.problem.occluders.
  void beyond_view(const RgbdFrame& frame, PerceptionResult& r) const;
  /// classify.cpp: the remembered hidden voxels as vertices of p, after its
  /// `seen` columns (TrackingSettings::hidden_vertices).
  void hidden_vertices(ViewProblem& p, std::size_t seen) const;
};

}  // namespace ofv::perception
