// The perception front end, one frame at a time: cloud -> supervoxels ->
// adjacency -> the object (selected, then tracked) -> remembered ->
// classified into the ViewProblem. The stages live in the files named in
// front_end.h.
#include "front_end.h"
#include "parallel.h"

#include <chrono>
#include <stdexcept>
#include <string>

namespace ofv::perception {

namespace {

double ms_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
      .count();
}

}  // namespace

PerceptionResult Perception::Impl::process(const RgbdFrame& frame) {
  const auto start = std::chrono::steady_clock::now();
  PerceptionResult r;
  r.wMc = frame.wMc;
  if (settings.classes == PerceptionSettings::Classes::Labels && frame.labels.empty()) {
    throw std::invalid_argument("perception with classes from labels needs frames that carry labels (the "
                                "simulator's, ofv's own recordings); this frame has none");
  }

  // 1. Cloud: crop to the sphere around the last centroid (or the user box).
  auto stage = std::chrono::steady_clock::now();
  CropVolume crop;
  crop.max_depth = settings.max_depth;
  const double crop_radius = settings.r_sphere + settings.crop_margin;
  if (initialised) {
    crop.centre = centroid;
    crop.radius = crop_radius;
  } else if (settings.selection.mode == ObjectSelection::Mode::Box) {
    crop.centre = settings.selection.box.center();
    crop.radius = crop_radius + 0.5 * settings.selection.box.diagonal().norm();
  }
  builder.build(frame, crop, cloud);
  r.counts.valid_pixels = cloud.valid_pixels;
  r.counts.cropped_points = cloud.cropped_points;
  r.counts.voxels = cloud.points.size();
  r.timings.cloud = ms_since(stage);

  // 2. Supervoxels, and the R_adj graph between them.
  stage = std::chrono::steady_clock::now();
  if (settings.supervoxels.method == SupervoxelSettings::Method::Pcl) {
    detail::cluster_supervoxels(cloud, settings.supervoxels, frame.wMc.translation(), sv);
  } else {
    vccs.run(cloud, settings.supervoxels, frame.wMc.translation(), sv);
  }
  const bool labelled = settings.classes == PerceptionSettings::Classes::Labels;
  if (labelled) split_by_labels(frame);
  r.supervoxels = sv.supervoxels;
  r.voxels = sv.voxels;
  r.voxel_owner = sv.owner;
  r.counts.supervoxels = r.supervoxels.size();
  r.timings.supervoxels = ms_since(stage);

  stage = std::chrono::steady_clock::now();
  adjacency(r);
  r.timings.adjacency = ms_since(stage);

  // 3. The object: selected in the first frame, tracked afterwards; then remembered.
  stage = std::chrono::steady_clock::now();
  std::string why;
  voxel_revealed.assign(r.voxels.size(), 0);  // only track() finds revealed surface
  voxel_anchor.clear();                         // nor matches a remembered chromaticity
  std::vector<char> object =
      labelled ? labelled_object(frame, r) : initialised ? track(frame, r) : select(frame, r, why);
  // A supervoxel that straddles the object and the plane at its foot, or
  // (once tracked) a hand at its edge, gives up the voxels tracking would
  // not take.
  if (!labelled && split_off_others(frame, object)) {
    r.supervoxels = sv.supervoxels;
    r.voxel_owner = sv.owner;
    object.resize(r.supervoxels.size(), 0);
  }
  set_status(frame, r, object, why);
  if (r.status != TrackingStatus::Lost) {
    remember(frame, r, object);
  }
  r.timings.tracking = ms_since(stage);

  // 4. Classification and the estimator's input.
  stage = std::chrono::steady_clock::now();
  if (r.status != TrackingStatus::Lost) {
    classify(frame, r, object);
    centroid = r.centroid;
  }
  r.timings.classify = ms_since(stage);
  if (settings.tracking.grow_revealed) {  // what this frame could see, for the next one's revealed surface
    previous.depth.assign(frame.depth.begin(), frame.depth.end());
    previous.intrinsics = frame.intrinsics;
    previous.wMc = frame.wMc;
  }
  if (plane) r.support_plane = SupportPlane{*plane, plane_chroma};
  r.timings.total = ms_since(start);
  return r;
}

void Perception::Impl::adjacency(PerceptionResult& r) {
  const double r_adj = settings.supervoxels.adjacency_alpha * settings.supervoxels.seed_resolution;
  centroids.clear();
  for (const SupervoxelInfo& s : r.supervoxels) {
    centroids.push_back(s.centroid.cast<float>());
  }
  grid.build(centroids, r_adj);
  const auto r2 = static_cast<float>(r_adj * r_adj);
  // Pairs (i, j) by i, then as the grid lists j.
  const auto near = [&](std::size_t i, std::vector<std::pair<int, int>>& found) {
    grid.for_each_near(centroids[i], [&](int j) {
      if (static_cast<std::size_t>(j) > i && (centroids[static_cast<std::size_t>(j)] - centroids[i]).squaredNorm() <= r2) {
        found.emplace_back(static_cast<int>(i), j);
      }
    });
  };
  detail::collect_in_parallel(centroids.size(), adjacency_found, near);
  for (const auto& found : adjacency_found) r.adjacency.insert(r.adjacency.end(), found.begin(), found.end());
  r.counts.adjacency_edges = r.adjacency.size();
}

std::size_t Perception::Impl::remembered_in_view(const RgbdFrame& frame) const {
  const Eigen::Isometry3d cMw = frame.wMc.inverse();
  const Eigen::Vector3f camera = frame.wMc.translation().cast<float>();
  std::size_t n = 0;
  for (std::size_t i = 0; i < memory.size(); ++i) {
    const bool facing = memory_normal[i].isZero() || memory_normal[i].dot(camera - memory[i]) > 0.0f;
    if (!facing) continue;
    const auto l = detail::look(frame, cMw, memory[i].cast<double>());
    n += l && l->measured() ? 1u : 0u;
  }
  return n;
}

void Perception::Impl::set_status(const RgbdFrame& frame, PerceptionResult& r, const std::vector<char>& object,
                                  std::string why) {
  std::size_t object_voxels = 0;
  for (std::size_t i = 0; i < r.voxels.size(); ++i) {
    object_voxels += object[static_cast<std::size_t>(r.voxel_owner[i])] ? 1u : 0u;
  }
  bool lost = object_voxels == 0;
  if (lost && why.empty()) {
    why = "no supervoxel near the object's last state";
  }
  const auto too_few = [&](std::size_t of) {
    return static_cast<double>(object_voxels) < settings.tracking.min_kept_fraction * static_cast<double>(of);
  };
  if (!lost && initialised && too_few(initial_voxels)) {
    // As many as this view can show: the first frame's, unless the
    // remembered object (seen or hidden) has fewer facing the camera where
    // the sensor measures depth (a face seen edge-on gives none). Counted
    // only when the first frame's alone would call the object lost.
    const std::size_t can_show = std::min(initial_voxels, remembered_in_view(frame));
    if (too_few(can_show)) {
      lost = true;
      why = std::to_string(object_voxels) + " object voxels found, fewer than " +
            std::to_string(settings.tracking.min_kept_fraction) + " x the " + std::to_string(can_show) +
            " this view can show (the first frame's " + std::to_string(initial_voxels) +
            ", or the remembered ones facing the camera on pixels with depth)";
    }
  }
  if (lost) {
    r.status = TrackingStatus::Lost;
    r.message = why;
    return;
  }
  r.status = initialised ? TrackingStatus::Tracking : TrackingStatus::Initialised;
  if (!initialised) {
    initial_voxels = object_voxels;
    initialised = true;
  }
}

Perception::Perception(const PerceptionSettings& settings) {
  validate(settings);
  impl_ = std::make_unique<Impl>(settings);
}
Perception::~Perception() = default;
Perception::Perception(Perception&&) noexcept = default;
Perception& Perception::operator=(Perception&&) noexcept = default;

PerceptionResult Perception::process(const RgbdFrame& frame) { return impl_->process(frame); }

void Perception::reset() {
  impl_->initialised = false;
  impl_->memory.clear();
  impl_->holder.clear();
  impl_->holder_age = 0;
  impl_->foreign_voxels.clear();
  impl_->memory_chroma.clear();
  impl_->memory_age.clear();
  impl_->memory_normal.clear();
  impl_->previous_outline.clear();
  impl_->previous_outline_normals.clear();
  impl_->initial_voxels = 0;
  impl_->plane.reset();
  impl_->incomplete = false;
}

const PerceptionSettings& Perception::settings() const { return impl_->settings; }

}  // namespace ofv::perception
