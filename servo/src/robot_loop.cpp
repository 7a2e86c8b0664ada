// The closed loop on a robot: source → observer (perception) → ViewLoop → robot.
#include "ofv/servo/robot_loop.h"

#include "ofv/servo/target_pose.h"

#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <stdexcept>
#include <string>
#include <thread>

namespace ofv::servo {

namespace {

using Clock = std::chrono::steady_clock;

std::string first_line(const std::string& text) { return text.substr(0, text.find('\n')); }

// Every call of the loop to the robot goes through it, one at a time. From
// its own thread, it sends the robot a zero velocity when the last command
// moved it and no other came within `timeout` (a source that stalls, a
// perception that hangs), whatever the loop's thread is blocked in. A
// command that does not return within its period plus `timeout` (a driver
// stuck in setVelocity; ViSP's drivers may keep the cadence by waiting out
// the period) cannot be overridden through the same driver: it is recorded,
// and the loop ends the run when the command returns.
class Watchdog {
 public:
  Watchdog(CameraRobot& robot, double timeout, bool on) : robot_(robot), timeout_(seconds(timeout)) {
    if (on) thread_ = std::thread([this] { watch(); });
  }
  ~Watchdog() {
    {
      const std::lock_guard<std::mutex> lock(state_mutex_);
      done_ = true;
    }
    wake_.notify_all();
    if (thread_.joinable()) thread_.join();
  }
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  RobotStep command(const vpColVector& v, double dt) {
    const std::lock_guard<std::mutex> robot(robot_mutex_);
    set_busy(true, false, std::isfinite(dt) && dt > 0.0 ? dt : 0.0);
    struct Done {  // also when the driver throws
      Watchdog& w;
      bool moving;
      ~Done() { w.set_busy(false, moving); }
    } done{*this, v.frobeniusNorm() > 0.0};
    return robot_.step(v, dt);
  }
  [[nodiscard]] vpHomogeneousMatrix pose() {
    const std::lock_guard<std::mutex> robot(robot_mutex_);
    return robot_.wMc();
  }
  /// A command took longer than its period plus the timeout.
  [[nodiscard]] bool blocked() {
    const std::lock_guard<std::mutex> lock(state_mutex_);
    return blocked_;
  }
  [[nodiscard]] long stops() {
    const std::lock_guard<std::mutex> lock(state_mutex_);
    return stops_;
  }

 private:
  static Clock::duration seconds(double s) {
    return std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
  void set_busy(bool busy, bool moving = false, double period = 0.0) {
    {
      const std::lock_guard<std::mutex> lock(state_mutex_);
      busy_ = busy;
      since_ = Clock::now();
      period_ = seconds(period);
      if (!busy) moving_ = moving;
    }
    wake_.notify_all();
  }
  void watch() {
    std::unique_lock<std::mutex> lock(state_mutex_);
    while (!done_) {
      const Clock::time_point due = since_ + timeout_ + (busy_ ? period_ : Clock::duration::zero());
      if (!busy_ && !moving_) {
        wake_.wait(lock);
      } else if (Clock::now() < due) {
        wake_.wait_until(lock, due);
      } else if (busy_) {
        blocked_ = true;
        wake_.wait(lock);  // until the command returns
      } else {
        lock.unlock();
        std::unique_lock<std::mutex> robot(robot_mutex_, std::try_to_lock);
        if (robot.owns_lock()) {
          try {
            (void)robot_.step(vpColVector(6, 0.0), 0.0);
          } catch (...) {
            // The loop's next command meets the driver's error.
          }
        }
        lock.lock();
        if (robot.owns_lock()) {
          moving_ = false;
          ++stops_;
        }
        // else a command began meanwhile: it resets the clock.
      }
    }
  }

  CameraRobot& robot_;
  const Clock::duration timeout_;
  std::mutex robot_mutex_;  // held during every call to the robot
  std::mutex state_mutex_;  // guards what follows
  std::condition_variable wake_;
  Clock::time_point since_ = Clock::now();  // the last command began (busy) or returned
  Clock::duration period_{};                // of the command in progress
  bool busy_ = false;                       // a command is in progress
  bool moving_ = false;                     // the last command was not zero
  bool blocked_ = false;
  long stops_ = 0;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace

RobotLoopSummary run_on_robot(FrameSource& source, Observer& observer, CameraRobot& robot,
                              const LoopSettings& settings, const RobotLoopOptions& options,
                              const std::function<void(const RobotLoopFrame&)>& on_frame) {
  if (settings.method == ViewMethod::Hindsight) throw std::invalid_argument(kHindsightIsSimulationOnly);
  ViewLoop loop(settings);
  Watchdog watchdog(robot, settings.safety.stale_timeout, options.move_robot && options.watchdog);
  const auto rest = [&] {
    if (options.move_robot) (void)watchdog.command(vpColVector(6, 0.0), 0.0);
  };

  RobotLoopSummary summary;
  long watchdog_stops = 0;       // as of the previous frame
  BadFrameBudget bad_frames(options.max_bad_frames_in_row, options.max_bad_frames_per_minute);
  try {
    std::optional<double> first_stamp, last_stamp;
    ObjectHint object;  // for the pose source: the object in the last frame
    while (options.stop == nullptr || *options.stop == 0) {
      const auto asked = Clock::now();
      std::optional<RgbdFrame> frame;
      std::string unusable;  // a frame the source could not read (BadFrame)
      try {
        frame = source.next();
      } catch (const BadFrame& e) {
        unusable = first_line(e.what());
        frame.emplace();  // in its place: the previous time, the robot's pose
        frame->timestamp = last_stamp.value_or(0.0);
        frame->wMc = to_eigen(watchdog.pose());
      }
      // A stop requested while the frame was awaited (a signal during a
      // blocking read) wins over the frame: no command after it but the stop.
      if (!frame || (options.stop != nullptr && *options.stop != 0)) break;
      const auto arrived = Clock::now();
      // A timestamp that is not finite stops this frame (the safety filter
      // refuses its period) but is not the time base of the next ones.
      const bool stamped = std::isfinite(frame->timestamp);
      if (!first_stamp && stamped) first_stamp = frame->timestamp;
      if (stamped && first_stamp && frame->timestamp - *first_stamp > options.max_duration + 1e-9) break;
      if (options.pose_from_robot) frame->wMc = to_eigen(watchdog.pose());
      const double gap = last_stamp ? frame->timestamp - *last_stamp : 0.0;
      const double dt = last_stamp ? gap : options.first_period;
      if (stamped) last_stamp = frame->timestamp;

      RobotLoopFrame out;
      out.index = summary.frames;
      out.frame = &*frame;
      out.source_s = std::chrono::duration<double>(arrived - asked).count();
      // The robot stopped by the watchdog since: the next command starts from rest.
      if (watchdog.stops() != watchdog_stops) loop.robot_stopped();
      watchdog_stops = watchdog.stops();
      Observation observation;
      std::optional<FramePose> pose;
      out.bad_frame = unusable;
      try {
        if (unusable.empty()) {
          if (options.pose_source) {
            // The observer sees the frame with the source's pose; the frame
            // keeps its own (the robot's, the recording's) for on_frame.
            pose = options.pose_source(*frame, object);
            const Eigen::Isometry3d own = frame->wMc;
            frame->wMc = pose->wMc;
            struct Restore {
              RgbdFrame& f;
              Eigen::Isometry3d wMc;
              ~Restore() { f.wMc = wMc; }
            } restore{*frame, own};
            observation = observer.observe(*frame);
          } else {
            observation = observer.observe(*frame);
          }
        }
      } catch (const std::invalid_argument& e) {
        out.bad_frame = first_line(e.what());
      }
      if (!out.bad_frame.empty()) {
        // Skipped with a stop; the loop keeps its state for the next frame.
        ++summary.bad_frames;
        bad_frames.bad(arrived, out.bad_frame);
        loop.robot_stopped();
        observation.wMc = to_eigen(watchdog.pose());
        LoopStep skipped;
        skipped.status = StepStatus::BadFrame;
        skipped.safety = SafetyAction::BadFrame;
        skipped.mode = loop.mode();
        skipped.velocity = vpColVector(6, 0.0);
        out.observation = &observation;
        out.step = &skipped;
        if (options.move_robot) (void)watchdog.command(skipped.velocity, 0.0);
        ++summary.frames;
        if (on_frame) on_frame(out);
        continue;
      }
      bad_frames.good();
      observation.wMc = pose ? pose->wMc : frame->wMc;
      observation.pose = !pose || pose->ok ? PoseStatus::Known : PoseStatus::Unknown;
      out.pose = pose ? &*pose : nullptr;
      object = observation.problem
                   ? object_hint(observation.problem->positions, observation.wMc, observation.support_plane)
                   : ObjectHint{};
      out.perception_s = std::chrono::duration<double>(Clock::now() - arrived).count();
      observation.age = out.frame_age = options.wall_clock_age ? out.perception_s : gap;
      out.observation = &observation;
      const LoopStep step = loop.step(observation, dt);
      out.step = &step;
      summary.lost += step.status == StepStatus::ObjectLost ? 1 : 0;
      summary.pose_unknown += observation.pose == PoseStatus::Unknown ? 1 : 0;
      // A period that is not finite and positive (a timestamp going backwards
      // or NaN) came with a stop: the robot gets no period it cannot integrate.
      out.dt = std::isfinite(dt) && dt > 0.0 ? dt : 0.0;
      if (options.move_robot) (void)watchdog.command(step.velocity, out.dt);
      if (watchdog.blocked()) {
        throw std::runtime_error(robot.name() + ": a command took longer than its period plus stale_timeout (" +
                                 std::to_string(settings.safety.stale_timeout) +
                                 " s) to return, and no stop could be sent meanwhile; the run is stopped");
      }
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
  summary.watchdog_stops = watchdog.stops();
  return summary;
}

}  // namespace ofv::servo
