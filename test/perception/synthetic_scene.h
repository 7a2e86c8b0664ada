// Test helper: analytically ray-cast RGB-D frames of simple shapes (a table,
// boxes, capsules), with a ground-truth label per pixel.
#pragma once

#include "ofv/rgbd_frame.h"

#include <Eigen/Geometry>

#include <cmath>
#include <limits>
#include <optional>
#include <random>
#include <vector>

namespace ofv::test {

/// Ground-truth labels of a synthetic frame.
enum Label : int { kNone = 0, kTable = 1, kObject = 2, kHand = 3, kOther = 4 };

/// A box (pose = centre and orientation in the world) or a capsule
/// (segment from a to b, radius).
struct Shape {
  enum class Kind { Box, Capsule } kind = Kind::Box;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // box centre/orientation
  Eigen::Vector3d half = Eigen::Vector3d::Constant(0.05);  // box half extents [m]
  Eigen::Vector3d a = Eigen::Vector3d::Zero();             // capsule ends [m]
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double radius = 0.02;  // capsule radius [m]
  Eigen::Vector3d colour{200, 200, 200};
  int label = kOther;
};

inline Shape make_box(const Eigen::Vector3d& centre, const Eigen::Vector3d& size,
                      const Eigen::Vector3d& colour, int label,
                      const Eigen::Matrix3d& rotation = Eigen::Matrix3d::Identity()) {
  Shape s;
  s.kind = Shape::Kind::Box;
  s.pose.linear() = rotation;
  s.pose.translation() = centre;
  s.half = 0.5 * size;
  s.colour = colour;
  s.label = label;
  return s;
}

inline Shape make_capsule(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double radius,
                          const Eigen::Vector3d& colour, int label) {
  Shape s;
  s.kind = Shape::Kind::Capsule;
  s.a = a;
  s.b = b;
  s.radius = radius;
  s.colour = colour;
  s.label = label;
  return s;
}

/// Camera pose looking from `eye` at `target`, world Z up, ViSP axes (X right, Y down).
inline Eigen::Isometry3d look_at(const Eigen::Vector3d& eye, const Eigen::Vector3d& target) {
  const Eigen::Vector3d z = (target - eye).normalized();
  Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ());
  if (x.norm() < 1e-9) {
    x = Eigen::Vector3d::UnitX();
  }
  x.normalize();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
  wMc.linear().col(0) = x;
  wMc.linear().col(1) = y;
  wMc.linear().col(2) = z;
  wMc.translation() = eye;
  return wMc;
}

/// Hit distance along the unit ray o + t d, t > 0, and the outward normal.
inline std::optional<std::pair<double, Eigen::Vector3d>> intersect(const Shape& s,
                                                                   const Eigen::Vector3d& o,
                                                                   const Eigen::Vector3d& d) {
  if (s.kind == Shape::Kind::Box) {
    const Eigen::Vector3d lo = s.pose.inverse() * o;
    const Eigen::Vector3d ld = s.pose.linear().transpose() * d;
    double t0 = -std::numeric_limits<double>::infinity();
    double t1 = std::numeric_limits<double>::infinity();
    int axis = -1;
    double sign = 0.0;
    for (int k = 0; k < 3; ++k) {
      if (std::abs(ld(k)) < 1e-15) {
        if (std::abs(lo(k)) > s.half(k)) {
          return std::nullopt;
        }
        continue;
      }
      double ta = (-s.half(k) - lo(k)) / ld(k);
      double tb = (s.half(k) - lo(k)) / ld(k);
      double near_sign = -1.0;
      if (ta > tb) {
        std::swap(ta, tb);
        near_sign = 1.0;
      }
      if (ta > t0) {
        t0 = ta;
        axis = k;
        sign = near_sign;
      }
      t1 = std::min(t1, tb);
    }
    if (t0 > t1 || t0 <= 1e-9 || axis < 0) {
      return std::nullopt;
    }
    Eigen::Vector3d n = Eigen::Vector3d::Zero();
    n(axis) = sign;
    return std::make_pair(t0, s.pose.linear() * n);
  }
  // Capsule: nearest hit of the cylinder body and the two end spheres.
  std::optional<std::pair<double, Eigen::Vector3d>> best;
  const auto consider = [&best](double t, const Eigen::Vector3d& n) {
    if (t > 1e-9 && (!best || t < best->first)) {
      best = std::make_pair(t, n.normalized());
    }
  };
  for (const Eigen::Vector3d& c : {s.a, s.b}) {
    const Eigen::Vector3d oc = o - c;
    const double bq = oc.dot(d);
    const double disc = bq * bq - (oc.squaredNorm() - s.radius * s.radius);
    if (disc >= 0.0) {
      const double t = -bq - std::sqrt(disc);
      consider(t, o + t * d - c);
    }
  }
  const Eigen::Vector3d axis = (s.b - s.a).normalized();
  const double len = (s.b - s.a).norm();
  const Eigen::Vector3d oa = o - s.a;
  const Eigen::Vector3d dp = d - d.dot(axis) * axis;
  const Eigen::Vector3d op = oa - oa.dot(axis) * axis;
  const double qa = dp.squaredNorm();
  if (qa > 1e-15) {
    const double qb = 2.0 * dp.dot(op);
    const double qc = op.squaredNorm() - s.radius * s.radius;
    const double disc = qb * qb - 4.0 * qa * qc;
    if (disc >= 0.0) {
      const double t = (-qb - std::sqrt(disc)) / (2.0 * qa);
      const double along = (o + t * d - s.a).dot(axis);
      if (along >= 0.0 && along <= len) {
        consider(t, o + t * d - (s.a + along * axis));
      }
    }
  }
  return best;
}

/// A world of shapes seen by one camera.
struct SyntheticScene {
  std::vector<Shape> shapes;
  /// A surface met more obliquely than this (ray to normal) has no depth,
  /// as on a real sensor; its colour stays.
  double grazing_deg = 90.0;

  /// Renders depth (Z [m]), colour (Lambert-like shading) and labels.
  RgbdFrame render(const CameraIntrinsics& k, const Eigen::Isometry3d& wMc,
                   std::vector<int>* labels = nullptr, double timestamp = 0.0) const {
    RgbdFrame f;
    f.timestamp = timestamp;
    f.intrinsics = k;
    f.wMc = wMc;
    const auto n = static_cast<std::size_t>(k.width) * static_cast<std::size_t>(k.height);
    f.depth.assign(n, 0.0f);
    f.rgb.assign(3 * n, 0);
    if (labels != nullptr) {
      labels->assign(n, kNone);
    }
    const Eigen::Vector3d o = wMc.translation();
    const double cos_grazing = std::cos(grazing_deg * M_PI / 180.0);
    for (int v = 0; v < k.height; ++v) {
      for (int u = 0; u < k.width; ++u) {
        const Eigen::Vector3d dc((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
        const Eigen::Vector3d d = (wMc.linear() * dc).normalized();
        double best = std::numeric_limits<double>::infinity();
        const Shape* hit = nullptr;
        Eigen::Vector3d normal;
        for (const Shape& s : shapes) {
          if (const auto h = intersect(s, o, d); h && h->first < best) {
            best = h->first;
            hit = &s;
            normal = h->second;
          }
        }
        if (hit == nullptr) {
          continue;
        }
        const std::size_t i = f.index(u, v);
        if (std::abs(normal.dot(d)) >= cos_grazing) {
          f.depth[i] = static_cast<float>(best * d.dot(wMc.linear().col(2)));
        }
        const double shade = 0.6 + 0.4 * std::abs(normal.dot(d));
        for (int c = 0; c < 3; ++c) {
          f.rgb[3 * i + static_cast<std::size_t>(c)] =
              static_cast<std::uint8_t>(std::min(255.0, hit->colour(c) * shade));
        }
        if (labels != nullptr) {
          (*labels)[i] = hit->label;
        }
      }
    }
    return f;
  }
};

/// Sensor-like depth noise: Gaussian with sigma = sigma_at_1m * Z^2, and
/// pixels at depth discontinuities (a step above `edge_jump` to a neighbour)
/// dropped with probability `edge_dropout`. Deterministic given `seed`.
inline void add_depth_noise(RgbdFrame& f, unsigned seed, double sigma_at_1m = 0.001,
                            double edge_jump = 0.03, double edge_dropout = 0.5) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  const std::vector<float> clean = f.depth;
  const int w = f.intrinsics.width;
  const int h = f.intrinsics.height;
  for (int v = 0; v < h; ++v) {
    for (int u = 0; u < w; ++u) {
      const std::size_t i = f.index(u, v);
      const double z = clean[i];
      if (!(z > 0.0)) {
        continue;
      }
      bool edge = false;
      for (const auto& [du, dv] : {std::pair{1, 0}, {-1, 0}, {0, 1}, {0, -1}}) {
        const int nu = u + du, nv = v + dv;
        if (nu >= 0 && nv >= 0 && nu < w && nv < h) {
          const double zn = clean[f.index(nu, nv)];
          edge = edge || !(zn > 0.0) || std::abs(zn - z) > edge_jump;
        }
      }
      if (edge && uniform(rng) < edge_dropout) {
        f.depth[i] = 0.0f;
      } else {
        f.depth[i] = static_cast<float>(z + sigma_at_1m * z * z * gauss(rng));
      }
    }
  }
}

/// 640 x 480 or 320 x 240 intrinsics with a 615 px (or 307.5 px) focal length.
inline CameraIntrinsics vga(int width = 640) {
  CameraIntrinsics k;
  const double s = width / 640.0;
  k.width = width;
  k.height = width * 3 / 4;
  k.fx = k.fy = 615.0 * s;
  k.cx = 320.0 * s;
  k.cy = 240.0 * s;
  return k;
}

/// The reference world: a table (z = 0 top), a DVD case standing on it
/// (0.19 x 0.015 x 0.135 m, centre `object_centre`), plus whatever the test adds.
inline SyntheticScene table_and_case(const Eigen::Vector3d& object_centre = {0.0, 0.0, 0.0675}) {
  SyntheticScene s;
  s.shapes.push_back(make_box({0.0, 0.0, -0.02}, {1.6, 1.6, 0.04}, {150, 110, 70}, kTable));
  s.shapes.push_back(make_box(object_centre, {0.19, 0.015, 0.135}, {40, 60, 200}, kObject));
  return s;
}

/// Camera 0.5 m in front of the case, slightly above, looking at it.
inline Eigen::Isometry3d front_camera(const Eigen::Vector3d& target = {0.0, 0.0, 0.0675}) {
  return look_at(target + Eigen::Vector3d(0.0, -0.45, 0.22), target);
}

}  // namespace ofv::test
