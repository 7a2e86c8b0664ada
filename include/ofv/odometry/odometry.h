/**
 * \file odometry.h
 * \brief Camera poses without a robot: RGB-D odometry on OpenCV's rgbd
 *        module (opencv_contrib), frame to keyframe or frame to frame.
 *
 * Each step matches the new frame (the source) against a reference frame
 * (the last keyframe, or the previous frame) and gives the motion
 * `kMc` (camera -> reference camera, OpenCV's `Rt`: p_k = Rt p_c); the
 * world pose is `wMc = wMk * kMc`, starting at the first frame's own `wMc`.
 * A frame with too few usable pixels (Failed), or a step OpenCV reports
 * failed or whose motion is not finite, too large
 * (OdometrySettings::max_translation, max_rotation) or matched by too few
 * pixels (Implausible), is a status: the pose stays the last good one. So
 * is a step where what is still apart from the object does not fix the
 * camera's translation (Degenerate): there the motion found may be the
 * object's, and the pose is not the world's.
 *
 * \code
 * ofv::odometry::Odometry odometry;  // ICPOdometry against a keyframe (or: odometry_pose_source())
 * while (auto frame = source->next()) {
 *   const ofv::odometry::OdometryResult r = odometry.step(*frame);  // or step(*frame, object_hint(...))
 *   if (r.status == ofv::odometry::OdometryStatus::Ok) frame->wMc = r.wMc;
 * }
 * \endcode
 */
#pragma once

#include "ofv/pose_source.h"
#include "ofv/rgbd_frame.h"
#include "ofv/settings_table.h"

#include <Eigen/Geometry>

#include <limits>
#include <memory>
#include <string>

namespace ofv::odometry {

/// \brief Which of OpenCV's rgbd odometries runs.
enum class OdometryMethod {
  Icp,      ///< cv::rgbd::ICPOdometry: point-to-plane ICP on depth (`icp`)
  RgbdIcp,  ///< cv::rgbd::RgbdICPOdometry: ICP and photometric terms (`rgbd_icp`)
  FastIcp,  ///< cv::rgbd::FastICPOdometry: KinectFusion's projective ICP (`fast_icp`)
  Rgbd,     ///< cv::rgbd::RgbdOdometry: photometric, needs texture (`rgbd`)
};

/// \brief What one step of the odometry found.
enum class OdometryStatus {
  Ok,           ///< the motion was estimated and is plausible; the pose moved
  FirstFrame,   ///< the first frame: the pose is the frame's own wMc
  /// The frame alone gives nothing to match: too few usable pixels
  /// (OdometrySettings::min_valid_fraction; a blank depth image), or OpenCV
  /// threw on it. The pose is the last good one.
  Failed,
  /// The frame does not fit the reference: OpenCV found no motion (with
  /// pixels enough), or one that is not finite, larger than max_translation
  /// or max_rotation, after which too few pixels fall on the reference's
  /// (OdometryDiagnostics::overlap_fraction below min_overlap_fraction), too
  /// few of those match (min_inlier_fraction) or those that do differ by far
  /// more than before (max_residual_ratio). The pose is the last good one.
  Implausible,
  /// The scene apart from the object (the used pixels farther than
  /// OdometrySettings::object_radius from the object's supervoxels in the
  /// previous frame) leaves a direction of the camera's translation free
  /// (OdometryDiagnostics::still_constraint below min_still_constraint): a
  /// bare table beside the object fixes only the depth. A motion found
  /// would then be the object's as much as the camera's (the object is what
  /// holds the match), so none is sought: the pose stays the last good one,
  /// as for Implausible. Checked with an object given, before the match;
  /// and, object or not, on the pixels that match the reference after it
  /// (OdometryDiagnostics::match_constraint): a match that stands on a plane.
  Degenerate,
};

/**
 * \brief The odometry's settings, defaults from the measurements in
 *        docs/perception.md ("Camera poses from RGB-D odometry"). The
 *        table odometry_settings_table() documents and parses them.
 */
struct OdometrySettings {
  OdometryMethod method = OdometryMethod::Icp;  ///< which OpenCV odometry
  bool keyframe = true;  ///< match against the last keyframe (false: against the previous frame)
  /// Start each match from the last pose moved again by the last step's
  /// motion (false: from the last pose). A camera that starts to turn
  /// fast is then met where it goes: on dvd-one-hand's and dvd-two-hands'
  /// seed 2 (turning 2-3 degrees a frame as they dodge) ATE 5.3 -> 2.1 mm and
  /// 2.9 -> 0.5 mm, the other seeds unchanged (docs/perception.md). After
  /// steps without a pose, the motion found over them is shared among their
  /// frames.
  bool constant_velocity = true;
  double keyframe_translation = 0.03;  ///< a new keyframe when the camera moved more than this from it [m]
  double keyframe_rotation = 3.0;      ///< ... or turned more than this from it [deg]
  double max_translation = 0.05;       ///< a step's motion beyond this is implausible [m per frame]
  double max_rotation = 5.0;           ///< a step's rotation beyond this is implausible [deg per frame]
  double min_valid_fraction = 0.05;    ///< fewer of the image's pixels with usable depth (after the mask): failed
  /// Fewer of the image's pixels used and falling, after the motion, on
  /// pixels the reference used (OdometryDiagnostics::overlap_fraction):
  /// implausible, too little to judge the match by.
  double min_overlap_fraction = 0.02;
  double min_inlier_fraction = 0.6;    ///< fewer of the used pixels that fall on the reference's matching it after the motion: implausible
  /// Leave out of the overlap the pixels that fall behind what the reference
  /// saw there (hidden from it), counting as mismatches only those in front.
  bool occlusion_aware = true;
  /// A step whose matching pixels differ from the reference (RMS,
  /// OdometryDiagnostics::residual) by more than this times the median of
  /// the last 9 Ok steps' is implausible (0: never; with 3 Ok steps or more).
  /// A right motion leaves the sensor's noise, growing with the distance
  /// from the keyframe and the speed: 0.3-2 mm on the simulator's scenes,
  /// 0.8-6.8 mm on ViSP's castel (a real SR300), at most 5.1x the median of
  /// the steps before; a match that took one surface for another within
  /// max_depth_diff, after the camera moved on while the pose was not known,
  /// 15-50x (docs/perception.md).
  double max_residual_ratio = 10.0;
  /// After a step whose pose was not known (the camera may have moved on
  /// while it was not), a match that passes is made again from starts this
  /// far from it along each of the camera's axes, and again around the best
  /// while one fits the reference better (a lower residual, with the overlap
  /// and inliers a step needs), as far as max_translation (10 rounds at
  /// most); the best is then judged as a match
  /// (OdometryDiagnostics::restart_shift) [m] (0: not made again). A
  /// keyframe left centimetres behind is met from far, and ICP can stop in a
  /// wrong minimum that passes every check: on `sweep` seed 4, after 4
  /// degenerate frames, 12.5 mm short of the camera's motion with 97 % of
  /// inliers and a 3.6 mm residual, where restarts found it (1.9 mm, 99.9 %;
  /// beyond max_translation, so implausible).
  double restart_distance = 0.01;
  double max_depth_diff = 0.07;  ///< a pixel matches when its depth differs by at most this [m] (OpenCV's maxDepthDiff)
  double min_depth = 0.1;        ///< pixels nearer than this are not used [m]
  double max_depth = 4.0;        ///< pixels farther than this are not used [m]
  /// Iterations at the 2nd and 3rd pyramid levels (at the finest too, but
  /// for finest_iterations), 1.5x at the 4th, the coarsest (OpenCV's default 7).
  int iterations = 7;
  /// Iterations of `icp` and `rgbd_icp` at the finest level, the frame as
  /// matched (OpenCV's default 7; the other methods do `iterations` there):
  /// the costliest, each a pass over every pixel. After the
  /// coarser levels, more fit the finest level's noise: on the still scenes
  /// of docs/perception.md's table, 1 gave 0.20 mm / 0.054 deg of error per
  /// frame, 7 gave 0.34 mm / 0.082 deg.
  int finest_iterations = 1;
  double max_points_part = 0.07;  ///< share of the pixels OpenCV samples (ICP, RGB-D; OpenCV's maxPointsPart)
  /// Frames wider than this [px] are matched at a whole fraction of their
  /// size, every 2nd (3rd, ...) pixel of every 2nd row, the smallest that
  /// brings them within it (0: at their own size). The cost goes with the
  /// pixels: a 640x480 sensor at 320x240 costs about a quarter.
  int max_width = 320;
  /// Leave out pixels nearer than the object's depth minus mask_margin but
  /// not on its support plane (within mask_plane_distance of it, of its
  /// colour), when the caller gives them (ObjectHint): hands in front of the
  /// object. Without the plane the table running towards the camera was left
  /// out too, and the turn about the optical axis of a camera facing a case
  /// was fixed by the case's sides alone: 0.10-0.17 deg of error per frame on
  /// dvd-static, 0.01 deg with the table (docs/perception.md).
  bool mask = true;
  double mask_margin = 0.10;  ///< [m] see `mask`: the hands and occluders in front of the object
  double mask_plane_distance = 0.01;  ///< [m] see `mask`: pixels this near the support plane stay in ...
  double mask_plane_chroma = 0.06;    ///< ... when their chromaticity is this near the plane's (colour frames)
  /// A step is Degenerate when the still scene, or the part of the frame
  /// that matches the reference, fixes the camera's translation less than
  /// this (OdometryDiagnostics::still_constraint, match_constraint; 0:
  /// never). On the simulator's scenes (docs/perception.md): the table
  /// within the sensor's range beside a case or a cloth, or an arm over the
  /// view, 1e-5 and less; the case's holding hand or a cage 1.4e-3 and more.
  double min_still_constraint = 2e-4;
  /// [m] pixels within this of one of the object's supervoxel centroids
  /// (the previous frame's, ObjectHint) are the object's: they do not count
  /// as still scene (3/4 of R_seed, about a supervoxel's reach from its
  /// centroid: twice as much covered the DVD case's holder too).
  double object_radius = 0.015;
};

/// \brief The numbers behind a step's status.
struct OdometryDiagnostics {
  double valid_fraction = 0.0;   ///< of the image's pixels, those used (depth in range, not masked)
  double masked_fraction = 0.0;  ///< of the image's pixels, those the mask left out
  /// Of the image's pixels, those used that fall, after the motion, on a
  /// pixel the reference used (in view, not masked there): the overlap.
  /// Below min_overlap_fraction the step is implausible.
  double overlap_fraction = 0.0;
  double inlier_fraction = 0.0;  ///< of the overlap, the pixels matching the reference within max_depth_diff
  double residual = 0.0;         ///< RMS depth difference of the matching pixels [m]
  /// How well the still scene fixes the camera's translation: the smallest
  /// eigenvalue of the mean n n^T of the normals of the flat 8 x 8 pixel
  /// patches (as matched) of the used pixels away from the object, 0 to 1
  /// (1/3 for patches facing every way alike; 0 when all are parallel or
  /// fewer than 8 patches are left). NaN when not measured (no object given,
  /// min_still_constraint 0, the first frame or one that failed).
  double still_constraint = std::numeric_limits<double>::quiet_NaN();
  /// The same of the pixels that match the reference after the motion
  /// (around the inlier samples): what the match itself stands on. NaN when
  /// not measured (min_still_constraint 0, or the step was refused before).
  double match_constraint = std::numeric_limits<double>::quiet_NaN();
  /// After a step whose pose was not known: how far the motion kept of the
  /// restarted matches (OdometrySettings::restart_distance) is from the one
  /// first found [m] (0: the first fits best). NaN when not restarted.
  double restart_shift = std::numeric_limits<double>::quiet_NaN();
  double translation = 0.0;      ///< the step's motion from the previous pose [m] (as found, even when rejected)
  double rotation = 0.0;         ///< the step's rotation from the previous pose [deg]
  bool converged = false;        ///< OpenCV's compute() found a motion
  double orthonormality = 0.0;   ///< |R^T R - I| of OpenCV's rotation before it is re-orthonormalised
  bool keyframe = false;         ///< this frame became the reference
  double ms = 0.0;               ///< wall time of the step [ms]
};

/// \brief One step's outcome.
struct OdometryResult {
  OdometryStatus status = OdometryStatus::Failed;  ///< see OdometryStatus
  /// The camera pose in the world: the new one when Ok or FirstFrame, the
  /// last good one otherwise (never a jump).
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
  OdometryDiagnostics diagnostics;  ///< why
};

/**
 * \brief RGB-D odometry over a sequence of frames (one camera, fixed intrinsics).
 *
 * Not thread-safe; one object per sequence. Frames whose intrinsics
 * differ from the first frame's are refused (std::invalid_argument).
 */
class Odometry {
 public:
  /// \throws std::invalid_argument naming the setting that is invalid (validate()).
  explicit Odometry(const OdometrySettings& settings = {});
  ~Odometry();
  Odometry(const Odometry&) = delete;
  Odometry& operator=(const Odometry&) = delete;
  /// \brief Moves the state (reference frame, pose) of another sequence's odometry.
  Odometry(Odometry&&) noexcept;
  /// \brief Moves the state (reference frame, pose) of another sequence's odometry.
  Odometry& operator=(Odometry&&) noexcept;

  /**
   * \brief One frame: its pose from the motion since the reference frame.
   * \param frame        depth [m] (colour for the `rgbd` methods), intrinsics; its
   *                     wMc is read only on the first frame (the start pose).
   * \param object       the object's supervoxels in the previous frame's camera:
   *                     with OdometrySettings::mask, pixels nearer than the nearest
   *                     minus mask_margin are left out (hands, occluders); the
   *                     rest of the scene away from them must fix the motion
   *                     (Degenerate). Empty: no mask and no such check (the
   *                     check of what the match stands on is made all the same).
   * \throws std::invalid_argument when the frame's buffers disagree with its
   *         intrinsics or the intrinsics change.
   */
  OdometryResult step(const RgbdFrame& frame, const ObjectHint& object = {});

  /// \brief Forgets every frame: the next one is a first frame.
  void reset();
  /// \brief The current pose (the last good one) [m]; identity before the first frame.
  [[nodiscard]] const Eigen::Isometry3d& wMc() const;
  /// \brief The settings it runs with.
  [[nodiscard]] const OdometrySettings& settings() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/**
 * \brief A step's outcome as a pose source's answer (ofv::FramePose): the
 *        pose, ok for Ok and FirstFrame, source `odometry`, the status's word
 *        and the diagnostics (valid_fraction, masked_fraction,
 *        overlap_fraction, inlier_fraction, residual_m, still_constraint,
 *        match_constraint, translation_m, rotation_deg, keyframe, ms).
 */
[[nodiscard]] FramePose frame_pose(const OdometryResult& result);

/**
 * \brief RGB-D odometry as a pose source (ofv::PoseSource) for perceive(),
 *        ofv::servo::run_on_robot (RobotLoopOptions::pose_source) and the
 *        simulated episode (setting `poses`): one Odometry over the frames
 *        it is called with, shared by the copies of the function.
 * \throws std::invalid_argument naming the setting that is invalid.
 */
[[nodiscard]] PoseSource odometry_pose_source(const OdometrySettings& settings = {});

/// \brief Throws std::invalid_argument naming the first invalid setting and its value.
void validate(const OdometrySettings& settings);
/// \brief The settings table: names, types, defaults, units, docs and parsers.
[[nodiscard]] const SettingsTable<OdometrySettings>& odometry_settings_table();

/// \brief The method's word: icp, rgbd_icp, fast_icp, rgbd.
[[nodiscard]] const char* to_string(OdometryMethod method);
/// \brief The status's word: ok, first_frame, failed, implausible, degenerate.
[[nodiscard]] const char* to_string(OdometryStatus status);
/// \brief The method a word names.
/// \throws std::invalid_argument naming `what` and listing the words.
[[nodiscard]] OdometryMethod parse_method(const std::string& what, const std::string& word);

}  // namespace ofv::odometry
