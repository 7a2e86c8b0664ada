// A simulated sensor rendering in wall-clock time.
#include "ofv/sim/live_source.h"

namespace ofv::sim {

LiveSource::LiveSource(Renderer& renderer, PoseProvider pose, double duration)
    : renderer_(renderer), pose_(std::move(pose)), duration_(duration) {}

std::optional<RgbdFrame> LiveSource::next() {
  const auto now = std::chrono::steady_clock::now();
  if (!start_) start_ = now;
  const double t = std::chrono::duration<double>(now - *start_).count();
  if (t > duration_) return std::nullopt;
  const Eigen::Isometry3d wMc = pose_();
  renderer_.set_time(t);
  RenderedFrame rendered = renderer_.render(wMc, index_++);
  rendered.frame.timestamp = t;
  rendered.frame.wMc = wMc;
  return std::move(rendered.frame);
}

std::string LiveSource::describe() const {
  return "simulated sensor in wall-clock time (" + renderer_.scenario().name + ")";
}

}  // namespace ofv::sim
