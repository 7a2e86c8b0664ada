// Later frames: the object is found near the voxels remembered from the
// previous frames; the memory is then updated with what is seen, and keeps
// for a while what is hidden.
#include "front_end.h"

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <utility>
#include <vector>

namespace ofv::perception {

namespace {
/// A surface facing a camera at less than this cosine (17 degrees from
/// edge-on) gives it too few and too noisy pixels to be told apart.
constexpr double kGrazing = 0.3;

/// Nearest of `points` (hashed in `grid`, cells >= radius) to p within
/// radius that has accept(j); -1 when none.
template <typename Accept>
int nearest(const detail::PointGrid& grid, const std::vector<Eigen::Vector3f>& points,
            const Eigen::Vector3f& p, float radius, Accept&& accept) {
  int best = -1;
  float best_d2 = radius * radius;
  grid.for_each_near(p, [&](int j) {
    const float d2 = (points[static_cast<std::size_t>(j)] - p).squaredNorm();
    if (d2 <= best_d2 && accept(j)) {
      best_d2 = d2;
      best = j;
    }
  });
  return best;
}
}  // namespace

std::vector<char> Perception::Impl::track(const RgbdFrame& frame, const PerceptionResult& r) {
  const std::size_t n = r.supervoxels.size();
  const TrackingSettings& t = settings.tracking;
  grid.build(memory, t.max_motion);
  std::vector<int> near(n, 0);
  voxel_matched.assign(r.voxels.size(), 0);
  voxel_anchor.resize(r.voxels.size());
  const auto radius = static_cast<float>(t.max_motion);
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    const int match = plane_voxel(r.voxels[i], sv.colours[i])
                          ? -1
                          : remembered_match(r.voxels[i], radius, chromaticity(sv.colours[i]));
    near[owner] += match >= 0 ? 1 : 0;
    voxel_matched[i] = match >= 0 ? 1 : 0;
    // Remembered with the chromaticity it matched, not its own: a voxel
    // mixing the object's colour with a touching hand's may match, but
    // cannot carry the match a step further towards the hand's colour in
    // the next frame (cloth-fold: step by step, the whole hand joined).
    if (match >= 0) voxel_anchor[i] = memory_chroma[static_cast<std::size_t>(match)];
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
  if (t.grow_revealed) grow_revealed(frame, r, near, object);
  return object;
}

int Perception::Impl::remembered_match(const Eigen::Vector3f& p, float radius, const Eigen::Vector3f& c) const {
  const auto max_chroma = static_cast<float>(settings.tracking.max_chroma_distance);
  return nearest(grid, memory, p, radius, [&](int j) {
    return max_chroma <= 0.0f || (memory_chroma[static_cast<std::size_t>(j)] - c).norm() <= max_chroma;
  });
}

void Perception::Impl::grow_revealed(const RgbdFrame& frame, const PerceptionResult& r, const std::vector<int>& near,
                                     std::vector<char>& object) {
  if (previous.depth.empty()) return;
  const TrackingSettings& t = settings.tracking;
  const std::size_t n = r.supervoxels.size();
  const auto res = static_cast<float>(settings.supervoxels.voxel_resolution);
  const auto radius = static_cast<float>(t.max_motion);
  // Surface the previous frame could not show, voxel by voxel (so that a
  // hand never joins through a supervoxel that mixes it with the object):
  // - hidden: behind a surface nearer its camera by more than max_motion.
  //   The voxel is the object's when that surface was the object (a
  //   remembered voxel of the voxel's chromaticity: its own fold hid it).
  // - unseen: beyond its image, on a pixel it had no depth for, or on a
  //   surface that faced its camera at less than kGrazing (seen edge-on or
  //   from behind: the top of a box the camera rises over, whose grazing
  //   pixels a sensor drops; a part the first image cut). Nothing tells
  //   whose it is but what it touches: the object's when its component
  //   (below) touches the object through a neighbour of the object's colour.
  const Eigen::Isometry3d cMw = previous.wMc.inverse();
  const Eigen::Vector3d eye = previous.wMc.translation();
  std::vector<int> seen_before(n, 0);  // voxels the previous frame showed where they are, not edge-on
  std::vector<int> revealed(n, 0);     // voxels the object hid from it
  std::vector<int> unseen(n, 0);       // voxels beyond its image, without depth or edge-on to it
  std::vector<char> voxel_state(r.voxels.size(), 0);  // 1 hidden by the object, 2 unseen
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    const SupervoxelInfo& s = r.supervoxels[owner];
    if (object[owner] || plane_voxel(r.voxels[i], sv.colours[i])) continue;
    const Eigen::Vector3d p = r.voxels[i].cast<double>();
    const auto l = detail::look(previous, cMw, p);
    if (l && !l->measured()) {
      voxel_state[i] = 2;
      ++unseen[owner];
      continue;
    }
    const double d = l ? static_cast<double>(l->observed) : 0.0;
    if (l && d < l->z - t.max_motion) {
      const Eigen::Vector3f hider = detail::unproject(previous, l->u, l->v, d).cast<float>();
      if (remembered_near(hider, res, chromaticity(sv.colours[i]))) {
        voxel_state[i] = 1;
        ++revealed[owner];
      }
      continue;
    }
    // (A supervoxel too small for a normal tells nothing of its facing.)
    const bool edge_on = s.normal_valid && s.normal.dot((eye - p).normalized()) < kGrazing;
    if (!l || edge_on) {
      voxel_state[i] = 2;
      ++unseen[owner];
    } else if (s.normal_valid && std::abs(d - l->z) <= t.max_motion) {
      ++seen_before[owner];
    }
  }
  const auto any = [](const std::vector<int>& v) { return std::any_of(v.begin(), v.end(), [](int c) { return c > 0; }); };
  if (!any(revealed) && !any(unseen)) return;
  // A supervoxel joins when its revealed voxels (and its unseen ones, when
  // its component touches the object) and those near the memory make
  // min_near_fraction of it; the revealed voxels of one that does not yet
  // (revealed a strip at a time) are remembered, so that it joins once
  // enough of it is. Ambiguous, and left out: one linked, through
  // neighbours of one chromaticity that are not the object's, to a surface
  // of that colour the previous frame showed that is not the object's
  // (supervoxels most of whose voxels it showed, none near the memory: one
  // covering a seed cell's face or more, or together a quarter of the
  // component's voxels; a few smaller ones on a surface seen grazing, their
  // normals too noisy to tell their facing, do not): a distractor whose
  // side the object hid could be either's, and a hand of the object's
  // colour that touches it is one. Neighbours: two voxels within R_adj (eq. 1's
  // distance, here between voxels, not centroids: a strip revealed along a
  // distractor's edge, seen grazing, is a broken line of voxels whose
  // centroids lie farther than R_adj from the part it continues).
  const auto alike = [&](std::size_t x, std::size_t y) {
    return detail::alike(r.supervoxels[x].colour, r.supervoxels[y].colour, t.max_chroma_distance);
  };
  const auto candidate = [&](std::size_t j) { return !object[j] && !on_plane(r.supervoxels[j]); };
  contacts.build(r, settings.supervoxels.adjacency_alpha * settings.supervoxels.seed_resolution,
                 [&](std::size_t j) { return !on_plane(r.supervoxels[j]); });
  const double per_side = settings.supervoxels.seed_resolution / settings.supervoxels.voxel_resolution;
  const int cell_face = std::max(1, static_cast<int>(per_side * per_side));  // voxels on a seed cell's face
  const Eigen::Isometry3d frame_cMw = frame.wMc.inverse();
  const auto gap_seen = [&](const Eigen::Vector3f& p, const Eigen::Vector3f& q) {
    for (const float s : {0.25f, 0.5f, 0.75f}) {
      const auto l = detail::look(frame, frame_cMw, (p + s * (q - p)).cast<double>());
      if (l && l->measured() && static_cast<double>(l->observed) > l->z + settings.contact_distance) return true;
    }
    return false;
  };
  const auto seen_not_object = [&](std::size_t j) {
    return 2 * seen_before[j] > r.supervoxels[j].voxel_count && near[j] == 0;
  };
  // From each revealed or unseen supervoxel, its component (of candidates
  // linked to alike neighbours); a component is searched once.
  std::vector<int> component(n, -1);
  std::vector<char> component_ambiguous;
  std::vector<char> component_touches;  // linked to an object supervoxel of its colour
  std::vector<std::size_t> open;
  for (std::size_t j = 0; j < n; ++j) {
    if ((revealed[j] == 0 && unseen[j] == 0) || component[j] >= 0 || !candidate(j)) continue;
    const int id = static_cast<int>(component_ambiguous.size());
    int voxels = 0;
    int seen_voxels = 0;
    bool seen_surface = false;
    bool touches = false;
    component[j] = id;
    open.assign(1, j);
    while (!open.empty()) {
      const std::size_t x = open.back();
      open.pop_back();
      const int count = r.supervoxels[x].voxel_count;
      voxels += count;
      if (seen_not_object(x)) {
        seen_voxels += count;
        seen_surface = seen_surface || count >= cell_face;
      }
      contacts.for_each_pair(x, [&](std::size_t y, const Eigen::Vector3f& p, const Eigen::Vector3f& q) {
        if (!alike(x, y)) return;
        if (object[y]) {
          // Touching the object: a voxel within R_adj of an object voxel
          // where the object is of this colour (its memory there: an object
          // supervoxel at its border can mix its colour with what touches
          // it, and through it a hand's sides, edge-on to the previous
          // frame, joined the object: cloth-fold), with no empty space seen
          // between the two (the frame shows what lies behind the gap: a box
          // of the object's colour a few centimetres beside it is not its
          // continuation).
          touches = touches ||
                    (remembered_near(q, radius, chromaticity(r.supervoxels[x].colour)) && !gap_seen(p, q));
        } else if (component[y] < 0) {
          component[y] = id;
          open.push_back(y);
        }
      });
    }
    const bool ambiguous = seen_surface || 4 * seen_voxels >= voxels;
    component_ambiguous.push_back(ambiguous ? 1 : 0);
    component_touches.push_back(touches ? 1 : 0);
  }
  std::vector<char> reached(n, 0);
  std::vector<char> counts_unseen(n, 0);
  for (std::size_t j = 0; j < n; ++j) {
    if ((revealed[j] == 0 && unseen[j] == 0) || !candidate(j)) continue;
    const auto id = static_cast<std::size_t>(component[j]);
    if (component_ambiguous[id]) continue;
    reached[j] = 1;
    counts_unseen[j] = component_touches[id];
    const int counted = revealed[j] + near[j] + (counts_unseen[j] ? unseen[j] : 0);
    object[j] = static_cast<double>(counted) >= t.min_near_fraction * static_cast<double>(r.supervoxels[j].voxel_count);
  }
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    voxel_revealed[i] = reached[owner] && (voxel_state[i] == 1 || (voxel_state[i] == 2 && counts_unseen[owner])) ? 1 : 0;
  }
}

namespace {

/// The plane of points `d` (mean, unit normal): least squares, refitted
/// three times to the points within `inlier` of the last fit, so that the
/// larger face wins where two meet; nullopt with fewer than 10 on it.
std::optional<std::pair<Eigen::Vector3d, Eigen::Vector3d>> surface_plane(const std::vector<Eigen::Vector3d>& d,
                                                                         double inlier) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  Eigen::Vector3d normal = Eigen::Vector3d::Zero();
  for (int fit = 0; fit < 3; ++fit) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    std::size_t count = 0;
    for (const Eigen::Vector3d& x : d) {
      if (fit > 0 && std::abs(normal.dot(x - mean)) > inlier) continue;
      sum += x;
      scatter += x * x.transpose();
      ++count;
    }
    if (count < 10) return std::nullopt;
    mean = sum / static_cast<double>(count);
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter / static_cast<double>(count) -
                                                             mean * mean.transpose());
    normal = eig.eigenvectors().col(0);
  }
  return std::make_pair(mean, normal);
}

}  // namespace

Eigen::Isometry3d Perception::Impl::object_motion(const RgbdFrame& frame,
                                                  const PerceptionResult& r,
                                                  const std::vector<char>& object) {
  const TrackingSettings& t = settings.tracking;
  const double res = settings.supervoxels.voxel_resolution;
  // The frame's object voxels (those that may enter the memory), each with
  // its supervoxel's normal.
  moved.clear();
  moved_normals.clear();
  moved_chroma.clear();
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    if (object[owner] && voxel_matched[i]) {
      moved.push_back(r.voxels[i]);
      moved_chroma.push_back(chromaticity(sv.colours[i]));
      moved_normals.push_back(r.supervoxels[owner].normal_valid
                                  ? Eigen::Vector3f(r.supervoxels[owner].normal.cast<float>())
                                  : Eigen::Vector3f::Zero());
    }
  }

  // Its outline: voxels whose neighbours lie to one side within the surface.
  // Only the object's own outline tells how it moves in its plane; where an
  // occluder (something nearer the camera just outside) or the image border
  // cuts it, or nothing is seen there, the outline stays where the cut is.
  const auto neighbourhood = static_cast<float>(1.5 * res);
  moved_grid.build(moved, neighbourhood);
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const CameraIntrinsics& k = frame.intrinsics;
  const double in_front = 0.5 * t.max_motion;
  // The outline found in the depth image, to the pixel: from voxel p walk
  // outward (m) over the pixels while they show the surface; the last one is
  // the edge. nullopt when what lies beyond is nearer the camera (an
  // occluder cuts the object there: the last surface point and how much
  // nearer the occluder is go to `cut`; the object's own nearer part is no
  // cut) or the walk leaves the image.
  const auto edge = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& m,
                        std::optional<std::pair<Eigen::Vector3f, double>>& cut) -> std::optional<Eigen::Vector3f> {
    double z0 = 0.0;
    double z1 = 0.0;
    const auto p0 = detail::project(frame, cMw, p, &z0);
    const auto p1 = detail::project(frame, cMw, p + res * m, &z1);
    if (!p0 || !p1) return std::nullopt;
    const Eigen::Vector2d step = *p1 - *p0;
    const double pixels_per_voxel = step.norm();
    if (!(pixels_per_voxel > 0.5)) return std::nullopt;
    const Eigen::Vector2d dir = step / pixels_per_voxel;
    const int max_steps = static_cast<int>(std::ceil(3.0 * pixels_per_voxel));
    std::optional<Eigen::Vector3f> last;
    double z_last = z0;
    int s_last = max_steps;
    for (int s = 0; s <= max_steps; ++s) {
      const Eigen::Vector2d px = *p0 + static_cast<double>(s) * dir;
      const int u = static_cast<int>(std::lround(px.x()));
      const int v = static_cast<int>(std::lround(px.y()));
      if (u < 0 || v < 0 || u >= k.width || v >= k.height) return std::nullopt;
      const float observed = frame.depth[frame.index(u, v)];
      if (!(std::isfinite(observed) && observed > 0.0f)) continue;  // drop-out: look further
      // Depth expected on the surface here (it may be slanted).
      const double expected = z0 + (z1 - z0) * static_cast<double>(s) / pixels_per_voxel;
      const auto d = static_cast<double>(observed);
      if (std::abs(d - expected) <= in_front && std::abs(d - z_last) <= in_front) {
        last = detail::unproject(frame, px.x(), px.y(), d).cast<float>();
        z_last = d;
        s_last = s;
        continue;
      }
      if (d < expected - in_front) {  // occluded edge
        // By the object's own nearer part (a cloth's fold), no occluder cuts it.
        const Eigen::Vector3f q = detail::unproject(frame, px.x(), px.y(), d).cast<float>();
        if (!moved_grid.any_within(q, neighbourhood, [](int) { return true; })) {
          cut.emplace(last ? *last : p.cast<float>(), expected - d);
        }
        return std::nullopt;
      }
      if (!last) return std::nullopt;
      return s_last < max_steps ? last : std::nullopt;
    }
    // Nothing seen beyond the surface (out of range, or drop-outs): the
    // edge, if the walk went a pixel or more past it.
    return last;
  };
  outline.clear();
  outline_normals.clear();
  cuts.clear();
  for (std::size_t i = 0; i < moved.size(); ++i) {
    const Eigen::Vector3f& p = moved[i];
    Eigen::Vector3f offset = Eigen::Vector3f::Zero();
    int count = 0;
    moved_grid.for_each_near(p, [&](int j) {
      const Eigen::Vector3f d = moved[static_cast<std::size_t>(j)] - p;
      if (static_cast<std::size_t>(j) != i && d.squaredNorm() <= neighbourhood * neighbourhood) {
        offset += d;
        ++count;
      }
    });
    if (count == 0) continue;
    offset /= static_cast<float>(count);
    const Eigen::Vector3f& n = moved_normals[i];
    offset -= n * n.dot(offset);  // within the surface (n = 0: as is)
    if (offset.norm() < static_cast<float>(0.35 * res)) continue;  // inside
    const Eigen::Vector3f m = -offset.normalized();
    std::optional<std::pair<Eigen::Vector3f, double>> cut;
    if (const auto e = edge(p.cast<double>(), m.cast<double>(), cut)) {
      outline.push_back(*e);
      outline_normals.push_back(m);
    } else if (cut) {
      cuts.push_back({cut->first, m, moved_chroma[i], cut->second});
    }
  }

  Eigen::Isometry3d motion = Eigen::Isometry3d::Identity();
  const std::size_t min_points = 20;
  if (t.follow_motion && memory.size() >= min_points && moved.size() >= min_points) {
    // Gauss-Newton on A, this frame -> the previous (x -> R (x - c) + c + t,
    // small angles): point-to-plane to the nearest memory voxel, and along
    // the outline's normal to the nearest previous outline voxel facing the
    // same way. A weak prior on zero motion keeps what nothing constrains at zero.
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const Eigen::Vector3f& p : moved) c += p.cast<double>();
    c /= static_cast<double>(moved.size());
    const auto radius = static_cast<float>(t.max_motion);
    grid.build(memory, t.max_motion);
    outline_grid.build(previous_outline, t.max_motion);
    Eigen::Isometry3d a = Eigen::Isometry3d::Identity();
    std::size_t matched = 0;
    for (int iteration = 0; iteration < 6; ++iteration) {
      Eigen::Matrix<double, 6, 6> h = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> g = Eigen::Matrix<double, 6, 1>::Zero();
      matched = 0;
      const auto add = [&](const Eigen::Vector3d& x, const Eigen::Vector3d& dir, double residual,
                           bool turns) {
        // Huber weight: a voxel off by more than half a voxel counts less.
        const double w = std::min(1.0, 0.5 * res / std::max(std::abs(residual), 1e-12));
        Eigen::Matrix<double, 6, 1> j;
        j.head<3>() = turns ? Eigen::Vector3d((x - c).cross(dir)) : Eigen::Vector3d::Zero();
        j.tail<3>() = dir;
        h += w * j * j.transpose();
        g += w * j * residual;
      };
      for (std::size_t i = 0; i < moved.size(); ++i) {
        if (moved_normals[i].isZero()) continue;
        const Eigen::Vector3d x = a * moved[i].cast<double>();
        const int q = nearest(grid, memory, x.cast<float>(), radius, [](int) { return true; });
        if (q < 0) continue;
        ++matched;
        const Eigen::Vector3d n = a.linear() * moved_normals[i].cast<double>();
        add(x, n, n.dot(x - memory[static_cast<std::size_t>(q)].cast<double>()), true);
      }
      for (std::size_t i = 0; i < outline.size(); ++i) {
        const Eigen::Vector3d x = a * outline[i].cast<double>();
        const Eigen::Vector3d m = a.linear() * outline_normals[i].cast<double>();
        const int q = nearest(outline_grid, previous_outline, x.cast<float>(), radius, [&](int j) {
          return previous_outline_normals[static_cast<std::size_t>(j)].cast<double>().dot(m) > 0.7;
        });
        if (q < 0) continue;
        // Translation only: the outline is too coarse to tell a turn.
        add(x, m, m.dot(x - previous_outline[static_cast<std::size_t>(q)].cast<double>()), false);
      }
      if (matched < min_points) break;
      Eigen::Matrix<double, 6, 1> prior;
      prior << Eigen::Vector3d::Constant(2.0 * 0.05 * 0.05), Eigen::Vector3d::Constant(2.0);
      h.diagonal() += prior;
      const Eigen::Matrix<double, 6, 1> step = -h.ldlt().solve(g);
      if (!step.allFinite()) break;
      Eigen::Isometry3d update = Eigen::Isometry3d::Identity();
      const double angle = step.head<3>().norm();
      if (angle > 0.0) {
        update.linear() = Eigen::AngleAxisd(angle, step.head<3>() / angle).toRotationMatrix();
      }
      update.translation() = c - update.linear() * c + step.tail<3>();
      a = update * a;
      if (step.tail<3>().norm() < 1e-5 && angle < 1e-4) break;
    }
    // The motion is small (paper assumption 2): anything else is a wrong fit.
    const Eigen::Isometry3d d = a.inverse();
    const double angle = Eigen::AngleAxisd(d.linear()).angle();
    const double displacement = (d * c - c).norm();
    if (matched >= moved.size() / 2 && matched >= min_points && displacement <= t.max_motion &&
        angle <= 0.1) {
      motion = d;
    }
  }
  previous_outline.swap(outline);
  previous_outline_normals.swap(outline_normals);
  return motion;
}

void Perception::Impl::remember(const RgbdFrame& frame, PerceptionResult& r,
                                const std::vector<char>& object) {
  // Old object voxels not seen in this frame (behind something nearer the
  // camera, out of the image, or on a pixel with no depth away from the seen
  // surface) stay in the state for a while, so that the object's occluded
  // part is recognised when it reappears and stays part of the object
  // (classify()). They follow the object's motion, estimated from what is
  // seen of it.
  const Eigen::Isometry3d motion = object_motion(frame, r, object);
  const Eigen::Isometry3f motion_f = motion.cast<float>();
  for (Eigen::Vector3f& p : holder) p = motion_f * p;  // the holder moves with what it holds
  for (Eigen::Vector3f& p : grip.moved) p = motion_f * p;
  std::vector<Eigen::Vector3f> next;
  std::vector<Eigen::Vector3f> next_chroma;
  std::vector<int> next_age;
  std::vector<Eigen::Vector3f> next_normal;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    if ((object[owner] && voxel_matched[i]) || voxel_revealed[i]) {
      const SupervoxelInfo& s = r.supervoxels[owner];
      next.push_back(r.voxels[i]);
      next_chroma.push_back(voxel_matched[i] && !voxel_anchor.empty() ? voxel_anchor[i] : chromaticity(sv.colours[i]));
      next_age.push_back(0);
      next_normal.push_back(s.normal_valid ? Eigen::Vector3f(s.normal.cast<float>())
                                           : Eigen::Vector3f::Zero());
    }
  }
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const double tolerance = settings.tracking.max_motion;
  const int max_age = settings.tracking.occlusion_memory_frames;
  // A pixel with no depth hides the voxel only when the frame does not show
  // the same voxel (within half a voxel) through other pixels: a drop-out
  // amid the seen surface does not hide it.
  const auto res = static_cast<float>(settings.supervoxels.voxel_resolution);
  seen_grid.build(next, res);
  const auto unseen = [&](const Eigen::Vector3f& p) {
    switch (detail::sight(frame, cMw, p.cast<double>(), tolerance)) {
      case detail::Sight::Hidden: return true;
      case detail::Sight::NoDepth: return !seen_grid.any_within(p, 0.5f * res, [](int) { return true; });
      case detail::Sight::Shown: return false;
    }
    return false;
  };
  for (std::size_t i = 0; i < memory.size(); ++i) {
    memory[i] = motion_f * memory[i];
    if (memory_age[i] + 1 <= max_age && unseen(memory[i])) {
      next.push_back(memory[i]);
      next_chroma.push_back(memory_chroma[i]);
      next_age.push_back(memory_age[i] + 1);
      next_normal.push_back(motion_f.linear() * memory_normal[i]);
    }
  }
  memory.swap(next);
  memory_chroma.swap(next_chroma);
  memory_age.swap(next_age);
  memory_normal.swap(next_normal);
  behind_occluders(frame, r);
}

void Perception::Impl::behind_occluders(const RgbdFrame& frame, PerceptionResult& r) {
  // The cuts by an occluder: nearer the camera than the OBB's margin, so
  // not a hand holding the object by its edge.
  const double min_gap = settings.obb_margin;
  const auto deep = static_cast<std::size_t>(
      std::count_if(cuts.begin(), cuts.end(), [&](const Cut& c) { return c.gap > min_gap; }));
  if (r.status == TrackingStatus::Initialised) {
    // A few voxels (not noise), and no more than the object's own outline
    // (object_motion() has just made the frame's outline the previous one):
    // one side cut, not an object seen through the gaps of a cage, whose
    // seen parts tell too little of the rest.
    incomplete = deep >= 3 && deep <= previous_outline.size();
  } else if (deep == 0) {
    incomplete = false;  // seen with nothing in front: its extent is known
  }
  if (!settings.behind_occluders || !incomplete || moved.empty()) return;

  const auto res = static_cast<float>(settings.supervoxels.voxel_resolution);
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const CameraIntrinsics& k = frame.intrinsics;
  const double tolerance = settings.tracking.max_motion;
  using Cell = Eigen::Matrix<std::int64_t, 3, 1>;
  struct Presumed {
    Cell cell;
    std::size_t cut;
    Eigen::Vector3f p, normal;
  };
  std::vector<Presumed> found;
  const auto reach = static_cast<float>(2.0 * settings.supervoxels.seed_resolution);
  const double camera_side =
      plane ? (plane->head<3>().dot(frame.wMc.translation()) + (*plane)(3) < 0.0 ? -1.0 : 1.0) : 1.0;
  around.build(moved, reach);
  for (std::size_t c = 0; c < cuts.size(); ++c) {
    const Cut& cut = cuts[c];
    if (!(cut.gap > min_gap)) continue;
    // The plane of the seen surface around the cut (a supervoxel's normal
    // bends at the object's edges).
    near_cut.clear();
    around.for_each_near(cut.point, [&](int j) {
      const Eigen::Vector3f d = moved[static_cast<std::size_t>(j)] - cut.point;
      if (d.squaredNorm() <= reach * reach) near_cut.push_back(d.cast<double>());
    });
    const auto fitted = surface_plane(near_cut, 0.5 * res);
    if (!fitted) continue;
    Eigen::Vector3f normal = fitted->second.cast<float>();
    const Eigen::Vector3f start = cut.point + normal * normal.dot(fitted->first.cast<float>());
    if (normal.dot(frame.wMc.translation().cast<float>() - start) < 0.0f) normal = -normal;
    Eigen::Vector3f outward = cut.outward - normal * normal.dot(cut.outward);
    if (outward.norm() < 0.5f) continue;
    outward.normalize();
    // Across the line of sight only: a surface seen at a grazing angle (the
    // top of a box seen from above) is not continued towards the camera.
    const Eigen::Vector3f ray = (start - frame.wMc.translation().cast<float>()).normalized();
    if (std::abs(ray.dot(outward)) > 0.5f) continue;
    // The surface continued in its plane, outwards from the cut, while a
    // surface nearer the camera hides it there, and at most as far as the
    // seen part is wide that way.
    float lo = 0.0f, hi = 0.0f;
    for (const Eigen::Vector3f& p : moved) {
      const float x = outward.dot(p - start);
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
    const int steps = static_cast<int>(std::ceil((hi - lo) / res));
    for (int j = 1; j <= steps; ++j) {
      const Eigen::Vector3f q = start + (static_cast<float>(j) * res) * outward;
      double z = 0.0;
      const auto px = detail::project(frame, cMw, q.cast<double>(), &z);
      if (!px) break;
      const int u = static_cast<int>(std::lround(px->x()));
      const int v = static_cast<int>(std::lround(px->y()));
      if (u < 0 || v < 0 || u >= k.width || v >= k.height) break;
      const float observed = frame.depth[frame.index(u, v)];
      if (!(std::isfinite(observed) && static_cast<double>(observed) < z - tolerance)) break;
      // Not into or behind the support plane, nor hidden by it.
      if (plane) {
        const auto d = static_cast<double>(observed);
        const Eigen::Vector3d hider = detail::unproject(frame, px->x(), px->y(), d);
        const double side = plane->head<3>().dot(q.cast<double>()) + (*plane)(3);
        if (side * camera_side <= settings.tracking.plane_distance ||
            std::abs(plane->head<3>().dot(hider) + (*plane)(3)) <= settings.tracking.plane_distance) {
          break;
        }
      }
      found.push_back({(q / res).array().floor().cast<std::int64_t>(), c, q, normal});
    }
  }
  std::sort(found.begin(), found.end(), [](const Presumed& a, const Presumed& b) {
    return std::lexicographical_compare(a.cell.data(), a.cell.data() + 3, b.cell.data(), b.cell.data() + 3);
  });
  found.erase(std::unique(found.begin(), found.end(),
                          [](const Presumed& a, const Presumed& b) { return a.cell == b.cell; }),
              found.end());
  // Where the object is remembered already, the memory holds it.
  grid.build(memory, res);
  const std::size_t before = memory.size();
  for (const Presumed& f : found) {
    if (grid.any_within(f.p, 0.75f * res, [](int) { return true; })) continue;
    memory.push_back(f.p);
    memory_chroma.push_back(cuts[f.cut].chroma);
    memory_age.push_back(1);
    memory_normal.push_back(f.normal);
  }
  r.counts.presumed_voxels = memory.size() - before;
}

}  // namespace ofv::perception
