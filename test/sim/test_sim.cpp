// The simulated world: scenario files, motion, deformation, rendering against
// analytic depth, labels, ground-truth visibility, determinism.
#include "ofv/sim/live_source.h"
#include "ofv/sim/renderer.h"
#include "ofv/constants.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace ofv::sim {
namespace {

constexpr const char* kSource = "test.yaml";

std::string error_of(const std::string& yaml) {
  try {
    (void)scenario_from_yaml(yaml, kSource);
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

// A flat wall (thin box) facing the camera at depth `z`, and optional extra YAML.
Scenario wall_scene(double z, const std::string& extra = "") {
  return scenario_from_yaml(
      "sensor: {noise: {enabled: false}}\n"
      "object: {shape: box, size: [0.2, 0.2, 0.01], position: [0, 0, " + std::to_string(z) + "]}\n" + extra,
      kSource);
}

TEST(Scenario, DefaultsOfAMinimalFile) {
  const Scenario s = scenario_from_yaml("object: {shape: box}", kSource);
  EXPECT_EQ(s.duration, 4.0);
  EXPECT_EQ(s.rate, 30.0);
  EXPECT_EQ(s.sensor.intrinsics.width, 320);
  EXPECT_EQ(s.sensor.min_depth, 0.1);
  EXPECT_EQ(s.sensor.max_depth, 3.0);
  EXPECT_TRUE(s.sensor.noise.enabled);
  EXPECT_EQ(s.robot, "camera");
  EXPECT_TRUE(s.wMc_start.isApprox(Eigen::Isometry3d::Identity()));  // looks along +z, y down
  ASSERT_EQ(s.bodies.size(), 1U);
  EXPECT_EQ(s.bodies[0].role, Role::Object);
  EXPECT_NEAR(s.bodies[0].mesh.area(), 2 * (0.19 * 0.135 + 0.19 * 0.015 + 0.135 * 0.015), 1e-6);
  EXPECT_EQ(s.r_sphere(), 0.5);
}

TEST(Scenario, ErrorsNameFileKeyAndValue) {
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases{
      {"duration: 2", {"missing 'object'"}},
      {"object: {shape: cone}", {"object.shape", "cone"}},
      {"object: {shape: box, colr: [1, 2, 3]}", {"object.colr", "unknown key"}},
      {"object: {shape: box}\nspeed: 3", {"speed", "unknown key"}},
      {"object: {shape: box}\nduration: -1", {"duration", "-1"}},
      {"object: {shape: box}\nrate: fast", {"rate", "fast"}},
      {"object: {shape: box, colour: [300, 0, 0]}", {"object.colour", "300"}},
      {"object: {shape: box, size: [1, 2]}", {"object.size"}},
      {"object: {shape: box, waypoints: [{t: 1}, {t: 0.5}]}", {"object.waypoints[1].t", "increase"}},
      {"object: {shape: mesh}", {"object", "file"}},
      {"object: {shape: mesh, file: /nonexistent.obj}", {"object.file", "nonexistent.obj"}},
      {"object: {shape: box}\nsensor: {preset: kinect}", {"sensor.preset", "kinect"}},
      {"object: {shape: box}\nsensor: {noise: {edge_dropout: 2}}", {"sensor.noise.edge_dropout", "2"}},
      {"object: {shape: box}\nestimator: {step: -1}", {"estimator", "step", "-1"}},
      {"object: {shape: box}\nestimator: {speed: 1}", {"estimator.speed", "unknown parameter"}},
      {"object: {shape: box}\nrobot: puma", {"robot", "puma"}},
      {"object: {shape: box}\ncamera: {position: [0, 0, 0], look_at: [0, 0, 0]}", {"camera"}},
      {"object: {shape: box, wave: {amplitude: 0.1}}", {"object.wave", "cloth"}},
      {"object: [1, 2", {"invalid YAML"}},
      {"object: {shape: box}\nvariation: {time: -1}", {"variation.time", "-1"}},
      {"object: {shape: box}\nvariation: {speed: 1}", {"variation.speed", "unknown key"}},
  };
  for (const auto& [yaml, mentions] : cases) {
    const std::string message = error_of(yaml);
    EXPECT_NE(message.find(kSource), std::string::npos) << yaml << " -> " << message;
    for (const auto& m : mentions) EXPECT_NE(message.find(m), std::string::npos) << yaml << " -> " << message;
  }
}

TEST(Scenario, RepeatedKeysDeepNestingAndAliasBombsAreErrors) {
  // yaml-cpp keeps the first of two equal keys: the check names the second.
  EXPECT_NE(error_of("object: {shape: box}\nrate: 10\nrate: 30").find("test.yaml:3: duplicate key 'rate'"),
            std::string::npos);
  EXPECT_NE(error_of("object:\n  shape: box\n  shape: sphere").find("test.yaml:3: duplicate key 'shape'"),
            std::string::npos);
  EXPECT_NE(error_of("object: {shape: box}\ndescription: " + std::string(40, '[') + std::string(40, ']'))
                .find("nested deeper than 32"),
            std::string::npos);
  // Each alias is walked where it is used: nine levels of ten make 10^9 nodes.
  std::string bomb = "a0: &a0 [x, x, x, x, x, x, x, x, x, x]\n";
  for (int k = 1; k < 9; ++k) {
    const std::string p = "*a" + std::to_string(k - 1);
    bomb += "a" + std::to_string(k) + ": &a" + std::to_string(k) + " [" + p + ", " + p + ", " + p + ", " + p +
            ", " + p + ", " + p + ", " + p + ", " + p + ", " + p + ", " + p + "]\n";
  }
  EXPECT_NE(error_of(bomb).find("more than 100000 nodes"), std::string::npos) << error_of(bomb);
}

TEST(Scenario, EveryNumberHasAnUpperBound) {
  for (const char* yaml :
       {"object: {shape: cloth, grid: [100000, 100000]}", "object: {shape: box}\nduration: 1e9",
        "object: {shape: box}\nrate: 1e9", "object: {shape: box}\nsensor: {width: 40000}",
        "object: {shape: box}\nsensor: {fx: 1e300}", "object: {shape: sphere, radius: 1e6}",
        "object: {shape: box, position: [0, 0, 1e9]}", "object: {shape: box}\ncontroller: {gain: 1e9}",
        "object: {shape: box}\ntable: {size: [1e9, 1, 1]}"}) {
    EXPECT_NE(error_of(yaml).find("expected"), std::string::npos) << yaml << " -> " << error_of(yaml);
  }
}

TEST(Scenario, BuiltInScenariosLoad) {
  const auto names = builtin_scenarios();
  for (const char* expected : {"dvd-static", "dvd-one-hand", "dvd-two-hands", "cloth-occluder",
                               "sweep", "moving-object", "no-free-view"}) {
    EXPECT_NE(std::find(names.begin(), names.end(), expected), names.end()) << expected;
  }
  for (const auto& n : names) {
    const Scenario s = load_scenario(n);
    EXPECT_EQ(s.name, n);
    for (const auto& b : s.bodies) EXPECT_TRUE(b.mesh.valid()) << n << " " << b.name;
  }
  EXPECT_THROW((void)load_scenario("no-such-scenario"), std::invalid_argument);
}

TEST(Scenario, SeedsVaryTheOccludersWithinTheScenarioVariation) {
  const Scenario base = load_scenario("dvd-two-hands");
  ASSERT_GT(base.variation.time, 0.0);
  ASSERT_GT(base.variation.position, 0.0);
  const Scenario same = with_seed(base, 0);
  EXPECT_EQ(same.seed, base.seed);
  const auto waypoints_equal = [](const Body& a, const Body& b) {
    if (a.motion.waypoints.size() != b.motion.waypoints.size()) return false;
    for (std::size_t i = 0; i < a.motion.waypoints.size(); ++i) {
      if (a.motion.waypoints[i].t != b.motion.waypoints[i].t ||
          a.motion.waypoints[i].position != b.motion.waypoints[i].position) {
        return false;
      }
    }
    return true;
  };
  int moved = 0;
  for (unsigned k = 0; k < 4; ++k) {
    const Scenario s = with_seed(base, k);
    EXPECT_EQ(s.seed, base.seed + k);
    const Scenario again = with_seed(base, k);
    for (std::size_t b = 0; b < base.bodies.size(); ++b) {
      const Body& before = base.bodies[b];
      const Body& after = s.bodies[b];
      EXPECT_TRUE(waypoints_equal(after, again.bodies[b])) << "seed " << k << " is not reproducible";
      if (k == 0 || before.role != Role::Occluder) {
        EXPECT_TRUE(waypoints_equal(before, after)) << "seed " << k << " changed " << before.name;
        continue;
      }
      moved += waypoints_equal(before, after) ? 0 : 1;
      // One delay and one shift for the whole motion, within the bounds.
      const double delay = after.motion.waypoints[0].t - before.motion.waypoints[0].t;
      const Eigen::Vector3d shift = after.motion.waypoints[0].position - before.motion.waypoints[0].position;
      EXPECT_LE(std::abs(delay), base.variation.time + 1e-12);
      EXPECT_LE(shift.norm(), base.variation.position + 1e-12);
      for (std::size_t i = 0; i < before.motion.waypoints.size(); ++i) {
        EXPECT_NEAR(after.motion.waypoints[i].t - before.motion.waypoints[i].t, delay, 1e-12);
        EXPECT_TRUE((after.motion.waypoints[i].position - before.motion.waypoints[i].position).isApprox(shift, 1e-12));
      }
    }
  }
  EXPECT_EQ(moved, 6) << "seeds 1-3 should move both hands";
}

TEST(Motion, InterpolatesPositionLinearlyAndRotationBySlerp) {
  Motion m;
  Waypoint a, b;
  a.t = 1.0;
  a.position = {0, 0, 0};
  b.t = 3.0;
  b.position = {2, 0, 0};
  b.rpy_deg = {0, 0, 90};
  m.waypoints = {a, b};
  EXPECT_TRUE(m.at(0.0).translation().isApprox(Eigen::Vector3d::Zero()));  // held before
  EXPECT_TRUE(m.at(2.0).translation().isApprox(Eigen::Vector3d(1, 0, 0)));
  EXPECT_NEAR(Eigen::AngleAxisd(m.at(2.0).linear()).angle(), kPi / 4, 1e-9);
  EXPECT_TRUE(m.at(9.0).translation().isApprox(Eigen::Vector3d(2, 0, 0)));  // held after
}

TEST(Mesh, PrimitivesAreValidAndClosedWithOutwardNormals) {
  for (const TriangleMesh& m : {make_box({0.1, 0.2, 0.3}), make_sphere(0.1), make_capsule(0.05, 0.2),
                                make_sheet(0.3, 0.2, 0.002, 6, 4)}) {
    ASSERT_TRUE(m.valid());
    // Divergence theorem: the signed volume is positive iff normals point out.
    double volume = 0.0;
    for (const auto& t : m.triangles) {
      volume += m.vertices[t[0]].cast<double>().dot(m.vertices[t[1]].cast<double>().cross(m.vertices[t[2]].cast<double>())) / 6.0;
    }
    EXPECT_GT(volume, 0.0);
  }
  EXPECT_NEAR(make_box({0.1, 0.2, 0.3}).area(), 2 * (0.02 + 0.03 + 0.06), 1e-6);
  EXPECT_NEAR(make_sphere(0.1, 64, 32).area(), 4 * kPi * 0.01, 2e-3);
}

TEST(Mesh, DeformationKeepsTheSheetValid) {
  const TriangleMesh rest = make_sheet(0.3, 0.2, 0.004, 20, 10);
  TriangleMesh bent;
  for (double t : {0.0, 0.3, 1.7}) {
    deform_sheet(rest, 0.02, 0.15, 0.5, 1.0, t, bent);
    ASSERT_TRUE(bent.valid());
    EXPECT_EQ(bent.triangles, rest.triangles);
    // Both faces move together: the thickness is kept.
    const std::size_t per_face = rest.vertices.size() / 2;
    EXPECT_NEAR((bent.vertices[per_face + 7] - bent.vertices[7]).norm(), 0.004, 1e-6);
  }
  deform_sheet(rest, 0.02, 0.15, 0.5, 0.0, 0.0, bent);
  EXPECT_FALSE(bent.vertices[3].isApprox(rest.vertices[3]));
}

TEST(Renderer, DepthOfAPlaneMatchesTheAnalyticValue) {
  const Scenario s = scenario_from_yaml(
      "sensor: {noise: {enabled: false}}\nobject: {shape: box, size: [1, 1, 0.01], position: [0, 0, 1]}", kSource);
  Renderer r(s);
  // The sensor stores depth in counts of 1/5000 m, as TUM recordings do.
  const auto stored = [](double z) { return depth_from_units(depth_to_units(z, kTumDepthFactor), kTumDepthFactor); };
  // Straight on: every pixel on the wall sees its front face at z = 0.995.
  RenderedFrame f = r.render(s.wMc_start, 0);
  const CameraIntrinsics& k = f.frame.intrinsics;
  EXPECT_EQ(f.frame.depth[f.frame.index(160, 120)], stored(0.995));
  EXPECT_EQ(f.frame.depth[f.frame.index(170, 130)], stored(0.995));
  // Tilted camera about x by 5 degrees: depth along each ray is analytic.
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
  wMc.linear() = Eigen::AngleAxisd(5.0 * kPi / 180, Eigen::Vector3d::UnitX()).toRotationMatrix();
  f = r.render(wMc, 0);
  for (const auto& [u, v] : {std::pair{160, 120}, std::pair{150, 100}, std::pair{170, 140}}) {
    const Eigen::Vector3d ray_w = wMc.linear() * Eigen::Vector3d((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
    const double expected = 0.995 / ray_w.z();  // Z of the hit along a unit-Z camera ray
    EXPECT_EQ(f.frame.depth[f.frame.index(u, v)], stored(expected)) << u << "," << v;
  }
}

TEST(Renderer, APoseThatIsNotFiniteIsRefused) {
  const Scenario s = scenario_from_yaml("object: {shape: box, size: [1, 1, 0.01], position: [0, 0, 1]}", kSource);
  Renderer r(s);
  Eigen::Isometry3d wMc = s.wMc_start;
  wMc.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW((void)r.render(wMc, 0), std::invalid_argument);
  wMc = s.wMc_start;
  wMc.linear()(2, 2) = std::numeric_limits<double>::infinity();
  EXPECT_THROW((void)r.render(wMc, 0), std::invalid_argument);
  EXPECT_NO_THROW((void)r.render(s.wMc_start, 0));
}

TEST(Renderer, DepthOfASphereMatchesTheAnalyticValue) {
  const Scenario s = scenario_from_yaml(
      "sensor: {noise: {enabled: false}}\nobject: {shape: sphere, radius: 0.1, position: [0, 0, 0.8]}", kSource);
  Renderer r(s);
  const RenderedFrame f = r.render(s.wMc_start, 0);
  const CameraIntrinsics& k = f.frame.intrinsics;
  EXPECT_NEAR(f.frame.depth[f.frame.index(160, 120)], 0.7, 1e-3);  // tessellation tolerance
  // Silhouette radius: tan(asin(r / d)) f.
  const double radius_px = std::tan(std::asin(0.1 / 0.8)) * k.fx;
  EXPECT_GT(f.frame.depth[f.frame.index(160 + static_cast<int>(radius_px) - 3, 120)], 0.0f);
  EXPECT_EQ(f.frame.depth[f.frame.index(160 + static_cast<int>(radius_px) + 3, 120)], 0.0f);
  // Off-centre pixel inside: analytic ray-sphere hit, Z component.
  const Eigen::Vector3d d((180 - k.cx) / k.fx, (130 - k.cy) / k.fy, 1.0);
  const Eigen::Vector3d c(0, 0, 0.8);
  const double b = d.dot(c), a = d.squaredNorm();
  const double t = (b - std::sqrt(b * b - a * (c.squaredNorm() - 0.01))) / a;
  EXPECT_NEAR(f.frame.depth[f.frame.index(180, 130)], t, 2e-3);
}

TEST(Renderer, LabelsNameWhatEachPixelSees) {
  const Scenario s = wall_scene(1.0,
      "occluders: [{shape: box, size: [0.05, 0.05, 0.05], position: [0, 0, 0.5]}]\n"
      "holder: {shape: sphere, radius: 0.02, position: [0.12, 0, 1.0]}\n"
      "table: {position: [0, 0.3, 1.0], size: [2, 0.02, 2]}\n");
  Renderer r(s);
  const RenderedFrame f = r.render(s.wMc_start, 0);
  const CameraIntrinsics& k = f.frame.intrinsics;
  auto label_at = [&](const Eigen::Vector3d& p) {
    const int u = static_cast<int>(std::lround(k.fx * p.x() / p.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * p.y() / p.z() + k.cy));
    return f.frame.labels[f.frame.index(u, v)];
  };
  EXPECT_EQ(label_at({0, 0, 0.5}), kLabelOccluder0);
  EXPECT_EQ(label_at({0.07, 0.05, 1.0}), kLabelObject);
  EXPECT_EQ(label_at({0.125, 0.0, 1.0}), kLabelInteracting);
  EXPECT_EQ(label_at({0.0, 0.29, 1.2}), kLabelBackground);
  EXPECT_EQ(f.frame.labels[f.frame.index(2, 2)], kLabelNone);
  EXPECT_EQ(f.frame.depth[f.frame.index(2, 2)], 0.0f);
}

TEST(Renderer, AHolderApartFromTheObjectIsAnOccluder) {
  // A hand that comes to take the object: an occluder like any other body
  // until it touches the object (within 1 cm), then the object's holder.
  const Scenario s = wall_scene(1.0,
      "occluders: [{shape: box, size: [0.05, 0.05, 0.05], position: [0, 0, 0.5]}]\n"
      "holder: {shape: sphere, radius: 0.02, waypoints: [{t: 0, position: [0.3, 0, 1.0]},\n"
      "                                                  {t: 1, position: [0.125, 0, 1.0]}]}\n");
  Renderer r(s);
  const CameraIntrinsics& k = s.sensor.intrinsics;
  const auto label_at = [&](const RenderedFrame& f, const Eigen::Vector3d& p) {
    const int u = static_cast<int>(std::lround(k.fx * p.x() / p.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * p.y() / p.z() + k.cy));
    return f.frame.labels[f.frame.index(u, v)];
  };
  // The ground-truth problem's occluder cells within 3 cm of the holder's centre.
  const auto cells_near = [&](const Eigen::Vector3d& centre) {
    const ViewProblem p = r.ground_truth_problem(s.wMc_start, 0.02, 0.5, 0.02);
    int n = 0;
    for (Eigen::Index j = 0; j < p.occluders.cols(); ++j) n += (p.occluders.col(j) - centre).norm() < 0.03 ? 1 : 0;
    return n;
  };
  r.set_time(0.0);  // 18 cm from the wall's edge
  EXPECT_EQ(label_at(r.render(s.wMc_start, 0), {0.3, 0.0, 0.98}), kLabelOccluder0 + 1);
  EXPECT_EQ(r.truth(s.wMc_start, 0.5).occluders_in_sphere, 2);
  EXPECT_GT(cells_near({0.3, 0.0, 1.0}), 0);
  r.set_time(0.9);  // 2.25 cm from it
  EXPECT_EQ(label_at(r.render(s.wMc_start, 1), {0.1425, 0.0, 0.98}), kLabelOccluder0 + 1);
  r.set_time(1.0);  // 5 mm from it
  EXPECT_EQ(label_at(r.render(s.wMc_start, 2), {0.125, 0.0, 0.98}), kLabelInteracting);
  EXPECT_EQ(r.truth(s.wMc_start, 0.5).occluders_in_sphere, 1);
  EXPECT_EQ(cells_near({0.125, 0.0, 1.0}), 0);
}

TEST(Truth, VisibleFractionOnHandComputedCases) {
  const double r_sphere = 0.5;
  {  // fully visible
    Renderer r(wall_scene(0.6));
    EXPECT_NEAR(r.truth(r.scenario().wMc_start, r_sphere).visible_fraction, 1.0, 1e-9);
  }
  {  // the left half covered by a box half-way between camera and wall: [-0.05, 0] at 0.3 m
  // covers [-0.1, 0] at 0.6 m (only the front face faces the camera)
    Renderer r(wall_scene(0.6, "occluders: [{shape: box, size: [0.05, 0.3, 0.02], position: [-0.025, 0, 0.3]}]"));
    const ObjectTruth t = r.truth(r.scenario().wMc_start, r_sphere);
    EXPECT_NEAR(t.visible_fraction, 0.5, 0.05);
    EXPECT_EQ(t.occluders_in_sphere, 1);
  }
  {  // fully covered
    Renderer r(wall_scene(0.6, "occluders: [{shape: box, size: [0.4, 0.4, 0.02], position: [0, 0, 0.3]}]"));
    EXPECT_EQ(r.truth(r.scenario().wMc_start, r_sphere).visible_fraction, 0.0);
  }
  {  // behind the camera
    Renderer r(wall_scene(-0.6));
    EXPECT_EQ(r.truth(r.scenario().wMc_start, r_sphere).visible_fraction, 0.0);
  }
  {  // half outside the image: the camera 0.312 m to the side puts the image's left border (fx 307.5,
     // cx 160) at x = 0 on the wall; the front face's right half and the side face towards the
     // camera (0.2 x 0.01) are seen, of the front and that side: 0.022 / 0.042
    Renderer r(wall_scene(0.6));
    Eigen::Isometry3d wMc = r.scenario().wMc_start;
    wMc.translation().x() = 0.6 * 160.0 / 307.5;
    EXPECT_NEAR(r.truth(wMc, r_sphere).visible_fraction, 0.022 / 0.042, 0.03);
    wMc.translation().x() = 1.0;  // the wall out of the image altogether
    EXPECT_EQ(r.truth(wMc, r_sphere).visible_fraction, 0.0);
  }
}

// Cameras on a sphere of radius r around c looking at c (y of the image as
// near world y as the view allows), in a Fibonacci spiral.
std::vector<Eigen::Isometry3d> views_around(const Eigen::Vector3d& c, double r, int n) {
  std::vector<Eigen::Isometry3d> views;
  for (int i = 0; i < n; ++i) {
    const double z = 1.0 - (2.0 * i + 1.0) / n, ring = std::sqrt(1.0 - z * z), phi = 2.399963229728653 * i;
    const Eigen::Vector3d o = c + r * Eigen::Vector3d(ring * std::cos(phi), z, ring * std::sin(phi));
    const Eigen::Vector3d look = (c - o).normalized();
    const Eigen::Vector3d side = Eigen::Vector3d::UnitY().cross(look);
    Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
    if (side.norm() < 1e-6) continue;
    const Eigen::Vector3d x = side.normalized(), y = look.cross(x);
    wMc.linear() << x, y, look;
    wMc.translation() = o;
    views.push_back(wMc);
  }
  return views;
}

TEST(Truth, VisibleFractionIsTheSameWhereNoShortcutApplies) {
  // No ray is cast where the answer is known: a convex object with no other
  // body between it and the camera (every facing sample seen), or a body
  // that is its own box across every line of sight (none seen). Turning the
  // world makes the table no longer its box's, and a small ball inside the
  // object puts a body in every view's cone: there every ray is cast.
  const std::string bodies =
      "object: {shape: box, size: [0.19, 0.135, 0.015], position: [0, 0, 0.5], rpy_deg: [0, 20, 0]}\n"
      "table: {position: [0, 0.09, 0.6], size: [1.2, 0.02, 1.0]}\n";
  const std::string hand = "{shape: capsule, radius: 0.03, length: 0.1, rpy_deg: [0, 90, 0], position: [0.05, -0.02, 0.3]}";
  const Scenario straight = scenario_from_yaml("sensor: {noise: {enabled: false}}\n" + bodies + "occluders: [" + hand + "]\n",
                                               kSource);
  Scenario turned = scenario_from_yaml("sensor: {noise: {enabled: false}}\n" + bodies + "occluders: [" + hand +
                                           ", {shape: sphere, radius: 0.004, position: [0, 0, 0.5]}]\n",
                                       kSource);
  const Eigen::Isometry3d R(Eigen::AngleAxisd(0.7, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  for (Body& b : turned.bodies) {
    for (Waypoint& w : b.motion.waypoints) {
      const Eigen::Matrix3d m = R.linear() * rpy_deg_to_matrix(w.rpy_deg);
      w.position = R * w.position;
      w.rpy_deg = Eigen::Vector3d(std::atan2(m(2, 1), m(2, 2)), std::asin(-m(2, 0)), std::atan2(m(1, 0), m(0, 0))) * 180.0 / kPi;
    }
  }
  const Renderer a(straight), b(turned);
  const std::vector<Eigen::Isometry3d> views = views_around({0, 0, 0.5}, 0.5, 400);
  std::vector<Eigen::Isometry3d> turned_views;
  for (const Eigen::Isometry3d& v : views) turned_views.push_back(R * v);
  const std::vector<double> fa = a.visible_fractions(views), fb = b.visible_fractions(turned_views);
  int none = 0, all = 0, part = 0;
  for (std::size_t i = 0; i < views.size(); ++i) {
    EXPECT_NEAR(fa[i], fb[i], 2e-3) << "view " << i << " at " << views[i].translation().transpose();
    none += fa[i] == 0.0 ? 1 : 0;
    all += fa[i] == 1.0 ? 1 : 0;
    part += fa[i] > 0.0 && fa[i] < 1.0 ? 1 : 0;
  }
  EXPECT_GT(none, 100);  // under the table
  EXPECT_GT(all, 100);
  EXPECT_GT(part, 10);   // behind the hand, across the table's edge
}

TEST(Truth, AThresholdStopsTheRaysOnlyBelowIt) {
  // The hindsight planner asks only whether a view can beat a threshold:
  // below it, an upper bound (fewer rays); at or above it, the same value as
  // without. Views all round the case with a hand in front, every ray cast
  // (a ball inside the case is in every view's cone).
  const Scenario s = scenario_from_yaml(
      "sensor: {noise: {enabled: false}}\n"
      "object: {shape: box, size: [0.19, 0.135, 0.015], position: [0, 0, 0.5]}\n"
      "table: {position: [0, 0.09, 0.6], size: [1.2, 0.02, 1.0]}\n"
      "occluders: [{shape: capsule, radius: 0.03, length: 0.1, rpy_deg: [0, 90, 0], position: [0.05, -0.02, 0.3]},\n"
      "            {shape: sphere, radius: 0.004, position: [0, 0, 0.5]}]\n",
      kSource);
  const Renderer r(s);
  const std::vector<Eigen::Isometry3d> views = views_around({0, 0, 0.5}, 0.5, 400);
  const std::vector<double> value = r.visible_fractions(views);
  int stops = 0, parts = 0;
  for (const double threshold : {0.3, 0.9, 0.999}) {
    // Each view twice: the second time its rays go first to the samples the
    // first found not seen (found again: a bound from fewer rays).
    std::vector<std::vector<std::uint64_t>> missed(views.size());
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<char> exact;
      const std::vector<double> bounded =
          r.visible_fractions(views, std::vector<double>(views.size(), threshold), exact, &missed);
      ASSERT_EQ(bounded.size(), views.size());
      for (std::size_t i = 0; i < views.size(); ++i) {
        if (exact[i] != 0) {
          EXPECT_EQ(bounded[i], value[i]) << "view " << i << ", threshold " << threshold;
        } else {
          EXPECT_LT(bounded[i], threshold) << "view " << i;
          EXPECT_GE(bounded[i], value[i]) << "view " << i;
          EXPECT_LT(value[i], threshold) << "view " << i;
          EXPECT_FALSE(missed[i].empty()) << "view " << i;
          stops += pass;
        }
        if (value[i] >= threshold) {
          EXPECT_NE(exact[i], 0) << "view " << i << ", threshold " << threshold;
        }
        parts += value[i] > 0.0 && value[i] < 1.0 ? 1 : 0;
      }
    }
  }
  EXPECT_GT(parts, 10);  // views that see part of the case
  EXPECT_GT(stops, 10);  // views whose rays stopped early
  std::vector<char> exact;
  EXPECT_THROW((void)r.visible_fractions(views, {0.5}, exact), std::invalid_argument);
  const std::vector<double> none = r.visible_fractions(views, std::vector<double>(views.size(), 0.0), exact);
  EXPECT_EQ(none, value);  // a threshold of 0 never stops the rays
}

TEST(Truth, AFaceSeenEdgeOnIsNotHiddenByItself) {
  // A camera within a hair of the plane of the case's right face sees that
  // face edge-on: the rays to its samples run along it. Nothing hides them
  // (the ball inside the case only makes every ray be cast), so all of the
  // case's facing samples are seen, as where no ray is needed.
  const std::string object = "object: {shape: box, size: [0.19, 0.135, 0.015], position: [0, 0, 0.5]}\n";
  const Renderer rays(scenario_from_yaml(
      "sensor: {noise: {enabled: false}}\n" + object + "occluders: [{shape: sphere, radius: 0.004, position: [0, 0, 0.5]}]\n",
      kSource));
  const Renderer no_rays(scenario_from_yaml("sensor: {noise: {enabled: false}}\n" + object, kSource));
  for (const double above : {1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3}) {
    Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
    wMc.translation() = Eigen::Vector3d(0.095 + above, 0.0, 0.0);
    const Eigen::Vector3d look = (Eigen::Vector3d(0, 0, 0.5) - wMc.translation()).normalized();
    const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(look).normalized();
    wMc.linear() << x, look.cross(x), look;
    EXPECT_EQ(no_rays.truth(wMc, 0.5).visible_fraction, 1.0) << above << " m off the face's plane";
    EXPECT_EQ(rays.truth(wMc, 0.5).visible_fraction, 1.0) << above << " m off the face's plane";
  }
}

// In front of the wall, beside the field of view, behind the wall, behind the camera.
Scenario four_occluders() {
  return wall_scene(0.6,
                    "occluders: [{shape: box, size: [0.05, 0.05, 0.02], position: [0, 0, 0.3]},\n"
                    "            {shape: box, size: [0.05, 0.05, 0.02], position: [2.0, 0, 0.3]},\n"
                    "            {shape: box, size: [0.05, 0.05, 0.02], position: [0, 0, 0.7]},\n"
                    "            {shape: box, size: [0.05, 0.05, 0.02], position: [0, 0, -0.3]}]");
}

TEST(Truth, OccludersSeenAreThoseTheFrameShows) {
  Renderer r(four_occluders());
  EXPECT_EQ(occluders_seen(r.render(r.scenario().wMc_start, 0).frame.labels), 1);
  EXPECT_EQ(r.truth(r.scenario().wMc_start, 1.0).occluders_in_sphere, 3);  // all but the one 2 m aside
  EXPECT_EQ(occluders_seen({}), 0);
  EXPECT_EQ(occluders_seen({kLabelObject, kLabelOccluder0 + 3, kLabelBackground, kLabelOccluder0 + 3,
                            kLabelOccluder0}), 2);
}

TEST(LiveSource, FramesCarryTheirLabels) {
  Renderer r(four_occluders());
  LiveSource source(r, [&r] { return r.scenario().wMc_start; }, 10.0);
  const std::optional<RgbdFrame> frame = source.next();
  ASSERT_TRUE(frame);
  EXPECT_EQ(frame->labels.size(), frame->depth.size());
  EXPECT_EQ(occluders_seen(frame->labels), 1);
}

TEST(Truth, GroundTruthProblemFacesTheCamera) {
  const Scenario s = wall_scene(0.6, "occluders: [{shape: sphere, radius: 0.03, position: [0, 0, 0.35]},"
                                      " {shape: sphere, radius: 0.03, position: [0, 0, -0.5]}]");
  Renderer r(s);
  const ViewProblem p = r.ground_truth_problem(s.wMc_start, 0.02, 0.5);
  ASSERT_GT(p.positions.cols(), 50);  // 0.2 x 0.2 m front face in 2 cm cells
  for (Eigen::Index k = 0; k < p.normals.cols(); ++k) {
    EXPECT_LT(p.normals(2, k), -0.9);  // towards the camera
  }
  ASSERT_GT(p.occluders.cols(), 0);
  for (Eigen::Index k = 0; k < p.occluders.cols(); ++k) {
    EXPECT_LT((p.occluders.col(k) - Eigen::Vector3d(0, 0, 0.6)).norm(), 0.5);  // only the one inside
  }
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(e.status, ViewStatus::Converged);
  EXPECT_GT(e.iterations, 0);
}

TEST(Truth, GroundTruthObjectIsTheProblemWithoutItsOccluders) {
  const Scenario s = load_scenario("dvd-one-hand");
  Renderer r(s);
  r.set_time(1.8);  // the hand in the sphere
  const ViewProblem whole = r.ground_truth_problem(s.wMc_start, 0.02, 0.5);
  const ViewProblem object = r.ground_truth_object(s.wMc_start, 0.02);
  ASSERT_GT(whole.occluders.cols(), 0);
  EXPECT_EQ(object.occluders.cols(), 0);
  EXPECT_EQ(object.positions, whole.positions);
  EXPECT_EQ(object.normals, whole.normals);
  EXPECT_EQ(object.camera, whole.camera);
}

TEST(Renderer, NoiseIsDeterministicPerFrame) {
  const Scenario s = load_scenario("dvd-one-hand");
  Renderer r(s);
  r.set_time(1.0);
  const RenderedFrame a = r.render(s.wMc_start, 30), b = r.render(s.wMc_start, 30), c = r.render(s.wMc_start, 31);
  EXPECT_EQ(a.frame.depth, b.frame.depth);
  EXPECT_NE(a.frame.depth, c.frame.depth);
  EXPECT_EQ(a.frame.labels, c.frame.labels);  // labels are noise-free ground truth
  std::size_t missing = 0, valid = 0;  // on the object, seen face-on
  for (std::size_t i = 0; i < a.frame.depth.size(); ++i) {
    if (a.frame.labels[i] != kLabelObject) continue;
    ++valid;
    missing += a.frame.depth[i] == 0.0f ? 1 : 0;
  }
  EXPECT_GT(missing, 0U);            // edges and grazing pixels drop out
  EXPECT_LT(missing, valid / 5);     // but most of the image is there
}

// The depth noise of a wall seen face-on at 1 m, 640x480 (300 000 draws):
// zero mean, the model's sigma, a Gaussian's kurtosis and tails, no
// correlation between neighbouring pixels or between frames.
TEST(Renderer, DepthNoiseIsGaussianAndIndependentFromPixelToPixel) {
  const Scenario s = scenario_from_yaml(
      "sensor: {preset: d435-640, noise: {depth_sigma: 0.004, grazing_deg: 89, edge_dropout: 0}}\n"
      "object: {shape: box, size: [4, 4, 0.01], position: [0, 0, 1.0]}\n",
      "wall.yaml");
  Renderer r(s);
  r.set_time(0.0);
  const RenderedFrame clean = r.render(s.wMc_start, 0, s.sensor.intrinsics, false);
  const RenderedFrame a = r.render(s.wMc_start, 0), b = r.render(s.wMc_start, 1);
  const auto standardised = [&](const RenderedFrame& f) {
    std::vector<double> e(f.frame.depth.size(), 0.0);
    for (std::size_t i = 0; i < e.size(); ++i) {
      const double z = clean.frame.depth[i];
      EXPECT_GT(f.frame.depth[i], 0.0f);
      e[i] = (f.frame.depth[i] - z) / (0.004 * z * z);
    }
    return e;
  };
  const std::vector<double> ea = standardised(a), eb = standardised(b);
  const double n = static_cast<double>(ea.size());
  double mean = 0, m2 = 0, m4 = 0, beyond3 = 0, lag = 0, frames = 0;
  for (std::size_t i = 0; i < ea.size(); ++i) {
    mean += ea[i] / n;
    m2 += ea[i] * ea[i] / n;
    m4 += std::pow(ea[i], 4) / n;
    beyond3 += std::abs(ea[i]) > 3.0 ? 1.0 / n : 0.0;
    if (i + 1 < ea.size()) lag += ea[i] * ea[i + 1] / n;
    frames += ea[i] * eb[i] / n;
  }
  EXPECT_NEAR(mean, 0.0, 0.01);
  EXPECT_NEAR(std::sqrt(m2), 1.0, 0.01);  // quantisation (0.2 mm) adds 0.0002 to the variance
  EXPECT_NEAR(m4 / (m2 * m2), 3.0, 0.05);
  EXPECT_NEAR(beyond3, 0.0027, 0.0005);  // a Gaussian's share beyond 3 sigma
  EXPECT_NEAR(lag / m2, 0.0, 0.01);
  EXPECT_NEAR(frames / m2, 0.0, 0.01);
}

TEST(Renderer, AFrameRenderedIntoAnotherIsTheFrameRenderedAfresh) {
  // The loop renders each frame into the memory of the one before (other
  // pose, size, time and noise): nothing of it may show through.
  const Scenario s = load_scenario("dvd-one-hand");
  Renderer r(s);
  r.set_time(2.0);
  Eigen::Isometry3d aside = s.wMc_start;
  aside.translation() += Eigen::Vector3d(0.1, -0.05, 0.02);
  const CameraIntrinsics big = intrinsics_preset("d435-640"), small = s.sensor.intrinsics;
  RenderedFrame reused;
  r.render(aside, 7, big, true, reused);
  for (const auto& [k, noise] : {std::pair{small, true}, std::pair{big, false}, std::pair{small, false}}) {
    r.set_time(r.time() + 0.5);
    const RenderedFrame fresh = r.render(s.wMc_start, 8, k, noise);
    r.render(s.wMc_start, 8, k, noise, reused);
    EXPECT_EQ(reused.frame.depth, fresh.frame.depth);
    EXPECT_EQ(reused.frame.rgb, fresh.frame.rgb);
    EXPECT_EQ(reused.frame.labels, fresh.frame.labels);
    EXPECT_EQ(reused.frame.intrinsics.width, k.width);
  }
}

// A dark or shiny body (`dropout`) loses that fraction of its depth pixels
// with the sensor's noise on, and none with it off; the others keep theirs.
// The labels and the object's centroid are the frame's ground truth either way.
TEST(Render, ADarkBodyLosesItsDropoutOfDepthPixels) {
  const std::string scene =
      "object: {shape: box, size: [0.2, 0.2, 0.01], position: [0, 0, 0.5], dropout: 0.4}\n"
      "occluders: [{shape: box, size: [0.1, 0.1, 0.01], position: [0.15, 0, 0.45]}]\n";
  const auto with_noise = [&](bool noise) {
    return scenario_from_yaml("sensor: {noise: {enabled: " + std::string(noise ? "true" : "false") +
                                  ", grazing_deg: 89, edge_dropout: 0}}\n" + scene,
                              "dark.yaml");
  };
  const auto missing = [](const RenderedFrame& r, std::uint16_t label) {
    int shown = 0, lost = 0;
    for (std::size_t i = 0; i < r.frame.labels.size(); ++i) {
      if (r.frame.labels[i] != label) continue;
      ++shown;
      lost += r.frame.depth[i] > 0.0f ? 0 : 1;
    }
    return static_cast<double>(lost) / shown;
  };
  const Scenario noisy = with_noise(true);
  Renderer dark(noisy);
  dark.set_time(0.0);
  const RenderedFrame a = dark.render(noisy.wMc_start, 0);
  EXPECT_NEAR(missing(a, kLabelObject), 0.4, 0.03);
  EXPECT_EQ(missing(a, kLabelOccluder0), 0.0);
  ASSERT_TRUE(a.frame.object_centroid);
  EXPECT_LT((*a.frame.object_centroid - Eigen::Vector3d(0, 0, 0.5)).norm(), 3e-3);  // of 4000 random surface samples
  const Scenario clean = with_noise(false);
  Renderer bright(clean);
  bright.set_time(0.0);
  EXPECT_EQ(missing(bright.render(clean.wMc_start, 0), kLabelObject), 0.0);
  EXPECT_THROW((void)scenario_from_yaml("object: {shape: box, dropout: 1.5}", "bad.yaml"), std::invalid_argument);
}


}  // namespace
}  // namespace ofv::sim
