// Deterministic scenes for the benchmarks.
#pragma once

#include "ofv/estimator.h"

#include <cmath>
#include <random>

namespace ofv::bench {

/**
 * \brief A flat square patch of `n` supervoxels 1 m in front of the origin,
 *        facing it, with `b` occluder points in a hand-sized cluster between
 *        the patch and the sphere, off the patch's normal ray.
 */
inline ViewProblem flat_patch_with_occluders(int n, int b, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const double spacing = 0.2 / side;  // a 0.2 m patch, like a DVD case
  ViewProblem p;
  p.positions.resize(3, n);
  p.normals.resize(3, n);
  for (int k = 0; k < n; ++k) {
    const double x = (k % side - 0.5 * (side - 1)) * spacing;
    const double y = (k / side - 0.5 * (side - 1)) * spacing;
    p.positions.col(k) << x, y, 1.0 + 0.002 * unit(rng);
    p.normals.col(k) = Eigen::Vector3d(0.05 * unit(rng), 0.05 * unit(rng), -1.0).normalized();
  }
  p.occluders.resize(3, b);
  const Eigen::Vector3d hand(0.04, 0.02, 0.75);
  for (int k = 0; k < b; ++k) {
    p.occluders.col(k) = hand + Eigen::Vector3d(0.05 * unit(rng), 0.04 * unit(rng), 0.02 * unit(rng));
  }
  return p;
}

/**
 * \brief The loop's largest problems (`sweep` with anticipation): a patch of
 *        `n` supervoxels as flat_patch_with_occluders(), and an upright arm
 *        of `b` occluder points between it and the sphere, spread over three
 *        places 0.18 m apart (the arm now and its two predicted copies), with
 *        the previous view beyond them: the warm start crosses their rays.
 */
inline ViewProblem patch_behind_sweeping_arm(int n, int b, unsigned seed = 7) {
  ViewProblem p = flat_patch_with_occluders(n, 0, seed);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  p.occluders.resize(3, b);
  for (int k = 0; k < b; ++k) {
    const double x = -0.1 + 0.18 * (k % 3);
    p.occluders.col(k) << x + 0.035 * unit(rng), 0.18 * unit(rng), 0.78 + 0.035 * unit(rng);
  }
  p.previous_view = Eigen::Vector3d(0.3, 0.0, 0.6);
  return p;
}

}  // namespace ofv::bench
