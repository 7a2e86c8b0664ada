// The TUM benchmark's measures on hand-made trajectories with known errors.
#include "ofv/odometry/evaluation.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ofv::odometry {
namespace {

constexpr double kDegree = M_PI / 180.0;

/// A camera going along a curve at 30 Hz for `n` frames, turning as it goes.
std::vector<StampedPose> curve(int n) {
  std::vector<StampedPose> poses;
  for (int k = 0; k < n; ++k) {
    StampedPose p;
    p.time = k / 30.0;
    p.wMc = Eigen::Translation3d(0.3 * std::sin(0.1 * k), 0.01 * k, 0.5) *
            Eigen::AngleAxisd(0.02 * k, Eigen::Vector3d(0.3, 1.0, 0.2).normalized());
    poses.push_back(p);
  }
  return poses;
}

TEST(TrajectoryErrors, SameTrajectoryHasNoError) {
  const auto truth = curve(60);
  const TrajectoryErrors e = trajectory_errors(truth, truth);
  EXPECT_EQ(e.poses, 60);
  EXPECT_NEAR(e.ate, 0.0, 1e-12);
  EXPECT_EQ(e.per_frame.pairs, 59);
  EXPECT_EQ(e.per_second.pairs, 30);  // pose i with pose i + 30, i = 0..29
  EXPECT_NEAR(e.per_frame.translation_max, 0.0, 1e-12);
  EXPECT_NEAR(e.per_second.rotation_max, 0.0, 1e-6);
}

TEST(TrajectoryErrors, ConstantOffsetGivesNoErrorAfterAlignment) {
  // The same trajectory in another world frame: aligning the first pose removes it.
  const auto truth = curve(50);
  auto estimate = truth;
  const Eigen::Isometry3d offset(Eigen::Translation3d(1.0, -2.0, 0.3) * Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()));
  for (auto& p : estimate) p.wMc = offset * p.wMc;
  const TrajectoryErrors e = trajectory_errors(estimate, truth);
  EXPECT_NEAR(e.ate, 0.0, 1e-9);
  EXPECT_NEAR(e.per_frame.translation_rmse, 0.0, 1e-9);
  EXPECT_NEAR(e.per_second.rotation_rmse, 0.0, 1e-6);
}

TEST(TrajectoryErrors, LinearDriftGivesItsRmse) {
  // Position error d*k along world x at frame k (k = 0..n-1): ATE =
  // d*sqrt(sum k^2 / n); each step's error is d, each second's 30 d.
  const int n = 31;
  const double d = 0.001;
  const auto truth = curve(n);
  auto estimate = truth;
  for (int k = 0; k < n; ++k) estimate[k].wMc.translation().x() += d * k;
  double sum = 0.0;
  for (int k = 0; k < n; ++k) sum += (d * k) * (d * k);
  const TrajectoryErrors e = trajectory_errors(estimate, truth);
  EXPECT_NEAR(e.ate, std::sqrt(sum / n), 1e-12);
  EXPECT_NEAR(e.ate_max, d * (n - 1), 1e-12);
  EXPECT_NEAR(e.per_frame.translation_rmse, d, 1e-12);
  EXPECT_NEAR(e.per_frame.translation_max, d, 1e-12);
  EXPECT_NEAR(e.per_frame.rotation_max, 0.0, 1e-6);
  EXPECT_EQ(e.per_second.pairs, 1);
  EXPECT_NEAR(e.per_second.translation_rmse, 30 * d, 1e-12);
}

TEST(TrajectoryErrors, RotationDriftGivesItsAngle) {
  // A camera turning in place, the estimate turned 0.1 degree more per
  // frame about the world's z: each step's error is Q_j^-1 Rz(0.1) Q_j, 0.1 degree.
  auto truth = curve(20);
  for (auto& p : truth) p.wMc.translation().setZero();
  auto estimate = truth;
  for (int k = 0; k < 20; ++k) estimate[k].wMc = Eigen::AngleAxisd(0.1 * k * kDegree, Eigen::Vector3d::UnitZ()) * truth[k].wMc;
  const RelativeErrors e = relative_pose_error(estimate, truth, 1, 0.0);
  EXPECT_EQ(e.pairs, 19);
  EXPECT_NEAR(e.rotation_rmse, 0.1, 1e-9);
  EXPECT_NEAR(e.translation_max, 0.0, 1e-12);
}

TEST(TrajectoryErrors, PosesAreAssociatedByTime) {
  // Ground truth at twice the rate: every estimated pose finds its own.
  auto truth = curve(40);
  std::vector<StampedPose> estimate;
  for (std::size_t k = 0; k < truth.size(); k += 2) estimate.push_back(truth[k]);
  const auto pairs = associate(estimate, truth);
  ASSERT_EQ(pairs.size(), 20u);
  for (std::size_t i = 0; i < pairs.size(); ++i) EXPECT_EQ(pairs[i].second, 2 * i);
  // Beyond max_time_difference there is no pair.
  for (auto& p : estimate) p.time += 10.0;
  EXPECT_TRUE(associate(estimate, truth).empty());
}

}  // namespace
}  // namespace ofv::odometry
