// `ofv run --robot NAME --source SOURCE [--set name=value ...] [--dry-run]`:
// the closed loop on a robot and a sensor, a recording, or a live simulation.
#include "commands.h"

#include "ofv/loop/episode.h"
#include "ofv/servo/robot_loop.h"
#include "ofv/servo/target_pose.h"
#include "ofv/sources/open_source.h"
#include "ofv/text_file.h"
#if defined(OFV_HAVE_DISPLAY)
#include "ofv/display/live_display.h"
#endif

#include <visp3/core/vpConfig.h>
#include <visp3/core/vpPoseVector.h>
#if defined(VISP_HAVE_VIPER850)
#include <visp3/robot/vpRobotViper850.h>
#endif
#if defined(VISP_HAVE_AFMA6)
#include <visp3/robot/vpRobotAfma6.h>
#endif

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <csignal>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <limits>
#include <sstream>

namespace ofv::cli {

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_signal(int) { g_stop = 1; }

// The camera-to-end-effector transform from a file of six numbers:
// tx ty tz [m] thetaux thetauy thetauz [rad] (ViSP's vpPoseVector of eMc).
vpHomogeneousMatrix read_eMc(const std::string& path) {
  std::istringstream in(read_text_file(path, 4096, "eMc"));
  double p[6];
  for (double& x : p) {
    if (!(in >> x) || !std::isfinite(x)) {
      throw std::invalid_argument(path + ": expected six numbers tx ty tz tux tuy tuz (eMc)");
    }
  }
  return vpHomogeneousMatrix(vpPoseVector(p[0], p[1], p[2], p[3], p[4], p[5]));
}

// Real drivers this ViSP was built with.
std::string real_drivers() {
  std::string list;
#if defined(VISP_HAVE_VIPER850)
  list += "viper850-real ";
#endif
#if defined(VISP_HAVE_AFMA6)
  list += "afma6-real ";
#endif
  return list.empty() ? "none in this ViSP build" : list;
}

// A real driver by name, or nullptr for the simulated robots.
std::unique_ptr<servo::CameraRobot> real_robot(const std::string& name, const vpHomogeneousMatrix& eMc) {
  (void)eMc;
#if defined(VISP_HAVE_VIPER850)
  if (name == "viper850-real") {
    static vpRobotViper850 driver;
    driver.init(vpViper850::TOOL_CUSTOM, eMc);
    return std::make_unique<servo::VispRobot>(driver, vpHomogeneousMatrix(), name);
  }
#endif
#if defined(VISP_HAVE_AFMA6)
  if (name == "afma6-real") {
    static vpRobotAfma6 driver;
    driver.init(vpAfma6::TOOL_CUSTOM, eMc);
    return std::make_unique<servo::VispRobot>(driver, vpHomogeneousMatrix(), name);
  }
#endif
  (void)name;
  return nullptr;
}

// A dry run's JSON lines own stdout: while the loop runs, whatever else
// writes there (ViSP's drivers and threaded simulators print warnings such as
// "Velocity control stopped: axis 3 on joint limit") goes to stderr instead.
class CommandLines {
 public:
  explicit CommandLines(bool dry_run) {
    if (!dry_run) return;
    std::cout.flush();
    std::fflush(stdout);
    saved_ = ::dup(STDOUT_FILENO);
    const int own = saved_ >= 0 ? ::dup(saved_) : -1;
    out_ = own >= 0 ? ::fdopen(own, "w") : nullptr;
    if (!out_) throw std::runtime_error("cannot duplicate stdout for the dry run's command lines");
    ::dup2(STDERR_FILENO, STDOUT_FILENO);
  }
  ~CommandLines() { close(); }
  CommandLines(const CommandLines&) = delete;
  CommandLines& operator=(const CommandLines&) = delete;

  /// One JSON line per command: frame, time, status, twist (17 digits),
  /// safety action, with a pose source its word for the frame's pose (ok,
  /// first_frame, failed, implausible, degenerate), the loop's mode, the guard that moved it and the
  /// proposer of the target, the confirmed occluder tracks seen in the frame
  /// (id, position [m], velocity [m/s], velocity standard deviation per axis [m/s]).
  void print(long frame, double t, const char* status, const vpColVector& v, const char* safety,
             const servo::LoopStep* step = nullptr, const std::string& bad_frame = {}, const FramePose* pose = nullptr) {
    if (!out_ || closed_) return;
    std::fprintf(out_, "{\"frame\": %ld, \"t\": %.17g, \"status\": \"%s\", \"v\": [", frame, t, status);
    for (unsigned i = 0; i < 6; ++i) std::fprintf(out_, "%s%.17g", i ? ", " : "", v[i]);
    std::fprintf(out_, "], \"safety\": \"%s\", ", safety);
    if (pose) std::fprintf(out_, "\"pose\": %s, ", nlohmann::json(pose->status).dump().c_str());
    if (!bad_frame.empty()) std::fprintf(out_, "\"bad_frame\": %s, ", nlohmann::json(bad_frame).dump().c_str());
    if (step) {
      std::fprintf(out_, "\"mode\": \"%s\", \"guard\": \"%s\", \"proposer\": \"%s\", ", to_string(step->mode),
                   to_string(step->guard), to_string(step->proposer));
    }
    std::fprintf(out_, "\"tracks\": [");
    bool first = true;
    for (const OccluderTrack& k : step ? step->tracks : std::vector<OccluderTrack>{}) {
      if (!k.confirmed || k.points.cols() == 0) continue;
      std::fprintf(out_, "%s{\"id\": %d, \"p\": [%.6g, %.6g, %.6g], \"v\": [%.6g, %.6g, %.6g], \"sigma_v\": %.6g}",
                   first ? "" : ", ", k.id, k.position.x(), k.position.y(), k.position.z(), k.velocity.x(),
                   k.velocity.y(), k.velocity.z(), k.speed_sigma());
      first = false;
    }
    std::fprintf(out_, "]}\n");
    std::fflush(out_);  // a line is readable as soon as its command is decided
    if (std::ferror(out_)) {
      // The reader went away (EPIPE: `| head`): stop as a signal does.
      closed_ = true;
      g_stop = 1;
    }
    next_frame_ = frame + 1;
    last_t_ = t;
  }

  /// The final stop line (zero velocity), then stdout back to what it was.
  /// The destructor calls it: every exit path, an exception too, ends with
  /// the stop line before the error is reported.
  void close() {
    if (!out_) return;
    print(next_frame_, last_t_, "stop", vpColVector(6, 0.0), "");  // nothing once the reader is gone
    std::fclose(out_);
    out_ = nullptr;
    std::cout.flush();
    std::fflush(stdout);
    ::dup2(saved_, STDOUT_FILENO);
    ::close(saved_);
  }

  /// Whether the reader of the lines went away (the run was stopped for it).
  [[nodiscard]] bool reader_gone() const { return closed_; }

 private:
  std::FILE* out_ = nullptr;
  bool closed_ = false;
  int saved_ = -1;
  long next_frame_ = 0;
  double last_t_ = 0.0;
};

}  // namespace

Command add_run_command(CLI::App& app) {
  struct Options {
    std::string robot = "camera";
    std::string source;
    std::string emc;
    std::string box, rect;
    std::vector<std::string> sets;
    std::string poses;
    bool dry_run = false;
    bool display = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("run", "Run the closed loop on a robot and a sensor, a recording, or a live simulation");
  CLI::Option* robot_flag = sub->add_option("--robot", opt->robot,
                  "camera, viper850, afma6 (ViSP's kinematic models; with a sim: source, ViSP's threaded simulators), "
                  "or a real driver: " + real_drivers())
      ->capture_default_str();
  sub->add_option("--source", opt->source,
                  "Frames: TUM folder, PCD sequence, FILE.oni, openni2://URI, or sim:SCENARIO (the scenario rendered "
                  "live from the simulated arm's camera: a rehearsal without hardware)")
      ->required();
  sub->add_option("--emc", opt->emc,
                  "File with the camera-end-effector transform eMc: tx ty tz tux tuy tuz (real robot drivers only)");
  sub->add_option("--set", opt->sets, "Any setting of 'ofv simulate' as name=value (repeatable), same defaults")
      ->type_name("NAME=VALUE");
  add_selection_options(*sub, opt->box, opt->rect);
  sub->add_option("--poses", opt->poses,
                  "The camera pose the front end and the loop get: robot (the robot's on a live sensor, else the "
                  "recording's or the simulated arm's; default) or odometry[:icp|rgbd_icp|fast_icp|rgbd] (RGB-D "
                  "odometry from the first frame's pose); a frame whose pose odometry cannot tell stops the robot "
                  "(safety \"pose unknown\"): setting poses");
  sub->add_flag("--dry-run", opt->dry_run,
                "Print every command (JSON lines, then the final stop) instead of sending it to hardware");
#if defined(OFV_HAVE_DISPLAY)
  sub->add_flag("--display", opt->display,
                "Show the loop live in ViSP windows (camera image with supervoxels, occluders, tracks and the feature; "
                "scene view; velocity and feature error curves). Left click: pause (the robot is sent a zero velocity "
                "first; not in a sim: rehearsal, whose threaded arm would run on) and resume; right click or q: stop, "
                "as SIGTERM does. Needs an X display (exit 2 without one)");
#endif
  sub->footer("Ctrl-C (or SIGTERM) stops the robot (zero velocity) and exits (0). The object is picked in the first frame "
              "(--box, --rect, or else the cluster at the image centre; a sim: rehearsal takes the scenario's "
              "object, select=labels); when it is lost, or a frame is stale (older than stale_timeout "
              "after the previous one, or not after it), the robot stops. An error mid-run (the source, perception or "
              "the robot fails) stops the robot, then is reported (exit 2 for an invalid recording, 1 otherwise). A dry "
              "run's lines are flushed one by one; the last one is always the stop.\n\n" +
              episode_settings_help());

  return {sub, [opt, robot_flag]() -> int {
            // First: a signal during start-up (loading a scenario, starting a
            // driver) must end the run with a stop too, not kill it.
            std::signal(SIGINT, on_signal);
            std::signal(SIGTERM, on_signal);
            const bool simulated = opt->source.rfind("sim:", 0) == 0;
            const bool real = opt->robot.size() > 5 && opt->robot.compare(opt->robot.size() - 5, 5, "-real") == 0;
            EpisodeSetup setup;
            std::unique_ptr<FrameSource> source;
            std::unique_ptr<servo::CameraRobot> robot;
            perception::ObjectSelection selection;
#if defined(OFV_HAVE_DISPLAY)
            std::unique_ptr<LiveDisplay> display;
#endif
            try {
              std::vector<std::pair<std::string, std::string>> settings;
              for (const auto& a : opt->sets) settings.push_back(split_assignment(a));
              refuse_set_against_flag(settings, "robot", "--robot", robot_flag->count() > 0, opt->robot);
              refuse_set_against_flag(settings, "poses", "--poses", !opt->poses.empty(), opt->poses);
              if (!real) settings.insert(settings.begin(), {"robot", opt->robot});
              if (!opt->poses.empty()) settings.insert(settings.begin(), {"poses", opt->poses});
              // The windows open once the settings are valid, before a driver
              // starts or a source opens: no display is an error at start.
              const auto open_display = [&] {
#if defined(OFV_HAVE_DISPLAY)
                if (!opt->display) return;
                LiveDisplayOptions options;
                options.title = "ofv run";
                options.r_sphere = setup.loop.estimator.resolve().r_sphere;
                // A pause holds the robot: zero velocity, as at the end of a run.
                // The rehearsal's arm is inside ofv::rehearse, out of reach: it
                // would keep its command, so a rehearsal has no pause.
                options.pause = !simulated;
                display = std::make_unique<LiveDisplay>(options);
                if (!opt->dry_run || !real) {
                  display->set_pause_hook([&robot] {
                    if (robot) (void)robot->step(vpColVector(6, 0.0), 0.0);
                  });
                }
#endif
              };
              if (!opt->emc.empty() && !real) {
                throw std::invalid_argument("--emc: the camera-end-effector transform is for a real robot driver (" +
                                            real_drivers() + "); --robot " + opt->robot + " carries its camera itself");
              }
              if (simulated) {
                if (!opt->box.empty() || !opt->rect.empty()) {
                  throw std::invalid_argument(
                      "--box and --rect are for recordings and sensors; a sim: rehearsal tracks the scenario's object "
                      "(or, with --set select=auto, the cluster at the image centre)");
                }
                setup = resolve_episode(sim::load_scenario(opt->source.substr(4)), settings);
                if (setup.loop.method == ViewMethod::Hindsight) throw std::invalid_argument(servo::kHindsightIsSimulationOnly);
                setup.real_time = true;
                if (setup.robot == servo::RobotKind::Camera) {
                  throw std::invalid_argument("--source sim: needs --robot viper850 or afma6 (ViSP's threaded simulators)");
                }
                open_display();
              } else {
                setup.duration = std::numeric_limits<double>::infinity();
                episode_settings_table().apply(setup, settings);
                (void)servo::ViewLoop(setup.loop);  // validates
                if (setup.loop.method == ViewMethod::Hindsight) throw std::invalid_argument(servo::kHindsightIsSimulationOnly);
                const bool select = std::any_of(settings.begin(), settings.end(), [](const auto& s) { return s.first == "select"; });
                if (setup.perception != PerceptionMode::Full || setup.seed != 0 || setup.real_time || select) {
                  throw std::invalid_argument(
                      "settings perception, seed, real_time and select need --source sim:SCENARIO (--box or --rect "
                      "point out the object of a recording or sensor)");
                }
                selection = object_selection(opt->box, opt->rect);
                open_display();
                const vpHomogeneousMatrix eMc = opt->emc.empty() ? vpHomogeneousMatrix() : read_eMc(opt->emc);
                robot = real ? real_robot(opt->robot, eMc) : servo::make_robot(setup.robot, vpHomogeneousMatrix());
                if (!robot) {
                  throw std::invalid_argument("--robot " + opt->robot + ": unknown (simulated: camera, viper850, afma6; real drivers: " +
                                              real_drivers() + ")");
                }
                source = open_source(opt->source, 1.0f, setup.poses != PoseOrigin::Odometry);
              }
            } catch (const std::exception& e) {  // sources report unreadable paths as runtime errors: here they are bad input
              std::cerr << "ofv run: " << e.what() << '\n';
              return kUsage;
            }
            try {
              CommandLines lines(opt->dry_run);
              bool user_quit = false;  // the display's quit, not a signal
              const auto print = [&](const servo::RobotLoopFrame& f) {
                lines.print(f.index, f.frame->timestamp, to_string(f.step->status), f.step->velocity,
                            to_string(f.step->safety), f.step, f.bad_frame, f.pose);
#if defined(OFV_HAVE_DISPLAY)
                // The user ending the run stops it as SIGTERM does.
                if (display && !display->observe(f)) {
                  user_quit = true;
                  g_stop = 1;
                }
#endif
              };
              if (simulated) {
                const EpisodeOutcome outcome = rehearse(setup, &g_stop, print);
                lines.close();
                // The summary goes where the lines went, unless their reader is gone.
                (lines.reader_gone() ? std::cerr : std::cout) << "ofv run: rehearsal of " << setup.scenario.name << " on the threaded " << to_string(setup.robot)
                          << (g_stop ? (user_quit ? ", stopped from the display"
                                        : lines.reader_gone() ? ", stopped: the output's reader went away" : ", stopped")
                                     : "")
                          << '\n'
                          << episode_summary(outcome.metrics);
                return kOk;
              }
              servo::RobotLoopOptions options;
              options.pose_from_robot = options.wall_clock_age = opt->source.rfind("openni2://", 0) == 0;
              options.move_robot = !opt->dry_run || !real;  // simulated robots follow a dry run
              options.max_duration = setup.duration;
              options.stop = &g_stop;
              options.pose_source = episode_pose_source(setup);
              perception::PerceptionSettings front_end = front_end_settings(setup);
              front_end.selection = selection;
              perception::PerceptionObserver perception(front_end);
              // A --box or --rect that selects nothing in the first frame
              // makes the run meaningless (every frame lost): stop and refuse.
              std::string selects_nothing;
              const auto first_frame = [&](const servo::RobotLoopFrame& f) {
                print(f);
                if (f.index == 0 && selection.mode != perception::ObjectSelection::Mode::Auto &&
                    perception.last().status == perception::TrackingStatus::Lost) {
                  selects_nothing = (opt->box.empty() ? "--rect " + opt->rect : "--box " + opt->box) +
                                    ": selects nothing in the first frame (" + perception.last().message + ")";
                  g_stop = 1;
                }
              };
              const servo::RobotLoopSummary summary =
                  servo::run_on_robot(*source, perception, *robot, setup.loop, options, first_frame);
              lines.close();
              if (!selects_nothing.empty()) {
                std::cerr << "ofv run: " << selects_nothing << '\n';
                return kUsage;
              }
              std::cerr << "ofv run: " << summary.frames << " frames, object lost in " << summary.lost
                        << (summary.stopped ? (user_quit             ? ", stopped from the display"
                                               : lines.reader_gone() ? ", stopped: the output's reader went away"
                                                                     : ", stopped by a signal")
                                            : "")
                        << (summary.bad_frames > 0 ? ", " + std::to_string(summary.bad_frames) + " bad frame(s) skipped" : "")
                        << (options.pose_source ? ", poses " + poses_word(setup) + ": " +
                                                      std::to_string(summary.pose_unknown) +
                                                      " unknown (the robot stopped for each)"
                                                : "")
                        << (summary.watchdog_stops > 0
                                ? "; the watchdog stopped the robot " + std::to_string(summary.watchdog_stops) +
                                      " time(s) while no frame came"
                                : "")
                        << '\n';
              return kOk;
            } catch (const std::invalid_argument& e) {  // a recorded frame that is not what it claims (after the stop line)
              std::cerr << "ofv run: " << e.what() << '\n';
              return kUsage;
            } catch (const std::exception& e) {
              std::cerr << "ofv run: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
