// The TUM RGB-D benchmark's trajectory measures (ofv/odometry/evaluation.h).
#include "ofv/odometry/evaluation.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ofv::odometry {

namespace {

constexpr double kDegree = M_PI / 180.0;

struct Sums {
  long n = 0;
  double t2 = 0.0, t_max = 0.0, r2 = 0.0, r_max = 0.0;
  void add(double t, double r) {
    ++n;
    t2 += t * t;
    r2 += r * r;
    t_max = std::max(t_max, t);
    r_max = std::max(r_max, r);
  }
  [[nodiscard]] RelativeErrors errors() const {
    RelativeErrors e;
    e.pairs = n;
    if (n > 0) {
      e.translation_rmse = std::sqrt(t2 / static_cast<double>(n));
      e.rotation_rmse = std::sqrt(r2 / static_cast<double>(n));
      e.translation_max = t_max;
      e.rotation_max = r_max;
    }
    return e;
  }
};

}  // namespace

std::vector<std::pair<std::size_t, std::size_t>> associate(const std::vector<StampedPose>& estimate,
                                                           const std::vector<StampedPose>& truth,
                                                           double max_time_difference) {
  std::vector<std::pair<std::size_t, std::size_t>> pairs;
  std::size_t j = 0;
  for (std::size_t i = 0; i < estimate.size() && !truth.empty(); ++i) {
    const double t = estimate[i].time;
    while (j + 1 < truth.size() && std::abs(truth[j + 1].time - t) <= std::abs(truth[j].time - t)) ++j;
    if (std::abs(truth[j].time - t) <= max_time_difference) pairs.emplace_back(i, j);
  }
  return pairs;
}

std::pair<double, double> absolute_trajectory_error(const std::vector<StampedPose>& estimate,
                                                    const std::vector<StampedPose>& truth, double max_time_difference) {
  const auto pairs = associate(estimate, truth, max_time_difference);
  if (pairs.empty()) return {0.0, 0.0};
  // The transform that puts the first estimated pose on the first true one.
  const Eigen::Isometry3d align = truth[pairs.front().second].wMc * estimate[pairs.front().first].wMc.inverse();
  double sum = 0.0;
  double worst = 0.0;
  for (const auto& [i, j] : pairs) {
    const double e = ((align * estimate[i].wMc).translation() - truth[j].wMc.translation()).norm();
    sum += e * e;
    worst = std::max(worst, e);
  }
  return {std::sqrt(sum / static_cast<double>(pairs.size())), worst};
}

RelativeErrors relative_pose_error(const std::vector<StampedPose>& estimate, const std::vector<StampedPose>& truth,
                                   int frames, double seconds, double max_time_difference) {
  const auto pairs = associate(estimate, truth, max_time_difference);
  Sums sums;
  std::size_t b = 0;
  for (std::size_t a = 0; a < pairs.size(); ++a) {
    if (seconds > 0.0) {
      const double target = estimate[pairs[a].first].time + seconds;
      b = std::max(b, a + 1);
      while (b < pairs.size() && estimate[pairs[b].first].time < target - 1e-9) ++b;
    } else {
      b = a + static_cast<std::size_t>(std::max(frames, 1));
    }
    if (b >= pairs.size()) break;
    const auto& [ia, ja] = pairs[a];
    const auto& [ib, jb] = pairs[b];
    const Eigen::Isometry3d true_motion = truth[ja].wMc.inverse() * truth[jb].wMc;
    const Eigen::Isometry3d estimated_motion = estimate[ia].wMc.inverse() * estimate[ib].wMc;
    const Eigen::Isometry3d E = true_motion.inverse() * estimated_motion;
    sums.add(E.translation().norm(), Eigen::AngleAxisd(E.linear()).angle() / kDegree);
  }
  return sums.errors();
}

TrajectoryErrors trajectory_errors(const std::vector<StampedPose>& estimate, const std::vector<StampedPose>& truth,
                                   double max_time_difference) {
  TrajectoryErrors e;
  e.poses = static_cast<long>(associate(estimate, truth, max_time_difference).size());
  std::tie(e.ate, e.ate_max) = absolute_trajectory_error(estimate, truth, max_time_difference);
  e.per_frame = relative_pose_error(estimate, truth, 1, 0.0, max_time_difference);
  e.per_second = relative_pose_error(estimate, truth, 0, 1.0, max_time_difference);
  return e;
}

}  // namespace ofv::odometry
