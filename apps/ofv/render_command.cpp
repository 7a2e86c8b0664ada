// `ofv render SCENARIO --time T [--pose ...] --out DIR`: look at a simulated frame.
#include "commands.h"

#include "ofv/sim/renderer.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>

namespace ofv::cli {

namespace {

namespace fs = std::filesystem;

// A distinct colour per label (object blue, interacting green, table brown, occluders red hues).
cv::Vec3b label_colour(std::uint16_t label) {
  switch (label) {
    case sim::kLabelNone: return {0, 0, 0};
    case sim::kLabelObject: return {220, 90, 30};
    case sim::kLabelInteracting: return {60, 200, 60};
    case sim::kLabelBackground: return {90, 110, 140};
    default: {
      const int k = label - sim::kLabelOccluder0;
      return {static_cast<uchar>(40 + 50 * (k % 3)), static_cast<uchar>(40 * (k % 4)), 230};
    }
  }
}

void write_cloud(const RgbdFrame& f, const std::string& path) {
  struct Point { Eigen::Vector3d p; const std::uint8_t* rgb; };
  std::vector<Point> points;
  const CameraIntrinsics& k = f.intrinsics;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const std::size_t i = f.index(u, v);
      const double z = f.depth[i];
      if (!(z > 0.0)) continue;
      const Eigen::Vector3d pc((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z);
      points.push_back({f.wMc * pc, &f.rgb[3 * i]});
    }
  }
  std::ofstream out(path);
  if (!out) throw std::runtime_error("cannot write " + path);
  const bool ply = fs::path(path).extension() == ".ply";
  if (ply) {
    out << "ply\nformat ascii 1.0\nelement vertex " << points.size()
        << "\nproperty float x\nproperty float y\nproperty float z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nend_header\n";
  } else {
    out << "# .PCD v0.7 - Point Cloud Data file format\nVERSION 0.7\nFIELDS x y z rgb\n"
           "SIZE 4 4 4 4\nTYPE F F F U\nCOUNT 1 1 1 1\nWIDTH " << points.size()
        << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size() << "\nDATA ascii\n";
  }
  for (const auto& pt : points) {
    out << static_cast<float>(pt.p.x()) << ' ' << static_cast<float>(pt.p.y()) << ' '
        << static_cast<float>(pt.p.z()) << ' ';
    if (ply) {
      out << int(pt.rgb[0]) << ' ' << int(pt.rgb[1]) << ' ' << int(pt.rgb[2]) << '\n';
    } else {
      out << ((std::uint32_t(pt.rgb[0]) << 16) | (std::uint32_t(pt.rgb[1]) << 8) | pt.rgb[2]) << '\n';
    }
  }
}

}  // namespace

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
              if (!(opt->time >= 0.0)) throw std::invalid_argument("--time must be >= 0");
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
              fs::create_directories(opt->out);
              cv::Mat rgb(k.height, k.width, CV_8UC3, const_cast<std::uint8_t*>(r.frame.rgb.data()));
              cv::Mat bgr;
              cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
              cv::Mat depth(k.height, k.width, CV_32F, const_cast<float*>(r.frame.depth.data()));
              cv::Mat scaled, coloured;
              depth.convertTo(scaled, CV_8U, -255.0 / scenario.sensor.max_depth, 255.0);
              cv::applyColorMap(scaled, coloured, cv::COLORMAP_TURBO);
              coloured.setTo(cv::Scalar(0, 0, 0), depth <= 0.0f);
              cv::Mat labels(k.height, k.width, CV_8UC3);
              for (int v = 0; v < k.height; ++v) {
                for (int u = 0; u < k.width; ++u) labels.at<cv::Vec3b>(v, u) = label_colour(r.labels[r.frame.index(u, v)]);
              }
              const fs::path dir(opt->out);
              cv::imwrite((dir / "colour.png").string(), bgr);
              cv::imwrite((dir / "depth.png").string(), coloured);
              cv::imwrite((dir / "labels.png").string(), labels);
              if (!opt->cloud.empty()) write_cloud(r.frame, opt->cloud);
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
