/**
 * \file live_source.h
 * \brief A simulated RGB-D sensor in wall-clock time: each frame renders the
 *        scenario at the time elapsed since the first frame, from the pose
 *        the camera has then (for example a threaded ViSP arm's), as a real
 *        sensor on a moving robot would see it.
 */
#pragma once

#include "ofv/frame_source.h"
#include "ofv/sim/renderer.h"

#include <Eigen/Geometry>

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

namespace ofv::sim {

/// \brief Frames of a scenario rendered live; ends after the scenario's duration.
class LiveSource : public FrameSource {
 public:
  /// \brief The camera pose in the world when a frame is taken.
  using PoseProvider = std::function<Eigen::Isometry3d()>;
  /**
   * \param renderer renders the scenario (outlives the source); its time is
   *                 left at the last frame's, so truth() can follow a frame.
   * \param pose     the camera pose at each frame.
   * \param duration end of the episode [s].
   */
  LiveSource(Renderer& renderer, PoseProvider pose, double duration);
  std::optional<RgbdFrame> next() override;
  [[nodiscard]] std::string describe() const override;

 private:
  Renderer& renderer_;
  PoseProvider pose_;
  double duration_;
  long index_ = 0;
  std::optional<std::chrono::steady_clock::time_point> start_;
};

}  // namespace ofv::sim
