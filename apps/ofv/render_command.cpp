// `ofv render SCENARIO --time T [--pose ...] --out DIR`: look at a simulated frame.
#include "commands.h"

#include "ofv/loop/frame_files.h"
#include "ofv/sim/renderer.h"

#include <cmath>
#include <filesystem>
#include <iostream>
#include <memory>
#include <sstream>

namespace ofv::cli {

namespace fs = std::filesystem;

Command add_render_command(CLI::App& app) {
  struct Options {
    std::string scenario = sim::kDefaultScenario;
    double time = 0.0;
    std::vector<double> pose;
    std::string size;
    std::string out = "render";
    std::string cloud;
    bool no_noise = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("render", "Render a simulated RGB-D frame to PNGs (colour, depth, labels)");
  sub->add_option("scenario", opt->scenario, "Scenario file or built-in name")->capture_default_str();
  sub->add_option("--time", opt->time, "Simulated time [s]")->capture_default_str();
  sub->add_option("--pose", opt->pose, "Camera pose wMc: x,y,z [m], theta-u tux,tuy,tuz [rad] (default: the scenario's start)")
      ->delimiter(',')->expected(6);
  sub->add_option("--size", opt->size, "Image size WIDTHxHEIGHT, e.g. 640x480 (default: the scenario's sensor)");
  sub->add_option("--out", opt->out, "Output folder")->capture_default_str();
  sub->add_option("--cloud", opt->cloud, "Also write the world-frame point cloud (.pcd or .ply)");
  sub->add_flag("--no-noise", opt->no_noise, "Render without sensor noise");
  std::string list;
  for (const auto& n : sim::builtin_scenarios()) list += (list.empty() ? "" : ", ") + n;
  sub->footer("Built-in scenarios: " + list);

  return {sub, [opt]() -> int {
            sim::Scenario scenario;
            CameraIntrinsics k;
            Eigen::Isometry3d wMc;
            try {
              scenario = sim::load_scenario(opt->scenario);
              if (!(opt->time >= 0.0) || opt->time > 3600.0) {
                throw std::invalid_argument("--time " + std::to_string(opt->time) + ": expected a time in [0, 3600] s");
              }
              k = scenario.sensor.intrinsics;
              if (!opt->size.empty()) {
                int w = 0, h = 0;
                char x = 0;
                std::istringstream in(opt->size);
                if (!(in >> w >> x >> h) || x != 'x' || w < 8 || h < 8 || w > 4096 || h > 4096) {
                  throw std::invalid_argument("--size " + opt->size + ": expected WIDTHxHEIGHT, e.g. 640x480");
                }
                k.fx *= static_cast<double>(w) / k.width;
                k.fy *= static_cast<double>(h) / k.height;
                k.cx *= static_cast<double>(w) / k.width;
                k.cy *= static_cast<double>(h) / k.height;
                k.width = w;
                k.height = h;
              }
              wMc = scenario.wMc_start;
              if (!opt->pose.empty()) {
                // Embree aborts on non-finite rays: every value finite, positions within 1 km.
                for (std::size_t i = 0; i < opt->pose.size(); ++i) {
                  if (!(std::abs(opt->pose[i]) <= 1e3)) {
                    throw std::invalid_argument("--pose: value " + std::to_string(i + 1) + " is " +
                                                std::to_string(opt->pose[i]) + ", expected a finite number in [-1000, 1000]");
                  }
                }
                const Eigen::Vector3d tu(opt->pose[3], opt->pose[4], opt->pose[5]);
                wMc = Eigen::Isometry3d::Identity();
                if (tu.norm() > 0.0) wMc.linear() = Eigen::AngleAxisd(tu.norm(), tu.normalized()).toRotationMatrix();
                wMc.translation() = Eigen::Vector3d(opt->pose[0], opt->pose[1], opt->pose[2]);
              }
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv render: " << e.what() << '\n';
              return kUsage;
            }
            try {
              sim::Renderer renderer(scenario);
              renderer.set_time(opt->time);
              const long frame_index = std::lround(opt->time * scenario.rate);
              const sim::RenderedFrame r = renderer.render(wMc, frame_index, k, !opt->no_noise);
              const fs::path dir(opt->out);
              (void)write_frame_pictures(dir.string(), r, scenario.sensor.max_depth);
              if (!opt->cloud.empty()) write_world_cloud(r.frame, opt->cloud);
              const sim::ObjectTruth truth = renderer.truth(wMc, scenario.r_sphere());
              std::cout << "wrote " << (dir / "colour.png").string() << ", depth.png, labels.png"
                        << (opt->cloud.empty() ? "" : " and " + opt->cloud) << "\nvisible fraction "
                        << truth.visible_fraction << ", occluders in the sphere " << truth.occluders_in_sphere << '\n';
              return kOk;
            } catch (const std::exception& e) {
              std::cerr << "ofv render: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
