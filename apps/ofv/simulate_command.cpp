// `ofv simulate [SCENARIO] [--robot R] [--set name=value ...] [--perception M] [--out DIR]`:
// the closed loop in simulation, with its trajectory, metrics and pictures.
#include "commands.h"

#include "ofv/loop/episode.h"
#include "ofv/loop/episode_files.h"
#include "ofv/loop/progress.h"
#if defined(OFV_HAVE_DISPLAY)
#include "ofv/display/live_display.h"

#include <nlohmann/json.hpp>
#endif

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <optional>


namespace ofv::cli {

namespace fs = std::filesystem;

std::string episode_settings_help() {
  return "Settings (--set name=value; also in scenario files' controller section and in grids):\n" +
         settings_help(episode_settings_table().docs());
}

void refuse_set_against_flag(const std::vector<std::pair<std::string, std::string>>& sets, const std::string& name,
                             const std::string& flag, bool given, const std::string& value) {
  if (!given) return;
  for (const auto& [k, v] : sets) {
    if (k == name && v != value) {
      throw std::invalid_argument("--set " + k + "=" + v + " and " + flag + " " + value +
                                  " set the same setting to different values: give one");
    }
  }
}

Command add_simulate_command(CLI::App& app) {
  struct Options {
    std::string scenario = sim::kDefaultScenario;
    std::string robot;
    std::vector<std::string> sets;
    std::string perception;
    std::string poses;
    std::string out;
    std::string record;
    int seed = 0;
    bool pictures = true;
    bool real_time = false;
    bool video = false;
    bool display = false;
    double display_speed = 1.0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("simulate", "Run the closed loop in simulation: render, perceive, estimate, servo");
  sub->add_option("scenario", opt->scenario, "Scenario file or built-in name")->capture_default_str();
  sub->add_option("--robot", opt->robot, "camera (free-flying), viper850 or afma6 (default: the scenario's)");
  sub->add_option("--set", opt->sets, "Override a setting: name=value (repeatable; the settings are listed below)")
      ->type_name("NAME=VALUE");
  sub->add_option("--perception", opt->perception, "full (the front end, default), labels (the same with the rendered labels in place of segmentation and classification) or ground-truth (the simulator's supervoxels and every occluder in the sphere)");
  sub->add_option("--poses", opt->poses,
                  "The camera pose the front end and the loop get: simulator (the true pose, default) or "
                  "odometry[:icp|rgbd_icp|fast_icp|rgbd] (RGB-D odometry from the first frame's pose; the renderer and "
                  "the metrics keep the true pose; needs perception full or labels): setting poses");
  CLI::Option* seed_flag = sub->add_option("--seed", opt->seed, "The scenario's k-th random world: sensor noise and, for k > 0, occluder timing and placement within the scenario's variation (0 = as written)")->capture_default_str();
  sub->add_option("--out", opt->out, "Output folder (default: out/simulate/SCENARIO)");
  sub->add_flag("!--no-pictures", opt->pictures, "Skip the PNG pictures");
  sub->add_option("--record", opt->record,
                  "Also write every frame the loop saw as a TUM RGB-D sequence in this folder, with the true camera poses "
                  "(also with --poses odometry): 'ofv run --robot camera --source DIR --dry-run' with the same settings replays the same commands");
  sub->add_flag("--video", opt->video, "Also write episode.avi: the scene view and the camera's view, frame by frame (MJPEG)");
  sub->add_flag("--real-time", opt->real_time,
                "Run the arm on ViSP's threaded simulator (vpSimulatorViper850/Afma6) in wall-clock time: a "
                "real-time demo, not exactly repeatable (needs --robot viper850 or afma6)");
#if defined(OFV_HAVE_DISPLAY)
  CLI::Option* display_flag = sub->add_flag("--display", opt->display,
                "Show the loop live in ViSP windows: the camera image with supervoxels, occluders, tracks and the "
                "feature, the scene view, and curves (visible fraction, velocity, feature error). Left click: pause "
                "and resume (not with --real-time); right click or q: end the episode (its files are written, marked ended_by_user). Needs "
                "an X display (exit 2 without one)");
  sub->add_option("--display-speed", opt->display_speed,
                  "With --display: frames shown at this multiple of the scenario's rate (1 = real time, 0 = as fast "
                  "as the loop runs); the episode's results do not depend on it")
      ->capture_default_str()
      ->check(CLI::Range(0.0, 1000.0))
      ->check(CLI::Validator(
          [](const std::string& text) {
            return std::isfinite(std::strtod(text.c_str(), nullptr)) ? std::string() : "not a finite number";
          },
          "", "finite"))
      ->needs(display_flag);
#endif
  std::string list;
  for (const auto& n : sim::builtin_scenarios()) list += (list.empty() ? "" : ", ") + n;
  sub->footer("Built-in scenarios: " + list + "\nWrites trajectory.csv, metrics.json and pictures (camera views and "
              "scene views at the start, when an occluder enters the sphere or the visibility falls below 0.9, 1 s later "
              "and at the end; visibility.png); with --video, episode.avi.\n\n" + episode_settings_help());

  return {sub, [opt, seed_flag]() -> int {
            EpisodeSetup setup;
#if defined(OFV_HAVE_DISPLAY)
            std::unique_ptr<LiveDisplay> display;
#endif
            try {
              const sim::Scenario scenario = sim::load_scenario(opt->scenario);
              std::vector<std::pair<std::string, std::string>> settings;
              if (!opt->robot.empty()) settings.emplace_back("robot", opt->robot);
              if (opt->real_time) settings.emplace_back("real_time", "true");
              if (!opt->perception.empty()) settings.emplace_back("perception", opt->perception);
              if (!opt->poses.empty()) settings.emplace_back("poses", opt->poses);
              settings.emplace_back("seed", std::to_string(opt->seed));
              std::vector<std::pair<std::string, std::string>> sets;
              for (const auto& a : opt->sets) sets.push_back(split_assignment(a));
              refuse_set_against_flag(sets, "robot", "--robot", !opt->robot.empty(), opt->robot);
              refuse_set_against_flag(sets, "perception", "--perception", !opt->perception.empty(), opt->perception);
              refuse_set_against_flag(sets, "poses", "--poses", !opt->poses.empty(), opt->poses);
              refuse_set_against_flag(sets, "seed", "--seed", seed_flag->count() > 0, std::to_string(opt->seed));
              refuse_set_against_flag(sets, "real_time", "--real-time", opt->real_time, "true");
              settings.insert(settings.end(), sets.begin(), sets.end());
              setup = resolve_episode(scenario, settings);
#if defined(OFV_HAVE_DISPLAY)
              if (opt->display) {
                LiveDisplayOptions options;
                options.title = "ofv simulate " + setup.scenario.name;
                options.r_sphere = setup.loop.estimator.resolve().r_sphere;
                options.ground_truth = true;
                // The threaded arms already run in wall-clock time, and run on
                // while the observer waits: no pause with --real-time.
                options.pace_rate = setup.real_time ? 0.0 : opt->display_speed * setup.scenario.rate;
                options.pause = !setup.real_time;
                display = std::make_unique<LiveDisplay>(options);
              }
            } catch (const DisplayUnavailable& e) {
              std::cerr << "ofv simulate: " << e.what() << '\n';
              return kUsage;
#endif
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv simulate: " << e.what() << '\n';
              return kUsage;
            }
            try {
              const fs::path dir = opt->out.empty() ? fs::path("out/simulate") / setup.scenario.name : fs::path(opt->out);
              EpisodeFiles files;
              files.pictures = opt->pictures;
              files.video = opt->video;
              files.record_dir = opt->record;
              EpisodeWriter writer(dir.string(), setup, files);
              ProgressBar progress(setup.duration, "s of the episode");
              // The user ending the episode from the display: thrown by the
              // observer out of run_episode, with the steps seen so far.
              struct EndedByUser {};
              std::vector<StepRecord> seen;
              EpisodeOutcome outcome;
              bool ended_by_user = false;
              try {
                outcome = run_episode(setup, [&](const StepRecord& rec, const StepDetail& d) {
                  writer.observe(rec, d);
                  progress.set(rec.time);
#if defined(OFV_HAVE_DISPLAY)
                  if (display) {
                    seen.push_back(rec);
                    if (!display->observe(rec, d)) throw EndedByUser{};
                  }
#endif
                });
              } catch (const EndedByUser&) {
                ended_by_user = true;
                outcome.steps = std::move(seen);
                outcome.metrics = summarise(outcome.steps);
              }
              const std::vector<std::string> written = writer.finish(outcome);
              (void)ended_by_user;
#if defined(OFV_HAVE_DISPLAY)
              if (ended_by_user) {  // metrics.json says so, with the duration asked for
                const fs::path metrics = dir / "metrics.json";
                nlohmann::json j = nlohmann::json::parse(std::ifstream(metrics));
                j["ended_by_user"] = true;
                j["planned_duration"] = setup.duration;
                std::ofstream(metrics) << j.dump(2) << '\n';
                std::cout << "ofv simulate: ended by the user at t=" << outcome.metrics.duration << " s\n";
              }
#endif
              std::cout << "ofv simulate: " << setup.scenario.name << ", robot " << to_string(setup.robot) << ", "
                        << to_string(setup.loop.method)
                        << (setup.loop.method == ViewMethod::Hindsight ? std::string(" (no perception: the plan)")
                                                                       : ", perception " + std::string(to_string(setup.perception)))
                        << (setup.poses == PoseOrigin::Frame ? std::string() : ", poses " + poses_word(setup)) << '\n'
                        << episode_summary(outcome.metrics) << "  wrote " << written.size() << " files in " << dir.string()
                        << " (trajectory.csv, metrics.json ...)";
              if (!opt->record.empty()) std::cout << "; frames recorded in " << opt->record;
              std::cout << '\n';
              return kOk;
            } catch (const std::exception& e) {
              std::cerr << "ofv simulate: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
