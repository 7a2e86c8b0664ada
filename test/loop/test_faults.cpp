// Faults in the closed loop. A recorded simulated episode (TUM files written
// by run_episode's frames) is replayed through ofv::servo::run_on_robot with faults
// injected between the source and the loop (FaultySource) and between the
// loop and the robot (FaultyRobot); every command the robot receives is
// checked against the safety invariants (check_invariants). End to end,
// `ofv run --dry-run` meets the same faults in its files and signals.
#include "cli_run.h"

#include "ofv/loop/episode.h"
#include "ofv/servo/robot_loop.h"
#include "ofv/servo/target_pose.h"
#include "ofv/sources/tum_sequence.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <functional>
#include <iterator>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace ofv {
namespace {

namespace fs = std::filesystem;

const char* kScenario = "dvd-one-hand";
constexpr double kDuration = 1.0;  // [s] of recording: 31 frames at 30 Hz

/// The episode the faults are injected into: its settings, its recording
/// (TUM files) and the commands the simulated loop gave.
struct Recording {
  EpisodeSetup setup;
  fs::path dir;
  EpisodeOutcome outcome;
};

const Recording& recording() {
  static const Recording r = [] {
    Recording out;
    out.setup = resolve_episode(sim::load_scenario(kScenario), {{"duration", std::to_string(kDuration)}});
    out.dir = fs::path(test::scratch_dir()) / "faults_recording";
    TumSequenceWriter writer(out.dir.string());
    out.outcome = run_episode(out.setup, [&](const StepRecord&, const StepDetail& d) { writer.write(*d.frame); });
    return out;
  }();
  return r;
}

// ---------------------------------------------------------------- the faults

enum class Fault {
  None,
  Drop,        ///< the frame never arrives
  NoDepth,     ///< every depth pixel missing (0): a covered or blinded sensor
  NanDepth,    ///< every depth pixel NaN
  EmptyDepth,  ///< no depth image at all (a malformed frame)
  Gap,         ///< this frame and the next ones `amount` s later
  Backwards,   ///< this frame and the next ones `amount` s earlier
  NanTime,     ///< a NaN timestamp
  PoseJump,    ///< the frame's pose moved by `amount` m along x
  NanPose,     ///< a NaN in the frame's pose
  Throw,       ///< the source throws
  BadRead,     ///< the source cannot read this frame (ofv::BadFrame) and goes on
  Stop,        ///< the stop flag is raised while the frame is awaited (a signal)
};

struct Injection {
  long frame;  ///< index in the recording
  Fault fault;
  double amount = 0.0;
};

/// A FrameSource that injects faults into another one and remembers the
/// frames it delivered.
class FaultySource : public FrameSource {
 public:
  FaultySource(FrameSource& inner, std::vector<Injection> plan, volatile std::sig_atomic_t* stop = nullptr)
      : inner_(inner), plan_(std::move(plan)), stop_(stop) {}

  std::optional<RgbdFrame> next() override {
    for (;;) {
      std::optional<RgbdFrame> f = inner_.next();
      if (!f) return f;
      const long k = index_++;
      bool drop = false;
      Fault fault = Fault::None;
      for (const Injection& i : plan_) {
        if (i.frame != k) continue;
        fault = i.fault;
        switch (i.fault) {
          case Fault::Drop: drop = true; break;
          case Fault::NoDepth: std::fill(f->depth.begin(), f->depth.end(), 0.0f); break;
          case Fault::NanDepth: std::fill(f->depth.begin(), f->depth.end(), std::numeric_limits<float>::quiet_NaN()); break;
          case Fault::EmptyDepth: f->depth.clear(); break;
          case Fault::Gap: shift_ += i.amount; break;
          case Fault::Backwards: shift_ -= i.amount; break;
          case Fault::NanTime: break;
          case Fault::PoseJump: f->wMc.translation().x() += i.amount; break;
          case Fault::NanPose: f->wMc.translation().y() = std::numeric_limits<double>::quiet_NaN(); break;
          case Fault::Throw: throw std::runtime_error("source fault at frame " + std::to_string(k));
          case Fault::BadRead:
            delivered_.push_back({std::numeric_limits<double>::quiet_NaN(), fault});
            throw BadFrame("short read at frame " + std::to_string(k));
          case Fault::Stop: *stop_ = 1; break;
          case Fault::None: break;
        }
      }
      f->timestamp += shift_;
      if (fault == Fault::NanTime) f->timestamp = std::numeric_limits<double>::quiet_NaN();
      if (drop) continue;
      delivered_.push_back({f->timestamp, fault});
      return f;
    }
  }
  [[nodiscard]] std::string describe() const override { return "faulty " + inner_.describe(); }

  struct Delivered {
    double timestamp;
    Fault fault;
  };
  [[nodiscard]] const std::vector<Delivered>& delivered() const { return delivered_; }

 private:
  FrameSource& inner_;
  std::vector<Injection> plan_;
  volatile std::sig_atomic_t* stop_;
  long index_ = 0;
  double shift_ = 0.0;
  std::vector<Delivered> delivered_;
};

/// A CameraRobot that records every command and throws at the loop's
/// command `fail_at` (once, or on every command from then on when it
/// `refuses`). The loop's commands (sent from the thread that built the robot)
/// answer one frame each; the watchdog's stops (from its own thread, when a
/// slow machine leaves the robot without a command for stale_timeout) answer
/// none, so they are told apart.
class FaultyRobot : public servo::CameraRobot {
 public:
  struct Command {
    vpColVector v;
    double dt;
    bool after_stop;  ///< the stop flag was up when it was sent
    bool from_loop = true;
  };
  FaultyRobot(servo::CameraRobot& inner, long fail_at, bool refuses, const volatile std::sig_atomic_t* stop)
      : inner_(inner), fail_at_(fail_at), refuses_(refuses), stop_(stop) {}
  [[nodiscard]] vpHomogeneousMatrix wMc() const override { return inner_.wMc(); }
  servo::RobotStep step(const vpColVector& v, double dt) override {
    // run_on_robot's watchdog holds its robot lock during every call: no two at once.
    const bool from_loop = std::this_thread::get_id() == loop_thread_;
    received_.push_back({v, dt, *stop_ != 0, from_loop});
    if (from_loop) {
      const long n = loop_commands_++;
      if (n == fail_at_ || (refuses_ && fail_at_ >= 0 && n > fail_at_)) {
        throw std::runtime_error("robot fault at command " + std::to_string(n));
      }
    }
    return inner_.step(v, dt);
  }
  [[nodiscard]] std::string name() const override { return "faulty " + inner_.name(); }
  /// Every command, the watchdog's included, in the order received.
  [[nodiscard]] const std::vector<Command>& received() const { return received_; }

 private:
  servo::CameraRobot& inner_;
  long fail_at_;
  bool refuses_;
  const volatile std::sig_atomic_t* stop_;
  const std::thread::id loop_thread_ = std::this_thread::get_id();
  long loop_commands_ = 0;
  std::vector<Command> received_;
};

/// One replay with faults: what the robot received and how the run ended.
struct FaultRun {
  std::vector<FaultyRobot::Command> received;  ///< every command, the watchdog's stops included
  std::vector<FaultyRobot::Command> commands;  ///< the loop's: one per frame it answered, then its stops
  std::vector<FaultySource::Delivered> delivered;
  std::vector<servo::SafetyAction> actions;  ///< per frame the loop finished
  std::vector<servo::StepStatus> statuses;
  servo::RobotLoopSummary summary;
  std::optional<std::string> error;  ///< what run_on_robot threw
};

struct FaultPlan {
  std::vector<Injection> source;
  long robot_fails_at = -1;
  bool robot_refuses = false;
  long observer_throws_at = -1;
  long observer_stalls_at = -1;  ///< the observer sleeps twice stale_timeout (a loaded machine)
  double max_duration = std::numeric_limits<double>::infinity();
};

FaultRun replay(const FaultPlan& plan) {
  const Recording& rec = recording();
  TumSequenceSource files(rec.dir.string());
  volatile std::sig_atomic_t stop = 0;
  FaultySource source(files, plan.source, &stop);
  servo::FreeFlyingCamera camera{vpHomogeneousMatrix()};
  FaultyRobot robot(camera, plan.robot_fails_at, plan.robot_refuses, &stop);
  servo::RobotLoopOptions options;
  options.stop = &stop;
  options.max_duration = plan.max_duration;
  FaultRun out;
  try {
    perception::PerceptionObserver perception(front_end_settings(rec.setup));
    out.summary = servo::run_on_robot(source, perception, robot, rec.setup.loop, options, [&](const servo::RobotLoopFrame& f) {
      out.actions.push_back(f.step->safety);
      out.statuses.push_back(f.step->status);
      if (f.index == plan.observer_throws_at) throw std::runtime_error("observer fault");
      if (f.index == plan.observer_stalls_at) {
        std::this_thread::sleep_for(std::chrono::duration<double>(2.0 * rec.setup.loop.safety.stale_timeout));
      }
    });
  } catch (const std::exception& e) {
    out.error = e.what();
  }
  out.received = robot.received();
  std::copy_if(out.received.begin(), out.received.end(), std::back_inserter(out.commands),
               [](const FaultyRobot::Command& c) { return c.from_loop; });
  out.delivered = source.delivered();
  return out;
}

double linear(const vpColVector& v) { return std::hypot(v[0], v[1], v[2]); }
double angular(const vpColVector& v) { return std::hypot(v[3], v[4], v[5]); }
bool is_zero(const vpColVector& v) { return v.frobeniusNorm() == 0.0; }

/**
 * The safety invariants, on every command the robot received (1–3, 5, 6) and
 * on the loop's answer to each frame (4):
 *  1. speed: |v| <= max_linear_speed, |w| <= max_angular_speed;
 *  2. acceleration: |dv| <= max_linear_accel dt, |dw| <= max_angular_accel dt
 *     from the previous command (the robot starts at rest), except for a
 *     stop (zero velocity: the drive's own deceleration applies);
 *  3. the period sent with a command is finite and >= 0;
 *  4. zero velocity for a frame that must stop the robot (stale: older than
 *     stale_timeout after the previous frame, timestamp not after the previous
 *     one or not finite, no depth), i.e. within one period of the fault;
 *  5. the last command is zero (every exit path leaves the robot at rest);
 *  6. nothing but zero once the stop flag is up.
 */
void check_invariants(const FaultRun& run, const servo::SafetySettings& limits) {
  constexpr double eps = 1e-9;
  ASSERT_FALSE(run.received.empty());
  vpColVector previous(6, 0.0);
  for (std::size_t k = 0; k < run.received.size(); ++k) {
    const auto& c = run.received[k];
    EXPECT_LE(linear(c.v), limits.max_linear_speed + eps) << "command " << k;
    EXPECT_LE(angular(c.v), limits.max_angular_speed + eps) << "command " << k;
    EXPECT_TRUE(std::isfinite(c.dt) && c.dt >= 0.0) << "command " << k << ": period " << c.dt;
    if (!is_zero(c.v)) {
      EXPECT_LE(linear(c.v - previous), limits.max_linear_accel * c.dt + eps) << "command " << k;
      EXPECT_LE(angular(c.v - previous), limits.max_angular_accel * c.dt + eps) << "command " << k;
    }
    EXPECT_TRUE(!c.after_stop || is_zero(c.v)) << "command " << k << " sent after the stop flag";
    previous = c.v;
  }
  EXPECT_TRUE(is_zero(run.received.back().v)) << "the last command does not stop the robot";
  std::optional<double> last;  // the last finite timestamp
  for (std::size_t k = 0; k < run.delivered.size() && k < run.commands.size(); ++k) {
    const FaultySource::Delivered& d = run.delivered[k];
    const double gap = last ? d.timestamp - *last : 0.0;  // NaN for a NaN timestamp
    const bool stale = k > 0 && !(gap > 0.0 && gap <= limits.stale_timeout);
    if (std::isfinite(d.timestamp)) last = d.timestamp;
    const bool blind = d.fault == Fault::NoDepth || d.fault == Fault::NanDepth || d.fault == Fault::NanPose;
    if (stale || blind) {
      EXPECT_TRUE(is_zero(run.commands[k].v)) << "frame " << k << " must stop the robot";
    }
  }
}

const servo::SafetySettings& limits() { return recording().setup.loop.safety; }

std::size_t count(const std::vector<servo::SafetyAction>& actions, servo::SafetyAction a) {
  return static_cast<std::size_t>(std::count(actions.begin(), actions.end(), a));
}

// ---------------------------------------------------------------- the loop

TEST(Faults, ReplayWithoutFaultsKeepsTheInvariants) {
  const FaultRun r = replay({});
  EXPECT_FALSE(r.error);
  EXPECT_EQ(r.summary.frames, static_cast<long>(recording().outcome.steps.size()));
  ASSERT_EQ(r.commands.size(), r.delivered.size() + 1);  // every frame, then the stop
  check_invariants(r, limits());
  EXPECT_GT(linear(r.commands[5].v), 1e-3);  // it does move: the checks can fail
}

TEST(Faults, SimulatedEpisodeKeepsTheSpeedAndAccelerationLimits) {
  // run_episode renders its frames synchronously (never stale or dropped);
  // its commands obey the same limits, and a lost object stops the camera.
  const EpisodeOutcome& o = recording().outcome;
  FaultRun r;
  for (const StepRecord& s : o.steps) {
    vpColVector v(6);
    for (unsigned i = 0; i < 6; ++i) v[i] = s.velocity(i);
    r.commands.push_back({v, 1.0 / recording().setup.scenario.rate, false});
    if (s.status == servo::StepStatus::ObjectLost) {
      EXPECT_TRUE(is_zero(v)) << s.time;
    }
  }
  r.commands.push_back({vpColVector(6, 0.0), 0.0, false});  // the episode's end: the robot is no longer stepped
  r.received = r.commands;
  check_invariants(r, limits());
}

TEST(Faults, DroppedFramesStopTheRobotOnceTheGapIsStale) {
  // One dropped frame (a 67 ms gap) is not stale; seven (267 ms) are.
  FaultPlan plan;
  plan.source = std::vector<Injection>{{5, Fault::Drop}};
  for (long k = 12; k < 19; ++k) plan.source.push_back({k, Fault::Drop});
  const FaultRun r = replay(plan);
  EXPECT_FALSE(r.error);
  check_invariants(r, limits());
  EXPECT_EQ(count(r.actions, servo::SafetyAction::StaleFrame), 1U);
  EXPECT_EQ(r.actions.at(12 - 1), servo::SafetyAction::StaleFrame);  // one frame dropped before
}

TEST(Faults, FramesWithoutDepthLoseTheObjectUntilItIsFoundAgain) {
  FaultPlan plan;
  plan.source = std::vector<Injection>{{6, Fault::NoDepth}, {7, Fault::NanDepth}, {8, Fault::NoDepth}, {9, Fault::NanDepth}};
  const FaultRun r = replay(plan);
  EXPECT_FALSE(r.error);
  check_invariants(r, limits());
  for (std::size_t k = 6; k <= 9; ++k) {
    EXPECT_EQ(r.statuses.at(k), servo::StepStatus::ObjectLost) << k;
    EXPECT_EQ(r.actions.at(k), servo::SafetyAction::ObjectLost) << k;
  }
  // Found again: tracked and moving before the end.
  bool found = false;
  for (std::size_t k = 10; k < r.statuses.size(); ++k) {
    found = found || (r.statuses[k] != servo::StepStatus::ObjectLost && !is_zero(r.commands[k].v));
  }
  EXPECT_TRUE(found);
}

TEST(Faults, TimestampGapsAndJumpsBackwardsStopTheRobot) {
  FaultPlan plan;
  plan.source = std::vector<Injection>{{5, Fault::Gap, 5.0}, {10, Fault::Backwards, 3.0}, {15, Fault::Backwards, 0.05},
                 {20, Fault::NanTime}};
  const FaultRun r = replay(plan);
  EXPECT_FALSE(r.error);
  check_invariants(r, limits());
  EXPECT_EQ(r.actions.at(5), servo::SafetyAction::StaleFrame);
  EXPECT_TRUE(stops(r.actions.at(10)));
  EXPECT_TRUE(stops(r.actions.at(15)));
  EXPECT_TRUE(stops(r.actions.at(20)));
  // A NaN timestamp stops one frame, not the rest of the run.
  EXPECT_FALSE(stops(r.actions.at(22)));
  EXPECT_FALSE(is_zero(r.commands.at(22).v));
}

TEST(Faults, ALoopThatStallsIsStoppedByTheWatchdogAndGoesOn) {
  // The loop answers frame 6 late (its observer sleeps): the watchdog stops
  // the robot meanwhile, the loop's next command starts from rest, and every
  // frame still gets exactly one answer.
  FaultPlan plan;
  plan.observer_stalls_at = 6;
  const FaultRun r = replay(plan);
  EXPECT_FALSE(r.error);
  EXPECT_GE(r.summary.watchdog_stops, 1);
  EXPECT_GT(r.received.size(), r.commands.size());
  EXPECT_EQ(r.commands.size(), r.delivered.size() + 1);
  check_invariants(r, limits());
  EXPECT_FALSE(is_zero(r.commands.at(12).v));
}

TEST(Faults, PoseJumpsKeepTheLimits) {
  FaultPlan plan;
  plan.source = std::vector<Injection>{{5, Fault::PoseJump, 0.3}, {6, Fault::PoseJump, -0.3}, {12, Fault::PoseJump, 2.0}};
  const FaultRun r = replay(plan);
  EXPECT_FALSE(r.error);
  check_invariants(r, limits());
}

TEST(Faults, AFrameThatFailsItsChecksIsSkippedWithAStopAndCounted) {
  // Perception refuses a pose that is not finite or far away (it once
  // reached PCL's octree, which aborted the process) and a frame without a
  // depth image: that frame is skipped, the robot stopped for it, and the
  // run goes on, its next commands starting from rest.
  for (const Injection& bad :
       {Injection{8, Fault::NanPose}, Injection{8, Fault::PoseJump, 1e7}, Injection{8, Fault::EmptyDepth},
        Injection{8, Fault::BadRead}}) {
    FaultPlan plan;
    plan.source = std::vector<Injection>{bad};
    const FaultRun r = replay(plan);
    EXPECT_FALSE(r.error) << *r.error;
    EXPECT_EQ(r.summary.bad_frames, 1);
    ASSERT_GT(r.statuses.size(), 20U);  // the run went on
    EXPECT_EQ(r.statuses.at(8), servo::StepStatus::BadFrame);
    EXPECT_EQ(r.actions.at(8), servo::SafetyAction::BadFrame);
    EXPECT_TRUE(is_zero(r.commands.at(8).v));
    EXPECT_FALSE(is_zero(r.commands.at(12).v));
    check_invariants(r, limits());
  }
}

TEST(Faults, TooManyBadFramesEndTheRunWithAStop) {
  // More than max_bad_frames_in_row (10) in a row: the run ends, naming the
  // last reason, the robot at rest.
  FaultPlan plan;
  for (long k = 8; k < 30; ++k) plan.source.push_back({k, Fault::EmptyDepth});
  const FaultRun r = replay(plan);
  ASSERT_TRUE(r.error);
  EXPECT_NE(r.error->find("11 bad frames in a row, the last: "), std::string::npos) << *r.error;
  EXPECT_NE(r.error->find("depth"), std::string::npos) << *r.error;
  EXPECT_EQ(r.commands.size(), 8U + 10U + 1U);  // 8 frames, 10 skipped with a stop, then the stop
  check_invariants(r, limits());
}

TEST(Faults, ASourceThatThrowsLeavesTheRobotAtRest) {
  FaultPlan plan;
  plan.source = std::vector<Injection>{{8, Fault::Throw}};
  const FaultRun r = replay(plan);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(*r.error, "source fault at frame 8");
  EXPECT_EQ(r.commands.size(), 9U);  // 8 frames, then the stop
  check_invariants(r, limits());
}

TEST(Faults, ARobotThatThrowsOnceIsStoppedAndTheErrorReported) {
  FaultPlan plan;
  plan.robot_fails_at = 8;
  const FaultRun r = replay(plan);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(*r.error, "robot fault at command 8");
  EXPECT_EQ(r.commands.size(), 10U);  // 8 accepted, the 9th thrown, then the stop
  check_invariants(r, limits());
}

TEST(Faults, ARobotThatRefusesEverythingReportsTheFirstError) {
  // The stop is tried too; its failure must not hide the first one.
  FaultPlan plan;
  plan.robot_fails_at = 8;
  plan.robot_refuses = true;
  const FaultRun r = replay(plan);
  ASSERT_TRUE(r.error);
  EXPECT_EQ(*r.error, "robot fault at command 8");
  EXPECT_EQ(r.commands.size(), 10U);
  check_invariants(r, limits());
}

TEST(Faults, EveryOtherExitPathEndsWithAStop) {
  {  // an observer (printing, recording) that throws
    FaultPlan plan;
    plan.observer_throws_at = 4;
    const FaultRun r = replay(plan);
    ASSERT_TRUE(r.error);
    EXPECT_EQ(*r.error, "observer fault");
    check_invariants(r, limits());
  }
  {  // max_duration
    FaultPlan plan;
    plan.max_duration = 0.5;
    const FaultRun r = replay(plan);
    EXPECT_FALSE(r.error);
    EXPECT_EQ(r.summary.frames, 16);
    check_invariants(r, limits());
  }
}

TEST(Faults, AStopRequestedWhileAFrameIsAwaitedSendsNothingButTheStop) {
  FaultPlan plan;
  plan.source = std::vector<Injection>{{10, Fault::Stop}};
  const FaultRun r = replay(plan);
  EXPECT_FALSE(r.error);
  EXPECT_TRUE(r.summary.stopped);
  check_invariants(r, limits());
  EXPECT_EQ(r.summary.frames, 10);
}

// ---------------------------------------------------------------- the command line

struct Line {
  std::string status;
  std::string safety;
  std::vector<double> v;
};

std::vector<Line> dry_run_lines(const std::string& out) {
  std::vector<Line> lines;
  std::stringstream in(out);
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] != '{') continue;
    const auto j = nlohmann::json::parse(line);
    lines.push_back({j.at("status").get<std::string>(), j.at("safety").get<std::string>(),
                     j.at("v").get<std::vector<double>>()});
  }
  return lines;
}

/// A copy of the recording with its timestamps changed by `change(index, t)`.
fs::path retimed_copy(const std::string& name, const std::function<double(long, double)>& change) {
  const fs::path dir = fs::path(test::scratch_dir()) / name;
  fs::remove_all(dir);
  fs::copy(recording().dir, dir, fs::copy_options::recursive);
  for (const char* list : {"depth.txt", "rgb.txt", "groundtruth.txt"}) {
    std::ifstream in(dir / list);
    std::stringstream out;
    long k = 0;
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') {
        out << line << '\n';
        continue;
      }
      const auto space = line.find(' ');
      char stamp[64];
      std::snprintf(stamp, sizeof stamp, "%.17g", change(k++, std::stod(line.substr(0, space))));
      out << stamp << line.substr(space) << '\n';
    }
    in.close();
    std::ofstream(dir / list) << out.str();
  }
  return dir;
}

TEST(FaultsCli, AGapInARecordingStopsTheRobotForThatFrame) {
  const fs::path dir = retimed_copy("faults_gap", [](long k, double t) { return k >= 10 ? t + 5.0 : t; });
  const CommandRun r = run("run --robot camera --source " + dir.string() + " --dry-run");
  ASSERT_EQ(r.code, 0) << r.err;
  const std::vector<Line> lines = dry_run_lines(r.out);
  ASSERT_EQ(lines.size(), recording().outcome.steps.size() + 1);
  EXPECT_EQ(lines.at(10).safety, "stale frame");
  EXPECT_EQ(lines.at(10).v, std::vector<double>(6, 0.0));
  EXPECT_EQ(lines.back().status, "stop");
}

TEST(FaultsCli, AMissingDepthImagePrintsTheStopAndFails) {
  // The source fails mid-run: the stop line comes first, then the error (exit 2: the recording is invalid).
  const fs::path dir = retimed_copy("faults_missing", [](long, double t) { return t; });
  std::string depth_file;
  {
    std::ifstream in(dir / "depth.txt");
    long k = 0;
    for (std::string line; std::getline(in, line);) {
      if (line.empty() || line[0] == '#') continue;
      if (k++ == 12) depth_file = line.substr(line.find(' ') + 1);
    }
  }
  ASSERT_TRUE(fs::remove(dir / depth_file));
  const CommandRun r = run("run --robot camera --source " + dir.string() + " --dry-run");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find(depth_file), std::string::npos) << r.err;
  const std::vector<Line> lines = dry_run_lines(r.out);
  ASSERT_EQ(lines.size(), 13U);  // 12 frames, then the stop
  EXPECT_EQ(lines.back().status, "stop");
  EXPECT_EQ(lines.back().v, std::vector<double>(6, 0.0));
}

// A 30 s dry-run rehearsal started in the background: its pid and the read
// end of its stdout (stderr goes to /dev/null).
std::pair<pid_t, int> start_dry_run() {
  int out[2];
  if (pipe(out) != 0) return {-1, -1};
  const pid_t pid = fork();
  if (pid == 0) {
    dup2(out[1], STDOUT_FILENO);
    close(out[0]);
    close(out[1]);
    const int null = open("/dev/null", O_WRONLY);
    dup2(null, STDERR_FILENO);
    execl(OFV_BINARY, OFV_BINARY, "run", "--robot", "afma6", "--source", "sim:dvd-one-hand", "--set", "duration=30",
          "--dry-run", static_cast<char*>(nullptr));
    _exit(127);
  }
  close(out[1]);
  return {pid, out[0]};
}

TEST(FaultsCli, DryRunLinesAreFlushedAsTheyAreProducedAndSigtermStops) {
  // Read the first command while the run still goes on, then SIGTERM it.
  const auto [pid, out] = start_dry_run();
  ASSERT_GT(pid, 0);
  FILE* in = fdopen(out, "r");
  ASSERT_NE(in, nullptr);
  char line[8192];
  ASSERT_NE(std::fgets(line, sizeof line, in), nullptr);
  EXPECT_EQ(waitpid(pid, nullptr, WNOHANG), 0) << "the first line came only when the run ended";
  EXPECT_EQ(nlohmann::json::parse(line).at("frame").get<long>(), 0);
  kill(pid, SIGTERM);
  std::string rest;
  for (std::size_t n; (n = std::fread(line, 1, sizeof line, in)) > 0;) rest.append(line, n);
  std::fclose(in);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const std::vector<Line> lines = dry_run_lines(rest);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back().status, "stop");
  EXPECT_LT(lines.size(), 300U);  // well before the 30 s
}

// The SIGTERM bit of /proc/PID/status's SigCgt: the process catches SIGTERM.
bool catches_sigterm(pid_t pid) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  for (std::string line; std::getline(in, line);) {
    if (line.rfind("SigCgt:", 0) == 0) return ((std::stoull(line.substr(7), nullptr, 16) >> (SIGTERM - 1)) & 1U) != 0;
  }
  return false;
}

TEST(FaultsCli, SigtermDuringStartUpStillEndsWithTheStop) {
  // As soon as ofv run catches SIGTERM (before it loads the scenario and
  // starts the threaded arm), a SIGTERM ends it with the stop line and exit 0.
  const auto [pid, out] = start_dry_run();
  ASSERT_GT(pid, 0);
  const auto start = std::chrono::steady_clock::now();
  while (!catches_sigterm(pid) && std::chrono::steady_clock::now() - start < std::chrono::seconds(20)) {
    std::this_thread::sleep_for(std::chrono::microseconds(200));
  }
  kill(pid, SIGTERM);
  FILE* in = fdopen(out, "r");
  ASSERT_NE(in, nullptr);
  std::string text;
  char buffer[4096];
  for (std::size_t n; (n = std::fread(buffer, 1, sizeof buffer, in)) > 0;) text.append(buffer, n);
  std::fclose(in);
  int status = 0;
  ASSERT_EQ(waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << "killed by signal " << (WIFSIGNALED(status) ? WTERMSIG(status) : 0);
  EXPECT_EQ(WEXITSTATUS(status), 0);
  const std::vector<Line> lines = dry_run_lines(text);
  ASSERT_FALSE(lines.empty());
  EXPECT_EQ(lines.back().status, "stop");
  EXPECT_LT(lines.size(), 300U);
}

}  // namespace
}  // namespace ofv
