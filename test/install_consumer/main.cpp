// Estimates the view of a one-supervoxel object with one occluder on its normal.
#include <ofv/estimator.h>

#include <cmath>
#include <iostream>

int main() {
  ofv::ViewProblem problem;
  problem.positions = Eigen::Matrix3Xd::Zero(3, 1);
  problem.normals = Eigen::Matrix3Xd(3, 1);
  problem.normals << 0, 0, 1;
  problem.occluders = Eigen::Matrix3Xd(3, 1);
  problem.occluders << 0.001, 0, 0.3;
  const ofv::ViewEstimate e = ofv::estimate_view(problem, ofv::EstimatorSettings{});
  const bool ok = e.status == ofv::ViewStatus::Converged && std::abs(e.tf.norm() - 0.5) < 1e-9 &&
                  (e.tf - e.t0).norm() > 0.01;
  std::cout << "t0 " << e.t0.transpose() << "  tf " << e.tf.transpose() << "  "
            << ofv::to_string(e.status) << '\n';
  return ok ? 0 : 1;
}
