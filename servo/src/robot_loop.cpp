// The closed loop on a robot: source → observer (perception) → ViewLoop → robot.
#include "ofv/servo/robot_loop.h"

#include "ofv/servo/target_pose.h"

#include <chrono>
#include <cmath>

namespace ofv::servo {

RobotLoopSummary run_on_robot(FrameSource& source, Observer& observer, CameraRobot& robot,
                              const LoopSettings& settings, const RobotLoopOptions& options,
                              const std::function<void(const RobotLoopFrame&)>& on_frame) {
  using Clock = std::chrono::steady_clock;
  ViewLoop loop(settings);
  const auto rest = [&] {
    if (options.move_robot) (void)robot.step(vpColVector(6, 0.0), 0.0);
  };

  RobotLoopSummary summary;
  try {
    std::optional<double> first_stamp, last_stamp;
    while (options.stop == nullptr || *options.stop == 0) {
      const auto asked = Clock::now();
      std::optional<RgbdFrame> frame = source.next();
      // A stop requested while the frame was awaited (a signal during a
      // blocking read) wins over the frame: no command after it but the stop.
      if (!frame || (options.stop != nullptr && *options.stop != 0)) break;
      const auto arrived = Clock::now();
      // A timestamp that is not finite stops this frame (the safety filter
      // refuses its period) but is not the time base of the next ones.
      const bool stamped = std::isfinite(frame->timestamp);
      if (!first_stamp && stamped) first_stamp = frame->timestamp;
      if (stamped && first_stamp && frame->timestamp - *first_stamp > options.max_duration + 1e-9) break;
      if (options.pose_from_robot) frame->wMc = to_eigen(robot.wMc());
      const double gap = last_stamp ? frame->timestamp - *last_stamp : 0.0;
      const double dt = last_stamp ? gap : options.first_period;
      if (stamped) last_stamp = frame->timestamp;

      RobotLoopFrame out;
      out.index = summary.frames;
      out.frame = &*frame;
      out.source_s = std::chrono::duration<double>(arrived - asked).count();
      Observation observation = observer.observe(*frame);
      observation.wMc = frame->wMc;
      out.perception_s = std::chrono::duration<double>(Clock::now() - arrived).count();
      observation.age = out.frame_age = options.wall_clock_age ? out.perception_s : gap;
      out.observation = &observation;
      const LoopStep step = loop.step(observation, dt);
      out.step = &step;
      summary.lost += step.status == StepStatus::ObjectLost ? 1 : 0;
      // A period that is not finite and positive (a timestamp going backwards
      // or NaN) came with a stop: the robot gets no period it cannot integrate.
      out.dt = std::isfinite(dt) && dt > 0.0 ? dt : 0.0;
      if (options.move_robot) (void)robot.step(step.velocity, out.dt);
      ++summary.frames;
      if (on_frame) on_frame(out);
    }
  } catch (...) {
    // Stop, then report the error that ended the run, not the stop's own
    // (a robot that refuses every command throws again here).
    try {
      rest();
    } catch (...) {
    }
    throw;
  }
  summary.stopped = options.stop != nullptr && *options.stop != 0;
  rest();
  return summary;
}

}  // namespace ofv::servo
