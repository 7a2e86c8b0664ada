//! \example tutorial-compare-settings.cpp
//! Tutorial 5: compare estimator settings in closed loop, with a baseline
//! beside them, the way `ofv compare` does.
//!
//!     tutorial-compare-settings [OUT_DIR] [--seeds N] [--duration S]
//!
//! From the command line the same comparison is
//!
//!     ofv compare --scenarios sim/scenarios/dvd-one-hand.yaml sim/scenarios/sweep.yaml
//!                 --grid my-grid.yaml --seeds 2 --jobs 2 --out OUT_DIR
//!
//! with my-grid.yaml holding the variants below (docs/compare.md).
#include <ofv/loop/compare.h>
#include <ofv/loop/episode.h>

#include <cstring>
#include <fstream>
#include <iostream>
#include <string>

int main(int argc, char** argv) {
  std::string out = "out/tutorial-compare";
  int seeds = 2;
  std::string duration = "4";
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--seeds") == 0 && i + 1 < argc) {
      seeds = std::atoi(argv[++i]);
    } else if (std::strcmp(argv[i], "--duration") == 0 && i + 1 < argc) {
      duration = argv[++i];
    } else {
      out = argv[i];
    }
  }
  try {
    // 1. The grid: named variants, each a list of settings by name — any
    //    estimator setting of the spec, the view method (baselines), the
    //    controller, the perception mode, the robot. Every variant runs every
    //    scenario with the same seeds, so only the method differs.
    ofv::Grid grid;
    grid.seeds = seeds;  // seed k > 0 also delays and moves the occluders (scenario `variation`)
    grid.variants = {
        {"paper", {{"preset", "paper"}}},
        {"push_radius=r_seed", {{"push_radius", "r_seed"}}},  // the paper's other reading
        {"t0_only", {{"method", "initial_view"}}},            // occlusion-blind baseline
    };
    for (auto& v : grid.variants) {
      v.settings.emplace_back("duration", duration);
      v.settings.emplace_back("perception", "ground-truth");  // the simulator's supervoxels: only the method differs
    }

    // 2. The scenarios: built-in ones by name, or your own YAML files.
    std::vector<std::pair<std::string, std::string>> scenarios;
    for (const char* name : {"dvd-one-hand", "sweep"}) {
      const ofv::sim::Scenario s = ofv::sim::load_scenario(name);  // resolves built-in names to their file
      scenarios.emplace_back(s.name, s.path);
    }

    // 3. Run every scenario x variant x seed in parallel. Each finished
    //    episode is written at once under OUT_DIR/episodes, so running the
    //    tutorial again resumes instead of starting over.
    const std::vector<ofv::EpisodeSpec> episodes = ofv::plan_episodes(scenarios, grid);
    ofv::SweepOptions options;
    options.jobs = 2;
    const int ran = ofv::run_sweep(episodes, ofv::simulation_runner(), out, options);
    std::cout << episodes.size() << " episodes, " << ran << " run now, "
              << episodes.size() - static_cast<std::size_t>(ran) << " already done\n";

    // 4. Aggregate: episodes.csv, summary.md/csv (mean and 95 % interval over
    //    seeds) and the plots.
    const std::vector<ofv::EpisodeRow> rows = ofv::load_episodes({out});
    const std::vector<std::string> plots = ofv::write_reports(rows, out);
    std::cout << std::ifstream(out + "/summary.md").rdbuf() << "\nplots: " << plots.size() << " in " << out << '\n';

    // 5. Use the rows directly, e.g. the paper's reading against the baseline.
    double paper = 0.0, blind = 0.0;
    for (const auto& r : rows) {
      if (r.spec.variant.name == "paper") paper += r.metrics.mean_visible_fraction;
      if (r.spec.variant.name == "t0_only") blind += r.metrics.mean_visible_fraction;
    }
    std::cout << "mean visible fraction: paper " << paper / static_cast<double>(rows.size() / 3) << ", t0 only "
              << blind / static_cast<double>(rows.size() / 3) << '\n';
    return paper > blind ? 0 : 1;
  } catch (const std::exception& e) {
    std::cerr << "tutorial-compare-settings: " << e.what() << '\n';
    return 2;
  }
}
