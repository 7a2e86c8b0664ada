/**
 * \file perceive.h
 * \brief The front end and the estimator on every frame of a source
 *        (`ofv perceive`): frame -> Perception::process -> estimate_view,
 *        each view estimated with the previous one as its warm start.
 *
 * \code
 * auto source = ofv::open_source("recording.oni");
 * const ofv::perception::PerceiveSummary s = ofv::perception::perceive(*source, ofv::perception::PerceptionSettings{},
 *     ofv::EstimatorSettings{}, -1, [](const ofv::perception::PerceivedFrame& f) {
 *       if (f.estimate) std::cout << f.index << ": " << f.estimate->tf.transpose() << '\n';
 *     });
 * \endcode
 *
 * The records of a perceived frame (JSON text, files) are in perceive_files.h.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/frame_source.h"
#include "ofv/perception/perception.h"
#include "ofv/perception/scores.h"
#include "ofv/pose_source.h"
#include "ofv/rgbd_frame.h"

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ofv::perception {

/// \brief A frame's pose from a pose source (ofv/pose_source.h): perceive()'s `pose_source` gives them.
using FramePose = ofv::FramePose;
/// \brief What gives a frame's pose before the front end runs (ofv/pose_source.h).
using PoseSource = ofv::PoseSource;

/// \brief One frame as perceive() saw it: what the front end found and the view estimated.
struct PerceivedFrame {
  long index = 0;   ///< position in the sequence, from 0
  RgbdFrame frame;  ///< the frame as the source gave it, with the pose the front end used (`wMc`)
  /// With a pose source: what it said, and the pose the frame source gave
  /// (ground truth for ofv's recordings) in `source_wMc`.
  std::optional<FramePose> pose;
  Eigen::Isometry3d source_wMc = Eigen::Isometry3d::Identity();  ///< the frame source's own pose [m]
  /// The front end's result. When the object is not lost, `result.problem`
  /// is exactly the estimator's input: its `previous_view` is the t_f of
  /// the last frame that had an estimate (none before the first).
  PerceptionResult result;
  /// The view estimated from `result.problem`; std::nullopt when the object is lost.
  std::optional<ViewEstimate> estimate;
  double estimate_ms = 0.0;  ///< wall time of estimate_view() [ms]; 0 when lost
  /// The front end scored against the frame's ground truth (scores.h), for
  /// a frame that carries labels (ofv's own recordings); its object
  /// centroid, when the frame has one, centres the occluders' sphere.
  std::optional<PerceptionScores> scores;
};

/// \brief What perceive() did over the whole sequence.
struct PerceiveSummary {
  long frames = 0;  ///< frames read and perceived
  long lost = 0;    ///< of those, frames in which the object was lost (no estimate)
  /// Frames skipped: the source could not read them (ofv::BadFrame) or the
  /// front end refused them (std::invalid_argument); not in `frames`, not
  /// given to the observer. More than ofv::kMaxBadFramesInRow in a row, or
  /// ofv::kMaxBadFramesPerMinute within a minute, end the run (std::runtime_error).
  long bad_frames = 0;
  std::string last_bad_frame;  ///< why the last skipped frame was skipped
  /// Median of the front end's total time per frame (PerceptionTimings::total)
  /// [ms]: the upper median, element frames / 2 of the sorted times; 0 without frames.
  double median_front_end_ms = 0.0;
  long scored = 0;  ///< frames with labels, scored
  /// Means over the scored frames of each score that is defined there
  /// (PerceptionScores; hidden_error needs the object's surface, which a recording lacks).
  std::optional<double> object_precision, object_recall, occluder_precision, occluder_recall, centroid_error;
  /// \var object_recall
  /// \brief Mean of PerceptionScores::object_recall over the scored frames that define it.
  /// \var occluder_precision
  /// \brief Mean of PerceptionScores::occluder_precision over the scored frames that define it.
  /// \var occluder_recall
  /// \brief Mean of PerceptionScores::occluder_recall over the scored frames that define it.
  /// \var centroid_error
  /// \brief Mean of PerceptionScores::centroid_error over the scored frames that define it [m].
};

/**
 * \brief Reads frames from `source` until its end (or `max_frames` frames),
 *        runs one Perception (settings `ps`) on each and, when the object is
 *        not lost, estimate_view() with `settings`, warm-started from the
 *        previous estimate (`previous_view`, see PerceivedFrame::result).
 *
 * `observer` is called once per frame, in order, before the next frame is
 * read; the frame it gets lives only for the call.
 *
 * \param source     the frames, read until its end.
 * \param ps         the front end's settings.
 * \param settings   the estimator's settings.
 * \param max_frames stop after this many frames; negative: no limit.
 * \param observer   called with every frame once it is perceived (may be empty).
 * \param pose_source when not empty, gives each frame's pose before the front
 *        end sees it (PoseSource); a pose it marks not ok is still used (its
 *        last good one) and recorded in PerceivedFrame::pose.
 * \throws std::invalid_argument for invalid settings or a frame whose buffers
 *         disagree with its intrinsics; whatever `source` and `observer` throw
 *         (std::runtime_error when a device or file fails mid-way).
 */
PerceiveSummary perceive(FrameSource& source, const PerceptionSettings& ps,
                         const EstimatorSettings& settings, long max_frames,
                         const std::function<void(const PerceivedFrame&)>& observer,
                         const PoseSource& pose_source = {});

}  // namespace ofv::perception

/// \cond OFV_OLD_NAMES
// The names of ofv 0.1, kept for one release: use ofv::perception::.
namespace ofv {
using perception::perceive;
using PerceiveSummary [[deprecated("use ofv::perception::PerceiveSummary")]] = perception::PerceiveSummary;
using PerceivedFrame [[deprecated("use ofv::perception::PerceivedFrame")]] = perception::PerceivedFrame;
}  // namespace ofv
/// \endcond
