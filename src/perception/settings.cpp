// The front end's settings checked, and its closed sets of words.
#include "ofv/perception/perception.h"

#include <algorithm>
#include <cmath>
#include <utility>
#include <stdexcept>
#include <string>

namespace ofv::perception {

Observation observation(const PerceptionResult& result, double voxel) {
  Observation o;
  o.wMc = result.wMc;
  o.support_plane = result.support_plane;
  if (result.status == TrackingStatus::Lost) return o;
  // The occluders beyond the image border come last (classify, then beyond_view).
  const Eigen::Index all = result.problem.occluders.cols();
  const Eigen::Index presumed = std::min<Eigen::Index>(static_cast<Eigen::Index>(result.counts.beyond_view), all);
  o.problem = result.problem;
  o.problem->occluders = result.problem.occluders.leftCols(all - presumed);
  o.presumed = result.problem.occluders.rightCols(presumed);
  o.shown_area = static_cast<double>(result.counts.object_voxels) * voxel * voxel;
  return o;
}

PerceptionObserver::PerceptionObserver(const PerceptionSettings& settings) : perception_(settings) {}

Observation PerceptionObserver::observe(const RgbdFrame& frame) {
  last_ = perception_.process(frame);
  return observation(last_, perception_.settings().supervoxels.voxel_resolution);
}

const SettingsTable<PerceptionSettings>& perception_settings_table() {
  using P = PerceptionSettings;
  static const SettingsTable<P> table = [] {
    const P d;
    SettingsTable<P> t;
    t.add({"supervoxels", "ofv | pcl", to_string(d.supervoxels.method), "",
           "the front end (perception full or labels): VCCS supervoxels by ofv's own stage on the voxel grid "
           "(2-3x faster) or by pcl::SupervoxelClustering (the reference); docs/perception.md compares them"},
          [](P& p, const std::string& v) {
            p.supervoxels.method = parse_word<SupervoxelSettings::Method>(
                "supervoxels", v, {{"ofv", SupervoxelSettings::Method::Ofv}, {"pcl", SupervoxelSettings::Method::Pcl}});
          },
          [](const P& p) { return std::string(to_string(p.supervoxels.method)); });
    t.add({"beyond_view", "bool", format_bool(d.beyond_view), "",
           "the front end (perception full or labels): an occluder the image border cuts goes on beyond it, to the "
           "sphere (false: only what the frame shows)"},
          [](P& p, const std::string& v) { p.beyond_view = parse_bool("beyond_view", v); },
          [](const P& p) { return format_bool(p.beyond_view); });
    t.add({"behind_occluders", "bool", format_bool(d.behind_occluders), "",
           "the front end (perception full or labels): when an occluder cuts the object in the first frame, the object "
           "goes on behind it (false: only what has been seen)"},
          [](P& p, const std::string& v) { p.behind_occluders = parse_bool("behind_occluders", v); },
          [](const P& p) { return format_bool(p.behind_occluders); });
    t.add({"grow_revealed", "bool", format_bool(d.tracking.grow_revealed), "",
           "the front end (perception full): surface that comes into view from behind the object (its own fold), "
           "from beyond the previous image or from edge-on joins the object, however far from what was seen "
           "(false: only what lies within max_motion of the remembered object)"},
          [](P& p, const std::string& v) { p.tracking.grow_revealed = parse_bool("grow_revealed", v); },
          [](const P& p) { return format_bool(p.tracking.grow_revealed); });
    t.add({"holder_body", "bool", format_bool(d.holder_body), "",
           "the front end (perception full): the body of what holds the object when it is selected, or of what "
           "touches it later and then carries it 2 cm, beyond the augmented OBB (in contact with it and of its "
           "colour, in turn), is interacting too, and what touches it after coming as an occluder stays one until "
           "then (false: the paper's classes, an occluder outside the box)"},
          [](P& p, const std::string& v) { p.holder_body = parse_bool("holder_body", v); },
          [](const P& p) { return format_bool(p.holder_body); });
    return t;
  }();
  return table;
}

const char* to_string(SupervoxelSettings::Method method) {
  return method == SupervoxelSettings::Method::Pcl ? "pcl" : "ofv";
}

const char* to_string(TrackingStatus status) {
  switch (status) {
    case TrackingStatus::Initialised:
      return "initialised";
    case TrackingStatus::Tracking:
      return "tracking";
    case TrackingStatus::Lost:
      return "lost";
  }
  return "?";
}

const char* to_string(PerceptionSettings::Classes classes) {
  return classes == PerceptionSettings::Classes::Labels ? "labels" : "segmentation";
}

const char* to_string(SupervoxelClass label) {
  switch (label) {
    case SupervoxelClass::Object:
      return "object";
    case SupervoxelClass::Interacting:
      return "interacting";
    case SupervoxelClass::Occluder:
      return "occluder";
    case SupervoxelClass::Background:
      return "background";
  }
  return "?";
}

namespace {

void require(bool ok, const char* name, double value, const char* expected) {
  if (!ok) {
    throw std::invalid_argument(std::string("perception setting ") + name + " = " +
                                std::to_string(value) + ": expected " + expected);
  }
}

bool positive(double x) { return std::isfinite(x) && x > 0.0; }

}  // namespace

PerceptionSettings perception_settings(const EstimatorSettings& estimator, PerceptionSettings base) {
  PerceptionSettings ps = std::move(base);
  ps.r_sphere = estimator.r_sphere;
  ps.supervoxels.seed_resolution = estimator.r_seed;
  return ps;
}

void validate(const PerceptionSettings& s) {
  const SupervoxelSettings& sv = s.supervoxels;
  // Cells of points within 2 kMaxLength of the origin fit the grids' 32-bit indices.
  require(std::isfinite(sv.voxel_resolution) && sv.voxel_resolution >= 1e-4, "voxel_resolution", sv.voxel_resolution,
          ">= 1e-4 [m]");
  require(positive(sv.seed_resolution) && sv.seed_resolution >= sv.voxel_resolution,
          "seed_resolution", sv.seed_resolution, ">= voxel_resolution [m]");
  require(std::isfinite(sv.colour_importance) && sv.colour_importance >= 0.0, "colour_importance",
          sv.colour_importance, ">= 0");
  require(std::isfinite(sv.spatial_importance) && sv.spatial_importance >= 0.0,
          "spatial_importance", sv.spatial_importance, ">= 0");
  require(std::isfinite(sv.normal_importance) && sv.normal_importance >= 0.0, "normal_importance",
          sv.normal_importance, ">= 0");
  require(sv.adjacency_alpha >= 1.0 && sv.adjacency_alpha <= 1.5, "adjacency_alpha",
          sv.adjacency_alpha, "in [1, 1.5] (paper eq. 1)");
  const TrackingSettings& t = s.tracking;
  require(positive(t.max_motion), "max_motion", t.max_motion, "> 0 [m]");
  require(t.min_near_fraction > 0.0 && t.min_near_fraction <= 1.0, "min_near_fraction",
          t.min_near_fraction, "in (0, 1]");
  require(t.min_kept_fraction >= 0.0 && t.min_kept_fraction <= 1.0, "min_kept_fraction",
          t.min_kept_fraction, "in [0, 1]");
  require(std::isfinite(t.max_chroma_distance), "max_chroma_distance", t.max_chroma_distance,
          "a finite number (<= 0: off)");
  require(positive(t.plane_distance), "plane_distance", t.plane_distance, "> 0 [m]");
  require(t.min_cluster_supervoxels >= 1, "min_cluster_supervoxels", t.min_cluster_supervoxels,
          ">= 1");
  require(t.occlusion_memory_frames >= 0, "occlusion_memory_frames", t.occlusion_memory_frames,
          ">= 0");
  require(s.cloud.pixel_stride >= 1, "pixel_stride", s.cloud.pixel_stride, ">= 1");
  require(positive(s.r_sphere), "r_sphere", s.r_sphere, "> 0 [m]");
  require(std::isfinite(s.crop_margin) && s.crop_margin >= 0.0, "crop_margin", s.crop_margin,
          ">= 0 [m]");
  static_assert(kMaxLength == 1e4, "max_depth's message says 1e4");
  require(positive(s.max_depth) && s.max_depth <= kMaxLength, "max_depth", s.max_depth, "in (0, 1e4] [m]");
  require(std::isfinite(s.obb_margin) && s.obb_margin >= 0.0, "obb_margin", s.obb_margin,
          ">= 0 [m]");
  require(positive(s.contact_distance), "contact_distance", s.contact_distance, "> 0 [m]");
  if (s.selection.mode == ObjectSelection::Mode::Box && s.selection.box.isEmpty()) {
    throw std::invalid_argument("perception selection: mode box needs a non-empty box");
  }
  if (s.selection.mode == ObjectSelection::Mode::Image && s.selection.mask.empty() &&
      s.selection.rect.isEmpty()) {
    throw std::invalid_argument("perception selection: mode image needs a rectangle or a mask");
  }
}

}  // namespace ofv::perception
