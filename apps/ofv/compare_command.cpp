// `ofv compare --scenarios FILES|DIR --grid GRID.yaml --out DIR [--seeds N] [--jobs N] [--shard K/N]`
// `ofv compare --merge DIRS --out DIR`: settings compared in closed loop (docs/compare.md).
#include "commands.h"

#include "ofv/loop/compare.h"
#include "ofv/loop/episode.h"

#include <filesystem>
#include <iostream>
#include <memory>
#include <thread>

#include <unistd.h>

namespace ofv::cli {

namespace {

namespace fs = std::filesystem;

// Scenario names and paths from files, folders (their *.yaml) and built-in names.
std::vector<std::pair<std::string, std::string>> scenario_list(const std::vector<std::string>& args) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& a : args) {
    if (fs::is_directory(a)) {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(a)) {
        if (e.path().extension() == ".yaml") files.push_back(e.path());
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) throw std::invalid_argument("--scenarios " + a + ": no .yaml scenario in this folder");
      for (const auto& f : files) out.emplace_back(f.stem().string(), f.string());
    } else {
      const sim::Scenario s = sim::load_scenario(a);  // validates, and resolves built-in names
      out.emplace_back(s.name, s.path);
    }
  }
  return out;
}

}  // namespace

Command add_compare_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> scenarios;
    std::string grid;
    std::string out;
    int seeds = 0;
    int jobs = 0;
    std::string shard;
    std::vector<std::string> merge;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("compare", "Compare estimator settings and baselines in closed loop");
  sub->add_option("--scenarios", opt->scenarios, "Scenario files, folders of them, or built-in names");
  sub->add_option("--grid", opt->grid, "Settings grid (YAML, see docs/compare.md)");
  sub->add_option("--out", opt->out, "Output folder")->required();
  sub->add_option("--seeds", opt->seeds, "Seeds per scenario x variant (default: the grid's)");
  sub->add_option("--jobs", opt->jobs, "Episodes in parallel (default: all cores)");
  sub->add_option("--shard", opt->shard, "Run part K of N of the sweep (K/N, 1-based)");
  sub->add_option("--merge", opt->merge, "Merge the outputs of these runs (shards) into --out");
  sub->footer("Writes episodes/ (one .json + .csv per finished episode; a run resumes from them), "
              "episodes.csv, summary.csv, summary.md and plots/*.png.");

  return {sub, [opt]() -> int {
            std::vector<EpisodeSpec> episodes;
            try {
              if (!opt->merge.empty()) {
                if (!opt->scenarios.empty() || !opt->grid.empty()) {
                  throw std::invalid_argument("--merge takes no --scenarios or --grid");
                }
                const auto rows = load_episodes(opt->merge);
                const auto plots = write_reports(rows, opt->out);
                std::cout << "ofv compare: merged " << rows.size() << " episodes from " << opt->merge.size()
                          << " runs into " << opt->out << "/summary.md (" << plots.size() << " plots)\n";
                return kOk;
              }
              if (opt->scenarios.empty() || opt->grid.empty()) {
                throw std::invalid_argument("--scenarios and --grid are required (or --merge DIRS)");
              }
              Grid grid = read_grid(opt->grid);
              if (opt->seeds < 0) throw std::invalid_argument("--seeds must be >= 1");
              if (opt->seeds > 0) grid.seeds = opt->seeds;
              const auto scenarios = scenario_list(opt->scenarios);
              // Every variant's settings must be valid on every scenario before anything runs.
              for (const auto& [name, path] : scenarios) {
                const sim::Scenario s = sim::load_scenario(path);
                for (const auto& v : grid.variants) {
                  try {
                    (void)resolve_episode(s, v.settings);
                  } catch (const std::invalid_argument& e) {
                    throw std::invalid_argument(opt->grid + ": variant '" + v.name + "': " + e.what());
                  }
                }
              }
              episodes = plan_episodes(scenarios, grid);
              if (!opt->shard.empty()) {
                int k = 0, n = 0;
                char slash = 0;
                std::istringstream in(opt->shard);
                if (!(in >> k >> slash >> n) || slash != '/' || !in.eof()) {
                  throw std::invalid_argument("--shard " + opt->shard + ": expected K/N, e.g. 2/8");
                }
                episodes = shard(episodes, k, n);
              }
              if (opt->jobs < 0) throw std::invalid_argument("--jobs must be >= 1");
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv compare: " << e.what() << '\n';
              return kUsage;
            }
            try {
              SweepOptions options;
              options.jobs = opt->jobs > 0 ? opt->jobs : std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
              options.progress = isatty(2) != 0;
              const int ran = run_sweep(episodes, simulation_runner(), opt->out, options);
              const auto rows = load_episodes({opt->out});
              const auto plots = write_reports(rows, opt->out);
              std::cout << "ofv compare: " << episodes.size() << " episodes (" << ran << " run, "
                        << episodes.size() - static_cast<std::size_t>(ran) << " resumed); tables in " << opt->out
                        << "/summary.md, " << plots.size() << " plots in " << opt->out << "/plots\n";
              return kOk;
            } catch (const std::exception& e) {
              std::cerr << "ofv compare: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
