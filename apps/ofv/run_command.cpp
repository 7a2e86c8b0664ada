// `ofv run --robot NAME --source SOURCE [--dry-run]`: the closed loop on a
// robot and a sensor: frames → perception → estimator → controller → safety
// filter → robot.
#include "commands.h"

#include "ofv/perception/perception.h"
#include "ofv/servo/controller.h"
#include "ofv/servo/robot.h"
#include "ofv/servo/safety.h"
#include "ofv/servo/target_pose.h"

#include <visp3/core/vpConfig.h>
#include <visp3/core/vpPoseVector.h>
#if defined(VISP_HAVE_VIPER850)
#include <visp3/robot/vpRobotViper850.h>
#endif
#if defined(VISP_HAVE_AFMA6)
#include <visp3/robot/vpRobotAfma6.h>
#endif

#include <chrono>
#include <csignal>
#include <fstream>
#include <iomanip>
#include <iostream>

namespace ofv::cli {

namespace {

volatile std::sig_atomic_t g_stop = 0;
void on_sigint(int) { g_stop = 1; }

// The camera-to-end-effector transform from a file of six numbers:
// tx ty tz [m] thetaux thetauy thetauz [rad] (ViSP's vpPoseVector of eMc).
vpHomogeneousMatrix read_eMc(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot read the eMc file");
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

}  // namespace

Command add_run_command(CLI::App& app) {
  struct Options {
    std::string robot = "camera";
    std::string source;
    std::string emc;
    std::vector<std::string> sets;
    bool dry_run = false;
    double max_speed = 0.25;
    double stale = 0.2;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("run", "Run the closed loop on a robot and a sensor (or a recording, dry run)");
  sub->add_option("--robot", opt->robot,
                   "camera, viper850, afma6 (ViSP kinematic models, no hardware), or a real driver: " + real_drivers())
      ->capture_default_str();
  sub->add_option("--source", opt->source, "Frames: TUM folder, PCD sequence, FILE.oni or openni2://URI")->required();
  sub->add_option("--emc", opt->emc, "File with the camera-end-effector transform eMc: tx ty tz tux tuy tuz");
  sub->add_option("--set", opt->sets, "Estimator setting name=value (repeatable)")->type_name("NAME=VALUE");
  sub->add_flag("--dry-run", opt->dry_run, "Print every command (JSON lines) instead of sending it to hardware");
  sub->add_option("--max-speed", opt->max_speed, "Safety: linear speed limit [m/s]")->capture_default_str();
  sub->add_option("--stale", opt->stale, "Safety: frames older than this stop the robot [s]")->capture_default_str();
  sub->footer("Ctrl-C stops the robot (zero velocity) and exits. The object is picked in the first frame "
              "(the cluster nearest the image centre); when it is lost the robot stops.");

  return {sub, [opt]() -> int {
            std::unique_ptr<FrameSource> source;
            std::unique_ptr<CameraRobot> robot;
            EstimatorSettings settings;
            SafetySettings safety;
            try {
              EstimatorParams params;
              apply_sets(params, opt->sets);
              settings = params.resolve();
              if (!(opt->max_speed > 0.0) || !(opt->stale > 0.0)) throw std::invalid_argument("--max-speed and --stale must be positive");
              safety.max_linear_speed = opt->max_speed;
              safety.stale_timeout = opt->stale;
              vpHomogeneousMatrix eMc;
              if (!opt->emc.empty()) eMc = read_eMc(opt->emc);
              if (opt->robot == "camera" || opt->robot == "viper850" || opt->robot == "afma6") {
                robot = make_robot(opt->robot, vpHomogeneousMatrix());
#if defined(VISP_HAVE_VIPER850)
              } else if (opt->robot == "viper850-real") {
                static vpRobotViper850 driver;
                driver.init(vpViper850::TOOL_CUSTOM, eMc);
                robot = std::make_unique<VispRobot>(driver, vpHomogeneousMatrix(), "viper850-real");
#endif
#if defined(VISP_HAVE_AFMA6)
              } else if (opt->robot == "afma6-real") {
                static vpRobotAfma6 driver;
                driver.init(vpAfma6::TOOL_CUSTOM, eMc);
                robot = std::make_unique<VispRobot>(driver, vpHomogeneousMatrix(), "afma6-real");
#endif
              } else {
                throw std::invalid_argument("--robot " + opt->robot + ": unknown (simulated: camera, viper850, afma6; real drivers: " + real_drivers() + ")");
              }
              source = open_source(opt->source, 1.0f);
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv run: " << e.what() << '\n';
              return kUsage;
            }
            std::signal(SIGINT, on_sigint);
            try {
              PerceptionSettings ps;
              ps.r_sphere = settings.r_sphere;
              ps.supervoxels.seed_resolution = settings.r_seed;
              Perception perception(ps);
              ViewController controller;
              SafetyFilter filter(safety);
              const bool live = opt->source.rfind("openni2://", 0) == 0;
              std::optional<double> last_stamp;
              long frames = 0, lost = 0;
              while (!g_stop) {
                const auto read_at = std::chrono::steady_clock::now();
                std::optional<RgbdFrame> frame = source->next();
                if (!frame) break;
                // Eye-in-hand: a live sensor's pose is the robot's camera pose.
                if (live) frame->wMc = to_eigen(robot->wMc());
                const double dt = last_stamp ? std::max(1e-3, frame->timestamp - *last_stamp) : 1.0 / 30.0;
                last_stamp = frame->timestamp;
                const PerceptionResult r = perception.process(*frame);
                vpColVector v(6, 0.0);
                std::optional<ViewEstimate> e;
                if (r.status != TrackingStatus::Lost) {
                  try {
                    e = estimate_view(r.problem, settings);
                    v = controller.update(e->tf, e->centroid, settings.r_sphere, to_visp(frame->wMc), dt);
                  } catch (const std::invalid_argument&) {
                    e.reset();
                  }
                }
                lost += e ? 0 : 1;
                const double age = std::chrono::duration<double>(std::chrono::steady_clock::now() - read_at).count();
                const vpColVector safe = filter.filter(v, to_visp(frame->wMc), dt, e.has_value(), age);
                if (opt->dry_run) {
                  std::cout << std::setprecision(6) << "{\"frame\": " << frames << ", \"t\": " << frame->timestamp
                            << ", \"status\": \"" << (e ? to_string(e->status) : "object_lost") << "\", \"v\": [";
                  for (unsigned i = 0; i < 6; ++i) std::cout << (i ? ", " : "") << safe[i];
                  std::cout << "], \"safety\": \"" << filter.last_reason() << "\"}\n";
                }
                if (!opt->dry_run || opt->robot == "camera" || opt->robot == "viper850" || opt->robot == "afma6") {
                  (void)robot->step(safe, opt->dry_run ? dt : 0.0);
                }
                ++frames;
              }
              (void)robot->step(vpColVector(6, 0.0), 0.0);  // leave the robot at rest
              std::cerr << "ofv run: " << frames << " frames, object lost in " << lost << (g_stop ? ", stopped by Ctrl-C" : "") << '\n';
              return kOk;
            } catch (const std::exception& e) {
              (void)robot->step(vpColVector(6, 0.0), 0.0);
              std::cerr << "ofv run: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
