// Target pose on the sphere, roll by least rotation.
#include "ofv/servo/target_pose.h"
#include "ofv/constants.h"

#include <Eigen/Geometry>

#include <stdexcept>

namespace ofv::servo {

vpHomogeneousMatrix to_visp(const Eigen::Isometry3d& m) {
  vpHomogeneousMatrix h;
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 3; ++c) h[r][c] = m.linear()(r, c);
    h[r][3] = m.translation()(r);
  }
  return h;
}

Eigen::Isometry3d to_eigen(const vpHomogeneousMatrix& h) {
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  for (unsigned r = 0; r < 3; ++r) {
    for (unsigned c = 0; c < 3; ++c) m.linear()(r, c) = h[r][c];
    m.translation()(r) = h[r][3];
  }
  return m;
}

vpHomogeneousMatrix target_pose(const Eigen::Vector3d& t, const Eigen::Vector3d& centroid,
                                const vpHomogeneousMatrix& wMc) {
  const Eigen::Vector3d axis = centroid - t;
  if (!t.allFinite() || !centroid.allFinite() || axis.norm() < 1e-12) {
    throw std::invalid_argument("target_pose: the view must be finite and away from the centroid");
  }
  const Eigen::Isometry3d current = to_eigen(wMc);
  const Eigen::Matrix3d wRc = current.linear();
  const Eigen::Vector3d z_cur = wRc.col(2);
  const Eigen::Vector3d z_des = axis.normalized();
  Eigen::Matrix3d turn;
  if (z_cur.dot(z_des) < -1.0 + 1e-12) {
    turn = Eigen::AngleAxisd(kPi, wRc.col(0)).toRotationMatrix();
  } else {
    turn = Eigen::Quaterniond::FromTwoVectors(z_cur, z_des).toRotationMatrix();
  }
  Eigen::Isometry3d wMcd = Eigen::Isometry3d::Identity();
  wMcd.linear() = turn * wRc;
  wMcd.translation() = t;
  return to_visp(wMcd);
}

}  // namespace ofv::servo
