// The tracked object's shape (C, PCA axes, augmented OBB), the class of every
// supervoxel (paper II-B) and the estimator's ViewProblem.
#include "front_end.h"

#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <utility>
#include <vector>

namespace ofv::perception {

namespace {

/// How far the object must have moved with a body touching it before
/// taken_by_hand() tells a grip from a touch [m]: well above the drift of
/// the object's estimated motion over a few seconds (about half a
/// millimetre a frame on a still object).
constexpr float kGripTravel = 0.02f;

/// C, the mean of `points`, and their principal axes (columns, largest
/// variance first, right-handed).
void principal_axes(const std::vector<Eigen::Vector3d>& points, Eigen::Vector3d& c,
                    Eigen::Matrix3d& axes) {
  c = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    c += p;
  }
  c /= static_cast<double>(points.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) {
    cov += (p - c) * (p - c).transpose();
  }
  cov /= static_cast<double>(points.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  axes.col(0) = eig.eigenvectors().col(2);  // largest variance
  axes.col(1) = eig.eigenvectors().col(1);
  axes.col(2) = axes.col(0).cross(axes.col(1));
}

/// The augmented OBB: extents of `points` along `axes` from c, plus `margin` on every side.
OrientedBox augmented_obb(const std::vector<Eigen::Vector3d>& points, const Eigen::Vector3d& c,
                          const Eigen::Matrix3d& axes, double margin) {
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (const Eigen::Vector3d& p : points) {
    const Eigen::Vector3d local = axes.transpose() * (p - c);
    lo = lo.cwiseMin(local);
    hi = hi.cwiseMax(local);
  }
  OrientedBox obb;
  obb.axes = axes;
  obb.centre = c + axes * (0.5 * (lo + hi));
  obb.half_extents = 0.5 * (hi - lo) + Eigen::Vector3d::Constant(margin);
  return obb;
}

}  // namespace

void Perception::Impl::hidden_vertices(ViewProblem& p, std::size_t seen) const {
  // The hidden voxels grouped as the supervoxels of the seen part are, by
  // place and by surface: per cell of the seed resolution and per facing
  // (the axis and sign of the largest component of the normal their
  // supervoxel had), a vertex at their mean with their mean normal, when the
  // group holds at least a quarter of a cell's face of voxels.
  const double seed = settings.supervoxels.seed_resolution;
  const double per_side = seed / settings.supervoxels.voxel_resolution;
  const auto min_voxels =
      static_cast<std::size_t>(std::max(1.0, std::floor(0.25 * per_side * per_side)));
  using Key = Eigen::Matrix<int, 4, 1>;  // cell x, y, z; facing 0..5
  std::vector<std::pair<Key, std::size_t>> groups;
  for (std::size_t i = 0; i < memory.size(); ++i) {
    const Eigen::Vector3f& n = memory_normal[i];
    if (memory_age[i] == 0 || n.isZero()) continue;
    Eigen::Index axis = 0;
    n.cwiseAbs().maxCoeff(&axis);
    Key key;
    key.head<3>() = (memory[i].cast<double>() / seed).array().floor().cast<int>();
    key(3) = 2 * static_cast<int>(axis) + (n(axis) < 0.0f ? 1 : 0);
    groups.emplace_back(key, i);
  }
  std::sort(groups.begin(), groups.end(), [](const auto& a, const auto& b) {
    return std::lexicographical_compare(a.first.data(), a.first.data() + 4, b.first.data(),
                                        b.first.data() + 4) ||
           (a.first == b.first && a.second < b.second);
  });
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> found;  // position, normal
  for (std::size_t a = 0; a < groups.size();) {
    std::size_t b = a;
    Eigen::Vector3d position = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    for (; b < groups.size() && groups[b].first == groups[a].first; ++b) {
      position += memory[groups[b].second].cast<double>();
      normal += memory_normal[groups[b].second].cast<double>();
    }
    const std::size_t count = b - a;
    a = b;
    if (count >= min_voxels && normal.norm() > 1e-6) {
      found.emplace_back(position / static_cast<double>(count), normal.normalized());
    }
  }
  const auto k = static_cast<Eigen::Index>(seen);
  const auto n = static_cast<Eigen::Index>(found.size());
  p.positions.conservativeResize(3, k + n);
  p.normals.conservativeResize(3, k + n);
  for (Eigen::Index j = 0; j < n; ++j) {
    p.positions.col(k + j) = found[static_cast<std::size_t>(j)].first;
    p.normals.col(k + j) = found[static_cast<std::size_t>(j)].second;
  }
}

void Perception::Impl::grow_holder(const PerceptionResult& r, const std::vector<char>& object,
                                    const Eigen::Vector3d& c, std::vector<char>& interacting) {
  // The holder is what is interacting when the object is selected. Later
  // frames find it again inside the box near where it was (within
  // max_motion, moved with the object); from there its body grows through
  // supervoxels in contact (contact_distance, voxel to voxel) and of its
  // colour, in the sphere, not of the support plane. A body that comes to
  // touch the object later is an occluder beyond where it touches (a hand
  // over a cloth's fold), and where it touches too if it was an occluder in
  // the previous frame (it came from elsewhere), until it has moved with the
  // object (taken_by_hand()): then it is the holder. The plane's
  // supervoxels the body touches (its base) are interacting too.
  const std::size_t n = r.supervoxels.size();
  const bool first = r.status == TrackingStatus::Initialised;
  if (first) {
    holder.clear();
    grip.clear();
  }
  const auto radius = static_cast<float>(settings.tracking.max_motion);
  holder_grid.build(holder, radius);
  std::vector<char> body(n, 0);
  std::vector<std::size_t> open;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    const SupervoxelInfo& s = r.supervoxels[owner];
    if (body[owner] || object[owner] || on_plane(s)) continue;
    // Later frames: in the box, in contact or not (a hand gripping the
    // case's edge seen grazing may lie farther than contact_distance).
    if (first ? interacting[owner] != 0
              : (interacting[owner] || r.obb.contains(s.centroid)) &&
                    holder_grid.any_within(r.voxels[i], radius, [](int) { return true; })) {
      body[owner] = 1;
      open.push_back(owner);
    }
  }
  const auto candidate = [&](std::size_t j) {
    const SupervoxelInfo& s = r.supervoxels[j];
    return !object[j] && !on_plane(s) && (s.centroid - c).norm() < settings.r_sphere;
  };
  // Grows `in` from the supervoxels in `open` through those in contact and
  // of their colour (the contacts hashed once a frame, when anything grows).
  bool hashed = false;
  const auto grow = [&](std::vector<char>& in) {
    if (!open.empty() && !hashed) {
      contacts.build(r, settings.contact_distance, candidate);
      hashed = true;
    }
    while (!open.empty()) {
      const std::size_t x = open.back();
      open.pop_back();
      contacts.for_each(x, [&](std::size_t y) {
        if (!in[y] && detail::alike(r.supervoxels[x].colour, r.supervoxels[y].colour,
                                    settings.tracking.max_chroma_distance)) {
          in[y] = 1;
          open.push_back(y);
        }
      });
    }
  };
  grow(body);
  // The bodies that touch the object now and are not its holder.
  std::vector<char> toucher(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    if (interacting[i] && !body[i] && candidate(i)) {
      toucher[i] = 1;
      open.push_back(i);
    }
  }
  grow(toucher);
  native.assign(n, 0);
  if (!first && taken_by_hand(r, toucher)) {
    for (std::size_t i = 0; i < n; ++i) body[i] = body[i] || toucher[i];
  } else if (!first) {
    // What came as an occluder stays one while it touches the object and
    // has not carried it: a body that lingers against the object's face
    // (a box 5 mm in front of a book) is not holding it, and the paper's
    // rule alone made its touching part interacting, out of the
    // estimator's sight. Fragments of the object that tracking has not
    // joined were never occluders: they keep the paper's rule.
    foreign_grid.build(foreign_voxels, radius);
    std::vector<char> came(n, 0);
    for (std::size_t i = 0; i < r.voxels.size(); ++i) {
      const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
      if (toucher[owner] && !came[owner] && foreign_grid.any_within(r.voxels[i], radius, [](int) { return true; })) {
        came[owner] = 1;
        open.push_back(owner);
      }
    }
    grow(came);
    for (std::size_t i = 0; i < n; ++i) {
      if (came[i]) interacting[i] = 0;
      native[i] = toucher[i] && !came[i] ? 1 : 0;  // its part beyond the touch is an occluder, not a foreign one
    }
  }
  for (std::size_t i = 0; i < n; ++i) interacting[i] = interacting[i] || body[i];
  // Remembered as last seen, for as long as the object's hidden part is.
  std::vector<Eigen::Vector3f> seen;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    if (body[static_cast<std::size_t>(r.voxel_owner[i])]) seen.push_back(r.voxels[i]);
  }
  if (!seen.empty()) {
    // The holder's base on the support plane (a hand resting on a table of
    // its colour) looks like the plane, which the body does not grow into;
    // what of the plane, in the sphere, touches the body is interacting
    // too, the body's base or the table under it (not grown from).
    const auto contact = static_cast<float>(settings.contact_distance);
    base_grid.build(seen, contact);
    for (std::size_t i = 0; i < r.voxels.size(); ++i) {
      const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
      const SupervoxelInfo& s = r.supervoxels[owner];
      if (interacting[owner] || object[owner] || !on_plane(s) || (s.centroid - c).norm() >= settings.r_sphere) {
        continue;
      }
      if (base_grid.any_within(r.voxels[i], contact, [](int) { return true; })) interacting[owner] = 1;
    }
    holder.swap(seen);
    holder_age = 0;
  } else if (++holder_age > settings.tracking.occlusion_memory_frames) {
    holder.clear();
  }
}

bool Perception::Impl::taken_by_hand(const PerceptionResult& r, const std::vector<char>& toucher) {
  // A body that touches the object has taken it when, once the object has
  // moved by kGripTravel since the body first touched it, the body's voxels
  // lie where the object's motion has carried its voxels of then, not where
  // they were: a hand that grips, not a wall or a standing hand that the
  // object slides along, nor a hand that touches a still object. The
  // motion is object_motion()'s (remember() carries grip.moved with it).
  std::vector<Eigen::Vector3f> now;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    if (toucher[static_cast<std::size_t>(r.voxel_owner[i])]) now.push_back(r.voxels[i]);
  }
  if (now.empty()) {
    grip.clear();
    return false;
  }
  // Until the object moves, voxels of the bodies seen for the first time
  // (a hand reaching in) join the reference as they are now.
  const auto res = static_cast<float>(settings.supervoxels.voxel_resolution);
  const auto mean = [](const std::vector<Eigen::Vector3f>& v) {
    Eigen::Vector3f m = Eigen::Vector3f::Zero();
    for (const Eigen::Vector3f& p : v) m += p;
    return Eigen::Vector3f(m / static_cast<float>(std::max<std::size_t>(v.size(), 1)));
  };
  const auto travel = [&] { return (mean(grip.moved) - mean(grip.still)).norm(); };
  if (travel() < 0.5f * res) {
    detail::PointGrid reference;
    reference.build(grip.moved, res);
    for (const Eigen::Vector3f& p : now) {
      if (!reference.any_within(p, res, [](int) { return true; })) {
        grip.still.push_back(p);
        grip.moved.push_back(p);
      }
    }
  }
  if (travel() < kGripTravel) return false;
  // Each voxel of then against the body now: its distance to it carried
  // with the object and left where it was (capped at kGripTravel; a voxel
  // far from the body either way, of a body since gone, tells nothing).
  // The body moved with the object when carried voxels lie on it at less
  // than half the distance of those left where they were.
  detail::PointGrid body_now;
  body_now.build(now, kGripTravel);
  const auto distance = [&](const Eigen::Vector3f& p) {
    float best = kGripTravel * kGripTravel;
    body_now.for_each_near(p,
                           [&](int j) { best = std::min(best, (now[static_cast<std::size_t>(j)] - p).squaredNorm()); });
    return std::sqrt(best);
  };
  double with_object = 0.0;
  double where_it_was = 0.0;
  for (std::size_t i = 0; i < grip.still.size(); ++i) {
    const float carried = distance(grip.moved[i]);
    const float left = distance(grip.still[i]);
    if (std::min(carried, left) >= kGripTravel) continue;
    with_object += carried;
    where_it_was += left;
  }
  grip.clear();  // decided: a new reference from the next frame on
  return where_it_was > 0.0 && with_object < 0.5 * where_it_was;
}

void Perception::Impl::classify(const RgbdFrame& frame, PerceptionResult& r, const std::vector<char>& object) {
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
      r.hidden.push_back(memory[i]);
    }
  }
  r.counts.hidden_voxels = object_cloud.size() - r.counts.object_voxels;

  Eigen::Vector3d c;
  Eigen::Matrix3d axes;
  principal_axes(object_cloud, c, axes);
  r.centroid = c;
  r.axes = axes;
  r.obb = augmented_obb(object_cloud, c, axes, settings.obb_margin);

  // Interacting: inside the augmented OBB and in contact with the object
  // (a voxel within contact_distance of one of its voxels). The empty part
  // of the box of a bent or folded object (a hand in a cloth's hollow, over
  // its fold) holds occluders, not interacting elements.
  object_points.clear();
  for (const Eigen::Vector3d& p : object_cloud) object_points.push_back(p.cast<float>());
  object_grid.build(object_points, settings.contact_distance);
  // (Asked only of supervoxels that could be interacting: not object, centre in the box.)
  std::vector<char> touches(n, 0);
  std::vector<char> asked(n, 0);
  for (std::size_t i = 0; i < n; ++i) asked[i] = !object[i] && r.obb.contains(r.supervoxels[i].centroid) ? 1 : 0;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    char& t = touches[owner];
    t = t || (asked[owner] &&
              object_grid.any_within(r.voxels[i], static_cast<float>(settings.contact_distance), [](int) { return true; }));
  }

  const bool labelled = settings.classes == PerceptionSettings::Classes::Labels;
  std::vector<char> interacting = touches;
  if (settings.holder_body && !labelled) grow_holder(r, object, c, interacting);  // labels know the holder

  // Labels (paper II-B) and the estimator's input. Classes::Labels: the
  // frame's labels of each supervoxel (supervoxel_labels) for the bodies.
  const std::vector<std::uint16_t>& truth = supervoxel_labels;
  const auto is_body = [](std::uint16_t label) { return label == kPixelInteracting || label >= kPixelOccluder0; };
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
    } else if (labelled && is_body(truth[i])) {
      // Classes::Labels: the holder and the occluding bodies as labelled.
      const bool occluder = truth[i] != kPixelInteracting && (s.centroid - c).norm() < settings.r_sphere;
      s.label = truth[i] == kPixelInteracting ? SupervoxelClass::Interacting
                : occluder                    ? SupervoxelClass::Occluder
                                              : SupervoxelClass::Background;
      if (s.label == SupervoxelClass::Interacting) ++r.counts.interacting;
      if (occluder) {
        ++r.counts.occluders;
        occluders.push_back(static_cast<int>(i));
      }
    } else if (!settings.support_plane_occludes && (labelled ? truth[i] == kPixelSupport : on_plane(s))) {
      s.label = SupervoxelClass::Background;
    } else if (interacting[i]) {
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
    // The object's remembered part now hidden: the estimator keeps it in
    // view too, not only the part that is still seen.
    hidden_vertices(p, vertices.size());
  }
  r.counts.hidden_vertices = static_cast<std::size_t>(p.positions.cols()) - vertices.size();
  foreign_voxels.clear();
  if (settings.holder_body && !labelled) {  // grow_holder() ran and set `native`
    for (std::size_t i = 0; i < r.voxels.size(); ++i) {
      const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
      const SupervoxelInfo& s = r.supervoxels[owner];
      if (s.label == SupervoxelClass::Occluder && !native[owner] && !on_plane(s) &&
          !plane_voxel(s.centroid.cast<float>(), s.colour)) {
        foreign_voxels.push_back(r.voxels[i]);
      }
    }
  }
  p.occluders.resize(3, static_cast<Eigen::Index>(occluders.size()));
  for (std::size_t j = 0; j < occluders.size(); ++j) {
    p.occluders.col(static_cast<Eigen::Index>(j)) =
        r.supervoxels[static_cast<std::size_t>(occluders[j])].centroid;
  }
  p.centroid = c;
  p.axes = axes;
  p.camera = r.wMc.translation();
  if (settings.beyond_view) beyond_view(frame, r);
}

void Perception::Impl::beyond_view(const RgbdFrame& frame, PerceptionResult& r) const {
  const CameraIntrinsics& k = frame.intrinsics;
  const double seed = settings.supervoxels.seed_resolution;
  // The continuation's spacing: seen from the object's many vertices, the
  // occlusion points of neighbouring copies still overlap on the sphere.
  const double step = 2.0 * seed;
  const Eigen::Isometry3d cMw = r.wMc.inverse();
  using Cell = Eigen::Matrix<std::int64_t, 3, 1>;
  std::vector<std::pair<Cell, Eigen::Vector3d>> added;  // one per cell of `step`
  for (const SupervoxelInfo& s : r.supervoxels) {
    // The support plane is not continued: it goes on as a plane, not at one
    // depth (its supervoxels at the border may have a poor normal: its colour tells).
    if (s.label != SupervoxelClass::Occluder || on_plane(s) || plane_voxel(s.centroid.cast<float>(), s.colour)) {
      continue;
    }
    double z = 0.0;
    const auto px = detail::project(frame, cMw, s.centroid, &z);
    if (!px) continue;
    // Within one seed resolution of a border, seen at this depth [px].
    const double mu = k.fx * seed / z;
    const double mv = k.fy * seed / z;
    Eigen::Vector3d out = Eigen::Vector3d::Zero();  // outwards, camera frame
    if (px->x() < mu) out.x() = -1.0;
    if (px->x() > k.width - 1 - mu) out.x() = 1.0;
    if (px->y() < mv) out.y() = -1.0;
    if (px->y() > k.height - 1 - mv) out.y() = 1.0;
    if (out.isZero()) continue;
    out.normalize();
    const int most = static_cast<int>(std::ceil(2.0 * settings.r_sphere / step));  // the sphere's diameter
    for (int j = 1; j <= most; ++j) {
      const Eigen::Vector3d q = s.centroid + (j * step) * (r.wMc.linear() * out);
      if (!((q - r.centroid).norm() < settings.r_sphere)) break;
      if (!r.obb.contains(q)) added.emplace_back((q / step).array().floor().cast<std::int64_t>(), q);
    }
  }
  std::sort(added.begin(), added.end(), [](const auto& a, const auto& b) {
    return std::lexicographical_compare(a.first.data(), a.first.data() + 3, b.first.data(), b.first.data() + 3);
  });
  added.erase(std::unique(added.begin(), added.end(), [](const auto& a, const auto& b) { return a.first == b.first; }),
              added.end());
  ViewProblem& p = r.problem;
  const Eigen::Index seen = p.occluders.cols();
  r.counts.beyond_view = added.size();
  p.occluders.conservativeResize(3, seen + static_cast<Eigen::Index>(added.size()));
  for (std::size_t j = 0; j < added.size(); ++j) p.occluders.col(seen + static_cast<Eigen::Index>(j)) = added[j].second;
}

}  // namespace ofv::perception
