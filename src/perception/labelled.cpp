// Supervoxels cut into pieces. PerceptionSettings::Classes::Labels: the
// frame's ground-truth labels in place of segmentation (supervoxels cut
// where the labels change) and of tracking (the object is what is labelled
// object); classify() takes the bodies' classes from supervoxel_labels.
// Tracking: the support plane's voxels cut from the object's supervoxels.
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
  std::vector<int> whole;
  supervoxel_labels.clear();
  for (auto& [key, index] : piece_of) {
    index = static_cast<int>(whole.size());
    whole.push_back(key.first);
    supervoxel_labels.push_back(key.second);
  }
  std::vector<int> owner(sv.voxels.size());
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) owner[i] = piece_of.at({sv.owner[i], label[i]});
  cut_supervoxels(frame, std::move(owner), whole);
  sv.touching.clear();  // only the default selection (Classes::Segmentation) reads it
}

bool Perception::Impl::split_at_plane(const RgbdFrame& frame, const std::vector<char>& object) {
  if (!plane) return false;
  // The voxels of the support plane (on it, of its colour) of an object
  // supervoxel that has others too: a piece after the supervoxels.
  std::vector<int> plane_voxels(sv.supervoxels.size(), 0);
  std::vector<char> on(sv.voxels.size(), 0);
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) {
    on[i] = plane_voxel(sv.voxels[i], sv.colours[i]) ? 1 : 0;
    plane_voxels[static_cast<std::size_t>(sv.owner[i])] += on[i];
  }
  std::vector<int> whole(sv.supervoxels.size());
  for (std::size_t k = 0; k < whole.size(); ++k) whole[k] = static_cast<int>(k);
  std::vector<int> piece(sv.supervoxels.size(), -1);
  for (std::size_t k = 0; k < piece.size(); ++k) {
    if (object[k] && plane_voxels[k] > 0 && plane_voxels[k] < sv.supervoxels[k].voxel_count) {
      piece[k] = static_cast<int>(whole.size());
      whole.push_back(static_cast<int>(k));
    }
  }
  if (whole.size() == sv.supervoxels.size()) return false;
  std::vector<int> owner = sv.owner;
  for (std::size_t i = 0; i < owner.size(); ++i) {
    const int p = piece[static_cast<std::size_t>(owner[i])];
    if (on[i] && p >= 0) owner[i] = p;
  }
  cut_supervoxels(frame, std::move(owner), whole);
  return true;
}

void Perception::Impl::cut_supervoxels(const RgbdFrame& frame, std::vector<int> owner, const std::vector<int>& whole) {
  std::vector<SupervoxelInfo> split(whole.size());
  std::vector<Eigen::Vector3d> sum(whole.size(), Eigen::Vector3d::Zero());
  std::vector<Eigen::Matrix3d> scatter(whole.size(), Eigen::Matrix3d::Zero());
  std::vector<Eigen::Vector3f> colour(whole.size(), Eigen::Vector3f::Zero());
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) {
    const auto k = static_cast<std::size_t>(owner[i]);
    const Eigen::Vector3d p = sv.voxels[i].cast<double>();
    sum[k] += p;
    scatter[k] += p * p.transpose();
    colour[k] += sv.colours[i];
    ++split[k].voxel_count;
  }
  const Eigen::Vector3d camera = frame.wMc.translation();
  for (std::size_t k = 0; k < whole.size(); ++k) {
    const SupervoxelInfo& was = sv.supervoxels[static_cast<std::size_t>(whole[k])];
    SupervoxelInfo& s = split[k];
    const double n = s.voxel_count;
    s.centroid = sum[k] / n;
    s.colour = colour[k] / static_cast<float>(n);
    s.normal = was.normal;
    s.normal_valid = was.normal_valid;
    if (s.voxel_count < was.voxel_count && s.voxel_count >= 3) {
      // A piece's own surface normal: the least principal direction of its voxels.
      const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(scatter[k] / n - s.centroid * s.centroid.transpose());
      Eigen::Vector3d normal = eig.eigenvectors().col(0);
      if (eig.eigenvalues()(1) > 4.0 * eig.eigenvalues()(0) && normal.allFinite()) {
        if (normal.dot(camera - s.centroid) < 0.0) normal = -normal;
        s.normal = normal;
        s.normal_valid = true;
      }
    }
  }
  sv.supervoxels = std::move(split);
  sv.owner = std::move(owner);
}

std::vector<char> Perception::Impl::labelled_object(const RgbdFrame& frame, const PerceptionResult& r) {
  if (!initialised) fit_support_plane(frame, r);
  std::vector<char> object(r.supervoxels.size(), 0);
  for (std::size_t i = 0; i < object.size(); ++i) object[i] = supervoxel_labels[i] == kPixelObject ? 1 : 0;
  voxel_matched.assign(r.voxels.size(), 1);
  return object;
}

}  // namespace ofv::perception
