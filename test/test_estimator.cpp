// The estimator against hand-computed geometry and invariants (ESTIMATOR-SPEC.md).
#include "ofv/constants.h"
#include "ofv/estimator.h"

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>
#include <stdexcept>

namespace ofv {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kDeg = kPi / 180.0;

Eigen::Matrix3Xd cols(std::initializer_list<Eigen::Vector3d> points) {
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(points.size()));
  Eigen::Index k = 0;
  for (const auto& p : points) m.col(k++) = p;
  return m;
}

// One supervoxel at the origin facing +z, as seen by a camera on +z.
ViewProblem single_supervoxel() {
  ViewProblem p;
  p.positions = cols({{0, 0, 0}});
  p.normals = cols({{0, 0, 1}});
  p.occluders.resize(3, 0);
  return p;
}

// A flat nx x ny patch with spacing h in the plane z = z0, normals towards -z.
ViewProblem patch(int nx, int ny, double h, double z0 = 1.0) {
  ViewProblem p;
  p.positions.resize(3, nx * ny);
  p.normals.resize(3, nx * ny);
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < ny; ++j) {
      p.positions.col(i * ny + j) << (i - 0.5 * (nx - 1)) * h, (j - 0.5 * (ny - 1)) * h, z0;
      p.normals.col(i * ny + j) << 0, 0, -1;
    }
  }
  p.occluders.resize(3, 0);
  return p;
}

// Independent, literal reading of spec §4: projected points within `radius` of t.
int points_within(const ViewProblem& p, const ViewEstimate& e, const Eigen::Vector3d& t,
                  double r, double radius) {
  const Eigen::Vector3d c = e.centroid;
  const Eigen::Vector3d zi = -(t - c).normalized();  // camera axis, eq. 6
  int count = 0;
  for (Eigen::Index n = 0; n < p.positions.cols(); ++n) {
    const Eigen::Vector3d v = p.positions.col(n);
    if ((v - c).norm() >= r) continue;
    for (Eigen::Index b = 0; b < p.occluders.cols(); ++b) {
      const Eigen::Vector3d u = (p.occluders.col(b) - v).normalized();
      // |v + s u - C| = R, s > 0
      const double bb = (v - c).dot(u);
      const double s = -bb + std::sqrt(bb * bb - (v - c).squaredNorm() + r * r);
      const Eigen::Vector3d d = v + s * u - c;
      if (d.dot(-zi) <= 1e-9) continue;
      const Eigen::Vector3d dpi = c + d * ((t - c).dot(-zi) / d.dot(-zi));
      if ((dpi - t).norm() < radius) ++count;
    }
  }
  return count;
}

TEST(Estimator, SingleSupervoxelFacingCameraGivesItsNormalRay) {
  const ViewEstimate e = estimate_view(single_supervoxel(), EstimatorSettings{});
  EXPECT_TRUE(e.t0.isApprox(Eigen::Vector3d(0, 0, 0.5), 1e-12));
  EXPECT_EQ(e.status, ViewStatus::NoOccluders);
  EXPECT_EQ(e.tf, e.t0);
  EXPECT_EQ(e.iterations, 0);
  // N = 1: PCA cannot determine e1, so the spherical mean falls back (spec §2).
  EXPECT_EQ(e.initial_view_used, InitialViewUsed::VectorMean);
  EXPECT_TRUE(e.axes_from_world);
  ASSERT_TRUE(e.error_t0);
  EXPECT_NEAR(e.error_t0->mean, 0.0, 1e-9);
  EXPECT_NEAR(e.error_t0->std, 0.0, 1e-9);
}

TEST(Estimator, NormalsToSphereRayLeavesTheSphereAlongTheNormal) {
  // A supervoxel off-centre: its ray starts at v, not at C (eq. 3).
  ViewProblem p;
  p.positions = cols({{0.1, 0, 0}, {-0.1, 0, 0}});
  p.normals = cols({{0, 0, 1}, {0, 0, 1}});
  p.centroid = Eigen::Vector3d::Zero();
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  // s_n = (+-0.1, 0, sqrt(0.25 - 0.01)); both rays make the same angle with z.
  const double expected = std::atan2(0.1, std::sqrt(0.24)) / kDeg;
  ASSERT_TRUE(e.error_t0);
  EXPECT_NEAR(e.error_t0->mean, expected, 1e-9);
  EXPECT_NEAR(e.error_t0->std, 0.0, 1e-9);
  EXPECT_TRUE(e.t0.isApprox(Eigen::Vector3d(0, 0, 0.5), 1e-12));
}

TEST(Estimator, OccluderOnTheInitialRayIsAvoided) {
  ViewProblem p = single_supervoxel();
  p.occluders = cols({{0, 0, 0.3}});  // exactly between the object and t0
  EstimatorSettings s;
  s.clearance = 0.015;
  const ViewEstimate e = estimate_view(p, s, {true});
  // The only projected point is t0 itself: v = 0, the nearest point coincides
  // with t0, so the push is along e1 = world x (PCA undetermined).
  EXPECT_EQ(e.status, ViewStatus::Converged);
  EXPECT_EQ(e.iterations, 1);
  const Eigen::Vector3d expected = 0.5 * Eigen::Vector3d(0.02, 0, 0.5).normalized();
  EXPECT_TRUE(e.tf.isApprox(expected, 1e-12)) << e.tf.transpose();
  ASSERT_EQ(e.path.size(), 2U);
  EXPECT_EQ(e.path.front(), e.t0);
}

TEST(Estimator, TwoSymmetricOccludersPushWithinTheSymmetryPlane) {
  ViewProblem p = single_supervoxel();
  p.occluders = cols({{0.005, 0, 0.3}, {-0.005, 0, 0.3}});
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(e.status, ViewStatus::Converged);
  EXPECT_GT(e.iterations, 0);
  EXPECT_NEAR(e.tf.y(), 0.0, 1e-12);
  EXPECT_GT(std::abs(e.tf.x()), 0.02);
  EXPECT_NEAR(e.tf.norm(), 0.5, 1e-12);
  EXPECT_EQ(points_within(p, e, e.tf, 0.5, 0.02), 0);
}

TEST(Estimator, FarHemispherePointsHaveNoGnomonicImage) {
  ViewProblem p = single_supervoxel();
  p.occluders = cols({{0.01, 0, -0.3}});  // behind the object, seen from t0
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(e.status, ViewStatus::Converged);
  EXPECT_EQ(e.iterations, 0);
  EXPECT_EQ(e.tf, e.t0);
  EXPECT_EQ(e.occlusion_points, 1);
}

TEST(Estimator, CoincidentOccluderAndSupervoxelMakeNoRay) {
  ViewProblem p = single_supervoxel();
  p.occluders = cols({{0, 0, 0}});
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(e.occlusion_points, 0);
  EXPECT_EQ(e.status, ViewStatus::Converged);
  EXPECT_EQ(e.tf, e.t0);
}

TEST(Estimator, SupervoxelAtTheSphereBoundaryIsSkipped) {
  ViewProblem p;
  p.positions = cols({{0, 0, 0}, {0.5, 0, 0}, {0, 0.5 - 1e-9, 0}});
  p.normals = cols({{0, 0, 1}, {0, 0, 1}, {0, 0, 1}});
  p.centroid = Eigen::Vector3d::Zero();
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(e.skipped_supervoxels, 1);
}

// Spec, Inputs: skipping removes a supervoxel's ray, never its part in C or
// in the PCA. A cross longer in x than in y has C = (0, 0, 1) and e1 = x; a
// fifth supervoxel F = (0, 2, 1) far along y moves C to the mean of the five,
// (0, 0.4, 1), which leaves F 1.6 m away (outside R = 0.5: skipped) and the
// other four inside (at most sqrt(0.1^2 + 0.4^2) = 0.41 m and 0.45 m). With F
// the covariance is diag(0.02/5, 3.205/5, 0) (cov_xy = 0.1*0.4 - 0.1*0.4 = 0),
// so e1 = +-y.
TEST(Estimator, SkippedSupervoxelStillMovesTheCentroidAndTheAxes) {
  ViewProblem cross;
  cross.positions = cols({{-0.1, 0, 1}, {0.1, 0, 1}, {0, -0.05, 1}, {0, 0.05, 1}});
  cross.normals = cols({{0, 0, -1}, {0, 0, -1}, {0, 0, -1}, {0, 0, -1}});
  cross.occluders = cols({{0.02, 0.03, 0.6}});
  const ViewEstimate without = estimate_view(cross, EstimatorSettings{});
  EXPECT_EQ(without.skipped_supervoxels, 0);
  EXPECT_TRUE(without.centroid.isApprox(Eigen::Vector3d(0, 0, 1), 1e-15));
  EXPECT_NEAR(std::abs(without.axes.col(0).x()), 1.0, 1e-12);

  ViewProblem with_far = cross;
  with_far.positions = cols({{-0.1, 0, 1}, {0.1, 0, 1}, {0, -0.05, 1}, {0, 0.05, 1}, {0, 2, 1}});
  with_far.normals = cols({{0, 0, -1}, {0, 0, -1}, {0, 0, -1}, {0, 0, -1}, {0, 0, -1}});
  const ViewEstimate e = estimate_view(with_far, EstimatorSettings{});
  EXPECT_EQ(e.skipped_supervoxels, 1);
  EXPECT_EQ(e.occlusion_points, 4);  // F has no ray: 4 supervoxels x 1 occluder
  EXPECT_NEAR((e.centroid - Eigen::Vector3d(0, 0.4, 1)).norm(), 0.0, 1e-15);
  EXPECT_NEAR(std::abs(e.axes.col(0).y()), 1.0, 1e-12);
  EXPECT_FALSE(e.axes_from_world);
  EXPECT_NEAR(e.axes.col(0).cross(e.axes.col(1)).dot(e.axes.col(2)), 1.0, 1e-12);
  // t0 lies on the sphere about the moved C.
  EXPECT_NEAR((e.t0 - e.centroid).norm(), 0.5, 1e-12);
}

TEST(Estimator, AllSupervoxelsOutsideTheSphereFallBackToTheCamera) {
  ViewProblem p;
  p.positions = cols({{1, 0, 0}, {-1, 0, 0}});
  p.normals = cols({{0, 0, 1}, {0, 0, 1}});
  p.centroid = Eigen::Vector3d::Zero();
  p.camera = Eigen::Vector3d(0, 2, 0);
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(e.skipped_supervoxels, 2);
  EXPECT_EQ(e.initial_view_used, InitialViewUsed::Camera);
  EXPECT_TRUE(e.t0.isApprox(Eigen::Vector3d(0, 0.5, 0), 1e-12));
  EXPECT_FALSE(e.error_t0);
  EXPECT_FALSE(e.error_tf);

  p.camera.reset();
  EXPECT_THROW((void)estimate_view(p, EstimatorSettings{}), std::invalid_argument);
  p.camera = Eigen::Vector3d::Zero();  // at C: no direction
  EXPECT_THROW((void)estimate_view(p, EstimatorSettings{}), std::invalid_argument);
}

TEST(Estimator, OppositeNormalsFallBackToTheCamera) {
  ViewProblem p;
  p.positions = cols({{0, 0, 0}, {0, 0, 0.01}});
  p.normals = cols({{0, 0, 1}, {0, 0, -1}});
  p.camera = Eigen::Vector3d(1, 0, 0);
  EstimatorSettings s;
  s.initial_view = InitialView::VectorMean;
  const ViewEstimate e = estimate_view(p, s);
  EXPECT_EQ(e.initial_view_used, InitialViewUsed::Camera);
  const Eigen::Vector3d c(0, 0, 0.005);
  EXPECT_TRUE(e.t0.isApprox(c + 0.5 * (*p.camera - c).normalized(), 1e-12));
}

TEST(Estimator, InvalidSupervoxelsAndOccludersAreSkippedAndCounted) {
  ViewProblem p = patch(3, 2, 0.02);
  p.positions(0, 1) = kNaN;
  p.normals.col(2).setZero();
  p.normals(1, 3) = std::numeric_limits<double>::infinity();
  p.occluders = cols({{0.0, 0, 0.7}, {kNaN, 0, 0.7}});
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(e.skipped_supervoxels, 3);
  EXPECT_EQ(e.skipped_occluders, 1);
  EXPECT_EQ(e.occlusion_points, 3);  // 3 usable supervoxels x 1 occluder
}

TEST(Estimator, NoUsableSupervoxelAndNoCentroidIsTheNoSupervoxelsOutcome) {
  ViewProblem empty;
  const ViewEstimate e = estimate_view(empty, EstimatorSettings{});
  EXPECT_EQ(e.status, ViewStatus::NoSupervoxels);
  EXPECT_STREQ(to_string(e.status), "no_supervoxels");
  EXPECT_EQ(e.t0, Eigen::Vector3d::Zero());
  EXPECT_EQ(e.tf, Eigen::Vector3d::Zero());
  EXPECT_EQ(e.iterations, 0);
  EXPECT_FALSE(e.error_t0);
  EXPECT_FALSE(e.error_tf);

  // Every supervoxel unusable by §7; the camera stays where it is.
  ViewProblem p = patch(2, 2, 0.02);
  p.normals.col(0).setZero();
  p.normals(2, 1) = kNaN;
  p.positions(0, 2) = std::numeric_limits<double>::infinity();
  p.normals.col(3) *= 1e-13;
  p.occluders = cols({{0, 0, 0.7}, {kNaN, 0, 0.7}});
  p.camera = Eigen::Vector3d(0.1, 0.2, 0.3);
  const ViewEstimate f = estimate_view(p, EstimatorSettings{}, {true});
  EXPECT_EQ(f.status, ViewStatus::NoSupervoxels);
  EXPECT_EQ(f.t0, *p.camera);
  EXPECT_EQ(f.tf, *p.camera);
  EXPECT_EQ(f.iterations, 0);
  EXPECT_EQ(f.skipped_supervoxels, 4);
  EXPECT_EQ(f.skipped_occluders, 1);
  EXPECT_FALSE(f.error_t0);
  EXPECT_FALSE(f.error_tf);

  // With a given centroid there is something to look at: the §2 fallbacks apply.
  p.centroid = Eigen::Vector3d(0, 0, 1);
  const ViewEstimate g = estimate_view(p, EstimatorSettings{});
  EXPECT_NE(g.status, ViewStatus::NoSupervoxels);
  EXPECT_EQ(g.initial_view_used, InitialViewUsed::Camera);
}

TEST(Estimator, InvalidInputStillThrowsWithoutUsableSupervoxels) {
  ViewProblem p;
  EstimatorSettings s;
  s.step = 0.0;
  EXPECT_THROW((void)estimate_view(p, s), std::invalid_argument);
  p.camera = Eigen::Vector3d(kNaN, 0, 0);
  EXPECT_THROW((void)estimate_view(p, EstimatorSettings{}), std::invalid_argument);
  p.camera.reset();
  p.axes = Eigen::Matrix3d::Zero();
  EXPECT_THROW((void)estimate_view(p, EstimatorSettings{}), std::invalid_argument);
  p.axes.reset();
  p.positions.resize(3, 1);
  p.positions.setZero();
  EXPECT_THROW((void)estimate_view(p, EstimatorSettings{}), std::invalid_argument);
}

TEST(Estimator, NormalsAreNormalised) {
  ViewProblem a = patch(4, 2, 0.03);
  ViewProblem b = a;
  b.normals *= 7.5;
  a.occluders = b.occluders = cols({{0.01, 0.005, 0.7}});
  const ViewEstimate ea = estimate_view(a, EstimatorSettings{});
  const ViewEstimate eb = estimate_view(b, EstimatorSettings{});
  EXPECT_TRUE(ea.tf.isApprox(eb.tf, 1e-12));
}

TEST(Estimator, InvalidSettingsNameTheParameter) {
  const ViewProblem p = single_supervoxel();
  auto message_for = [&](const EstimatorSettings& s) -> std::string {
    try {
      (void)estimate_view(p, s);
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "no error";
  };
  EstimatorSettings s;
  s.step = -0.1;
  EXPECT_NE(message_for(s).find("step"), std::string::npos);
  s = {};
  s.r_sphere = kNaN;
  EXPECT_NE(message_for(s).find("r_sphere"), std::string::npos);
  s = {};
  s.clearance = 0.0;
  EXPECT_NE(message_for(s).find("clearance"), std::string::npos);
  s = {};
  s.max_iterations = -1;
  EXPECT_NE(message_for(s).find("max_iterations"), std::string::npos);
  // Extreme but finite lengths are refused, not turned into a view at C or NaN.
  for (double* length : {&s.r_seed, &s.r_sphere, &s.clearance, &s.push_radius, &s.step}) {
    s = {};
    *length = 1e300;
    EXPECT_NE(message_for(s).find("at most 10000 m"), std::string::npos);
  }
  s = {};
  s.time_budget = 0.0;
  EXPECT_NE(message_for(s).find("time_budget"), std::string::npos);
  s = {};
  s.max_iterations = kMaxIterations + 1;
  EXPECT_NE(message_for(s).find("max_iterations"), std::string::npos);
}

TEST(Estimator, ExtremeCoordinatesAndHugeProblemsAreRefused) {
  ViewProblem p = single_supervoxel();
  p.occluders = cols({{0, 0, 0.2}, {0, 0, 1e308}});
  try {
    (void)estimate_view(p, EstimatorSettings{});
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("occluder 1 has a coordinate beyond"), std::string::npos) << e.what();
  }
  p = single_supervoxel();
  p.camera = Eigen::Vector3d(0, 0, -2e4);
  EXPECT_THROW((void)estimate_view(p, EstimatorSettings{}), std::invalid_argument);
  // 4000 x 4000 occlusion rays would take 384 MB: refused before any is made.
  p = patch(80, 50, 0.001);
  p.occluders = Eigen::Matrix3Xd::Constant(3, 4000, 0.2);
  try {
    (void)estimate_view(p, EstimatorSettings{});
    ADD_FAILURE() << "no error";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("4000 supervoxels x 4000 occluders"), std::string::npos) << e.what();
  }
}

TEST(Estimator, TheTimeBudgetEndsTheIterationWithTheBestIterate) {
  // The scene of NotConvergedReturnsTheBestVisitedIterate, which never
  // clears and does not cycle within 10^9 steps of 1 nm.
  ViewProblem p = patch(4, 3, 0.03);
  p.occluders = cols({{0.0, 0.0, 0.8}, {0.05, 0.0, 0.8}, {-0.05, 0.0, 0.8}, {0.0, 0.05, 0.8}});
  EstimatorSettings s;
  s.clearance = 0.1;
  s.step = 1e-9;
  s.max_iterations = kMaxIterations;
  s.time_budget = 0.05;
  const ViewEstimate e = estimate_view(p, s);
  EXPECT_EQ(e.status, ViewStatus::OutOfTime);
  EXPECT_GT(e.iterations, 0);
  EXPECT_LT(e.iterations, s.max_iterations);
  EXPECT_TRUE(e.tf.allFinite());
  EXPECT_NEAR((e.tf - e.centroid).norm(), s.r_sphere, 1e-9);
  EXPECT_FALSE(is_free(e.status));
}

TEST(Estimator, GivenAxesMustBeFiniteAndNonZero) {
  ViewProblem p = patch(3, 2, 0.02);
  p.axes = Eigen::Matrix3d::Identity();
  p.axes->col(1).setZero();
  try {
    (void)estimate_view(p, EstimatorSettings{});
    ADD_FAILURE() << "a zero axis was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("axis e2"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("[0, 0, 0]"), std::string::npos) << e.what();
  }
  p.axes = Eigen::Matrix3d::Identity() * 3.0;  // normalised, not an error
  EXPECT_NO_THROW((void)estimate_view(p, EstimatorSettings{}));
  // Not a frame: refused up front, naming the pair (before, a skewed frame
  // gave views off the intended symmetry, or an internal error).
  p.axes = Eigen::Matrix3d::Identity();
  p.axes->col(2) << 0.0, 0.01, 1.0;
  try {
    (void)estimate_view(p, EstimatorSettings{});
    ADD_FAILURE() << "skewed axes were accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("e2 and e3 must be orthogonal"), std::string::npos) << e.what();
  }
  p.axes->col(2) << 0.0, 1e-8, 1.0;  // orthogonal to rounding
  EXPECT_NO_THROW((void)estimate_view(p, EstimatorSettings{}));
}

TEST(Estimator, MismatchedPositionsAndNormalsIsAUsageError) {
  ViewProblem p = patch(2, 2, 0.02);
  p.normals.conservativeResize(3, 3);
  EXPECT_THROW((void)estimate_view(p, EstimatorSettings{}), std::invalid_argument);
}

// Table I of the paper, as behaviour: no occluder leaves t0 alone; an
// occluder that forces a move costs angular error.
TEST(Estimator, TableIBehaviour) {
  ViewProblem p = patch(5, 4, 0.03);
  for (Eigen::Index k = 0; k < p.normals.cols(); ++k) {
    p.normals.col(k) = Eigen::Vector3d(0.1 * std::sin(3.0 * k), 0.1 * std::cos(5.0 * k), -1);
  }
  const ViewEstimate clear = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(clear.tf, clear.t0);
  EXPECT_EQ(clear.error_tf->mean, clear.error_t0->mean);
  EXPECT_EQ(clear.error_tf->std, clear.error_t0->std);

  p.occluders = cols({{-0.03, 0.0, 0.75}, {-0.02, 0.01, 0.76}, {-0.04, -0.01, 0.74}});
  const ViewEstimate moved = estimate_view(p, EstimatorSettings{});
  EXPECT_EQ(moved.status, ViewStatus::Converged);
  EXPECT_GT(moved.iterations, 0);
  EXPECT_GT(moved.error_tf->mean, moved.error_t0->mean);
  EXPECT_GT(moved.tf.x(), 0.0);  // the occluders are on -x: the view moves to +x
}

TEST(Estimator, ConvergedViewIsClearAndOnTheSphere) {
  ViewProblem p = patch(6, 4, 0.02);
  p.occluders = cols({{0.0, 0.0, 0.8}, {0.02, 0.01, 0.75}, {-0.01, 0.02, 0.7}});
  const EstimatorSettings s;
  const ViewEstimate e = estimate_view(p, s, {true});
  ASSERT_EQ(e.status, ViewStatus::Converged);
  EXPECT_NEAR((e.tf - e.centroid).norm(), s.r_sphere, 1e-12);
  EXPECT_EQ(points_within(p, e, e.tf, s.r_sphere, s.clearance), 0);
  // Every earlier iterate was not clear, and every step has length <= step.
  ASSERT_EQ(e.path.size(), static_cast<std::size_t>(e.iterations) + 1);
  for (std::size_t i = 0; i + 1 < e.path.size(); ++i) {
    EXPECT_GT(points_within(p, e, e.path[i], s.r_sphere, s.clearance), 0) << i;
    EXPECT_LE((e.path[i + 1] - e.path[i]).norm(), s.step + 1e-12);
    EXPECT_NEAR((e.path[i] - e.centroid).norm(), s.r_sphere, 1e-12);
  }
}

TEST(Estimator, NotConvergedReturnsTheBestVisitedIterate) {
  ViewProblem p = patch(4, 3, 0.03);
  p.occluders = cols({{0.0, 0.0, 0.8}, {0.05, 0.0, 0.8}, {-0.05, 0.0, 0.8}, {0.0, 0.05, 0.8}});
  EstimatorSettings s;
  s.clearance = 0.1;  // too wide to clear in three short steps
  s.step = 0.01;
  s.max_iterations = 3;
  const ViewEstimate e = estimate_view(p, s, {true});
  ASSERT_EQ(e.status, ViewStatus::NotConverged);
  EXPECT_EQ(e.iterations, 3);
  ASSERT_EQ(e.path.size(), 4U);
  int best = std::numeric_limits<int>::max();
  for (const auto& t : e.path) best = std::min(best, points_within(p, e, t, s.r_sphere, s.clearance));
  EXPECT_EQ(points_within(p, e, e.tf, s.r_sphere, s.clearance), best);
  EXPECT_EQ(e.clearance_points, best);
  bool visited = false;
  for (const auto& t : e.path) visited = visited || t == e.tf;
  EXPECT_TRUE(visited);
}

TEST(Estimator, ZeroIterationsKeepsT0) {
  ViewProblem p = single_supervoxel();
  p.occluders = cols({{0.001, 0, 0.3}});
  EstimatorSettings s;
  s.max_iterations = 0;
  const ViewEstimate e = estimate_view(p, s);
  EXPECT_EQ(e.status, ViewStatus::NotConverged);
  EXPECT_EQ(e.iterations, 0);
  EXPECT_EQ(e.tf, e.t0);
}

TEST(Estimator, WarmStartStartsFromThePreviousView) {
  ViewProblem p = patch(3, 3, 0.02);
  p.occluders = cols({{0.0, 0.0, 0.75}});
  p.previous_view = Eigen::Vector3d(0.3, 0.1, 0.5);
  EstimatorSettings s;
  const ViewEstimate cold = estimate_view(p, s);
  s.warm_start = true;
  const ViewEstimate warm = estimate_view(p, s);
  const Eigen::Vector3d start =
      warm.centroid + 0.5 * (*p.previous_view - warm.centroid).normalized();
  EXPECT_TRUE(warm.tf.isApprox(start, 1e-12));  // already clear
  EXPECT_EQ(warm.iterations, 0);
  EXPECT_EQ(warm.t0, cold.t0);
  EXPECT_NEAR(warm.tf_to_t0_deg, angle_between(warm.tf - warm.centroid, warm.t0 - warm.centroid) / kDeg, 1e-12);
  p.previous_view.reset();  // no previous view: t0
  const ViewEstimate first = estimate_view(p, s);
  EXPECT_EQ(first.tf, cold.tf);
}

TEST(Estimator, InverseDistanceWeightingIsSelectable) {
  ViewProblem p = patch(5, 3, 0.02);
  p.occluders = cols({{0.01, 0.0, 0.8}, {0.03, 0.02, 0.8}, {-0.04, 0.0, 0.7}});
  EstimatorSettings s;
  const ViewEstimate sum = estimate_view(p, s);
  s.push_weighting = PushWeighting::InverseDistance;
  const ViewEstimate inv = estimate_view(p, s);
  EXPECT_EQ(inv.status, ViewStatus::Converged);
  EXPECT_FALSE(inv.tf.isApprox(sum.tf, 1e-6));
  EXPECT_EQ(inv.t0, sum.t0);
}

TEST(EstimatorParams, PresetsUseTheFinalRadiiAndExplicitValuesWin) {
  EstimatorParams p;
  EXPECT_EQ(p.resolve().step, 0.02);
  EXPECT_EQ(p.resolve().push_radius, 0.5);
  p.preset = Preset::AuthorsCode;
  p.r_seed = 0.03;
  p.r_sphere = 0.6;
  EstimatorSettings s = p.resolve();
  EXPECT_DOUBLE_EQ(s.step, 0.015);
  EXPECT_DOUBLE_EQ(s.clearance, 0.06);
  EXPECT_DOUBLE_EQ(s.push_radius, 0.6);
  EXPECT_EQ(s.max_iterations, 50);
  p.step = 0.05;
  p.max_iterations = 7;
  s = p.resolve();
  EXPECT_EQ(s.step, 0.05);
  EXPECT_EQ(s.max_iterations, 7);
  p.clearance = -1.0;
  EXPECT_THROW((void)p.resolve(), std::invalid_argument);
}

TEST(EstimatorParams, WordsRoundTrip) {
  for (auto v : {InitialView::SphericalMean, InitialView::VectorMean}) {
    EXPECT_EQ(parse_initial_view(to_string(v)), v);
  }
  for (auto v : {PushWeighting::Sum, PushWeighting::InverseDistance}) {
    EXPECT_EQ(parse_push_weighting(to_string(v)), v);
  }
  for (auto v : {Preset::Paper, Preset::AuthorsCode}) EXPECT_EQ(parse_preset(to_string(v)), v);
  EXPECT_FALSE(parse_preset("Paper"));
  EXPECT_FALSE(parse_initial_view(""));
}

// A bent patch with occluders, used by the invariance tests.
ViewProblem bent_scene() {
  ViewProblem p = patch(6, 5, 0.025);
  for (Eigen::Index k = 0; k < p.positions.cols(); ++k) {
    const double x = p.positions(0, k);
    p.positions(2, k) += 2.0 * x * x;
    p.normals.col(k) = Eigen::Vector3d(4.0 * x, 0.05 * std::sin(7.0 * k), -1).normalized();
  }
  p.occluders = cols({{-0.02, 0.01, 0.78}, {0.0, 0.03, 0.74}, {-0.05, -0.02, 0.8}});
  p.camera = Eigen::Vector3d(0.05, -0.02, 0.4);
  return p;
}

TEST(EstimatorInvariance, RigidMotionOfTheSceneMovesTheViews) {
  const ViewProblem p = bent_scene();
  const EstimatorSettings s;
  const ViewEstimate e = estimate_view(p, s);
  ASSERT_EQ(e.status, ViewStatus::Converged);
  ASSERT_GT(e.iterations, 0);
  const Eigen::Isometry3d m =
      Eigen::Translation3d(0.4, -1.2, 2.0) *
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, -0.5).normalized());
  ViewProblem q = p;
  q.positions = m * p.positions;
  q.normals = m.linear() * p.normals;
  q.occluders = m * p.occluders;
  q.camera = m * *p.camera;
  const ViewEstimate f = estimate_view(q, s);
  EXPECT_EQ(f.status, e.status);
  EXPECT_EQ(f.iterations, e.iterations);
  EXPECT_LT((f.t0 - m * e.t0).norm(), 1e-9);
  EXPECT_LT((f.tf - m * e.tf).norm(), 1e-9);
  EXPECT_NEAR(f.error_tf->mean, e.error_tf->mean, 1e-7);
}

TEST(EstimatorInvariance, AxisSignsAndTheE2E3ChoiceDoNotMatter) {
  ViewProblem p = bent_scene();
  const ViewEstimate pca = estimate_view(p, EstimatorSettings{});
  const Eigen::Matrix3d axes = pca.axes;
  const std::vector<Eigen::Matrix3d> variants = [&] {
    std::vector<Eigen::Matrix3d> v;
    Eigen::Matrix3d flipped = axes;
    flipped.col(0) *= -1;
    flipped.col(2) *= -1;  // keep right-handed
    v.push_back(flipped);
    Eigen::Matrix3d rotated = axes;
    const Eigen::AngleAxisd about_e1(0.9, axes.col(0));
    rotated.col(1) = about_e1 * axes.col(1);
    rotated.col(2) = about_e1 * axes.col(2);
    v.push_back(rotated);
    return v;
  }();
  for (const auto& a : variants) {
    p.axes = a;
    const ViewEstimate e = estimate_view(p, EstimatorSettings{});
    EXPECT_LT((e.t0 - pca.t0).norm(), 1e-12);
    EXPECT_LT((e.tf - pca.tf).norm(), 1e-9);
  }
}

TEST(EstimatorInvariance, MirrorSymmetricSceneGivesASymmetricView) {
  // Symmetric about the plane y = 0: so must t0 and tf be.
  ViewProblem p = patch(5, 4, 0.03);
  p.occluders = cols({{0.02, 0.01, 0.75}, {0.02, -0.01, 0.75}});
  const ViewEstimate e = estimate_view(p, EstimatorSettings{});
  EXPECT_NEAR(e.t0.y(), 0.0, 1e-12);
  EXPECT_NEAR(e.tf.y(), 0.0, 1e-12);
  EXPECT_LT(e.tf.x(), 0.0);
}

TEST(Geometry, SphereExitFromInsideLandsOnTheSphere) {
  const Eigen::Vector3d c(0.1, -0.2, 0.3);
  const Eigen::Vector3d o = c + Eigen::Vector3d(0.1, 0.05, -0.2);
  for (const Eigen::Vector3d& dir : {Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(-0.3, 2, 1)}) {
    const Eigen::Vector3d s = sphere_exit(c, 0.5, o, dir);
    EXPECT_NEAR((s - c).norm(), 0.5, 1e-12);
    EXPECT_GT((s - o).dot(dir), 0.0);
    EXPECT_LT((s - o).normalized().cross(dir.normalized()).norm(), 1e-12);
  }
  EXPECT_NEAR(angle_between({1, 0, 0}, {0, 2, 0}), kPi / 2, 1e-15);
  EXPECT_NEAR(angle_between({1, 0, 0}, {-1, 1e-20, 0}), kPi, 1e-15);
}

// ---------------------------------------------------------------------------
// Speed work (issue #12): pruning and the vectorised kernels must not change a
// bit. A deliberately plain reference of §3 and §4 (no pruning, one point at a
// time, the documented summation order: point k into partial sum k % 8,
// partial sums added ((s0+s1)+(s2+s3))+((s4+s5)+(s6+s7))) must visit exactly
// the iterates the library visits.
namespace reference {

struct Result {
  std::vector<Eigen::Vector3d> path;
  int in_clearance_at_end = 0;
};

double combine(const double (&s)[8]) {
  return ((s[0] + s[1]) + (s[2] + s[3])) + ((s[4] + s[5]) + (s[6] + s[7]));
}

// Converged or cycle-free runs only: returns the path up to the first clear
// iterate, or max_iterations + 1 iterates.
#if defined(__GNUC__) && !defined(__clang__)
__attribute__((optimize("fp-contract=off")))
#endif
Result iterate(const UsableInput& in, const Eigen::Vector3d& c, const Eigen::Vector3d& start,
               const EstimatorSettings& s) {
  const double r = s.r_sphere;
  std::vector<double> dx, dy, dz;  // §3, as the library rounds it
  for (Eigen::Index n = 0; n < in.positions.cols(); ++n) {
    const double ax = in.positions(0, n) - c.x(), ay = in.positions(1, n) - c.y(),
                 az = in.positions(2, n) - c.z();
    const double a_in = (ax * ax + ay * ay) + az * az - r * r;
    for (Eigen::Index b = 0; b < in.occluders.cols(); ++b) {
      double ux = (in.occluders(0, b) - c.x()) - ax;
      double uy = (in.occluders(1, b) - c.y()) - ay;
      double uz = (in.occluders(2, b) - c.z()) - az;
      const double len = std::sqrt(ux * ux + uy * uy + uz * uz);
      if (!(len >= 1e-9)) continue;
      const double inv = 1.0 / len;
      ux *= inv;
      uy *= inv;
      uz *= inv;
      double t = ax * ux + ay * uy + az * uz;
      t = std::sqrt(t * t - a_in) - t;
      dx.push_back(ax + t * ux);
      dy.push_back(ay + t * uy);
      dz.push_back(az + t * uz);
    }
  }
  Result res;
  Eigen::Vector3d t = start;
  for (int i = 0;; ++i) {
    res.path.push_back(t);
    const Eigen::Vector3d tc = t - c;
    const Eigen::Vector3d w = tc.normalized();
    double count[8] = {}, vx[8] = {}, vy[8] = {}, vz[8] = {};
    for (std::size_t k = 0; k < dx.size(); ++k) {
      const double dw = dx[k] * w.x() + dy[k] * w.y() + dz[k] * w.z();
      if (dw <= 1e-9) continue;
      const double scale = r / dw;
      const double px = dx[k] * scale - tc.x(), py = dy[k] * scale - tc.y(),
                   pz = dz[k] * scale - tc.z();
      const double dist2 = px * px + py * py + pz * pz;
      if (dist2 < s.clearance * s.clearance) count[k % 8] += 1.0;
      if (dist2 < s.push_radius * s.push_radius) {
        const double weight =
            s.push_weighting == PushWeighting::InverseDistance ? 1.0 / dist2 : 1.0;
        vx[k % 8] -= weight * px;
        vy[k % 8] -= weight * py;
        vz[k % 8] -= weight * pz;
      }
    }
    res.in_clearance_at_end = static_cast<int>(combine(count));
    if (res.in_clearance_at_end == 0 || i == s.max_iterations) return res;
    const Eigen::Vector3d v(combine(vx), combine(vy), combine(vz));
    if (v.norm() < 1e-12) return res;  // the fallbacks are not this test's subject
    const Eigen::Vector3d t_pi = t + s.step * v.normalized();
    t = c + r * (t_pi - c).normalized();
  }
}

}  // namespace reference

// Random scenes (fixed seeds), around a patch, with the default push radius
// (little to prune) and with push_radius = r_seed (most points pruned), both
// weightings: every visited iterate is bit-for-bit the plain reference's.
TEST(EstimatorSpeed, PruningAndKernelsGiveTheReferenceIteratesBitForBit) {
#if defined(__FMA__)
  GTEST_SKIP() << "this test file is built with FMA contraction; the library is not";
#endif
  std::mt19937 rng(12);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int compared = 0, pruned_scenes = 0;
  for (int scene = 0; scene < 60; ++scene) {
    ViewProblem p = patch(5, 4, 0.03);
    const int b = 5 + scene % 40;
    p.occluders.resize(3, b);
    const Eigen::Vector3d hand(0.1 * u(rng), 0.1 * u(rng), 0.6 + 0.3 * std::abs(u(rng)));
    const double spread = scene % 4 == 3 ? 0.3 : 0.06;  // wide: rays over much of the sphere
    for (int k = 0; k < b; ++k) {
      p.occluders.col(k) = hand + Eigen::Vector3d(spread * u(rng), spread * u(rng), 0.03 * u(rng));
    }
    EstimatorSettings s;
    if (scene % 2 == 1) {
      s.push_radius = s.r_seed;
      ++pruned_scenes;
    }
    if (scene % 3 == 2) s.push_weighting = PushWeighting::InverseDistance;
    s.max_iterations = 200;
    EstimateOptions o;
    o.record_path = true;
    const ViewEstimate e = estimate_view(p, s, o);
    const UsableInput in = usable_input(p, e.centroid, s.r_sphere);
    const reference::Result ref = reference::iterate(in, e.centroid, e.t0, s);
    if (e.status == ViewStatus::NotConverged && e.path.size() != ref.path.size()) {
      continue;  // a cycle cut short, or a fallback push: not this test's subject
    }
    ASSERT_EQ(e.path.size(), ref.path.size()) << "scene " << scene;
    for (std::size_t i = 0; i < ref.path.size(); ++i) {
      ASSERT_EQ(e.path[i], ref.path[i]) << "scene " << scene << " iterate " << i;
    }
    if (e.status == ViewStatus::Converged) {
      EXPECT_EQ(e.tf, ref.path.back());
      EXPECT_EQ(e.iterations + 1, static_cast<int>(ref.path.size()));
    }
    ++compared;
  }
  EXPECT_GE(compared, 50);
  EXPECT_GT(pruned_scenes, 0);
}

// Working memory prepared ahead changes no result.
TEST(EstimatorSpeed, ReservedMemoryGivesTheSameEstimate) {
  ViewProblem p = patch(5, 4, 0.03);
  p.occluders.resize(3, 9);
  for (int k = 0; k < 9; ++k) p.occluders.col(k) << (k % 3 - 1) * 0.01, (k / 3 - 1) * 0.01, 0.75;
  EstimateOptions o;
  o.record_path = true;
  const ViewEstimate before = estimate_view(p, EstimatorSettings{}, o);
  reserve_estimator_memory(100'000);
  reserve_estimator_memory(10);  // less than before: nothing to do
  const ViewEstimate after = estimate_view(p, EstimatorSettings{}, o);
  EXPECT_EQ(before.tf, after.tf);
  EXPECT_EQ(before.path, after.path);
  EXPECT_GT(after.iterations, 0);
}

}  // namespace
}  // namespace ofv
