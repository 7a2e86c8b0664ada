// The per-frame loop of `ofv perceive` (ofv/perception/perceive.h).
#include "ofv/perception/perceive.h"

#include <algorithm>
#include <chrono>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ofv::perception {

PerceiveSummary perceive(FrameSource& source, const PerceptionSettings& ps,
                         const EstimatorSettings& settings, long max_frames,
                         const std::function<void(const PerceivedFrame&)>& observer,
                         const PoseSource& pose_source) {
  Perception perception(ps);
  std::optional<Eigen::Vector3d> previous_view;
  PerceiveSummary summary;
  std::vector<double> front_end_ms;
  // Sums and counts of each score over the scored frames.
  constexpr int kScores = 5;
  const std::optional<double> PerceptionScores::*score[kScores] = {
      &PerceptionScores::object_precision, &PerceptionScores::object_recall, &PerceptionScores::occluder_precision,
      &PerceptionScores::occluder_recall, &PerceptionScores::centroid_error};
  std::optional<double> PerceiveSummary::*mean[kScores] = {
      &PerceiveSummary::object_precision, &PerceiveSummary::object_recall, &PerceiveSummary::occluder_precision,
      &PerceiveSummary::occluder_recall, &PerceiveSummary::centroid_error};
  double sum[kScores] = {};
  long count[kScores] = {};
  BadFrameBudget bad_frames(kMaxBadFramesInRow, kMaxBadFramesPerMinute);
  ObjectHint object;  // the object in the last perceived frame's camera
  while (max_frames < 0 || summary.frames < max_frames) {
    PerceivedFrame f;
    // A frame the source cannot read (BadFrame) or the front end refuses is
    // skipped and counted; a broken recording (the source's
    // std::invalid_argument) or too many bad frames (BadFrameBudget) end the run.
    std::string bad;
    try {
      std::optional<RgbdFrame> frame = source.next();
      if (!frame) break;
      f.frame = std::move(*frame);
    } catch (const BadFrame& e) {
      bad = e.what();
    }
    if (bad.empty()) {
      f.source_wMc = f.frame.wMc;
      if (pose_source) {
        f.pose = pose_source(f.frame, object);
        f.frame.wMc = f.pose->wMc;
      }
    }
    try {
      if (bad.empty()) f.result = perception.process(f.frame);
    } catch (const std::invalid_argument& e) {
      bad = e.what();
    }
    if (!bad.empty()) {
      ++summary.bad_frames;
      summary.last_bad_frame = bad.substr(0, bad.find('\n'));
      bad_frames.bad(BadFrameBudget::Clock::now(), summary.last_bad_frame);
      continue;
    }
    bad_frames.good();
    f.index = summary.frames;
    object = f.result.status != TrackingStatus::Lost
                 ? object_hint(f.result.problem.positions, f.frame.wMc, f.result.support_plane)
                 : ObjectHint{};
    front_end_ms.push_back(f.result.timings.total);
    if (f.result.status != TrackingStatus::Lost) {
      f.result.problem.previous_view = previous_view;
      const auto start = std::chrono::steady_clock::now();
      f.estimate = estimate_view(f.result.problem, settings);
      f.estimate_ms =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
              .count();
      previous_view = f.estimate->tf;
    } else {
      ++summary.lost;
    }
    if (!f.frame.labels.empty()) {
      PerceptionTruth truth;
      truth.centroid = f.frame.object_centroid;
      truth.r_sphere = ps.r_sphere;
      f.scores = score_perception(f.frame, f.result, truth, ps);
      ++summary.scored;
      for (int k = 0; k < kScores; ++k) {
        if (!((*f.scores).*score[k])) continue;
        sum[k] += *((*f.scores).*score[k]);
        ++count[k];
      }
    }
    if (observer) {
      observer(f);
    }
    ++summary.frames;
  }
  for (int k = 0; k < kScores; ++k) {
    if (count[k] > 0) summary.*mean[k] = sum[k] / static_cast<double>(count[k]);
  }
  std::sort(front_end_ms.begin(), front_end_ms.end());
  summary.median_front_end_ms = front_end_ms.empty() ? 0.0 : front_end_ms[front_end_ms.size() / 2];
  return summary;
}

}  // namespace ofv::perception
