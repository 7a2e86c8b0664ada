// Later frames: the object is found near the voxels remembered from the
// previous frames; the memory is then updated with what is seen, and keeps
// for a while what is hidden.
#include "front_end.h"

#include <algorithm>
#include <cstddef>
#include <vector>

namespace ofv {

using detail::chroma;

std::vector<char> Perception::Impl::track(const PerceptionResult& r) {
  const std::size_t n = r.supervoxels.size();
  const TrackingSettings& t = settings.tracking;
  grid.build(memory, t.max_motion);
  std::vector<int> near(n, 0);
  voxel_matched.assign(r.voxels.size(), 0);
  const auto radius = static_cast<float>(t.max_motion);
  const auto max_chroma = static_cast<float>(t.max_chroma_distance);
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    const Eigen::Vector3f c = chroma(sv.colours[i]);
    const bool is_near =
        !plane_voxel(r.voxels[i], sv.colours[i]) &&
        grid.any_within(r.voxels[i], radius, [&](int j) {
          return max_chroma <= 0.0f ||
                 (memory_chroma[static_cast<std::size_t>(j)] - c).norm() <= max_chroma;
        });
    near[owner] += is_near ? 1 : 0;
    voxel_matched[i] = is_near ? 1 : 0;
  }
  std::vector<char> object(n, 0);
  for (std::size_t i = 0; i < n; ++i) {
    object[i] =
        static_cast<double>(near[i]) >=
                    t.min_near_fraction * static_cast<double>(r.supervoxels[i].voxel_count) &&
                !on_plane(r.supervoxels[i])
            ? 1
            : 0;
  }
  return object;
}

void Perception::Impl::remember(const RgbdFrame& frame, const PerceptionResult& r,
                                const std::vector<char>& object) {
  // Old object voxels now hidden behind something nearer the camera (or out
  // of the image) stay in the state for a while, so that the object's
  // occluded part is recognised when it reappears.
  std::vector<Eigen::Vector3f> next;
  std::vector<Eigen::Vector3f> next_chroma;
  std::vector<int> next_age;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    const auto owner = static_cast<std::size_t>(r.voxel_owner[i]);
    if (object[owner] && voxel_matched[i]) {
      next.push_back(r.voxels[i]);
      next_chroma.push_back(chroma(sv.colours[i]));
      next_age.push_back(0);
    }
  }
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const double tolerance = settings.tracking.max_motion;
  const int max_age = settings.tracking.occlusion_memory_frames;
  for (std::size_t i = 0; i < memory.size(); ++i) {
    if (memory_age[i] + 1 <= max_age &&
        detail::hidden(frame, cMw, memory[i].cast<double>(), tolerance)) {
      next.push_back(memory[i]);
      next_chroma.push_back(memory_chroma[i]);
      next_age.push_back(memory_age[i] + 1);
    }
  }
  memory.swap(next);
  memory_chroma.swap(next_chroma);
  memory_age.swap(next_age);

  // The same for the object's supervoxels (the estimator's vertices). A
  // remembered vertex goes when it shows again or a seen one takes its place.
  std::vector<Vertex> vertices;
  for (std::size_t i = 0; i < r.supervoxels.size(); ++i) {
    if (object[i] && r.supervoxels[i].normal_valid) {
      vertices.push_back({r.supervoxels[i].centroid, r.supervoxels[i].normal, 0});
    }
  }
  const std::size_t seen = vertices.size();
  const double spacing = 0.5 * settings.supervoxels.seed_resolution;
  for (const Vertex& m : vertex_memory) {
    if (m.age + 1 > max_age || !detail::hidden(frame, cMw, m.centroid, tolerance)) continue;
    const bool replaced =
        std::any_of(vertices.begin(), vertices.begin() + static_cast<std::ptrdiff_t>(seen),
                    [&](const Vertex& v) { return (v.centroid - m.centroid).norm() < spacing; });
    if (!replaced) vertices.push_back({m.centroid, m.normal, m.age + 1});
  }
  vertex_memory.swap(vertices);
}

}  // namespace ofv
