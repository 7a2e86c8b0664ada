// `ofv compare --scenarios FILES|DIR --grid GRID.yaml --out DIR [--seeds N] [--jobs N] [--shard K/N]`
// `ofv compare --merge DIRS --out DIR`: settings compared in closed loop (docs/compare.md).
#include "commands.h"

#include "ofv/loop/compare.h"
#include "ofv/loop/episode.h"
#include "ofv/loop/scenario_set.h"

#include <iostream>
#include <memory>

namespace ofv::cli {

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
  CLI::Option* seeds = sub->add_option("--seeds", opt->seeds, "Seeds per scenario x variant, 1..1000 (default: the grid's)");
  CLI::Option* jobs = sub->add_option("--jobs", opt->jobs, "Episodes in parallel, 1..256 (default: one per core)");
  sub->add_option("--shard", opt->shard, "Run part K of N of the sweep (K/N, 1-based)");
  sub->add_option("--merge", opt->merge, "Merge the outputs of these runs (shards) into --out");
  sub->footer("Writes episodes/ (one .json + .csv per finished episode; a run resumes from them), "
              "episodes.csv, summary.csv, summary.md and plots/*.png.");

  return {sub, [opt, seeds, jobs]() -> int {
            // Usage errors (exit 2) are all found before anything runs or is written.
            std::vector<EpisodeRow> merged;
            std::vector<EpisodeSpec> episodes;
            try {
              if (!opt->merge.empty()) {
                if (!opt->scenarios.empty() || !opt->grid.empty()) {
                  throw std::invalid_argument("--merge takes no --scenarios or --grid");
                }
                merged = load_episodes(opt->merge);
              } else {
                if (opt->scenarios.empty() || opt->grid.empty()) {
                  throw std::invalid_argument("--scenarios and --grid are required (or --merge DIRS)");
                }
                if (jobs->count() > 0 && (opt->jobs < 1 || opt->jobs > kMaxJobs)) {
                  throw std::invalid_argument("--jobs: expected an integer in 1.." + std::to_string(kMaxJobs) +
                                              ", got " + std::to_string(opt->jobs));
                }
                if (seeds->count() > 0 && (opt->seeds < 1 || opt->seeds > kMaxSeeds)) {
                  throw std::invalid_argument("--seeds: expected an integer in 1.." + std::to_string(kMaxSeeds) +
                                              ", got " + std::to_string(opt->seeds));
                }
                Grid grid = read_grid(opt->grid);
                if (seeds->count() > 0) grid.seeds = opt->seeds;
                const auto scenarios = scenario_set(opt->scenarios);
                try {
                  check_sweep_size(scenarios.size(), grid.variants.size(), grid.seeds);
                } catch (const std::invalid_argument& e) {
                  throw std::invalid_argument(opt->grid + (seeds->count() > 0 ? " with --seeds: " : ": ") +
                                              e.what());
                }
                check_grid(scenarios, grid, opt->grid);
                episodes = plan_episodes(scenarios, grid);
                if (!opt->shard.empty()) {
                  const Shard part = parse_shard(opt->shard);
                  episodes = shard(episodes, part.k, part.n);
                }
              }
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv compare: " << e.what() << '\n';
              return kUsage;
            }
            try {
              if (!opt->merge.empty()) {
                const auto plots = write_reports(merged, opt->out);
                std::cout << "ofv compare: merged " << merged.size() << " episodes from " << opt->merge.size()
                          << " runs into " << opt->out << "/summary.md (" << plots.size() << " plots)\n";
                return kOk;
              }
              SweepOptions options;
              options.jobs = jobs->count() > 0 ? opt->jobs : 0;  // 0: one per core
              options.progress = true;   // drawn only on a terminal
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
