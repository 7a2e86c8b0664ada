// Test helper: scores a PerceptionResult against per-pixel ground-truth labels.
#pragma once

#include "ofv/perception/perception.h"

#include <cmath>
#include <map>
#include <vector>

namespace ofv::test {

/// Majority ground-truth label of each supervoxel: its voxels projected into
/// the frame's camera and looked up in `labels` (width x height).
inline std::vector<int> supervoxel_truth(const perception::PerceptionResult& r, const RgbdFrame& frame,
                                         const std::vector<int>& labels) {
  std::vector<std::map<int, int>> votes(r.supervoxels.size());
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const CameraIntrinsics& k = frame.intrinsics;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const Eigen::Vector3d pc = cMw * r.voxels[i].cast<double>();
    if (pc.z() <= 0.0) {
      continue;
    }
    const int u = static_cast<int>(std::lround(k.fx * pc.x() / pc.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * pc.y() / pc.z() + k.cy));
    if (u < 0 || v < 0 || u >= k.width || v >= k.height) {
      continue;
    }
    ++votes[static_cast<std::size_t>(r.voxel_owner[i])][labels[frame.index(u, v)]];
  }
  std::vector<int> truth(r.supervoxels.size(), 0);
  for (std::size_t s = 0; s < votes.size(); ++s) {
    int best = -1;
    for (const auto& [label, count] : votes[s]) {
      if (count > best) {
        best = count;
        truth[s] = label;
      }
    }
  }
  return truth;
}

/// Mean of the voxels whose pixel carries ground-truth label `label`: the
/// centroid a perfect segmentation of this frame's voxels would give.
inline Eigen::Vector3d truth_centroid(const perception::PerceptionResult& r, const RgbdFrame& frame,
                                      const std::vector<int>& labels, int label) {
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const CameraIntrinsics& k = frame.intrinsics;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (const Eigen::Vector3f& voxel : r.voxels) {
    const Eigen::Vector3d pc = cMw * voxel.cast<double>();
    const int u = static_cast<int>(std::lround(k.fx * pc.x() / pc.z() + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * pc.y() / pc.z() + k.cy));
    if (pc.z() > 0.0 && u >= 0 && v >= 0 && u < k.width && v < k.height &&
        labels[frame.index(u, v)] == label) {
      sum += voxel.cast<double>();
      ++n;
    }
  }
  return n > 0 ? Eigen::Vector3d(sum / n) : Eigen::Vector3d::Constant(NAN);
}

/// Precision and recall of the Object class against ground-truth label `object`.
struct ObjectScore {
  double precision = 0.0;
  double recall = 0.0;
  int true_positives = 0;
  int predicted = 0;
  int actual = 0;
};

inline ObjectScore score_object(const perception::PerceptionResult& r, const std::vector<int>& truth,
                                int object) {
  ObjectScore s;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const bool predicted = r.supervoxels[i].label == perception::SupervoxelClass::Object;
    const bool actual = truth[i] == object;
    s.predicted += predicted ? 1 : 0;
    s.actual += actual ? 1 : 0;
    s.true_positives += predicted && actual ? 1 : 0;
  }
  s.precision = s.predicted > 0 ? static_cast<double>(s.true_positives) / s.predicted : 0.0;
  s.recall = s.actual > 0 ? static_cast<double>(s.true_positives) / s.actual : 0.0;
  return s;
}

/// How many supervoxels with ground-truth label `label` got class `cls`.
inline int count_truth_as(const perception::PerceptionResult& r, const std::vector<int>& truth, int label,
                          perception::SupervoxelClass cls) {
  int n = 0;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    n += truth[i] == label && r.supervoxels[i].label == cls ? 1 : 0;
  }
  return n;
}

}  // namespace ofv::test
