// `ofv perceive SOURCE [--out DIR] [--pictures]`: the perception front end
// and the estimator on every frame of a recording or device. The loop is
// ofv::perception::perceive() and the records ofv/perception/perceive_files.h: this file
// parses the options, calls them and prints.
#include "commands.h"

#include "ofv/estimator.h"
#include "ofv/perception/perceive.h"
#include "ofv/perception/perceive_files.h"
#include "ofv/perception/perception.h"
#include "ofv/sources/open_source.h"
#include "ofv/sources/openni2_source.h"
#include "ofv/sources/sequence_files.h"
#ifdef OFV_HAVE_ODOMETRY
#include "ofv/odometry/evaluation.h"
#include "ofv/odometry/odometry.h"
#endif

#include <algorithm>
#include <filesystem>
#include <map>
#include <iomanip>
#include <sstream>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace fs = std::filesystem;

namespace ofv::cli {

namespace {

constexpr const char* kSourceHelp = R"(Sources:
  DIR                 a TUM RGB-D sequence (depth.txt, rgb.txt, depth/, rgb/, groundtruth.txt;
                      with --poses odometry groundtruth.txt may be left out)
  DIR                 a PCD sequence (*.pcd organised clouds, camera frame, + poses.txt)
  FILE.oni            an OpenNI2 recording (poses from FILE.oni.poses.txt if present)
  openni2://URI       a live OpenNI2 device (openni2:// alone: the first device)

Camera poses (--poses): `source` the source's own (groundtruth.txt, poses.txt, a robot's);
`odometry[:METHOD]` RGB-D odometry from the first frame's pose (METHOD icp (default),
rgbd_icp, fast_icp, rgbd; its settings with --set, `ofv perceive --help-odometry`). With a
source that has poses of its own (a TUM folder's groundtruth.txt), ATE and RPE against them
are printed at the end.

Output: with --out DIR, DIR/frame_NNNNNN.json per frame ({"frame", "timestamp", "status",
"pose" (with --poses odometry: its status and diagnostics), "problem" (a scene for 'ofv
estimate'), "estimate", "counts", "timings_ms"}), DIR/poses.txt (the poses the front end
used, TUM format) and, with --pictures, DIR/frame_NNNNNN.png; without --out, one JSON
object per line on stdout.
A summary goes to stderr. Exit 0 ok, 1 runtime failure, 2 bad input (one line on stderr).
)";

/// What the user asked for, as parsed.
struct Options {
  std::string source;
  std::string out;
  bool pictures = false;
  std::vector<std::string> sets;
  std::string box;
  std::string rect;
  int max_frames = -1;
  float speed = OpenNi2Options{}.playback_speed;
  double voxel = perception::SupervoxelSettings{}.voxel_resolution;
  double obb_margin = perception::PerceptionSettings{}.obb_margin;
  double max_motion = perception::TrackingSettings{}.max_motion;
  bool no_plane_occluders = false;
  std::string poses = "source";
  bool help_odometry = false;
};

/// The words of --poses, for its error message.
constexpr const char* kPosesWords = "source, odometry, odometry:icp, odometry:rgbd_icp, odometry:fast_icp, odometry:rgbd";

/// The camera poses asked for: the source's (false) or odometry (true), and its method in `os`.
/// \throws std::invalid_argument naming --poses and its words.
#ifdef OFV_HAVE_ODOMETRY
bool parse_poses(const std::string& text, odometry::OdometrySettings& os) {
  if (text == "source") return false;
  const std::string prefix = "odometry";
  if (text.rfind(prefix, 0) == 0) {
    if (text.size() == prefix.size()) return true;
    if (text[prefix.size()] == ':') {
      try {
        os.method = odometry::parse_method("--poses", text.substr(prefix.size() + 1));
        return true;
      } catch (const std::invalid_argument&) {
      }
    }
  }
  throw std::invalid_argument("--poses must be one of " + std::string(kPosesWords) + ", got \"" + text + "\"");
}
#else
bool parse_poses(const std::string& text) {
  if (text == "source") return false;
  throw std::invalid_argument("--poses must be source (this ofv was built without OpenCV's rgbd module, "
                              "so without odometry), got \"" + text + "\"");
}
#endif

/// The front end's settings: the options, and the estimator's R_seed and R_sphere.
/// \throws std::invalid_argument naming the option or setting that is invalid.
perception::PerceptionSettings perception_settings(const Options& opt, const EstimatorSettings& settings) {
  perception::PerceptionSettings ps = ofv::perception::perception_settings(settings);
  ps.supervoxels.voxel_resolution = opt.voxel;
  ps.obb_margin = opt.obb_margin;
  ps.tracking.max_motion = opt.max_motion;
  ps.support_plane_occludes = !opt.no_plane_occluders;
  ps.selection = object_selection(opt.box, opt.rect);
  validate(ps);
  return ps;
}

}  // namespace

Command add_perceive_command(CLI::App& app) {
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "perceive", "Run the perception front end and the estimator on every frame of a source");
  sub->add_option("source", opt->source, "TUM directory, PCD sequence, FILE.oni or openni2://URI")
      ->required();
  sub->add_option("--out", opt->out, "Write frame_NNNNNN.json (and .png) into this directory");
  sub->add_flag("--pictures", opt->pictures, "Also draw a PNG per frame (needs --out)");
  sub->add_option("--set", opt->sets,
                  "Estimator or front-end setting name=value (repeatable; `ofv settings`); r_seed and r_sphere "
                  "also set the supervoxel seed resolution and the sphere of the front end")
      ->type_name("NAME=VALUE");
  add_selection_options(*sub, opt->box, opt->rect);
  sub->add_option("--max-frames", opt->max_frames, "Stop after this many frames");
  sub->add_option("--speed", opt->speed,
                  "Playback speed of .oni files: 1 real time (frames past due skipped), 2 twice as fast, 0 or -1 every frame")
      ->capture_default_str();
  sub->add_option("--voxel", opt->voxel, "Voxel resolution [m]")->capture_default_str();
  sub->add_option("--obb-margin", opt->obb_margin, "Augmentation of the object's OBB [m]")
      ->capture_default_str();
  sub->add_option("--max-motion", opt->max_motion, "Largest object motion between frames [m]")
      ->capture_default_str();
  sub->add_flag("--no-plane-occluders", opt->no_plane_occluders,
                "The support plane (found in frame 0) is background, not occluders");
  sub->add_option("--poses", opt->poses,
                  "Camera poses: source (the source's own) or odometry[:icp|rgbd_icp|fast_icp|rgbd]")
      ->capture_default_str();
#ifdef OFV_HAVE_ODOMETRY
  sub->add_flag("--help-odometry", opt->help_odometry, "Print the odometry's settings (for --set) and exit");
#endif
  sub->footer(kSourceHelp);

  return {sub, [opt]() -> int {
#ifdef OFV_HAVE_ODOMETRY
            if (opt->help_odometry) {
              std::cout << settings_help(odometry::odometry_settings_table().docs());
              return kOk;
            }
            odometry::OdometrySettings odometry_settings;
            bool use_odometry = false;
#endif
            std::unique_ptr<FrameSource> source;
            EstimatorParams params;
            EstimatorSettings settings;
            perception::PerceptionSettings ps;
            try {
              if (opt->pictures && opt->out.empty()) {
                throw std::invalid_argument("--pictures needs --out DIR");
              }
              // The front end's own rows (supervoxels, beyond_view, ...) go to
              // it; the others are the estimator's.
              std::vector<std::string> estimator_sets;
              std::vector<std::pair<std::string, std::string>> front_end_sets;
#ifdef OFV_HAVE_ODOMETRY
              use_odometry = parse_poses(opt->poses, odometry_settings);
              std::vector<std::pair<std::string, std::string>> odometry_sets;
#else
              parse_poses(opt->poses);
#endif
              for (const std::string& assignment : opt->sets) {
                const auto eq = assignment.find('=');
                if (eq != std::string::npos && perception::perception_settings_table().find(assignment.substr(0, eq))) {
                  front_end_sets.emplace_back(assignment.substr(0, eq), assignment.substr(eq + 1));
#ifdef OFV_HAVE_ODOMETRY
                } else if (eq != std::string::npos &&
                           odometry::odometry_settings_table().find(assignment.substr(0, eq))) {
                  odometry_sets.emplace_back(assignment.substr(0, eq), assignment.substr(eq + 1));
#endif
                } else {
                  estimator_sets.push_back(assignment);
                }
              }
              apply_sets(params, estimator_sets);
              settings = params.resolve();
              ps = perception_settings(*opt, settings);
              perception::perception_settings_table().apply(ps, front_end_sets);
#ifdef OFV_HAVE_ODOMETRY
              odometry::odometry_settings_table().apply(odometry_settings, odometry_sets);
              odometry::validate(odometry_settings);
#endif
              source = open_source(opt->source, opt->speed, !use_odometry);
              if (!opt->out.empty()) {
                std::error_code ec;
                fs::create_directories(opt->out, ec);
                if (!fs::is_directory(opt->out)) {
                  throw std::invalid_argument(opt->out + ": cannot create the output directory");
                }
              }
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv perceive: " << e.what() << '\n';
              return kUsage;
            } catch (const std::exception& e) {
              // Sources report unreadable paths and absent devices as runtime errors:
              // at start-up they are bad input.
              std::cerr << "ofv perceive: " << e.what() << '\n';
              return kUsage;
            }

            // `ofv perceive ... | head`: a line that cannot be written (EPIPE,
            // SIGPIPE ignored in main) ends the run cleanly, saying why.
            struct ReaderGone {};
            try {
              // The poses the front end used, and the source's own to compare them with.
              std::vector<StampedPose> used, truth;
              std::vector<StampedPose> used_ok;  // of the frames whose pose the pose source could tell
              perception::PoseSource pose_source;
#ifdef OFV_HAVE_ODOMETRY
              std::map<std::string, long> statuses;
              std::vector<double> odometry_ms;
              if (use_odometry) {
                pose_source = [&statuses, &odometry_ms, steps = odometry::odometry_pose_source(odometry_settings)](
                                  const RgbdFrame& frame, const ObjectHint& object) {
                  perception::FramePose pose = steps(frame, object);
                  ++statuses[pose.status];
                  for (const auto& [name, value] : pose.diagnostics) {
                    if (name == "ms") odometry_ms.push_back(value);
                  }
                  return pose;
                };
              }
#endif
              const perception::PerceiveSummary summary = perception::perceive(
                  *source, ps, settings, opt->max_frames, [&](const perception::PerceivedFrame& f) {
                    used.push_back({f.frame.timestamp, f.frame.wMc});
                    if (!f.pose || f.pose->ok) used_ok.push_back(used.back());
                    truth.push_back({f.frame.timestamp, f.source_wMc});
                    if (opt->out.empty()) {
                      std::cout << perception::perceived_frame_json(f, params) << '\n' << std::flush;
                      if (!std::cout) throw ReaderGone{};
                    } else {
                      perception::write_perceived_frame(opt->out, f, params, opt->pictures, settings.r_sphere);
                    }
                  }, pose_source);
              if (!opt->out.empty()) {
                write_pose_file((fs::path(opt->out) / "poses.txt").string(), used,
                                "camera pose wMc the front end used (--poses " + opt->poses + ")");
              }
              std::cerr << "ofv perceive: " << source->describe() << ": " << summary.frames
                        << " frames, " << summary.lost << " lost, front end median "
                        << summary.median_front_end_ms << " ms"
                        << (summary.bad_frames > 0 ? "; " + std::to_string(summary.bad_frames) +
                                                         " bad frame(s) skipped, the last: " + summary.last_bad_frame
                                                   : "")
                        << '\n';
#ifdef OFV_HAVE_ODOMETRY
              if (use_odometry) {
                std::ostringstream text;
                text << std::fixed << std::setprecision(2);
                std::sort(odometry_ms.begin(), odometry_ms.end());
                text << "ofv perceive: odometry " << odometry::to_string(odometry_settings.method) << ": median "
                     << (odometry_ms.empty() ? 0.0 : odometry_ms[odometry_ms.size() / 2]) << " ms/frame;";
                for (const auto status : {odometry::OdometryStatus::Ok, odometry::OdometryStatus::FirstFrame,
                                          odometry::OdometryStatus::Failed, odometry::OdometryStatus::Implausible,
                                          odometry::OdometryStatus::Degenerate}) {
                  const auto n = statuses.find(odometry::to_string(status));
                  if (n != statuses.end()) text << ' ' << n->first << ' ' << n->second;
                }
                std::cerr << text.str() << '\n';
                // ofv's own recordings and TUM sequences carry ground truth.
                if (fs::exists(fs::path(opt->source) / "groundtruth.txt")) {
                  const odometry::TrajectoryErrors e = odometry::trajectory_errors(used, truth);
                  std::ostringstream line;
                  line << std::fixed << std::setprecision(2) << "ofv perceive: against groundtruth.txt (" << e.poses
                       << " poses): ATE " << 1000 * e.ate << " mm (max " << 1000 * e.ate_max
                       << "); RPE per frame " << 1000 * e.per_frame.translation_rmse << " mm (max "
                       << 1000 * e.per_frame.translation_max << "), " << std::setprecision(3)
                       << e.per_frame.rotation_rmse << " deg (max " << e.per_frame.rotation_max
                       << "); per second " << std::setprecision(2) << 1000 * e.per_second.translation_rmse
                       << " mm (max " << 1000 * e.per_second.translation_max << "), " << std::setprecision(3)
                       << e.per_second.rotation_rmse << " deg (max " << e.per_second.rotation_max << ")";
                  // What a user relies on: the frames the odometry called ok (aligned on the first of them).
                  const auto [ok_rmse, ok_max] = odometry::absolute_trajectory_error(used_ok, truth);
                  line << "; frames called ok: " << used_ok.size() << ", their ATE " << std::setprecision(2)
                       << 1000 * ok_rmse << " mm (max " << 1000 * ok_max << ")";
                  std::cerr << line.str() << '\n';
                }
              }
#endif
              if (summary.scored > 0) {
                const auto show = [](const std::optional<double>& x, double scale = 1.0) {
                  std::ostringstream text;
                  text << std::fixed << std::setprecision(3) << scale * x.value_or(0.0);
                  return x ? text.str() : std::string("n/a");
                };
                std::cerr << "ofv perceive: scores over " << summary.scored
                          << " labelled frames (means): object precision " << show(summary.object_precision)
                          << ", recall " << show(summary.object_recall) << "; occluder precision "
                          << show(summary.occluder_precision) << ", recall " << show(summary.occluder_recall)
                          << "; centroid error " << show(summary.centroid_error, 100.0) << " cm\n";
              }
              return kOk;
            } catch (const ReaderGone&) {
              std::cerr << "ofv perceive: stopped: the output's reader went away\n";
              return kOk;
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv perceive: " << e.what() << '\n';
              return kUsage;
            } catch (const std::exception& e) {
              std::cerr << "ofv perceive: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
