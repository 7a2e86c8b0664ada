// Supervoxels cut into pieces. PerceptionSettings::Classes::Labels: the
// frame's ground-truth labels in place of segmentation (supervoxels cut
// where the labels change) and of tracking (the object is what is labelled
// object); classify() takes the bodies' classes from supervoxel_labels.
// Tracking: what is not the object's cut from its supervoxels.
#include "front_end.h"

#include "ofv/perception/scores.h"

#include <Eigen/Eigenvalues>

#include <array>
#include <cstdint>
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

// A voxel of an object supervoxel is unlike the object when its
// chromaticity is farther than this many max_chroma_distance from what its
// matched voxels remember: a hand's is; one that mixes the object's colour
// with the table's or a hand's at its edge (half way) stays. With 1, edge
// voxels went too: a stretching box's recall by supervoxel 0.92 -> 0.87.
constexpr double kUnlike = 2.0;

bool Perception::Impl::split_off_others(const RgbdFrame& frame, const std::vector<char>& object) {
  // Of an object supervoxel, the voxels of the support plane (on it, of its
  // colour; kind 1) and those that neither match the remembered object nor
  // were revealed and are unlike the colour its matched voxels remember
  // (kind 2, kUnlike: a hand's, where VCCS merged it with the case's edge):
  // a piece of each kind after the supervoxels, where some of it is left.
  // (track() set voxel_matched, voxel_anchor and voxel_revealed for every
  // voxel; after select(), which sets no anchor, only the plane's go.)
  const std::size_t n = sv.supervoxels.size();
  std::vector<Eigen::Vector3f> anchor(n, Eigen::Vector3f::Zero());
  std::vector<int> anchored(n, 0);
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) {
    const auto k = static_cast<std::size_t>(sv.owner[i]);
    if (object[k] && voxel_matched[i] && !voxel_anchor.empty()) {
      anchor[k] += voxel_anchor[i];
      ++anchored[k];
    }
  }
  std::vector<std::uint8_t> kind(sv.voxels.size(), 0);
  std::vector<std::array<int, 3>> count(n, {0, 0, 0});
  for (std::size_t i = 0; i < sv.voxels.size(); ++i) {
    const auto k = static_cast<std::size_t>(sv.owner[i]);
    if (!object[k]) continue;
    if (plane_voxel(sv.voxels[i], sv.colours[i])) {
      kind[i] = 1;
    } else if (anchored[k] > 0 && !voxel_matched[i] && !voxel_revealed[i] &&
               (chromaticity(sv.colours[i]) - anchor[k] / static_cast<float>(anchored[k])).norm() >
                   static_cast<float>(kUnlike * settings.tracking.max_chroma_distance)) {
      kind[i] = 2;
    }
    ++count[k][kind[i]];
  }
  std::vector<int> whole(n);
  for (std::size_t k = 0; k < n; ++k) whole[k] = static_cast<int>(k);
  std::vector<std::array<int, 3>> piece(n, {-1, -1, -1});
  for (std::size_t k = 0; k < n; ++k) {
    for (int c = 1; c <= 2; ++c) {
      if (count[k][0] > 0 && count[k][static_cast<std::size_t>(c)] > 0) {
        piece[k][static_cast<std::size_t>(c)] = static_cast<int>(whole.size());
        whole.push_back(static_cast<int>(k));
      }
    }
  }
  if (whole.size() == n) return false;
  std::vector<int> owner = sv.owner;
  for (std::size_t i = 0; i < owner.size(); ++i) {
    const int p = kind[i] == 0 ? -1 : piece[static_cast<std::size_t>(owner[i])][kind[i]];
    if (p >= 0) owner[i] = p;
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
