// PerceptionSettings::Classes::Labels: the frame's ground-truth labels in
// place of segmentation (supervoxels cut where the labels change) and of
// tracking (the object is what is labelled object). classify() takes the
// bodies' classes from supervoxel_labels.
#include "front_end.h"

#include "ofv/perception/scores.h"

#include <Eigen/Eigenvalues>

#include <map>
#include <utility>

namespace ofv::perception {

void Perception::Impl::split_by_labels(const RgbdFrame& frame) {
  const VoxelLabels cells(frame, settings.supervoxels.voxel_resolution, settings.cloud.pixel_stride, settings.max_depth);
  // One piece per (supervoxel, label), in the order of the supervoxels.
  std::map<std::pair<int, std::uint16_t>, int> piece_of;
  std::vector<std::uint16_t> label(sv.voxels.size());
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) {
    label[i] = cells.label_at(sv.voxels[i]);
    piece_of.try_emplace({sv.owner[i], label[i]}, 0);
  }
  std::vector<std::pair<int, std::uint16_t>> pieces;
  for (auto& [key, index] : piece_of) {
    index = static_cast<int>(pieces.size());
    pieces.push_back(key);
  }
  std::vector<int> owner(sv.voxels.size());
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) owner[i] = piece_of.at({sv.owner[i], label[i]});

  std::vector<SupervoxelInfo> split(pieces.size());
  std::vector<Eigen::Vector3d> sum(pieces.size(), Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> scatter(pieces.size(), Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3f> colour(pieces.size(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) {
    const auto k = static_cast<std::size_t>(owner[i]);
    const Eigen::Vector3d p = sv.voxels[i].cast<double>();
    sum[k] += p;
    scatter[k] += p * p.transpose();
    colour[k] += sv.colours[i];
    ++split[k].voxel_count;
  }
  const Eigen::Vector3d camera = frame.wMc.translation();
  supervoxel_labels.resize(pieces.size());
  for (std::size_t k = 0; k < pieces.size(); ++k) {
    const SupervoxelInfo& whole = sv.supervoxels[static_cast<std::size_t>(pieces[k].first)];
    SupervoxelInfo& s = split[k];
    const double n = s.voxel_count;
    s.centroid = sum[k] / n;
    s.colour = colour[k] / static_cast<float>(n);
    s.normal = whole.normal;
    s.normal_valid = whole.normal_valid;
    if (s.voxel_count < whole.voxel_count && s.voxel_count >= 3) {
      // A piece's own surface normal: the least principal direction of its voxels.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter[k] / n - s.centroid * s.centroid.transpose());
      Eigen::Vector3d normal = eig.eigenvectors().col(0);
      if (eig.eigenvalues()(1) > 4.0 * eig.eigenvalues()(0) && normal.allFinite()) {
        if (normal.dot(camera - s.centroid) < 0.0) normal = -normal;
        s.normal = normal;
        s.normal_valid = true;
      }
    }
    supervoxel_labels[k] = pieces[k].second;
  }
  sv.supervoxels = std::move(split);
  sv.owner = std::move(owner);
  sv.touching.clear();  // only the default selection (Classes::Segmentation) reads it
}

std::vector<char> Perception::Impl::labelled_object(const RgbdFrame& frame, const PerceptionResult& r) {
  if (!initialised) fit_support_plane(frame, r);
  std::vector<char> object(r.supervoxels.size(), 0);
  for (std::size_t i = 0; i < object.size(); ++i) object[i] = supervoxel_labels[i] == kPixelObject ? 1 : 0;
  voxel_matched.assign(r.voxels.size(), 1);
  return object;
}

}  // namespace ofv::perception
