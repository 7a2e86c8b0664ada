// Internal: ofv's own supervoxel stage (setting `supervoxels=ofv`), VCCS
// (Papon et al., CVPR 2013) on the voxel grid the cloud stage already built.
//
// The algorithm, one frame:
//  1. Voxels. The cloud's points hashed on cells of `voxel_resolution`
//     (points sharing a cell are averaged: position and colour). Two face
//     neighbours of one colour whose means are within 0.4 voxel across their
//     common face are one surface patch the face split (a surface lying
//     along it, both sides taken as its noise decides): they become one
//     voxel. The 26-neighbourhood of every voxel as index lists.
//  2. Voxel normals. The smallest principal axis of the voxels within two
//     rings of neighbours (the voxel, its 26-neighbours and theirs, a voxel
//     counted once per path to it, as VCCS counts them), turned to face the
//     camera; voxels on a line or a point give no normal (a zero vector:
//     the normal term of the distance is then at its largest, 1).
//  3. Seeds. One per occupied cell of edge R_seed (`seed_resolution`): the
//     cell's voxel nearest the cell's centre (the first on a tie), kept when
//     more than 0.05 pi (R_seed/2)^2 / voxel^2 voxels lie within R_seed/2 of
//     it (a twentieth of a flat disc of voxels: isolated specks seed nothing).
//  4. Growth. With D = int(1.8 R_seed / voxel) as in VCCS, D - 1
//     rounds in which every supervoxel, in seed order, offers each
//     26-neighbour of its voxels that it does not own the distance
//        d = w_n (1 - |n_s . n_v|) + w_c |c_s - c_v| / 255 + w_s |x_s - x_v| / R_seed
//     from its centre s (position x, colour c, normal n) to the voxel v, and
//     takes the voxel when d is below the voxel's best so far (a voxel can
//     change hands; what a supervoxel took this round grows from the next).
//     After each round a supervoxel's centre becomes the mean position and
//     colour of its voxels and the normalised sum of their normals; one left
//     with no voxel is dropped.
//  5. Output. Supervoxels in seed order with their voxels; the supervoxel's
//     normal is its centre's, turned to the camera. Voxels no supervoxel
//     reached are left out. Two supervoxels touch when a voxel of one has a
//     26-neighbour in the other.
//
// Against pcl::SupervoxelClustering (setting `supervoxels=pcl`), the same
// steps and distance with three differences, each a correction: a supervoxel
// starts from its seed voxel's position, colour and normal (PCL's first
// round measures from a zero centre: the world origin, black, no normal);
// its seed voxel is its own from the start (PCL leaves the seed voxel free
// to be taken); normals face the camera (PCL turns them towards the world
// origin, which is meaningless for a world-frame cloud). docs/perception.md
// measures the two stages against each other.
#pragma once

#include "pcl_stages.h"

#include <memory>

namespace ofv::perception::detail {

/// The supervoxels of `cloud` (world frame) by the algorithm above; normals
/// face `camera` (world frame). Deterministic: the same cloud gives the same
/// output, whatever came before.
class Vccs {
 public:
  Vccs();
  ~Vccs();
  Vccs(Vccs&&) noexcept;
  Vccs& operator=(Vccs&&) noexcept;

  /// Fills `out`; the buffers of the run are kept for the next (their capacity only).
  void run(const WorldCloud& cloud, const SupervoxelSettings& settings, const Eigen::Vector3d& camera,
           SupervoxelOutput& out);

 private:
  struct Scratch;
  std::unique_ptr<Scratch> scratch_;
};

/// One run of a fresh Vccs.
void vccs_supervoxels(const WorldCloud& cloud, const SupervoxelSettings& settings, const Eigen::Vector3d& camera,
                      SupervoxelOutput& out);

}  // namespace ofv::perception::detail
