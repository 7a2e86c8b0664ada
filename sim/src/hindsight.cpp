// The hindsight planner: dynamic programming over (time step, view on the sphere).
#include "ofv/sim/hindsight.h"

#include "ofv/constants.h"
#include "ofv/settings_table.h"
#include "ofv/sim/renderer.h"
#include "ofv/view_methods.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>
#include <unordered_map>

namespace ofv::sim {

namespace {

constexpr double kUnreached = -std::numeric_limits<double>::infinity();
constexpr int kMaxViews = 100000;
constexpr double kPiece = 0.04;     // size of the pieces of a moving body tested against a view's cone [m]
constexpr double kOnSphere = 1e-3;  // a camera this close to its sphere is on it [m]

// The camera at `position` looking at `centroid`, turned from `start` by the least rotation.
Eigen::Isometry3d looking_at(const Eigen::Vector3d& position, const Eigen::Vector3d& centroid,
                             const Eigen::Isometry3d& start) {
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
  const Eigen::Vector3d z = start.linear().col(2);
  const Eigen::Vector3d look = (centroid - position).normalized();
  wMc.linear() = (Eigen::Quaterniond::FromTwoVectors(z, look) * Eigen::Quaterniond(start.linear())).toRotationMatrix();
  wMc.translation() = position;
  return wMc;
}

// For each direction, the directions within `chord` of it (itself first):
// a grid of cells `chord` wide on the unit directions, 27 cells searched.
std::vector<std::vector<int>> neighbours(const Eigen::Matrix3Xd& d, double chord) {
  const auto n = static_cast<int>(d.cols());
  const double cell = std::max(chord, 1e-6);
  auto key_of = [cell](const Eigen::Vector3d& p, int dx, int dy, int dz) {
    const auto q = [cell](double x, int dq) { return static_cast<long>(std::floor((x + 1.0) / cell)) + dq; };
    return (q(p.x(), dx) * 4099L + q(p.y(), dy)) * 4099L + q(p.z(), dz);
  };
  std::unordered_map<long, std::vector<int>> cells;
  for (int v = 0; v < n; ++v) cells[key_of(d.col(v), 0, 0, 0)].push_back(v);
  std::vector<std::vector<int>> out(static_cast<std::size_t>(n));
  tbb::parallel_for(0, n, [&](int v) {
    std::vector<int>& near = out[static_cast<std::size_t>(v)];
    near.push_back(v);
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cells.find(key_of(d.col(v), dx, dy, dz));
          if (it == cells.end()) continue;
          for (const int u : it->second) {
            if (u != v && (d.col(u) - d.col(v)).norm() <= chord) near.push_back(u);
          }
        }
      }
    }
  });
  return out;
}

// A ball around a part of the scene.
struct Ball {
  Eigen::Vector3d centre;
  double radius;
};

Ball ball_around(const Eigen::AlignedBox3d& box) { return {box.center(), 0.5 * box.diagonal().norm()}; }

// Balls that hold a mesh, about `cell` wide: the triangles are halved along
// their longest edge until no edge is longer than `cell`, and the pieces'
// bounding boxes are merged by the cell of their centre. Every point of the
// mesh lies in one of the balls.
std::vector<Ball> balls_of(const TriangleMesh& m, double cell) {
  std::unordered_map<long, Eigen::AlignedBox3d> boxes;
  const auto key_of = [cell](const Eigen::Vector3d& p) {
    const auto q = [cell](double x) { return static_cast<long>(std::floor(x / cell)); };
    return (q(p.x()) * 1000003L + q(p.y())) * 1000003L + q(p.z());
  };
  std::vector<std::array<Eigen::Vector3d, 3>> pieces;
  for (const auto& t : m.triangles) {
    pieces.push_back({m.vertices[t[0]].cast<double>(), m.vertices[t[1]].cast<double>(), m.vertices[t[2]].cast<double>()});
    while (!pieces.empty()) {
      const std::array<Eigen::Vector3d, 3> p = pieces.back();
      pieces.pop_back();
      int longest = 0;
      double length = 0.0;
      for (int e = 0; e < 3; ++e) {
        const double l = (p[static_cast<std::size_t>((e + 1) % 3)] - p[static_cast<std::size_t>(e)]).norm();
        if (l > length) {
          length = l;
          longest = e;
        }
      }
      if (length > cell) {
        const auto a = static_cast<std::size_t>(longest), b = static_cast<std::size_t>((longest + 1) % 3),
                   c = static_cast<std::size_t>((longest + 2) % 3);
        const Eigen::Vector3d mid = 0.5 * (p[a] + p[b]);
        pieces.push_back({p[a], mid, p[c]});
        pieces.push_back({mid, p[b], p[c]});
        continue;
      }
      Eigen::AlignedBox3d box(p[0]);
      box.extend(p[1]);
      box.extend(p[2]);
      auto [it, fresh] = boxes.try_emplace(key_of(box.center()), box);
      if (!fresh) it->second.extend(box);
    }
  }
  std::vector<Ball> balls;
  balls.reserve(boxes.size());
  for (const auto& [key, box] : boxes) balls.push_back(ball_around(box));
  return balls;
}

Ball ball_of(const TriangleMesh& m) {
  Eigen::AlignedBox3d box;
  for (const Eigen::Vector3f& v : m.vertices) box.extend(v.cast<double>());
  return ball_around(box);
}

// What changed between two steps: balls around the bodies that moved or
// deformed (at both steps), and whether the object did.
struct Changes {
  std::vector<Ball> balls;
  bool object = false;
  Ball object_ball{};  // the object's ball at the new step
};

// Every ray from a camera at `o` to the object's surface lies in the cone
// from o around the object's ball; a body whose ball stayed outside that
// cone (or beyond the object) cannot change the view's visible fraction.
bool may_change(const Changes& ch, const Eigen::Vector3d& o) {
  if (ch.object) return true;
  const Ball& obj = ch.object_ball;
  const Eigen::Vector3d axis = obj.centre - o;
  const double l = axis.norm();
  if (l <= obj.radius * 1.01) return true;
  const double half_angle = std::asin(obj.radius / l);
  return std::any_of(ch.balls.begin(), ch.balls.end(), [&](const Ball& b) {
    const Eigen::Vector3d to = b.centre - o;
    const double dist = to.norm();
    if (dist <= b.radius) return true;
    if (dist - b.radius > l + obj.radius) return false;
    const double angle = std::acos(std::clamp(to.dot(axis) / (dist * l), -1.0, 1.0));
    return angle <= half_angle + std::asin(b.radius / dist);
  });
}

}  // namespace

void check_hindsight(const HindsightSettings& s, double r_sphere, double duration, double rate) {
  if (!(std::isfinite(s.spacing) && s.spacing > 0.0)) {
    throw std::invalid_argument("setting 'hindsight_spacing' must be a positive length, got " + format_number(s.spacing));
  }
  if (s.frames_per_step < 1) {
    throw std::invalid_argument("setting 'hindsight_step' must be at least 1 frame, got " +
                                std::to_string(s.frames_per_step));
  }
  if (!(std::isfinite(s.max_speed) && s.max_speed > 0.0)) {
    throw std::invalid_argument("hindsight planner: the speed limit must be finite and positive, got " +
                                format_number(s.max_speed));
  }
  if (!(std::isfinite(r_sphere) && r_sphere > 0.0)) {
    throw std::invalid_argument("hindsight planner: r_sphere must be positive, got " + format_number(r_sphere));
  }
  if (!(std::isfinite(duration) && duration >= 0.0) || !(std::isfinite(rate) && rate > 0.0)) {
    throw std::invalid_argument("hindsight planner: duration and rate must be finite, got " + format_number(duration) +
                                " s at " + format_number(rate) + " Hz");
  }
  const double reach = s.max_speed * s.frames_per_step / rate;
  if (s.spacing > reach) {
    throw std::invalid_argument("setting 'hindsight_spacing' = " + format_number(s.spacing) +
                                " m is more than the camera travels in one step (" + format_number(reach) +
                                " m = max_linear_speed x hindsight_step / rate): it could never move; lower the "
                                "spacing or raise hindsight_step");
  }
  const double views = 4.0 * kPi * r_sphere * r_sphere / (s.spacing * s.spacing);
  if (views > kMaxViews) {
    throw std::invalid_argument("setting 'hindsight_spacing' = " + format_number(s.spacing) + " m on a sphere of radius " +
                                format_number(r_sphere) + " m gives " + format_number(std::round(views)) +
                                " views, more than " + std::to_string(kMaxViews) + "; use a larger spacing");
  }
}

HindsightPlan plan_hindsight(const Scenario& scenario, const Eigen::Isometry3d& wMc_start, double r_sphere,
                             double duration, const HindsightSettings& settings) {
  check_hindsight(settings, r_sphere, duration, scenario.rate);
  const auto started = std::chrono::steady_clock::now();
  HindsightPlan plan;
  const double frame = 1.0 / scenario.rate;
  plan.step = frame * settings.frames_per_step;
  const long frames = static_cast<long>(std::floor(duration * scenario.rate + 1e-9)) + 1;
  const long steps = (frames - 1) / settings.frames_per_step + 1;
  const double reach = settings.max_speed * plan.step;

  // The centroid's largest move in one step is at most the largest move of
  // one of the object's vertices (the centroid is a mean of surface points).
  const Body& target = scenario.bodies.front();
  double max_shift = 0.0;
  TriangleMesh before = target.world_mesh(0.0);
  for (long i = 0; i < steps; ++i) {
    plan.times.push_back(static_cast<double>(i * settings.frames_per_step) * frame);
    TriangleMesh now = target.world_mesh(plan.times.back());
    for (std::size_t k = 0; k < now.vertices.size(); ++k) {
      max_shift = std::max(max_shift, static_cast<double>((now.vertices[k] - before.vertices[k]).norm()));
    }
    before = std::move(now);
  }
  Renderer renderer(scenario);  // at time 0
  std::vector<Eigen::Vector3d> c(static_cast<std::size_t>(steps), renderer.object_centroid());

  const int n = std::max(1, static_cast<int>(std::lround(4.0 * kPi * r_sphere * r_sphere / (settings.spacing * settings.spacing))));
  plan.lattice_views = n;
  const Eigen::Matrix3Xd d = fibonacci_directions(n);
  const std::vector<std::vector<int>> near = neighbours(d, (reach + max_shift) / r_sphere);

  // The approach: from the start along the radius to the sphere, `reach` a step.
  const Eigen::Vector3d start = wMc_start.translation();
  const Eigen::Vector3d outward = start - c[0];
  const Eigen::Vector3d on_sphere =
      c[0] + r_sphere * (outward.norm() > 1e-9 ? outward.normalized() : Eigen::Vector3d(-wMc_start.linear().col(2)));
  const double approach = (on_sphere - start).norm();
  const int chain = approach > kOnSphere ? static_cast<int>(std::ceil(approach / reach)) : 0;
  std::vector<Eigen::Vector3d> a(static_cast<std::size_t>(chain + 1));
  for (int j = 0; j <= chain; ++j) {
    a[static_cast<std::size_t>(j)] = start + (on_sphere - start) * std::min(1.0, j * reach / std::max(approach, 1e-300));
  }

  // States: lattice views 0..n-1, then the approach n..n+chain (n is the start).
  const auto states = static_cast<std::size_t>(n + chain + 1);
  std::vector<double> total(states, kUnreached), next(states);
  std::vector<std::vector<int>> from(static_cast<std::size_t>(steps), std::vector<int>(states, -1));
  std::vector<std::vector<double>> value(static_cast<std::size_t>(steps), std::vector<double>(states, 0.0));
  auto position = [&](std::size_t s, long i) -> Eigen::Vector3d {
    return s < static_cast<std::size_t>(n) ? Eigen::Vector3d(c[static_cast<std::size_t>(i)] + r_sphere * d.col(static_cast<Eigen::Index>(s)))
                                           : a[s - static_cast<std::size_t>(n)];
  };

  std::vector<TriangleMesh> meshes(scenario.bodies.size());
  std::vector<std::vector<Ball>> pieces(scenario.bodies.size());  // of the bodies that moved, at the last step
  for (long i = 0; i < steps; ++i) {
    const auto si = static_cast<std::size_t>(i);
    Changes changes;
    for (std::size_t b = 0; b < scenario.bodies.size(); ++b) {
      TriangleMesh m = scenario.bodies[b].world_mesh(plan.times[si]);
      const bool object = scenario.bodies[b].role == Role::Object;
      if (object) changes.object_ball = ball_of(m);
      if (i > 0 && m.vertices != meshes[b].vertices) {
        changes.object = changes.object || object;
        if (pieces[b].empty()) pieces[b] = balls_of(meshes[b], kPiece);
        std::vector<Ball> now = balls_of(m, kPiece);
        changes.balls.insert(changes.balls.end(), pieces[b].begin(), pieces[b].end());
        changes.balls.insert(changes.balls.end(), now.begin(), now.end());
        pieces[b] = std::move(now);
      } else {
        pieces[b].clear();
      }
      meshes[b] = std::move(m);
    }
    if (changes.object) {
      renderer.set_time(plan.times[si]);
      c[si] = renderer.object_centroid();
    } else if (i > 0) {
      c[si] = c[si - 1];
    }
    // Every lattice view (the unlimited bound needs them all) that may have
    // changed since the last step, and the approach states reached by now.
    std::vector<int> evaluate;
    std::vector<Eigen::Isometry3d> poses;
    for (int v = 0; v < n; ++v) {
      const Eigen::Vector3d o = position(static_cast<std::size_t>(v), i);
      if (i > 0 && !may_change(changes, o)) {
        value[si][static_cast<std::size_t>(v)] = value[si - 1][static_cast<std::size_t>(v)];
        continue;
      }
      evaluate.push_back(v);
      poses.push_back(looking_at(o, c[si], wMc_start));
    }
    // At time 0 the camera is as the scenario puts it (the object may be
    // off its image); from the first step on it is taken to look at the centroid.
    for (int j = 0; j <= std::min<long>(chain, i); ++j) {
      const Eigen::Vector3d& o = a[static_cast<std::size_t>(j)];
      const bool aimed_before = j < i && !(i == 1 && j == 0);
      if (aimed_before && !may_change(changes, o)) {
        value[si][static_cast<std::size_t>(n + j)] = value[si - 1][static_cast<std::size_t>(n + j)];
        continue;
      }
      evaluate.push_back(n + j);
      poses.push_back(i == 0 ? wMc_start : looking_at(o, c[si], wMc_start));
    }
    if (poses.empty()) {
      plan.best_visible.push_back(plan.best_visible.back());
    } else {
      renderer.set_time(plan.times[si]);
      const std::vector<double> seen = renderer.visible_fractions(poses);
      plan.evaluations += static_cast<long>(seen.size());
      for (std::size_t k = 0; k < seen.size(); ++k) value[si][static_cast<std::size_t>(evaluate[k])] = seen[k];
      plan.best_visible.push_back(*std::max_element(value[si].begin(), value[si].begin() + n));
    }

    if (i == 0) {
      total[static_cast<std::size_t>(n)] = value[si][static_cast<std::size_t>(n)];
      continue;
    }
    std::fill(next.begin(), next.end(), kUnreached);
    // Lattice views: from a neighbour within reach, or from the end of the approach.
    const std::size_t end = static_cast<std::size_t>(n + chain);
    tbb::parallel_for(0, n, [&](int v) {
      const Eigen::Vector3d here = position(static_cast<std::size_t>(v), i);
      double best = kUnreached;
      int arg = -1;
      for (const int u : near[static_cast<std::size_t>(v)]) {
        const double t = total[static_cast<std::size_t>(u)];
        if (t > best && (here - position(static_cast<std::size_t>(u), i - 1)).norm() <= reach) {
          best = t;
          arg = u;
        }
      }
      if (total[end] > best && (here - a[static_cast<std::size_t>(chain)]).norm() <= reach) {
        best = total[end];
        arg = static_cast<int>(end);
      }
      if (arg >= 0) {
        next[static_cast<std::size_t>(v)] = best + value[si][static_cast<std::size_t>(v)];
        from[si][static_cast<std::size_t>(v)] = arg;
      }
    });
    // The approach: stay, or go one state on.
    for (int j = 0; j <= chain; ++j) {
      const auto s = static_cast<std::size_t>(n + j);
      double best = total[s];
      int arg = static_cast<int>(s);
      if (j > 0 && total[s - 1] > best) {
        best = total[s - 1];
        arg = static_cast<int>(s - 1);
      }
      if (best > kUnreached) {
        next[s] = best + value[si][s];
        from[si][s] = arg;
      }
    }
    total.swap(next);
  }

  // The best final state (the approach's end first: of equal paths, the one
  // that moves least), then back to the start.
  std::size_t last = static_cast<std::size_t>(n + chain);
  for (std::size_t s = 0; s < static_cast<std::size_t>(n); ++s) {
    if (total[s] > total[last]) last = s;
  }
  plan.views.resize(static_cast<std::size_t>(steps));
  plan.visible.resize(static_cast<std::size_t>(steps));
  for (long i = steps - 1; i >= 0; --i) {
    const auto si = static_cast<std::size_t>(i);
    plan.views[si] = position(last, i);
    plan.visible[si] = value[si][last];
    if (i > 0) last = static_cast<std::size_t>(from[si][last]);
  }
  plan.centroids = c;
  const auto mean = [](const std::vector<double>& x) {
    double sum = 0.0;
    for (const double v : x) sum += v;
    return sum / static_cast<double>(x.size());
  };
  plan.bound = mean(plan.visible);
  plan.unlimited_bound = mean(plan.best_visible);
  plan.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return plan;
}

namespace {

// Step index and fraction of time t within the plan's steps.
std::pair<std::size_t, double> locate(const HindsightPlan& p, double t) {
  if (p.times.empty()) throw std::logic_error("hindsight plan: no steps");
  if (!(t > p.times.front())) return {0, 0.0};
  const auto last = p.times.size() - 1;
  if (t >= p.times[last]) return {last, 0.0};
  const auto i = static_cast<std::size_t>(std::upper_bound(p.times.begin(), p.times.end(), t) - p.times.begin()) - 1;
  return {i, (t - p.times[i]) / (p.times[i + 1] - p.times[i])};
}

}  // namespace

Eigen::Vector3d HindsightPlan::centroid_at(double t) const {
  const auto [i, f] = locate(*this, t);
  if (f == 0.0) return centroids[i];
  return (1.0 - f) * centroids[i] + f * centroids[i + 1];
}

Eigen::Vector3d HindsightPlan::view_at(double t) const {
  const auto [i, f] = locate(*this, t);
  if (f == 0.0) return views[i];
  const Eigen::Vector3d c = centroid_at(t);
  const Eigen::Vector3d a = views[i] - centroids[i], b = views[i + 1] - centroids[i + 1];
  const double ra = a.norm(), rb = b.norm();
  if (ra < 1e-12 || rb < 1e-12) return (1.0 - f) * views[i] + f * views[i + 1];
  // Directions by spherical interpolation, radius linearly (the approach is off the sphere).
  const Eigen::Vector3d dir =
      Eigen::Quaterniond::Identity().slerp(f, Eigen::Quaterniond::FromTwoVectors(a, b)) * (a / ra);
  return c + ((1.0 - f) * ra + f * rb) * dir;
}

}  // namespace ofv::sim
