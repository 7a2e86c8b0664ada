// View methods: Fibonacci candidates, view scoring, the angular error and the sampling planner.
#include "ofv/view_methods.h"
#include "ofv/constants.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

namespace ofv {
namespace {

// A 5 x 4 patch at z = 0.5 facing a camera at the origin, one hand-sized
// occluder cluster right on the initial ray.
ViewProblem occluded_patch() {
  ViewProblem p;
  p.positions.resize(3, 20);
  p.normals.resize(3, 20);
  for (int k = 0; k < 20; ++k) {
    p.positions.col(k) << (k % 5 - 2) * 0.03, (k / 5 - 1.5) * 0.03, 0.5;
    p.normals.col(k) << 0, 0, -1;
  }
  p.occluders.resize(3, 9);
  for (int k = 0; k < 9; ++k) p.occluders.col(k) << (k % 3 - 1) * 0.01, (k / 3 - 1) * 0.01, 0.25;
  return p;
}

TEST(ViewMethods, FibonacciDirectionsCoverTheSphereEvenly) {
  const Eigen::Matrix3Xd d = fibonacci_directions(500);
  ASSERT_EQ(d.cols(), 500);
  EXPECT_LT((d.colwise().norm().array() - 1.0).abs().maxCoeff(), 1e-12);
  EXPECT_LT(d.rowwise().mean().norm(), 0.01);
  double nearest_max = 0.0;
  for (Eigen::Index i = 0; i < d.cols(); ++i) {
    double nearest = 10.0;
    for (Eigen::Index j = 0; j < d.cols(); ++j) {
      if (i != j) nearest = std::min(nearest, (d.col(i) - d.col(j)).norm());
    }
    nearest_max = std::max(nearest_max, nearest);
  }
  EXPECT_LT(nearest_max, 2.5 * std::sqrt(4.0 * kPi / 500));  // no hole
  EXPECT_THROW((void)fibonacci_directions(0), std::invalid_argument);
}

TEST(ViewMethods, OccluderOnTheInitialRay) {
  const ViewProblem p = occluded_patch();
  const EstimatorSettings s;
  const ViewEstimate e = estimate_view(p, s);
  const double rho = 0.015;
  const ScoredView at_t0 = score_view(p, e.centroid, s.r_sphere, e.t0, rho);
  const ScoredView at_tf = score_view(p, e.centroid, s.r_sphere, e.tf, rho);
  SamplingSettings sampling;
  sampling.candidates = 1500;
  sampling.occluder_radius = rho;
  const ScoredView sampled = sample_best_view(p, e.centroid, s.r_sphere, sampling);
  EXPECT_LT(at_t0.visible_fraction, 0.5);  // the blind view loses the object
  EXPECT_EQ(at_tf.visible_fraction, 1.0);  // ours keeps it
  EXPECT_EQ(sampled.visible_fraction, 1.0);
  EXPECT_NEAR((sampled.view - e.centroid).norm(), s.r_sphere, 1e-12);
  // Both moved off the ray, by a similar, small angle.
  EXPECT_GT(at_tf.mean_error_deg, at_t0.mean_error_deg);
  EXPECT_LT(sampled.mean_error_deg, 45.0);
}

TEST(ViewMethods, FacingAwaySupervoxelsAreUnseen) {
  ViewProblem p = occluded_patch();
  p.occluders.resize(3, 0);
  const Eigen::Vector3d c(0, 0, 0.5);
  EXPECT_EQ(score_view(p, c, 0.5, Eigen::Vector3d(0, 0, 0), 0.015).visible_fraction, 1.0);
  EXPECT_EQ(score_view(p, c, 0.5, Eigen::Vector3d(0, 0, 1), 0.015).visible_fraction, 0.0);
}

TEST(ViewMethods, AnOccluderBlocksALineOfSightWithinItsRadiusWhereverItIsInTheList) {
  // One supervoxel at the origin facing the camera at (0, 0, 1). 150
  // occluders far off the line of sight, and one at (d, 0, 0.5): it blocks
  // when d < rho, at every place in the list (the test runs in blocks).
  ViewProblem p;
  p.positions = Eigen::Matrix3Xd::Zero(3, 1);
  p.normals = Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d c = Eigen::Vector3d::Zero();
  const Eigen::Vector3d camera(0, 0, 1);
  const double rho = 0.02;
  for (const int where : {0, 63, 64, 65, 127, 150}) {
    for (const double d : {0.019, 0.021}) {
      p.occluders.resize(3, 151);
      for (int k = 0; k < 151; ++k) p.occluders.col(k) << 0.3, 0.01 * k - 0.75, 0.5;
      p.occluders.col(where) << d, 0.0, 0.5;
      EXPECT_EQ(score_view(p, c, 1.0, camera, rho).visible_fraction, d < rho ? 0.0 : 1.0)
          << "occluder " << where << " at " << d;
    }
  }
  // Past either end of the segment the distance is to the end point.
  p.occluders.resize(3, 1);
  p.occluders.col(0) << 0.015, 0.0, 1.01;  // 0.018 from the camera
  EXPECT_EQ(score_view(p, c, 1.0, camera, rho).visible_fraction, 0.0);
  p.occluders.col(0) << 0.015, 0.0, 1.015;  // 0.021 from the camera
  EXPECT_EQ(score_view(p, c, 1.0, camera, rho).visible_fraction, 1.0);
}

// At exactly rho the line of sight is clear: the distance is computed to the
// last bit as the plain Eigen expression computes it.
TEST(ViewMethods, AnOccluderExactlyAtTheRadiusDoesNotBlock) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int cases = 0;
  for (int k = 0; k < 4000; ++k) {
    const Eigen::Vector3d p(0.1 * u(rng), 0.1 * u(rng), 0.5 + 0.1 * u(rng));
    const Eigen::Vector3d view(0.3 * u(rng), 0.3 * u(rng), 0.05 * u(rng));
    const Eigen::Vector3d seg = view - p;
    const Eigen::Vector3d o = p + (0.5 + 0.6 * u(rng)) * seg + Eigen::Vector3d(0.03 * u(rng), 0.03 * u(rng), 0.0);
    const Eigen::Vector3d rel = o - p;
    const double t = std::clamp(rel.dot(seg) / seg.squaredNorm(), 0.0, 1.0);
    const double d2 = (rel - t * seg).squaredNorm();
    const double rho = std::sqrt(d2);
    if (rho * rho != d2) continue;
    ViewProblem prob;
    prob.positions = p;
    prob.normals = seg;
    prob.occluders = o;
    ASSERT_EQ(score_view(prob, p, 10.0, view, rho).visible_fraction, 1.0) << "case " << k;
    ++cases;
  }
  EXPECT_GT(cases, 500);
}

TEST(ViewMethods, AngularErrorIsTheAngleToEachRayFromTheCentroid) {
  // Two supervoxels at C facing +z and +x: rays along +z and +x. A camera
  // 30 degrees from +z towards +x is 30 and 60 degrees off them (eq. 9).
  ViewProblem p;
  p.positions = Eigen::Matrix3Xd::Zero(3, 2);
  p.normals.resize(3, 2);
  p.normals << 0, 1, 0, 0, 1, 0;
  const double a = 30.0 * kPi / 180.0;
  const Eigen::Vector3d view(0.5 * std::sin(a), 0.0, 0.5 * std::cos(a));
  EXPECT_NEAR(mean_angular_error_deg(p, Eigen::Vector3d::Zero(), 0.5, view), 45.0, 1e-9);
  // Supervoxels at or outside the sphere are skipped (spec §1).
  EXPECT_EQ(mean_angular_error_deg(p, Eigen::Vector3d(1, 0, 0), 0.5, view), 0.0);
}

}  // namespace
}  // namespace ofv
