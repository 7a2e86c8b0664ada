// RGB-D odometry on frames the simulator renders (with its sensor noise) at
// known camera poses: the motion it recovers and the statuses it reports.
#include "ofv/odometry/odometry.h"
#include "ofv/sim/renderer.h"
#include "ofv/sim/scenario.h"

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace ofv::odometry {
namespace {

constexpr double kDegree = M_PI / 180.0;

// Tolerances: one step of 1 cm or 1 degree (3x a scenario's largest
// motion per frame) within 10 % of the step, and 0.1 degree: the issue's
// goal per frame, for the default method (ICP). Measured with the
// renderer's noise (seeds 0, 1): ICP 0.05-0.47 mm (the largest for 1
// degree about y, the scene 0.5 m away), rgbd_icp 0.67-0.75 mm, fast_icp
// 0.30-0.75 mm; 0.004-0.054 degree, but fast_icp (OpenCV's defaults) 0.15
// degree with the renderer's counter-based noise: 0.2 for the other methods.
constexpr double kTranslationTolerance = 0.001;  // [m]
constexpr double kRotationTolerance = 0.1;        // [deg]
constexpr double kOtherMethodsRotationTolerance = 0.2;  // [deg]

/// A scenario's first frame rendered from its start pose moved by `cMc2` (in the camera's frame).
struct Scene {
  sim::Scenario scenario;
  sim::Renderer renderer;
  explicit Scene(const std::string& name) : scenario(sim::load_scenario(name)), renderer(scenario) {
    renderer.set_time(0.0);
  }
  RgbdFrame frame(const Eigen::Isometry3d& cMc2, long index) const {
    return renderer.render(scenario.wMc_start * cMc2, index).frame;
  }
};

/// An object hint at depth z (one point on the optical axis): the mask alone.
ObjectHint at_depth(double z) {
  ObjectHint hint;
  hint.points_c = Eigen::Vector3d(0.0, 0.0, z);
  return hint;
}

/// The object's surface seen from wMc, every 40th sample (about as many as its supervoxels).
ObjectHint object_of(const Scene& scene, const Eigen::Isometry3d& wMc) {
  const std::vector<Eigen::Vector3d> surface = scene.renderer.object_surface();
  Eigen::Matrix3Xd points(3, static_cast<Eigen::Index>((surface.size() + 39) / 40));
  for (std::size_t i = 0; i < surface.size(); i += 40) points.col(static_cast<Eigen::Index>(i / 40)) = surface[i];
  return object_hint(points, wMc);
}

/// The pose error of `wMc` against `wMc_true`: {translation [m], rotation [deg]}.
std::pair<double, double> error(const Eigen::Isometry3d& wMc, const Eigen::Isometry3d& wMc_true) {
  const Eigen::Isometry3d E = wMc_true.inverse() * wMc;
  return {E.translation().norm(), Eigen::AngleAxisd(E.linear()).angle() / kDegree};
}

void expect_recovers(OdometryMethod method, const Eigen::Isometry3d& cMc2,
                     double rotation_tolerance = kRotationTolerance) {
  Scene scene("dvd-static");
  OdometrySettings s;
  s.method = method;
  // A 1 cm step in one frame is 3x the scenarios' largest camera motion per
  // frame, and along the table only the case's edges hold ICP: with
  // OpenCV's 7 iterations it stops at 8.5 of the 10 mm, with 15 within 0.1 mm.
  s.iterations = 15;
  Odometry odometry(s);
  const RgbdFrame first = scene.frame(Eigen::Isometry3d::Identity(), 0);
  const OdometryResult r0 = odometry.step(first);
  EXPECT_EQ(r0.status, OdometryStatus::FirstFrame);
  EXPECT_TRUE(r0.wMc.isApprox(first.wMc));
  const RgbdFrame second = scene.frame(cMc2, 1);
  const OdometryResult r1 = odometry.step(second);
  ASSERT_EQ(r1.status, OdometryStatus::Ok) << to_string(r1.status) << " inliers " << r1.diagnostics.inlier_fraction;
  const auto [t, r] = error(r1.wMc, second.wMc);
  EXPECT_LT(t, kTranslationTolerance);
  EXPECT_LT(r, rotation_tolerance);
  // The pose is a rigid motion: its rotation is orthonormal to rounding.
  EXPECT_LT((r1.wMc.linear().transpose() * r1.wMc.linear() - Eigen::Matrix3d::Identity()).norm(), 1e-12);
  EXPECT_GT(r1.diagnostics.inlier_fraction, s.min_inlier_fraction);
  std::cout << to_string(method) << ": error " << t * 1000 << " mm, " << r << " deg, "
            << r1.diagnostics.ms << " ms, inliers " << r1.diagnostics.inlier_fraction << '\n';
}

TEST(Odometry, RecoversNoMotion) { expect_recovers(OdometryMethod::Icp, Eigen::Isometry3d::Identity()); }

TEST(Odometry, RecoversOneCentimetreTranslation) {
  expect_recovers(OdometryMethod::Icp, Eigen::Isometry3d(Eigen::Translation3d(0.01, 0.0, 0.0)));
  expect_recovers(OdometryMethod::Icp, Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.006, 0.008)));
}

TEST(Odometry, RecoversOneDegreeRotation) {
  expect_recovers(OdometryMethod::Icp, Eigen::Isometry3d(Eigen::AngleAxisd(kDegree, Eigen::Vector3d::UnitY())));
  expect_recovers(OdometryMethod::Icp, Eigen::Isometry3d(Eigen::AngleAxisd(kDegree, Eigen::Vector3d::UnitZ())));
}

TEST(Odometry, OtherIcpMethodsRecoverTranslation) {
  for (const auto method : {OdometryMethod::RgbdIcp, OdometryMethod::FastIcp}) {
    expect_recovers(method, Eigen::Isometry3d(Eigen::Translation3d(0.01, 0.0, 0.0)), kOtherMethodsRotationTolerance);
  }
}

TEST(Odometry, WideFramesAreMatchedAtAWholeFractionOfTheirSize) {
  // 640x480 frames: matched at 320x240 by default (every 2nd pixel of every
  // 2nd row), at their own size with max_width 0. Both recover a 1 cm step
  // and use the same share of the pixels.
  Scene scene("dvd-static");
  const CameraIntrinsics wide;  // 640x480, f 615 px
  const auto frame = [&](const Eigen::Isometry3d& cMc2, long index) {
    return scene.renderer.render(scene.scenario.wMc_start * cMc2, index, wide, true).frame;
  };
  const RgbdFrame first = frame(Eigen::Isometry3d::Identity(), 0);
  const RgbdFrame second = frame(Eigen::Isometry3d(Eigen::Translation3d(0.01, 0.0, 0.0)), 1);
  std::vector<double> valid;
  for (const int max_width : {320, 0}) {
    OdometrySettings s;
    s.max_width = max_width;
    s.iterations = 15;  // as expect_recovers(): 1 cm in one frame
    Odometry odometry(s);
    const OdometryResult r0 = odometry.step(first);
    ASSERT_EQ(r0.status, OdometryStatus::FirstFrame);
    valid.push_back(r0.diagnostics.valid_fraction);
    const OdometryResult r1 = odometry.step(second);
    ASSERT_EQ(r1.status, OdometryStatus::Ok) << "max_width " << max_width;
    EXPECT_LT(error(r1.wMc, second.wMc).first, kTranslationTolerance) << "max_width " << max_width;
    EXPECT_LT(error(r1.wMc, second.wMc).second, kRotationTolerance) << "max_width " << max_width;
  }
  EXPECT_NEAR(valid[0], valid[1], 0.01);
  // A frame of another size is refused, whatever size they are matched at.
  Odometry odometry;
  (void)odometry.step(first);
  EXPECT_THROW((void)odometry.step(scene.frame(Eigen::Isometry3d::Identity(), 1)), std::invalid_argument);
}

TEST(Odometry, StartsAtTheFirstFramesPoseAndComposes) {
  // Three steps of 1 cm along the camera's x: the pose composes them, and a
  // keyframe is taken once the camera is more than 3 cm from the first.
  Scene scene("dvd-static");
  Odometry odometry;
  ASSERT_EQ(odometry.step(scene.frame(Eigen::Isometry3d::Identity(), 0)).status, OdometryStatus::FirstFrame);
  RgbdFrame frame;
  OdometryResult r;
  int keyframes = 0;
  for (int k = 1; k <= 4; ++k) {
    frame = scene.frame(Eigen::Isometry3d(Eigen::Translation3d(0.01 * k, 0.0, 0.0)), k);
    r = odometry.step(frame);
    ASSERT_EQ(r.status, OdometryStatus::Ok) << "step " << k;
    keyframes += r.diagnostics.keyframe ? 1 : 0;
  }
  EXPECT_EQ(keyframes, 1);  // at 4 cm
  EXPECT_LT(error(r.wMc, frame.wMc).first, 4 * kTranslationTolerance);
}

TEST(Odometry, WhatTheReferenceMaskedTellsNothingOfTheMotion) {
  // A keyframe masked down to the far part of the scene (the object deep
  // behind what is left out), then the same view unmasked (the object lost:
  // no depth for the mask). The pixels the keyframe left out are no
  // mismatches: the step is Ok, its inliers counted on the overlap.
  Scene scene("dvd-static");
  const RgbdFrame first = scene.frame(Eigen::Isometry3d::Identity(), 0);
  Odometry probe;
  const double all = probe.step(first).diagnostics.valid_fraction;
  double depth = 0.0;  // masking at least half of the usable pixels, leaving more than 10 % of the image
  for (double d = 0.55; d < 1.2 && depth == 0.0; d += 0.01) {
    Odometry o;
    const OdometryDiagnostics m = o.step(first, at_depth(d)).diagnostics;
    if (m.masked_fraction >= 0.5 * all && m.valid_fraction > 0.1) depth = d;
  }
  ASSERT_GT(depth, 0.0);
  Odometry odometry;
  ASSERT_EQ(odometry.step(first, at_depth(depth)).status, OdometryStatus::FirstFrame);
  const RgbdFrame second = scene.frame(Eigen::Isometry3d(Eigen::Translation3d(0.005, 0.0, 0.0)), 1);
  const OdometryResult r = odometry.step(second);
  ASSERT_EQ(r.status, OdometryStatus::Ok) << to_string(r.status) << " inliers " << r.diagnostics.inlier_fraction
                                          << " overlap " << r.diagnostics.overlap_fraction;
  EXPECT_GT(r.diagnostics.inlier_fraction, 0.9);
  EXPECT_LT(r.diagnostics.overlap_fraction, 0.5 * r.diagnostics.valid_fraction + 0.05);
  EXPECT_LT(error(r.wMc, second.wMc).first, kTranslationTolerance);
}

TEST(Odometry, BlankDepthFails) {
  Scene scene("dvd-static");
  Odometry odometry;
  const OdometryResult first = odometry.step(scene.frame(Eigen::Isometry3d::Identity(), 0));
  RgbdFrame blank = scene.frame(Eigen::Isometry3d(Eigen::Translation3d(0.01, 0.0, 0.0)), 1);
  std::fill(blank.depth.begin(), blank.depth.end(), 0.0f);
  const OdometryResult r = odometry.step(blank);
  EXPECT_EQ(r.status, OdometryStatus::Failed);
  EXPECT_EQ(r.diagnostics.valid_fraction, 0.0);
  EXPECT_TRUE(r.wMc.isApprox(first.wMc));  // the last good pose, not a jump
}

TEST(Odometry, JumpIsImplausibleAndKeepsThePose) {
  Scene scene("dvd-static");
  Odometry odometry;
  const OdometryResult first = odometry.step(scene.frame(Eigen::Isometry3d::Identity(), 0));
  // 30 cm back: the depths differ by more than max_depth_diff. (30 cm along
  // the table is not seen: the plane fits itself, the case's pixels are few.)
  const OdometryResult r = odometry.step(scene.frame(Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, -0.3)), 1));
  EXPECT_EQ(r.status, OdometryStatus::Implausible) << to_string(r.status);
  EXPECT_TRUE(r.wMc.isApprox(first.wMc));
  // The odometry goes on from the last good pose: a frame near it is Ok again.
  const OdometryResult back = odometry.step(scene.frame(Eigen::Isometry3d(Eigen::Translation3d(0.005, 0.0, 0.0)), 2));
  EXPECT_EQ(back.status, OdometryStatus::Ok);
}

// Beside the case on a bare table (moving-object's; its hand stands nearer
// than the case, masked) only the table's plane is still: it fixes the
// camera's depth, not its motion along the table, which the case alone holds
// and would carry along if it moved. dvd-static's holding hand, a still
// curved body, fixes the rest. Without the object's hint, or with the check
// off, the same step is Ok and the constraint not measured (on the bare
// table ICP then misses most of the 5 mm: the case's edges alone hold it).
TEST(Odometry, ABareTableBesideTheObjectIsDegenerate) {
  for (const std::string name : {"dvd-static", "moving-object"}) {
    SCOPED_TRACE(name);
    const bool bare = name == "moving-object";
    Scene scene(name);
    const RgbdFrame first = scene.frame(Eigen::Isometry3d::Identity(), 0);
    const RgbdFrame second = scene.frame(Eigen::Isometry3d(Eigen::Translation3d(0.005, 0.0, 0.0)), 1);
    const ObjectHint object = object_of(scene, first.wMc);
    Odometry odometry;
    ASSERT_EQ(odometry.step(first, object).status, OdometryStatus::FirstFrame);
    const OdometryResult r = odometry.step(second, object);
    EXPECT_EQ(r.status, bare ? OdometryStatus::Degenerate : OdometryStatus::Ok) << to_string(r.status);
    if (bare) {
      EXPECT_LT(r.diagnostics.still_constraint, 1e-4);
      EXPECT_TRUE(r.wMc.isApprox(first.wMc));  // the last good pose
    } else {
      EXPECT_GT(r.diagnostics.still_constraint, 1e-3);
      EXPECT_LT(error(r.wMc, second.wMc).first, kTranslationTolerance);
    }
    OdometrySettings off;
    off.min_still_constraint = 0.0;
    Odometry unchecked(off);
    Odometry blind;
    for (Odometry* o : {&unchecked, &blind}) {
      const ObjectHint hint = o == &blind ? ObjectHint{} : object;
      (void)o->step(first, hint);
      const OdometryResult u = o->step(second, hint);
      EXPECT_EQ(u.status, OdometryStatus::Ok) << to_string(u.status);
      EXPECT_TRUE(std::isnan(u.diagnostics.still_constraint));
      if (!bare) {
        EXPECT_LT(error(u.wMc, second.wMc).first, kTranslationTolerance);
      }
    }
  }
}

// A camera orbiting the case at 3.5 degrees (3 cm) a frame, twice the loop's
// speed limit: followed within the tolerances whether each match starts
// from the last step's motion repeated (the default) or from the last pose.
// (Where the guess matters, frames with most pixels masked, is measured on
// the closed-loop recordings of docs/perception.md; a guess composed the
// wrong way round drifts 6 mm here.)
TEST(Odometry, ASteadyOrbitIsFollowedFromEitherGuess) {
  Scene scene("dvd-static");
  const Eigen::Vector3d centre(0.0, 0.0, 0.5);  // the case, in the start camera's frame
  constexpr double kTurn = 3.5 * kDegree;
  for (const bool constant : {true, false}) {
    SCOPED_TRACE(constant ? "constant velocity" : "from the last pose");
    OdometrySettings s;
    s.constant_velocity = constant;
    Odometry odometry(s);
    for (int k = 0; k < 8; ++k) {
      const Eigen::Isometry3d orbit = Eigen::Translation3d(centre) *
                                      Eigen::AngleAxisd(kTurn * k, Eigen::Vector3d::UnitY()) *
                                      Eigen::Translation3d(-centre);
      const RgbdFrame frame = scene.frame(orbit, k);
      const OdometryResult r = odometry.step(frame);
      ASSERT_EQ(r.status, k == 0 ? OdometryStatus::FirstFrame : OdometryStatus::Ok) << k << ' ' << to_string(r.status);
      const auto [metres, degrees] = error(r.wMc, frame.wMc);
      EXPECT_LT(metres, kTranslationTolerance) << k;
      EXPECT_LT(degrees, kRotationTolerance) << k;
    }
  }
}

/// A wall at 0.6 m, tilted 30 degrees about the vertical, seen from wMc at
/// 320x240 (exact depths: the check is about geometry, not noise).
RgbdFrame wall(const Eigen::Isometry3d& wMc) {
  RgbdFrame f;
  f.intrinsics = CameraIntrinsics{320, 240, 307.5, 307.5, 160.0, 120.0};
  f.wMc = wMc;
  f.depth.resize(320 * 240);
  const Eigen::Vector3d n = Eigen::AngleAxisd(30.0 * kDegree, Eigen::Vector3d::UnitY()) * Eigen::Vector3d::UnitZ();
  const double d = n.dot(Eigen::Vector3d(0.0, 0.0, 0.6));  // the wall: n . p = d (world)
  const Eigen::Vector3d nc = wMc.linear().transpose() * n;
  const double dc = d - n.dot(wMc.translation());
  for (int v = 0; v < 240; ++v) {
    for (int u = 0; u < 320; ++u) {
      const Eigen::Vector3d ray((u - 160.0) / 307.5, (v - 120.0) / 307.5, 1.0);
      f.depth[static_cast<std::size_t>(v * 320 + u)] = static_cast<float>(dc / nc.dot(ray));
    }
  }
  return f;
}

// A wall alone: the match stands on a plane, which fixes the motion along
// its normal only, whatever the object (none given here): degenerate by the
// matching pixels' own patches. The pose stays.
TEST(Odometry, AMatchOnAPlaneAloneIsDegenerate) {
  Odometry odometry;
  const RgbdFrame first = wall(Eigen::Isometry3d::Identity());
  ASSERT_EQ(odometry.step(first).status, OdometryStatus::FirstFrame);
  const OdometryResult r = odometry.step(wall(Eigen::Isometry3d(Eigen::Translation3d(0.005, 0.0, 0.0))));
  EXPECT_EQ(r.status, OdometryStatus::Degenerate) << to_string(r.status);
  EXPECT_TRUE(std::isnan(r.diagnostics.still_constraint));  // no object given
  EXPECT_LT(r.diagnostics.match_constraint, 1e-6);
  EXPECT_TRUE(r.wMc.isApprox(first.wMc));
  // With the check off the same step is Ok: a motion along the wall it cannot see.
  OdometrySettings off;
  off.min_still_constraint = 0.0;
  Odometry unchecked(off);
  (void)unchecked.step(first);
  EXPECT_EQ(unchecked.step(wall(Eigen::Isometry3d(Eigen::Translation3d(0.005, 0.0, 0.0)))).status, OdometryStatus::Ok);
}

// Four frames of a still camera, then one whose right half lies 1 cm
// deeper: every pixel is within max_depth_diff (7 cm) of the reference, but
// no motion fits both halves, and the matching pixels differ by about 3 mm
// RMS against the sensor's noise before (0.3 mm): implausible
// (max_residual_ratio); with the ratio off, Ok.
TEST(Odometry, AMatchFarWorseThanTheLastOnesIsImplausible) {
  Scene scene("dvd-static");
  for (const double ratio : {5.0, 0.0}) {
    SCOPED_TRACE(ratio);
    OdometrySettings s;
    s.max_residual_ratio = ratio;
    Odometry odometry(s);
    for (int k = 0; k < 4; ++k) {
      ASSERT_NE(odometry.step(scene.frame(Eigen::Isometry3d::Identity(), k)).status, OdometryStatus::Implausible);
    }
    RgbdFrame torn = scene.frame(Eigen::Isometry3d::Identity(), 4);
    const int w = torn.intrinsics.width;
    for (std::size_t i = 0; i < torn.depth.size(); ++i) {
      if (static_cast<int>(i % static_cast<std::size_t>(w)) >= w / 2 && torn.depth[i] > 0.0f) torn.depth[i] += 0.01f;
    }
    const OdometryResult r = odometry.step(torn);
    EXPECT_EQ(r.status, ratio > 0.0 ? OdometryStatus::Implausible : OdometryStatus::Ok) << to_string(r.status);
    EXPECT_GT(r.diagnostics.residual, 0.002);
  }
}

TEST(Odometry, OtherSceneIsImplausible) {
  Scene scene("dvd-static");
  Scene other("cloth-occluder");
  Odometry odometry;
  const OdometryResult first = odometry.step(scene.frame(Eigen::Isometry3d::Identity(), 0));
  // The other scene from a viewpoint 20 cm back and turned: nothing of the first frame's geometry.
  const OdometryResult r = odometry.step(
      other.frame(Eigen::Isometry3d(Eigen::AngleAxisd(20 * kDegree, Eigen::Vector3d::UnitX())), 1));
  EXPECT_NE(r.status, OdometryStatus::Ok) << to_string(r.status);
  EXPECT_EQ(r.status, OdometryStatus::Implausible) << to_string(r.status);
  EXPECT_TRUE(r.wMc.isApprox(first.wMc));
}

TEST(Odometry, FirstFrameWithoutDepthKeepsTrying) {
  Scene scene("dvd-static");
  Odometry odometry;
  RgbdFrame blank = scene.frame(Eigen::Isometry3d::Identity(), 0);
  std::fill(blank.depth.begin(), blank.depth.end(), 0.0f);
  EXPECT_EQ(odometry.step(blank).status, OdometryStatus::Failed);
  EXPECT_EQ(odometry.step(scene.frame(Eigen::Isometry3d::Identity(), 1)).status, OdometryStatus::FirstFrame);
}

TEST(Odometry, MaskLeavesOutWhatIsNearerThanTheObject) {
  Scene scene("dvd-static");
  Odometry odometry;
  const RgbdFrame frame = scene.frame(Eigen::Isometry3d::Identity(), 0);
  // Everything nearer than 0.4 m + the margin would be left out.
  Odometry unmasked;
  const OdometryResult all = unmasked.step(frame, at_depth(0.0));
  EXPECT_EQ(all.status, OdometryStatus::FirstFrame);
  EXPECT_EQ(all.diagnostics.masked_fraction, 0.0);
  // An object 10 m away: every pixel is nearer than it minus the margin.
  const OdometryResult r = odometry.step(frame, at_depth(10.0));
  EXPECT_EQ(r.status, OdometryStatus::Failed);
  EXPECT_EQ(r.diagnostics.valid_fraction, 0.0);
  EXPECT_DOUBLE_EQ(r.diagnostics.masked_fraction, all.diagnostics.valid_fraction);
  // With the mask off, the same object depth leaves every pixel in.
  OdometrySettings s;
  s.mask = false;
  Odometry off(s);
  EXPECT_DOUBLE_EQ(off.step(frame, at_depth(10.0)).diagnostics.valid_fraction, all.diagnostics.valid_fraction);
}

/// The table of a frame (its kPixelSupport pixels) as the front end gives
/// it: the least-squares plane of their points and their mean chromaticity,
/// in the world frame.
SupportPlane table_of(const RgbdFrame& f) {
  const CameraIntrinsics& k = f.intrinsics;
  std::vector<Eigen::Vector3d> points;
  Eigen::Vector3f chroma = Eigen::Vector3f::Zero();
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = f.index(u, v);
      if (f.labels[i] != kPixelSupport || !(f.depth[i] > 0.0f)) continue;
      const double z = f.depth[i];
      points.push_back(f.wMc * Eigen::Vector3d((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z));
      const Eigen::Vector3f rgb(f.rgb[3 * i], f.rgb[3 * i + 1], f.rgb[3 * i + 2]);
      chroma += chromaticity(rgb);
    }
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3d& p : points) mean += p;
  mean /= static_cast<double>(points.size());
  Eigen::Matrix3d spread = Eigen::Matrix3d::Zero();
  for (const Eigen::Vector3d& p : points) spread += (p - mean) * (p - mean).transpose();
  const Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(spread).eigenvectors().col(0);
  SupportPlane plane;
  plane.plane << n, -n.dot(mean);
  plane.chroma = chroma / static_cast<float>(points.size());
  return plane;
}

TEST(Odometry, TheSupportPlaneStaysInAndHoldsTheTurnAboutTheOpticalAxis) {
  // dvd-static: a camera facing the case, the table running towards it
  // below. The mask leaves out what is 10 cm nearer than the case: the near
  // table too, and then only the case's sides and the holder fix a turn
  // about the optical axis, which the sensor's noise moves from frame to
  // frame. Given the plane the case stands on, its pixels stay in.
  Scene scene("dvd-static");
  const RgbdFrame first = scene.frame(Eigen::Isometry3d::Identity(), 0);
  const SupportPlane table = table_of(first);
  SupportPlane another_colour = table;  // an arm lying on the table is on its plane, not of its colour
  another_colour.chroma = Eigen::Vector3f(0.1f, 0.1f, 0.8f);
  const auto hint = [&](const Eigen::Isometry3d& wMc, const std::optional<SupportPlane>& plane) {
    ObjectHint h = object_of(scene, wMc);
    h.plane_c = object_hint(Eigen::Matrix3Xd(3, 0), wMc, plane).plane_c;
    return h;
  };

  std::vector<double> masked, worst;
  for (const std::optional<SupportPlane>& plane : {std::optional<SupportPlane>(), std::optional(table),
                                                    std::optional(another_colour)}) {
    Odometry odometry;
    const OdometryResult r0 = odometry.step(first, hint(first.wMc, plane));
    masked.push_back(r0.diagnostics.masked_fraction);
    worst.push_back(0.0);
    Eigen::Isometry3d previous = first.wMc;
    for (long i = 1; i <= 20; ++i) {  // the camera moves 3 mm a frame along the case
      const RgbdFrame f =
          scene.frame(Eigen::Isometry3d(Eigen::Translation3d(0.003 * static_cast<double>(i), 0.0, 0.0)), i);
      const OdometryResult r = odometry.step(f, hint(previous, plane));
      ASSERT_EQ(r.status, OdometryStatus::Ok) << to_string(r.status);
      worst.back() = std::max(worst.back(), error(r.wMc, f.wMc).second);
      previous = f.wMc;
    }
  }
  std::cout << "masked " << masked[0] << " / " << masked[1] << " / " << masked[2] << "; worst turn " << worst[0]
            << " / " << worst[1] << " / " << worst[2] << " deg (without the plane / with it / another colour)\n";
  EXPECT_GT(masked[0], 0.05);              // the near table, without the plane
  EXPECT_LT(masked[1], 0.1 * masked[0]);   // with it: the table stays in
  EXPECT_DOUBLE_EQ(masked[2], masked[0]);  // what is not of its colour is left out as before
  EXPECT_LT(worst[1], 0.03);
  EXPECT_GT(worst[0], 2.0 * worst[1]);
}

TEST(OdometrySettings, TableParsesAndValidates) {
  OdometrySettings s;
  odometry_settings_table().set(s, "odometry", "fast_icp");
  EXPECT_EQ(s.method, OdometryMethod::FastIcp);
  odometry_settings_table().set(s, "keyframe", "false");
  EXPECT_FALSE(s.keyframe);
  EXPECT_THROW(odometry_settings_table().set(s, "odometry", "nope"), std::invalid_argument);
  EXPECT_THROW(odometry_settings_table().set(s, "max_translation", "-1"), std::invalid_argument);
  s = {};
  s.min_depth = 5.0;
  EXPECT_THROW(Odometry{s}, std::invalid_argument);
  // Every default reads back as itself.
  const OdometrySettings d;
  OdometrySettings back;
  odometry_settings_table().apply(back, odometry_settings_table().values(d));
  EXPECT_EQ(odometry_settings_table().values(back), odometry_settings_table().values(d));
}

// A camera moving along the table at 1.5 or 2.25 cm a frame with a blank
// frame between (no pose known): matched from the last pose, 3 or 4.5 cm
// behind, ICP stops in a wrong minimum that passes every check (along the
// table only the case's edges hold it; without restarts 17.6 and 40.7 mm
// off). Made again from around it, 1 cm each way along the camera's axes
// and again around the best while one fits better, it finds the motion; the
// next frame starts from a frame's share of it (not all of it again) and is
// Ok without restarts (they are made only after a step without a pose).
TEST(Odometry, AfterAGapTheMatchIsMadeAgainAroundItself) {
  Scene scene("dvd-static");
  for (const double speed : {0.015, 0.0225}) {
    for (const double restart : {0.0, OdometrySettings{}.restart_distance}) {
      SCOPED_TRACE(std::to_string(speed) + " m a frame, restart_distance " + std::to_string(restart));
      const auto at = [&](int k) { return scene.frame(Eigen::Isometry3d(Eigen::Translation3d(speed * k, 0, 0)), k); };
      OdometrySettings s;
      s.restart_distance = restart;
      Odometry odometry(s);
      ASSERT_EQ(odometry.step(at(0)).status, OdometryStatus::FirstFrame);
      RgbdFrame blank = at(1);
      std::fill(blank.depth.begin(), blank.depth.end(), 0.0f);
      ASSERT_EQ(odometry.step(blank).status, OdometryStatus::Failed);
      const RgbdFrame on = at(2);
      const OdometryResult r = odometry.step(on);
      ASSERT_EQ(r.status, OdometryStatus::Ok) << to_string(r.status);
      const double off = error(r.wMc, on.wMc).first;
      if (restart > 0.0) {
        EXPECT_LT(off, kTranslationTolerance);
        EXPECT_GT(r.diagnostics.restart_shift, 0.01);
        const RgbdFrame next = at(3);
        const OdometryResult after = odometry.step(next);
        ASSERT_EQ(after.status, OdometryStatus::Ok) << to_string(after.status);
        EXPECT_TRUE(std::isnan(after.diagnostics.restart_shift));
        EXPECT_LT(error(after.wMc, next.wMc).first, kTranslationTolerance);
      } else {
        EXPECT_GT(off, 0.01);  // the wrong minimum the restarts are for
        EXPECT_TRUE(std::isnan(r.diagnostics.restart_shift));
      }
    }
  }
}

}  // namespace
}  // namespace ofv::odometry
