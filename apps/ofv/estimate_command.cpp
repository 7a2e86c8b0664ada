// `ofv estimate SCENE.json [--set name=value ...]` (ESTIMATOR-SPEC.md §8).
#include "commands.h"

#include "ofv/estimator.h"
#include "ofv/estimator_settings.h"
#include "ofv/io/scene_json.h"

#include <nlohmann/json.hpp>

#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace ofv::cli {

namespace {

constexpr const char* kSceneHelp = R"(Scene file (metres, world frame):
  {"supervoxels": [{"position": [x,y,z], "normal": [x,y,z]}, ...],   required
   "occluders": [[x,y,z], ...],      points q_b (default none)
   "centroid": [x,y,z],              object centroid C (default: mean of positions)
   "axes": [[e1],[e2],[e3]],         object axes (default: PCA of positions)
   "camera": [x,y,z],                current camera (last fallback of t0)
   "previous_view": [x,y,z],         previous t_f, used with warm_start
   "params": {name: value, ...}}     any setting below

)";

}  // namespace

std::string estimator_settings_help() {
  return "Estimator settings (in \"params\" or with --set name=value; explicit values override the preset):\n" +
         settings_help(estimator_settings_table().docs());
}

namespace {

constexpr const char* kOutputHelp = R"(
Output: one JSON object (t0, tf, status, iterations, initial_view_used, skipped counts,
angular_error_deg) on stdout. Exit 0 ok, 2 bad input, including a scene with no usable
supervoxel and no centroid (one line on stderr).)";

}  // namespace

void apply_sets(EstimatorParams& params, const std::vector<std::string>& assignments) {
  for (const std::string& assignment : assignments) {
    const auto eq = assignment.find('=');
    if (eq == std::string::npos || eq == 0) {
      throw std::invalid_argument("--set " + assignment + ": expected name=value");
    }
    set_param(params, assignment.substr(0, eq), assignment.substr(eq + 1));
  }
}

Command add_estimate_command(CLI::App& app) {
  struct Options {
    std::string scene;
    std::vector<std::string> sets;
    bool path = false;
    bool compact = false;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand(
      "estimate", "Estimate the occlusion-free view of one frame from a scene JSON file");
  sub->add_option("scene", opt->scene, "Scene JSON file")->required();
  sub->add_option("--set", opt->sets, "Override one setting: name=value (repeatable)")
      ->type_name("NAME=VALUE");
  sub->add_flag("--path", opt->path, "Also output every visited iterate ('path')");
  sub->add_flag("--compact", opt->compact, "Print the JSON on one line");
  sub->footer(std::string(kSceneHelp) + estimator_settings_help() + kOutputHelp);

  return {sub, [opt]() -> int {
            try {
              Scene scene = read_scene(opt->scene);
              apply_sets(scene.params, opt->sets);
              EstimateOptions options;
              options.record_path = opt->path;
              ViewEstimate estimate;
              try {
                estimate = estimate_view(scene.problem, scene.params.resolve(), options);
              } catch (const std::invalid_argument& e) {
                throw std::invalid_argument(opt->scene + ": " + e.what());
              }
              if (estimate.status == ViewStatus::NoSupervoxels) {
                // Spec §8: nothing to look at is the scene's fault, not a result.
                const int n = estimate.skipped_supervoxels;
                throw std::invalid_argument(
                    opt->scene + ": no usable supervoxel and no centroid given (" +
                    (n == 0 ? std::string("the scene has no supervoxels")
                            : "none of the " + std::to_string(n) +
                                  " supervoxels has a finite position and a finite, non-zero "
                                  "normal") +
                    ")");
              }
              const auto json = estimate_to_json(estimate);
              std::cout << (opt->compact ? json.dump() : to_pretty_string(json)) << '\n';
              return kOk;
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv estimate: " << e.what() << '\n';
              return kUsage;
            } catch (const std::exception& e) {
              std::cerr << "ofv estimate: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
