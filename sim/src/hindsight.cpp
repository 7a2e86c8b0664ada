// The hindsight planner: dynamic programming over (time step, view on the sphere).
#include "ofv/sim/hindsight.h"

#include "ofv/constants.h"
#include "ofv/settings_table.h"
#include "ofv/sim/renderer.h"
#include "ofv/view_methods.h"
#include "bit_reversal.h"
#include "sight_cone.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdint>
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
constexpr int kDirectSteps = 8;     // straight moves from the start: up to this many steps longer than the approach

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

// Unit directions in a grid of cubes `cell` wide over [-1, 1]^3: the
// directions within `cell` of a point are in the 27 cubes around it.
class DirectionGrid {
 public:
  DirectionGrid(const Eigen::Matrix3Xd& d, double cell)
      : d_(d), cell_(std::max(cell, 1e-6)), side_(static_cast<int>(std::floor(2.0 / cell_)) + 1) {
    const std::size_t cubes = static_cast<std::size_t>(side_) * static_cast<std::size_t>(side_) * static_cast<std::size_t>(side_);
    first_.assign(cubes + 1, 0);
    std::vector<std::size_t> cube(static_cast<std::size_t>(d.cols()));
    for (Eigen::Index v = 0; v < d.cols(); ++v) {
      const auto q = cell_of(d.col(v));
      cube[static_cast<std::size_t>(v)] = index_of(q[0], q[1], q[2]);
      ++first_[cube[static_cast<std::size_t>(v)] + 1];
    }
    for (std::size_t c = 0; c < cubes; ++c) first_[c + 1] += first_[c];
    members_.resize(static_cast<std::size_t>(d.cols()));
    std::vector<int> filled(first_.begin(), first_.end() - 1);
    for (std::size_t v = 0; v < cube.size(); ++v) members_[static_cast<std::size_t>(filled[cube[v]]++)] = static_cast<int>(v);
  }
  // Calls f(u) for every direction u within `radius` (<= the cell) of p, in
  // the order of the cubes, then of the directions.
  template <typename F>
  void within(const Eigen::Vector3d& p, double radius, F&& f) const {
    const auto q = cell_of(p);
    for (int x = std::max(0, q[0] - 1); x <= std::min(side_ - 1, q[0] + 1); ++x) {
      for (int y = std::max(0, q[1] - 1); y <= std::min(side_ - 1, q[1] + 1); ++y) {
        for (int z = std::max(0, q[2] - 1); z <= std::min(side_ - 1, q[2] + 1); ++z) {
          const std::size_t c = index_of(x, y, z);
          for (int k = first_[c]; k < first_[c + 1]; ++k) {
            const int u = members_[static_cast<std::size_t>(k)];
            if ((d_.col(u) - p).norm() <= radius) f(u);
          }
        }
      }
    }
  }
  // The direction nearest p, if one lies within the cell.
  [[nodiscard]] int nearest(const Eigen::Vector3d& p) const {
    int best = -1;
    double best_distance = std::numeric_limits<double>::infinity();
    within(p, cell_, [&](int u) {
      const double distance = (d_.col(u) - p).norm();
      if (distance < best_distance || (distance == best_distance && u < best)) {
        best_distance = distance;
        best = u;
      }
    });
    return best;
  }

 private:
  [[nodiscard]] std::array<int, 3> cell_of(const Eigen::Vector3d& p) const {
    std::array<int, 3> q{};
    for (int a = 0; a < 3; ++a) {
      q[static_cast<std::size_t>(a)] = std::clamp(static_cast<int>(std::floor((p[a] + 1.0) / cell_)), 0, side_ - 1);
    }
    return q;
  }
  [[nodiscard]] std::size_t index_of(int x, int y, int z) const {
    return (static_cast<std::size_t>(x) * static_cast<std::size_t>(side_) + static_cast<std::size_t>(y)) *
               static_cast<std::size_t>(side_) +
           static_cast<std::size_t>(z);
  }
  const Eigen::Matrix3Xd& d_;
  double cell_;
  int side_;
  std::vector<int> first_;    // cube c's directions: members_[first_[c] .. first_[c + 1])
  std::vector<int> members_;
};

// For each direction, the directions within `chord` of it (itself first).
std::vector<std::vector<int>> neighbours(const Eigen::Matrix3Xd& d, double chord) {
  const DirectionGrid grid(d, chord);
  std::vector<std::vector<int>> out(static_cast<std::size_t>(d.cols()));
  tbb::parallel_for(0, static_cast<int>(d.cols()), [&](int v) {
    std::vector<int>& near = out[static_cast<std::size_t>(v)];
    near.push_back(v);
    grid.within(d.col(v), chord, [&](int u) {
      if (u != v) near.push_back(u);
    });
  });
  return out;
}

// The direction a fraction f of the way from a to b on the great circle.
Eigen::Vector3d between(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double f) {
  return Eigen::Quaterniond::Identity().slerp(f, Eigen::Quaterniond::FromTwoVectors(a, b)) * a;
}

// Straight moves of k steps into each view v: from a view u whose direction
// is at most `chord` per step away along the great circle (2 sin(angle/2k)
// <= chord), with the views nearest the directions at the k - 1 steps in
// between (they stand for the camera there, as each view stands for its
// cell of the sphere).
struct Segments {
  int k = 1;
  std::vector<std::size_t> first;  // view v's segments: [first[v], first[v + 1])
  std::vector<int> from;           // u
  std::vector<float> step_chord;   // 2 sin(angle(u, v) / 2k): the move per step on the unit sphere
  std::vector<int> mids;           // k - 1 per segment, at steps 1 .. k - 1 from u

  Segments(const Eigen::Matrix3Xd& d, int steps, double chord, double spacing) : k(steps) {
    const auto n = static_cast<std::size_t>(d.cols());
    first.assign(n + 1, 0);
    if (k < 2) return;
    const DirectionGrid partners(d, std::min(2.0, k * chord));
    const DirectionGrid fine(d, 2.0 * spacing);
    std::vector<std::vector<int>> from_of(n), mids_of(n);
    std::vector<std::vector<float>> chord_of(n);
    tbb::parallel_for(0, static_cast<int>(n), [&](int v) {
      const auto sv = static_cast<std::size_t>(v);
      partners.within(d.col(v), std::min(2.0, k * chord), [&](int u) {
        if (u == v) return;
        const double angle = std::acos(std::clamp(d.col(u).dot(d.col(v)), -1.0, 1.0));
        const double per_step = 2.0 * std::sin(angle / (2.0 * k));
        if (per_step > chord || angle > kPi - 1e-6) return;  // too far, or no one great circle
        from_of[sv].push_back(u);
        chord_of[sv].push_back(static_cast<float>(per_step));
        for (int g = 1; g < k; ++g) {
          const int mid = fine.nearest(between(d.col(u), d.col(v), static_cast<double>(g) / k));
          mids_of[sv].push_back(mid >= 0 ? mid : (2 * g < k ? u : v));
        }
      });
    });
    for (std::size_t v = 0; v < n; ++v) first[v + 1] = first[v] + from_of[v].size();
    from.reserve(first[n]);
    step_chord.reserve(first[n]);
    mids.reserve(first[n] * static_cast<std::size_t>(k - 1));
    for (std::size_t v = 0; v < n; ++v) {
      from.insert(from.end(), from_of[v].begin(), from_of[v].end());
      step_chord.insert(step_chord.end(), chord_of[v].begin(), chord_of[v].end());
      mids.insert(mids.end(), mids_of[v].begin(), mids_of[v].end());
    }
  }
};

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
  const detail::SightCone cone(o, ch.object_ball.centre, ch.object_ball.radius);
  if (cone.length() <= ch.object_ball.radius * 1.01) return true;
  return std::any_of(ch.balls.begin(), ch.balls.end(), [&](const Ball& b) { return cone.may_meet(b.centre, b.radius); });
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
  if (s.segment_steps < 1 || s.segment_steps > 8) {
    throw std::invalid_argument("setting 'hindsight_segment' must be 1 to 8 steps, got " +
                                std::to_string(s.segment_steps));
  }
  if (!(std::isfinite(s.max_speed) && s.max_speed > 0.0)) {
    throw std::invalid_argument("hindsight planner: the speed limit must be finite and positive, got " +
                                format_number(s.max_speed));
  }
  if (!(std::isfinite(s.max_turn_rate) && s.max_turn_rate > 0.0)) {
    throw std::invalid_argument("hindsight planner: the turn rate must be finite and positive, got " +
                                format_number(s.max_turn_rate));
  }
  if (!(std::isfinite(r_sphere) && r_sphere > 0.0)) {
    throw std::invalid_argument("hindsight planner: r_sphere must be positive, got " + format_number(r_sphere));
  }
  if (!(std::isfinite(duration) && duration >= 0.0) || !(std::isfinite(rate) && rate > 0.0)) {
    throw std::invalid_argument("hindsight planner: duration and rate must be finite, got " + format_number(duration) +
                                " s at " + format_number(rate) + " Hz");
  }
  // A camera moves between views at most reach apart, or segment_steps x
  // reach apart by a straight move.
  const double reach = s.max_speed * s.frames_per_step / rate;
  if (s.spacing > reach * s.segment_steps) {
    throw std::invalid_argument("setting 'hindsight_spacing' = " + format_number(s.spacing) +
                                " m is more than the camera travels in hindsight_segment steps (" +
                                format_number(reach * s.segment_steps) +
                                " m = max_linear_speed x hindsight_step x hindsight_segment / rate): it could never "
                                "move; lower the spacing or raise hindsight_step or hindsight_segment");
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

  // The object's centroid at every step, and a bound on its largest move in
  // one step: the largest move of one of the object's vertices (the
  // centroid is a mean of surface points).
  const Body& target = scenario.bodies.front();
  double max_shift = 0.0;
  Renderer renderer(scenario);  // at time 0
  std::vector<Eigen::Vector3d> c(static_cast<std::size_t>(steps), renderer.object_centroid());
  TriangleMesh before = target.world_mesh(0.0);
  for (long i = 0; i < steps; ++i) {
    const auto si = static_cast<std::size_t>(i);
    plan.times.push_back(static_cast<double>(i * settings.frames_per_step) * frame);
    TriangleMesh now = target.world_mesh(plan.times.back());
    for (std::size_t k = 0; k < now.vertices.size(); ++k) {
      max_shift = std::max(max_shift, static_cast<double>((now.vertices[k] - before.vertices[k]).norm()));
    }
    if (i > 0 && now.vertices != before.vertices) {
      renderer.set_time(plan.times.back());
      c[si] = renderer.object_centroid();
    } else if (i > 0) {
      c[si] = c[si - 1];
    }
    before = std::move(now);
  }

  const int n = std::max(1, static_cast<int>(std::lround(4.0 * kPi * r_sphere * r_sphere / (settings.spacing * settings.spacing))));
  plan.lattice_views = n;
  const Eigen::Matrix3Xd d = fibonacci_directions(n);
  const std::vector<std::vector<int>> near = neighbours(d, (reach + max_shift) / r_sphere);
  const Segments segments(d, settings.segment_steps, reach / r_sphere, settings.spacing / r_sphere);

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
  const int K = segments.k;
  const auto states = static_cast<std::size_t>(n + chain + 1);
  const auto nv = static_cast<std::size_t>(n);
  // Every state's value at every step as far as it is known: a lattice
  // view's as it looks at the centroid, exact or an upper bound; a state's
  // whose camera has not turned to the centroid yet, and the approach's, as
  // the camera there is turned by then.
  enum Known : char { kUnknown = 0, kLooking = 1, kAtMost = 2, kTurned = 3 };
  std::vector<std::vector<double>> value(static_cast<std::size_t>(steps), std::vector<double>(states, 0.0));
  std::vector<std::vector<char>> known(static_cast<std::size_t>(steps), std::vector<char>(states, kUnknown));
  const auto exact = [&](std::size_t si, std::size_t s) { return known[si][s] == kLooking || known[si][s] == kTurned; };
  auto position = [&](std::size_t s, long i) -> Eigen::Vector3d {
    return s < nv ? Eigen::Vector3d(c[static_cast<std::size_t>(i)] + r_sphere * d.col(static_cast<Eigen::Index>(s)))
                  : a[s - nv];
  };
  // A camera off its sphere need not reach it along the radius first:
  // straight moves from the start to a lattice view at constant speed, in
  // the fewest steps k (up to the approach's plus kDirectSteps) that reach
  // it. The steps in between are off the sphere, scored where the camera
  // is; `sum` gathers their values.
  struct Direct {
    int view = 0, k = 0;
    double sum = 0.0;
  };
  std::vector<Direct> direct;
  std::vector<int> direct_to(nv, -1);
  for (int v = 0; v < n && chain > 0; ++v) {
    for (long k = 1; k <= std::min<long>({chain + kDirectSteps, 255, steps - 1}); ++k) {
      if ((position(static_cast<std::size_t>(v), k) - start).norm() <= static_cast<double>(k) * reach) {
        direct_to[static_cast<std::size_t>(v)] = static_cast<int>(direct.size());
        direct.push_back({v, static_cast<int>(k)});
        break;
      }
    }
  }
  auto on_the_way = [&](const Direct& g, long i) -> Eigen::Vector3d {
    return start + (position(static_cast<std::size_t>(g.view), g.k) - start) * (static_cast<double>(i) / g.k);
  };
  // The camera at o at step i, turned from its start towards the centroid by
  // at most max_turn_rate x the time (at time 0: as the scenario places it);
  // whether it looks at the centroid yet.
  const Eigen::Vector3d start_axis = wMc_start.linear().col(2);
  auto aimed = [&](const Eigen::Vector3d& o, long i, bool* turned) {
    const auto si = static_cast<std::size_t>(i);
    const Eigen::Vector3d look = (c[si] - o).normalized();
    const double need = std::acos(std::clamp(start_axis.dot(look), -1.0, 1.0));
    const double allowed = settings.max_turn_rate * plan.times[si];
    *turned = need <= allowed;
    if (*turned) return looking_at(o, c[si], wMc_start);
    Eigen::Isometry3d wMc = wMc_start;
    wMc.linear() = (Eigen::Quaterniond::Identity().slerp(allowed / need, Eigen::Quaterniond::FromTwoVectors(start_axis, look)) *
                    Eigen::Quaterniond(wMc_start.linear()))
                       .toRotationMatrix();
    wMc.translation() = o;
    return wMc;
  };
  // Values cast at step i: the lattice views `views` looking at the
  // centroid, each only as far as it could reach its `at_least`, its rays
  // first to the samples it last found not seen (`not_seen`, a bitset a view).
  std::vector<std::vector<std::uint64_t>> not_seen(nv);
  long renderer_step = -1;  // the renderer is at this step's time
  const auto at_step = [&](long i) {
    if (renderer_step != i) renderer.set_time(plan.times[static_cast<std::size_t>(i)]);
    renderer_step = i;
  };
  const auto cast = [&](long i, const std::vector<int>& views, const std::vector<double>& at_least) {
    if (views.empty()) return;
    const auto si = static_cast<std::size_t>(i);
    at_step(i);
    std::vector<Eigen::Isometry3d> poses;
    poses.reserve(views.size());
    for (const int v : views) poses.push_back(looking_at(position(static_cast<std::size_t>(v), i), c[si], wMc_start));
    std::vector<std::vector<std::uint64_t>> missed(views.size());
    for (std::size_t k = 0; k < views.size(); ++k) missed[k].swap(not_seen[static_cast<std::size_t>(views[k])]);
    std::vector<char> whole;
    const std::vector<double> seen = renderer.visible_fractions(poses, at_least, whole, &missed);
    plan.evaluations += static_cast<long>(seen.size());
    for (std::size_t k = 0; k < seen.size(); ++k) {
      const auto sv = static_cast<std::size_t>(views[k]);
      value[si][sv] = seen[k];
      known[si][sv] = whole[k] != 0 ? kLooking : kAtMost;
      not_seen[sv].swap(missed[k]);
    }
  };

  // First a scan of the steps: the best lattice view at each step on its own
  // (the unlimited bound), the values of the states whose camera is not
  // turned to the centroid yet, and `upper`, the best value of any state at
  // each step. A view keeps its last value while no moving body comes near
  // its cone of sight to the object (`still`, per step and view: -1 not
  // tested yet). The views go in batches: first the kProbes best at the
  // step before, valued exactly; then the others (those best at the step
  // before first, then spread over the sphere), each batch only as far as
  // it could beat the best of the batches before, until one sees all.
  constexpr std::size_t kProbes = 32, kBatch = 1024;
  std::vector<std::size_t> spread(nv);  // a view's rank in an order spread over the sphere: bit-reversed indices
  const int bits = detail::bits_for(nv);
  for (std::size_t v = 0; v < nv; ++v) spread[v] = detail::bit_reversed(v, bits);
  std::vector<Changes> changes_at(static_cast<std::size_t>(steps));  // since the step before
  std::vector<std::vector<signed char>> still(static_cast<std::size_t>(steps), std::vector<signed char>(nv, -1));
  const auto unchanged = [&](long i, std::size_t v) {
    signed char& s = still[static_cast<std::size_t>(i)][v];
    if (s < 0) s = may_change(changes_at[static_cast<std::size_t>(i)], position(v, i)) ? 0 : 1;
    return s == 1;
  };
  std::vector<double> upper(static_cast<std::size_t>(steps), 0.0);
  std::vector<TriangleMesh> meshes(scenario.bodies.size());
  std::vector<std::vector<Ball>> pieces(scenario.bodies.size());  // of the bodies that moved, at the last step
  for (long i = 0; i < steps; ++i) {
    const auto si = static_cast<std::size_t>(i);
    Changes& changes = changes_at[si];
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
    // The lattice views: what still holds from the step before, then the
    // batches (none once a view sees all: a fraction is at most 1).
    double best = kUnreached;
    tbb::parallel_for(0, n, [&](int v) {
      const auto sv = static_cast<std::size_t>(v);
      const char held = i > 0 ? known[si - 1][sv] : static_cast<char>(kUnknown);
      if ((held == kLooking || held == kAtMost) && unchanged(i, sv)) {
        value[si][sv] = value[si - 1][sv];
        known[si][sv] = held;
      }
    });
    for (std::size_t v = 0; v < nv; ++v) {
      if (known[si][v] == kLooking) best = std::max(best, value[si][v]);
    }
    std::vector<int> order;
    for (int v = 0; v < n; ++v) {
      if (known[si][static_cast<std::size_t>(v)] != kLooking) order.push_back(v);
    }
    const auto last_value = [&](int v) {
      return i > 0 && known[si - 1][static_cast<std::size_t>(v)] != kUnknown ? value[si - 1][static_cast<std::size_t>(v)] : -1.0;
    };
    const auto first = [&](int u, int v) {
      const double lu = last_value(u), lv = last_value(v);
      return lu > lv || (lu == lv && spread[static_cast<std::size_t>(u)] < spread[static_cast<std::size_t>(v)]);
    };
    // The probes in order, the others sorted only if they are needed.
    const auto probe_end = order.begin() + static_cast<std::ptrdiff_t>(std::min(kProbes, order.size()));
    std::partial_sort(order.begin(), probe_end, order.end(), first);
    for (std::size_t k = 0; k < order.size() && best < 1.0;) {
      const bool probes = k == 0;
      if (k == kProbes) std::sort(probe_end, order.end(), first);
      const std::size_t end = std::min(order.size(), k + (probes ? kProbes : kBatch));
      std::vector<int> batch;
      for (; k < end; ++k) {
        const auto sv = static_cast<std::size_t>(order[k]);
        if (!(known[si][sv] == kAtMost && value[si][sv] < best)) batch.push_back(order[k]);
      }
      cast(i, batch, std::vector<double>(batch.size(), probes ? kUnreached : best));
      for (const int v : batch) {
        if (known[si][static_cast<std::size_t>(v)] == kLooking) best = std::max(best, value[si][static_cast<std::size_t>(v)]);
      }
    }
    plan.best_visible.push_back(best);
    upper[si] = best;
    // The camera's values where it cannot look at the centroid yet: views it
    // can have reached by now that it could not have turned at yet are cast
    // as turned so far; the approach states reached, as the camera there is
    // turned by now; the straight moves from the start on their way.
    std::vector<int> evaluate;
    std::vector<Eigen::Isometry3d> poses;
    for (int v = 0; v < n && i > 0; ++v) {
      const Eigen::Vector3d o = position(static_cast<std::size_t>(v), i);
      if ((o - start).norm() > static_cast<double>(i) * reach + 1e-9) continue;  // out of reach yet
      bool turned = false;
      Eigen::Isometry3d pose = aimed(o, i, &turned);
      if (turned) continue;
      evaluate.push_back(v);
      poses.push_back(pose);
    }
    for (int j = 0; j <= std::min<long>(chain, i); ++j) {
      const auto s = nv + static_cast<std::size_t>(j);
      const Eigen::Vector3d& o = a[static_cast<std::size_t>(j)];
      bool turned_before = false;
      if (j < i) (void)aimed(o, i - 1, &turned_before);
      if (turned_before && !may_change(changes, o)) {
        value[si][s] = value[si - 1][s];
        known[si][s] = kTurned;
        continue;
      }
      bool turned = false;
      evaluate.push_back(static_cast<int>(s));
      poses.push_back(aimed(o, i, &turned));
    }
    std::vector<std::size_t> under_way;  // the straight moves from the start not at their view yet
    for (std::size_t g = 0; g < direct.size() && i > 0; ++g) {
      if (direct[g].k <= i) continue;
      bool turned = false;
      under_way.push_back(g);
      poses.push_back(aimed(on_the_way(direct[g], i), i, &turned));
    }
    if (!poses.empty()) {
      at_step(i);
      const std::vector<double> seen = renderer.visible_fractions(poses);
      plan.evaluations += static_cast<long>(seen.size());
      for (std::size_t k = 0; k < seen.size(); ++k) {
        upper[si] = std::max(upper[si], seen[k]);
        if (k < evaluate.size()) {
          value[si][static_cast<std::size_t>(evaluate[k])] = seen[k];
          known[si][static_cast<std::size_t>(evaluate[k])] = kTurned;
        } else {
          direct[under_way[k - evaluate.size()]].sum += seen[k];
        }
      }
    }
    for (std::size_t s = nv; s < states; ++s) {
      if (known[si][s] == kTurned) upper[si] = std::max(upper[si], value[si][s]);
    }
  }
  // Of the steps after each, the sum of their best values.
  std::vector<double> after(static_cast<std::size_t>(steps), 0.0);
  for (long i = steps - 2; i >= 0; --i) {
    after[static_cast<std::size_t>(i)] = after[static_cast<std::size_t>(i + 1)] + upper[static_cast<std::size_t>(i + 1)];
  }

  // A lattice view's looking value at step i from an earlier step where it
  // is known exactly, if no moving body came near its cone of sight since.
  const auto carried = [&](long i, std::size_t v) {
    for (long j = i; j > 0 && unchanged(j, v); --j) {
      if (known[static_cast<std::size_t>(j - 1)][v] == kLooking) {
        value[static_cast<std::size_t>(i)][v] = value[static_cast<std::size_t>(j - 1)][v];
        known[static_cast<std::size_t>(i)][v] = kLooking;
        return true;
      }
    }
    return false;
  };
  // The straight moves from each view (segments by where they start).
  std::vector<std::vector<std::size_t>> moves_from(nv);
  for (std::size_t v = 0; v < nv; ++v) {
    for (std::size_t g = segments.first[v]; g < segments.first[v + 1]; ++g) {
      moves_from[static_cast<std::size_t>(segments.from[g])].push_back(g);
    }
  }

  // Then the programme, twice. First keeping at each step only the kBeam
  // lattice states of the largest totals: a path, whose total is `floor`.
  // Then keeping every state whose total, with the best values of the steps
  // after it, can still reach the floor: the best path is among them (the
  // others cannot beat the first path), so the second programme is exact;
  // it values only the states it may keep, each only as far as it could
  // still reach the floor, and the views that stand for the straight moves'
  // steps from the states it keeps. The best totals of the last K + 1 steps
  // (K = segment steps), in turn.
  constexpr std::size_t kBeam = 64;
  const double slack = 1e-9 * static_cast<double>(steps);  // rounding of sums in another order
  std::vector<std::vector<double>> totals(static_cast<std::size_t>(K + 1), std::vector<double>(states, kUnreached));
  const auto total_at = [&](long i) -> std::vector<double>& { return totals[static_cast<std::size_t>(i % (K + 1))]; };
  // How each state was reached: the state before the move and the move's steps (1 or K).
  std::vector<std::vector<int>> from(static_cast<std::size_t>(steps), std::vector<int>(states, -1));
  std::vector<std::vector<std::uint8_t>> move(static_cast<std::size_t>(steps), std::vector<std::uint8_t>(states, 1));
  std::vector<double> came(nv);  // the best total before the move into each lattice view
  std::vector<int> came_from(nv);
  std::vector<std::uint8_t> came_by(nv);
  std::vector<char> stands_for(nv);  // views that stand for a straight move's step here
  std::size_t last = states - 1;     // the best final state
  const auto programme = [&](bool beam, double floor) {
    for (std::vector<double>& t : totals) std::fill(t.begin(), t.end(), kUnreached);
    total_at(0)[nv] = value[0][nv];
    for (long i = 1; i < steps; ++i) {
      const auto si = static_cast<std::size_t>(i);
      const std::vector<double>& total = total_at(i - 1);
      std::vector<double>& next = total_at(i);
      std::fill(next.begin(), next.end(), kUnreached);
      // Lattice views: from a neighbour within reach, from the end of the
      // approach, or by a straight move of K steps (its centroid's largest move
      // in a step plus the camera's on the sphere within reach).
      const std::size_t end = nv + static_cast<std::size_t>(chain);
      double shift = 0.0;
      for (long j = std::max(1L, i - K + 1); j <= i && K > 1; ++j) {
        shift = std::max(shift, (c[static_cast<std::size_t>(j)] - c[static_cast<std::size_t>(j - 1)]).norm());
      }
      const std::vector<double>* before_move = i >= K && K > 1 ? &total_at(i - K) : nullptr;
      tbb::parallel_for(0, n, [&](int v) {
        const auto sv = static_cast<std::size_t>(v);
        const Eigen::Vector3d here = position(sv, i);
        double best = kUnreached;
        int arg = -1;
        std::uint8_t steps_of_move = 1;
        for (const int u : near[sv]) {
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
        if (const int g = direct_to[sv]; g >= 0 && direct[static_cast<std::size_t>(g)].k == i) {
          const double t = value[0][nv] + direct[static_cast<std::size_t>(g)].sum;
          if (t > best) {
            best = t;
            arg = n;
            steps_of_move = static_cast<std::uint8_t>(i);
          }
        }
        if (before_move != nullptr) {
          for (std::size_t g = segments.first[sv]; g < segments.first[sv + 1]; ++g) {
            double t = (*before_move)[static_cast<std::size_t>(segments.from[g])];
            if (!(t > kUnreached) || shift + r_sphere * segments.step_chord[g] > reach) continue;
            const int* mid = &segments.mids[g * static_cast<std::size_t>(K - 1)];
            for (int m = 1; m < K; ++m) {
              const auto sj = si - static_cast<std::size_t>(K - m);
              const auto sm = static_cast<std::size_t>(mid[m - 1]);
              if (!exact(sj, sm)) throw std::logic_error("hindsight planner: a straight move's step was not valued");
              t += value[sj][sm];
            }
            if (t > best) {
              best = t;
              arg = segments.from[g];
              steps_of_move = static_cast<std::uint8_t>(K);
            }
          }
        }
        came[sv] = best;
        came_from[sv] = arg;
        came_by[sv] = steps_of_move;
      });
      // The views that stand for the m-th step of a straight move from a
      // state kept at step i - m.
      std::fill(stands_for.begin(), stands_for.end(), 0);
      for (int m = 1; m < K && m <= i; ++m) {
        const std::vector<double>& kept = total_at(i - m);
        for (std::size_t u = 0; u < nv; ++u) {
          if (!(kept[u] > kUnreached)) continue;
          for (const std::size_t g : moves_from[u]) {
            stands_for[static_cast<std::size_t>(segments.mids[g * static_cast<std::size_t>(K - 1) + static_cast<std::size_t>(m - 1)])] = 1;
          }
        }
      }
      // What must be valued here, as far as it matters.
      std::vector<int> views;
      std::vector<double> at_least;
      for (std::size_t v = 0; v < nv; ++v) {
        if ((came_from[v] < 0 && !stands_for[v]) || exact(si, v) || carried(i, v)) continue;
        double need = kUnreached;
        if (!beam && !stands_for[v]) {
          need = floor - slack - after[si] - came[v];
          // It cannot reach the floor: even the step's best value would not, or its bound does not.
          if (need > upper[si] || (known[si][v] == kAtMost && value[si][v] < need)) continue;
        }
        views.push_back(static_cast<int>(v));
        at_least.push_back(need);
      }
      cast(i, views, at_least);
      for (std::size_t v = 0; v < nv; ++v) {
        if (came_from[v] < 0 || !exact(si, v)) continue;
        next[v] = came[v] + value[si][v];
        from[si][v] = came_from[v];
        move[si][v] = came_by[v];
      }
      // The approach: stay, or go one state on.
      for (int j = 0; j <= chain; ++j) {
        const auto s = nv + static_cast<std::size_t>(j);
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
      // Keep the beam, or the states that can still reach the floor.
      if (beam) {
        std::vector<std::pair<double, std::size_t>> ranked;
        for (std::size_t v = 0; v < nv; ++v) {
          if (next[v] > kUnreached) ranked.emplace_back(-next[v], v);
        }
        if (ranked.size() > kBeam) {
          std::nth_element(ranked.begin(), ranked.begin() + kBeam, ranked.end());
          for (auto r = ranked.begin() + kBeam; r != ranked.end(); ++r) next[r->second] = kUnreached;
        }
      } else {
        for (std::size_t v = 0; v < nv; ++v) {
          if (next[v] + after[si] < floor - slack) next[v] = kUnreached;
        }
      }
    }
    // The best final state (the approach's end first: of equal paths, the
    // one that moves least).
    const std::vector<double>& final_total = total_at(steps - 1);
    last = states - 1;
    for (std::size_t s = 0; s < nv; ++s) {
      if (final_total[s] > final_total[last]) last = s;
    }
    return final_total[last];
  };
  const double first = programme(true, kUnreached);
  programme(false, first);

  // Back to the start from the best final state. A straight move's steps lie
  // on its great circle; the nearest views stood for them in the programme,
  // the path's own values are then cast from where the camera is.
  plan.views.resize(static_cast<std::size_t>(steps));
  plan.visible.resize(static_cast<std::size_t>(steps));
  std::vector<std::size_t> inside;  // steps inside straight moves
  for (long i = steps - 1; i >= 0;) {
    const auto si = static_cast<std::size_t>(i);
    plan.views[si] = position(last, i);
    plan.visible[si] = value[si][last];
    if (i == 0) break;
    const int k = move[si][last];
    const auto u = static_cast<std::size_t>(from[si][last]);
    for (int m = 1; m < k; ++m) {
      const auto sj = si - static_cast<std::size_t>(k - m);
      const double f = static_cast<double>(m) / k;
      plan.views[sj] = u == static_cast<std::size_t>(n)
                           ? Eigen::Vector3d(start + (plan.views[si] - start) * f)  // from the start, straight
                           : Eigen::Vector3d(c[sj] + r_sphere * between(d.col(static_cast<Eigen::Index>(u)),
                                                                        d.col(static_cast<Eigen::Index>(last)), f));
      inside.push_back(sj);
    }
    last = u;
    i -= k;
  }
  for (const std::size_t sj : inside) {
    renderer.set_time(plan.times[sj]);
    bool turned = false;
    plan.visible[sj] = renderer.visible_fractions({aimed(plan.views[sj], static_cast<long>(sj), &turned)}).front();
    ++plan.evaluations;
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
