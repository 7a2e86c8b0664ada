// `ofv simulate [SCENARIO] [--robot R] [--set name=value ...] [--perception M] [--out DIR]`:
// the closed loop in simulation, with its trajectory, metrics and pictures.
#include "commands.h"

#include "ofv/loop/episode.h"
#include "ofv/loop/metrics_json.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/videoio.hpp>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <memory>
#include <sstream>

#include <unistd.h>

namespace ofv::cli {

namespace {

namespace fs = std::filesystem;

// Pinhole projection of a world point for drawing; nullopt behind the camera.
std::optional<cv::Point> project(const Eigen::Isometry3d& wMc, const CameraIntrinsics& k,
                                 const Eigen::Vector3d& p) {
  const Eigen::Vector3d c = wMc.inverse() * p;
  if (c.z() <= 1e-3) return std::nullopt;
  return cv::Point(static_cast<int>(std::lround(k.fx * c.x() / c.z() + k.cx)),
                   static_cast<int>(std::lround(k.fy * c.y() / c.z() + k.cy)));
}

// The camera's image with the true centroid (+) and the chosen target drawn on it.
cv::Mat camera_picture(const StepRecord& rec, const StepDetail& d) {
  const CameraIntrinsics& k = d.frame->intrinsics;
  cv::Mat rgb(k.height, k.width, CV_8UC3, const_cast<std::uint8_t*>(d.frame->rgb.data()));
  cv::Mat img;
  cv::cvtColor(rgb, img, cv::COLOR_RGB2BGR);
  if (auto c = project(rec.wMc, k, d.true_centroid)) {
    cv::drawMarker(img, *c, {255, 255, 255}, cv::MARKER_CROSS, 14, 2);
  }
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "t=" << rec.time << "s  visible " << rec.visible_fraction
       << "  " << rec.status;
  cv::putText(img, text.str(), {6, 16}, cv::FONT_HERSHEY_SIMPLEX, 0.42, {255, 255, 255}, 1, cv::LINE_AA);
  return img;
}

// A Fig. 6-style view of the scene from a virtual observer beside the camera:
// object supervoxels and normals (blue), occluders (red), the sphere, C, the
// real camera and its path (white), t0 (yellow), tf (green) and, where
// target hysteresis kept another, the target the controller follows (magenta).
cv::Mat scene_picture(const StepRecord& rec, const StepDetail& d,
                      const std::vector<Eigen::Vector3d>& path, double r_sphere) {
  const Eigen::Vector3d c = d.estimate ? d.estimate->centroid : d.true_centroid;
  const Eigen::Vector3d eye = c + Eigen::Vector3d(0.9, -0.7, -0.6);
  const Eigen::Vector3d z = (c - eye).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d(0, 1, 0).cross(z).normalized();
  Eigen::Isometry3d wMo = Eigen::Isometry3d::Identity();
  wMo.linear() << x, z.cross(x), z;
  wMo.translation() = eye;
  const CameraIntrinsics k{640, 480, 520.0, 520.0, 320.0, 240.0};
  cv::Mat img(k.height, k.width, CV_8UC3, cv::Scalar(30, 30, 30));
  auto p = [&](const Eigen::Vector3d& w) { return project(wMo, k, w); };
  // The sphere's outline: great circles in three planes.
  for (int axis = 0; axis < 3; ++axis) {
    std::optional<cv::Point> prev;
    for (int s = 0; s <= 72; ++s) {
      const double a = 2.0 * 3.14159265358979 * s / 72;
      Eigen::Vector3d q = Eigen::Vector3d::Zero();
      q((axis + 1) % 3) = std::cos(a);
      q((axis + 2) % 3) = std::sin(a);
      const auto pt = p(c + r_sphere * q);
      if (pt && prev) cv::line(img, *prev, *pt, {90, 90, 90}, 1, cv::LINE_AA);
      prev = pt;
    }
  }
  if (d.problem) {
    for (Eigen::Index i = 0; i < d.problem->positions.cols(); ++i) {
      const auto a = p(d.problem->positions.col(i));
      const auto b = p(d.problem->positions.col(i) + 0.03 * d.problem->normals.col(i).normalized());
      if (a) cv::circle(img, *a, 2, {255, 160, 60}, cv::FILLED);
      if (a && b) cv::line(img, *a, *b, {200, 120, 60}, 1, cv::LINE_AA);
    }
    for (Eigen::Index i = 0; i < d.problem->occluders.cols(); ++i) {
      if (const auto a = p(d.problem->occluders.col(i))) cv::rectangle(img, *a - cv::Point(2, 2), *a + cv::Point(2, 2), {60, 60, 230}, cv::FILLED);
    }
  }
  for (std::size_t i = 1; i < path.size(); ++i) {
    const auto a = p(path[i - 1]), b = p(path[i]);
    if (a && b) cv::line(img, *a, *b, {220, 220, 220}, 1, cv::LINE_AA);
  }
  auto mark = [&](const Eigen::Vector3d& w, const cv::Scalar& colour, const char* label) {
    if (const auto a = p(w)) {
      cv::circle(img, *a, 6, colour, 2, cv::LINE_AA);
      cv::putText(img, label, *a + cv::Point(8, -6), cv::FONT_HERSHEY_SIMPLEX, 0.5, colour, 1, cv::LINE_AA);
    }
  };
  mark(c, {255, 255, 255}, "C");
  mark(rec.wMc.translation(), {255, 255, 255}, "t_real");
  if (d.estimate) {
    mark(d.estimate->t0, {0, 220, 255}, "t0");
    mark(d.estimate->tf, {80, 220, 80}, "tf");
    if ((d.target - d.estimate->tf).norm() > 1e-3) mark(d.target, {220, 80, 220}, "target");
  }
  std::ostringstream text;
  text << std::fixed << std::setprecision(2) << "t=" << rec.time << " s   visible " << rec.visible_fraction
       << "   status " << rec.status;
  cv::putText(img, text.str(), {10, 22}, cv::FONT_HERSHEY_SIMPLEX, 0.55, {255, 255, 255}, 1, cv::LINE_AA);
  return img;
}

// Visibility and distance error over time, drawn by gnuplot.
bool plot_visibility(const fs::path& dir) {
  const fs::path script = dir / "visibility.gp";
  std::ofstream gp(script);
  gp << "set terminal pngcairo size 900,420 font 'Sans,10'\nset output '" << (dir / "visibility.png").string()
     << "'\nset datafile separator ','\nset grid\nset xlabel 'time [s]'\nset ylabel 'visible fraction'\n"
        "set y2label 'distance to the sphere [cm]'\nset ytics nomirror\nset y2tics\nset yrange [0:1.05]\n"
        "set key bottom right\nplot '" << (dir / "trajectory.csv").string()
     << "' using \"time\":\"visible_fraction\" with lines lw 2 title 'true visible fraction', '' using \"time\":(100*column(\"sphere_distance_error\")) axes x1y2 with lines title 'distance error [cm]'\n";
  gp.close();
  return std::system(("gnuplot '" + script.string() + "' 2>/dev/null").c_str()) == 0;
}

}  // namespace

Command add_simulate_command(CLI::App& app) {
  struct Options {
    std::string scenario = sim::kDefaultScenario;
    std::string robot;
    std::vector<std::string> sets;
    std::string perception;
    std::string out;
    int seed = 0;
    bool pictures = true;
    bool real_time = false;
    bool video = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("simulate", "Run the closed loop in simulation: render, perceive, estimate, servo");
  sub->add_option("scenario", opt->scenario, "Scenario file or built-in name")->capture_default_str();
  sub->add_option("--robot", opt->robot, "camera (free-flying), viper850 or afma6 (default: the scenario's)");
  sub->add_option("--set", opt->sets, "Override a setting: name=value (repeatable): any estimator setting, "
                                      "method, controller, gain, max_linear_speed, max_angular_speed, "
                                      "sampling_candidates, duration, seed ...")->type_name("NAME=VALUE");
  sub->add_option("--perception", opt->perception,
#ifdef OFV_HAVE_PERCEPTION
                  "full (PCL front end, default) or ground-truth (the simulator's supervoxels)"
#else
                  "ground-truth (default; this build has no perception front end) or full"
#endif
  );
  sub->add_option("--seed", opt->seed, "The scenario's k-th random world: sensor noise and, for k > 0, occluder timing and placement within the scenario's variation (0 = as written)")->capture_default_str();
  sub->add_option("--out", opt->out, "Output folder (default: out/simulate/SCENARIO)");
  sub->add_flag("!--no-pictures", opt->pictures, "Skip the PNG pictures");
  sub->add_flag("--video", opt->video, "Also write episode.avi: the scene view and the camera's view, frame by frame (MJPEG)");
  sub->add_flag("--real-time", opt->real_time,
                "Run the arm on ViSP's threaded simulator (vpSimulatorViper850/Afma6) in wall-clock time: a "
                "real-time demo, not exactly repeatable (needs --robot viper850 or afma6)");
  std::string list;
  for (const auto& n : sim::builtin_scenarios()) list += (list.empty() ? "" : ", ") + n;
  sub->footer("Built-in scenarios: " + list + "\nWrites trajectory.csv, metrics.json and pictures (camera views and "
              "scene views at the start, when an occluder enters the sphere or the visibility falls below 0.9, 1 s later "
              "and at the end; visibility.png); with --video, episode.avi.");

  return {sub, [opt]() -> int {
            EpisodeSetup setup;
            try {
              const sim::Scenario scenario = sim::load_scenario(opt->scenario);
              std::vector<std::pair<std::string, std::string>> settings;
              for (const auto& a : opt->sets) {
                const auto eq = a.find('=');
                if (eq == std::string::npos || eq == 0) throw std::invalid_argument("--set " + a + ": expected name=value");
                settings.emplace_back(a.substr(0, eq), a.substr(eq + 1));
              }
              if (!opt->robot.empty()) settings.emplace_back("robot", opt->robot);
              if (opt->real_time) settings.emplace_back("real_time", "true");
#ifdef OFV_HAVE_PERCEPTION
              settings.emplace_back("perception", opt->perception.empty() ? "full" : opt->perception);
#else
              settings.emplace_back("perception", opt->perception.empty() ? "ground-truth" : opt->perception);
#endif
              if (opt->seed < 0) throw std::invalid_argument("--seed must be >= 0");
              settings.emplace_back("seed", std::to_string(opt->seed));
              setup = resolve_episode(scenario, settings);
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv simulate: " << e.what() << '\n';
              return kUsage;
            }
            try {
              const fs::path dir = opt->out.empty() ? fs::path("out/simulate") / setup.scenario.name : fs::path(opt->out);
              fs::create_directories(dir);
              const bool tty = isatty(2) != 0;
              const long total = static_cast<long>(std::floor(setup.duration * setup.scenario.rate + 1e-9)) + 1;
              std::vector<Eigen::Vector3d> path;
              std::vector<std::string> pictures;
              long index = 0, picture_at = 0;
              int last_occluders = 0;
              double last_visible = 1.0;
              cv::VideoWriter video;
              if (opt->video) {
                const fs::path file = dir / "episode.avi";
                video.open(file.string(), cv::VideoWriter::fourcc('M', 'J', 'P', 'G'), setup.scenario.rate, {1280, 480});
                if (!video.isOpened()) throw std::runtime_error("cannot write the video " + file.string());
              }
              const auto observer = [&](const StepRecord& rec, const StepDetail& d) {
                path.push_back(rec.wMc.translation());
                // Key moments: an occluder enters the sphere, the visibility falls below 0.9.
                const bool onset = rec.occluders_in_sphere > last_occluders || (rec.visible_fraction < 0.9 && last_visible >= 0.9);
                last_occluders = rec.occluders_in_sphere;
                last_visible = rec.visible_fraction;
                if (onset) picture_at = index + static_cast<long>(setup.scenario.rate);  // 1 s later
                const bool picture = opt->pictures && (index == 0 || onset || index == picture_at || index == total - 1);
                if (picture || opt->video) {
                  const cv::Mat camera = camera_picture(rec, d);
                  const cv::Mat scene = scene_picture(rec, d, path, setup.estimator.r_sphere);
                  if (picture) {
                    char name[64];
                    std::snprintf(name, sizeof name, "t%05.2f", rec.time);
                    cv::imwrite((dir / (std::string("camera_") + name + ".png")).string(), camera);
                    cv::imwrite((dir / (std::string("scene_") + name + ".png")).string(), scene);
                    pictures.push_back(std::string("scene_") + name + ".png");
                  }
                  if (opt->video) {
                    cv::Mat frame(480, 1280, CV_8UC3);
                    scene.copyTo(frame(cv::Rect(0, 0, 640, 480)));
                    cv::resize(camera, frame(cv::Rect(640, 0, 640, 480)), {640, 480});
                    video.write(frame);
                  }
                }
                ++index;
                if (tty) {
                  const int filled = static_cast<int>(30 * index / total);
                  std::fprintf(stderr, "\r[%s%s] %.2f s / %.2f s  visible %.2f ", std::string(static_cast<std::size_t>(filled), '#').c_str(),
                               std::string(static_cast<std::size_t>(30 - filled), '.').c_str(), rec.time, setup.duration, rec.visible_fraction);
                  if (index == total) std::fprintf(stderr, "\n");
                }
              };
              const EpisodeOutcome outcome = run_episode(setup, observer);
              {
                std::ofstream csv(dir / "trajectory.csv");
                csv << trajectory_csv_header() << '\n';
                for (const auto& s : outcome.steps) csv << trajectory_csv_row(s) << '\n';
              }
              nlohmann::json j = metrics_to_json(outcome.metrics);
              j["scenario"] = setup.scenario.name;
              j["method"] = to_string(setup.method);
              j["robot"] = setup.robot;
              j["perception"] = setup.perception == PerceptionMode::Full ? "full" : "ground-truth";
              std::ofstream(dir / "metrics.json") << j.dump(2) << '\n';
              const bool plotted = opt->pictures && plot_visibility(dir);

              const EpisodeMetrics& m = outcome.metrics;
              std::cout << std::fixed << std::setprecision(3) << "ofv simulate: " << setup.scenario.name << ", "
                        << m.duration << " s, " << m.steps << " steps, robot " << setup.robot << ", "
                        << to_string(setup.method) << ", perception "
                        << (setup.perception == PerceptionMode::Full ? "full" : "ground-truth") << '\n'
                        << "  visible fraction: mean " << m.mean_visible_fraction << ", min "
                        << m.min_visible_fraction << ", below 0.9 for " << m.time_below_threshold << " s\n"
                        << "  occlusions (visible < 0.9): " << m.occlusions.size();
              if (!m.occlusions.empty()) {
                std::cout << ", worst recovery ";
                if (m.max_recovery_time) {
                  std::cout << *m.max_recovery_time << " s";
                } else {
                  std::cout << "never (" << m.unrecovered_occlusions << " still hidden at the end)";
                }
              }
              std::cout << "\n  distance to the sphere: max " << 100.0 * m.max_sphere_distance_error << " cm; path "
                        << m.path_length << " m; mean angular error " << m.mean_angular_error_deg << " deg\n"
                        << "  compute per step: " << 1e3 * m.mean_times.total() << " ms (render "
                        << 1e3 * m.mean_times.render << ", perception " << 1e3 * m.mean_times.perception
                        << ", estimate " << 1e3 * m.mean_times.estimate << ", control " << 1e3 * m.mean_times.control
                        << ")\n  wrote " << (dir / "trajectory.csv").string() << ", metrics.json"
                        << (plotted ? ", visibility.png" : "") << (opt->video ? ", episode.avi" : "");
              if (!pictures.empty()) std::cout << " and " << pictures.size() << " scene/camera pictures (" << pictures.front() << " ...)";
              std::cout << '\n';
              return kOk;
            } catch (const std::exception& e) {
              std::cerr << "ofv simulate: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
