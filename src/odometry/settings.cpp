// The odometry's settings table and validation (ofv/odometry/odometry.h).
#include "ofv/odometry/odometry.h"

#include <stdexcept>
#include <string>

namespace ofv::odometry {

namespace {

using S = OdometrySettings;

/// A row for a number in (lo, hi] (or [lo, hi]) of the member `field`; its type documents the range.
void number_row(SettingsTable<S>& t, const char* name, double S::*field, const char* unit, const char* doc,
                double lo, double hi, bool lo_open) {
  const S d;
  const std::string type =
      std::string("number in ") + (lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) + "]";
  t.add({name, type, format_number(d.*field), unit, doc},
        [=](S& s, const std::string& v) { s.*field = parse_number(name, v, lo, hi, lo_open); },
        [=](const S& s) { return format_number(s.*field); });
}

/// A row for a whole number in [lo, hi] of the member `field`; its type documents the range.
void integer_row(SettingsTable<S>& t, const char* name, int S::*field, const char* unit, const char* doc, long lo,
                 long hi) {
  const S d;
  const std::string type = "integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  t.add({name, type, std::to_string(d.*field), unit, doc},
        [=](S& s, const std::string& v) { s.*field = static_cast<int>(parse_integer(name, v, lo, hi)); },
        [=](const S& s) { return std::to_string(s.*field); });
}

void bool_row(SettingsTable<S>& t, const char* name, bool S::*field, const char* doc) {
  const S d;
  t.add({name, "bool", format_bool(d.*field), "", doc},
        [=](S& s, const std::string& v) { s.*field = parse_bool(name, v); },
        [=](const S& s) { return format_bool(s.*field); });
}

}  // namespace

const SettingsTable<OdometrySettings>& odometry_settings_table() {
  static const SettingsTable<S> table = [] {
    const S d;
    SettingsTable<S> t;
    t.add({"odometry", "icp | rgbd_icp | fast_icp | rgbd", to_string(d.method), "",
           "OpenCV's RGB-D odometry: point-to-plane ICP, ICP with photometric terms, KinectFusion's ICP, "
           "photometric only (needs texture)"},
          [](S& s, const std::string& v) { s.method = parse_method("odometry", v); },
          [](const S& s) { return std::string(to_string(s.method)); });
    bool_row(t, "keyframe", &S::keyframe,
             "match each frame against the last keyframe (false: against the previous frame, which drifts more)");
    bool_row(t, "constant_velocity", &S::constant_velocity,
             "start each match from the last pose moved again by the last step's motion (after steps without a "
             "pose, its share of the motion over them; false: from the last pose)");
    number_row(t, "keyframe_translation", &S::keyframe_translation, "m",
               "a frame becomes the keyframe when the camera moved more than this from the last one", 0.0, 1.0, false);
    number_row(t, "keyframe_rotation", &S::keyframe_rotation, "deg",
               "... or turned more than this from it", 0.0, 90.0, false);
    number_row(t, "max_translation", &S::max_translation, "m",
               "a step moving the camera more than this from the last pose is implausible (the pose stays)", 0.0,
               10.0, true);
    number_row(t, "max_rotation", &S::max_rotation, "deg",
               "a step turning the camera more than this from the last pose is implausible (the pose stays)", 0.0,
               180.0, true);
    number_row(t, "min_valid_fraction", &S::min_valid_fraction, "",
               "a frame with fewer of its pixels usable (depth in range, not masked) fails", 0.0, 1.0, false);
    number_row(t, "min_overlap_fraction", &S::min_overlap_fraction, "",
               "a step after which fewer of the image's pixels are used and fall on pixels the reference used is "
               "implausible (too little to judge the match by)",
               0.0, 1.0, false);
    number_row(t, "min_inlier_fraction", &S::min_inlier_fraction, "",
               "a step after which fewer of the used pixels that fall on pixels the reference used are within "
               "max_depth_diff of them is implausible",
               0.0, 1.0, false);
    bool_row(t, "occlusion_aware", &S::occlusion_aware,
             "min_overlap_fraction and min_inlier_fraction leave out the pixels that fall behind what the reference "
             "saw there by more than max_depth_diff (hidden from it; false: count them as mismatches)");
    number_row(t, "max_residual_ratio", &S::max_residual_ratio, "",
               "a step after which the pixels that match the reference differ from it (RMS) by more than this "
               "times the median of the last 9 ok steps' is implausible: one surface taken for another (0: never)",
               0.0, 1000.0, false);
    number_row(t, "restart_distance", &S::restart_distance, "m",
               "after a step whose pose was not known, a match that passes is made again from starts this far from "
               "it along each of the camera's axes, and around the best while one fits better (a lower residual "
               "with the overlap and inliers needed; as far as max_translation, 10 rounds at most); the best is "
               "judged instead (0: not made again)",
               0.0, 1.0, false);
    number_row(t, "max_depth_diff", &S::max_depth_diff, "m",
               "pixels of the two frames match when their depths differ by at most this (OpenCV's maxDepthDiff)", 0.0,
               1.0, true);
    number_row(t, "min_depth", &S::min_depth, "m", "pixels nearer than this are not used", 0.0, 100.0, false);
    number_row(t, "max_depth", &S::max_depth, "m", "pixels farther than this are not used", 0.0, 100.0, true);
    integer_row(t, "iterations", &S::iterations, "",
                "iterations at the 2nd and 3rd pyramid levels (at the finest too but for icp and rgbd_icp: "
                "finest_iterations), 1.5x at the 4th, the coarsest (OpenCV's default 7)",
                1, 1000);
    integer_row(t, "finest_iterations", &S::finest_iterations, "",
                "iterations of icp and rgbd_icp at the finest pyramid level, the frame as matched: the costliest, a "
                "pass over every pixel each (OpenCV's default 7; more fit the noise: docs/perception.md)",
                1, 1000);
    number_row(t, "max_points_part", &S::max_points_part, "",
               "share of the pixels the ICP and RGB-D methods sample (OpenCV's maxPointsPart)", 0.0, 1.0, true);
    integer_row(t, "max_width", &S::max_width, "px",
                "frames wider than this are matched at the whole fraction of their size that brings them within it, "
                "every 2nd (3rd, ...) pixel of every 2nd row (0: at their own size)",
                0, 100000);
    bool_row(t, "mask", &S::mask,
             "leave out pixels nearer than the object's depth in the previous frame minus mask_margin, but not "
             "those on the plane it stands on (hands, occluders)");
    number_row(t, "mask_margin", &S::mask_margin, "m",
               "see mask: how much nearer than the object a pixel must be to be left out", 0.0, 10.0, false);
    number_row(t, "mask_plane_distance", &S::mask_plane_distance, "m",
               "see mask: pixels within this of the object's support plane stay in (the table is still) ...", 0.0,
               1.0, false);
    number_row(t, "mask_plane_chroma", &S::mask_plane_chroma, "",
               "... when their chromaticity (R, G, B over their sum) is within this of the plane's (in colour "
               "frames: an arm on the table is on its plane too)",
               0.0, 2.0, false);
    number_row(t, "min_still_constraint", &S::min_still_constraint, "",
               "a step is degenerate (the pose stays) when the scene apart from the object, or the part that "
               "matches the reference, fixes the camera's translation less than this: the smallest eigenvalue of "
               "the mean n n^T of its flat patches' normals (a plane alone: 0; 0: never degenerate)",
               0.0, 1.0, false);
    number_row(t, "object_radius", &S::object_radius, "m",
               "pixels within this of the object's supervoxel centroids in the previous frame are the object's, not "
               "still scene (min_still_constraint)",
               0.0, 1.0, false);
    return t;
  }();
  return table;
}

void validate(const OdometrySettings& s) {
  // Every value goes back through its row's parser: one place for the bounds.
  for (const auto& [name, value] : odometry_settings_table().values(s)) {
    S scratch;
    odometry_settings_table().set(scratch, name, value);
  }
  if (!(s.min_depth < s.max_depth)) {
    throw std::invalid_argument("setting 'min_depth' must be below max_depth (" + format_number(s.max_depth) +
                                "), got " + format_number(s.min_depth));
  }
}

}  // namespace ofv::odometry
