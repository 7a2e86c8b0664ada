/**
 * \file target_pose.h
 * \brief The camera pose that goes with a view on the sphere (ESTIMATOR-SPEC §5).
 */
#pragma once

#include <Eigen/Geometry>
#include <visp3/core/vpHomogeneousMatrix.h>

namespace ofv::servo {

/// \brief ViSP <-> Eigen for poses (same convention: aMb maps b to a).
[[nodiscard]] vpHomogeneousMatrix to_visp(const Eigen::Isometry3d& aMb);
/// \brief Eigen <-> ViSP for poses, the inverse of to_visp().
[[nodiscard]] Eigen::Isometry3d to_eigen(const vpHomogeneousMatrix& aMb);

/**
 * \brief Desired camera pose wMcd at position `t` (world frame [m]) with the
 *        optical axis Z pointing at the object centroid `centroid`.
 *
 * The roll about the optical axis is not fixed by the method; it is chosen by
 * least rotation from the current camera `wMc`: the current orientation is
 * turned by the smallest rotation that takes its Z axis onto the desired Z
 * (about z_current x z_desired). When the two axes are opposite, the turn is
 * pi about the current X axis. Hence a camera already looking at C keeps its
 * orientation exactly.
 * \throws std::invalid_argument when t coincides with the centroid or is non-finite.
 */
[[nodiscard]] vpHomogeneousMatrix target_pose(const Eigen::Vector3d& t, const Eigen::Vector3d& centroid,
                                              const vpHomogeneousMatrix& wMc);

}  // namespace ofv::servo

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::servo::.
namespace ofv {
using servo::target_pose;
using servo::to_eigen;
using servo::to_visp;
}  // namespace ofv
/// \endcond
