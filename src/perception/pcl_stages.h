// Internal: the front end's PCL stages behind a PCL-free interface, so that
// PCL's templates are instantiated in supervoxels.cpp only.
#pragma once

#include "ofv/perception/cloud.h"
#include "ofv/perception/perception.h"

#include <Eigen/Core>

#include <optional>
#include <vector>

namespace ofv::perception::detail {

/// Supervoxels of one frame and the voxels they own (from either stage:
/// cluster_supervoxels() below or vccs_supervoxels() in vccs.h).
struct SupervoxelOutput {
  std::vector<SupervoxelInfo> supervoxels;    // label Background, normal oriented to the camera
  std::vector<Eigen::Vector3f> voxels;        // world frame [m]
  std::vector<Eigen::Vector3f> colours;       // R, G, B per voxel
  std::vector<int> owner;                     // index into supervoxels, per voxel
  std::vector<std::pair<int, int>> touching;  // pairs (i < j) whose voxels touch (26-neighbours)

  void clear() {
    supervoxels.clear();
    voxels.clear();
    colours.clear();
    touching.clear();
    owner.clear();
  }
};

/// Runs pcl::SupervoxelClustering<pcl::PointXYZRGBA> on a voxelised world
/// cloud; normals are flipped to face `camera` (world frame).
void cluster_supervoxels(const WorldCloud& cloud, const SupervoxelSettings& settings,
                         const Eigen::Vector3d& camera, SupervoxelOutput& out);

/// Dominant plane n.p + d = 0 (unit n) by RANSAC (pcl::SACSegmentation), or
/// nothing when fewer than `min_inliers` points fit it.
[[nodiscard]] std::optional<Eigen::Vector4d> fit_dominant_plane(
    const std::vector<Eigen::Vector3f>& points, double distance, std::size_t min_inliers);

}  // namespace ofv::perception::detail
