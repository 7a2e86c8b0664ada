// `ofv compare --scenarios FILES|DIR --grid GRID.yaml --out DIR [--seeds N] [--jobs N] [--shard K/N]`
// `ofv compare --merge DIRS --out DIR`: settings compared in closed loop (docs/compare.md).
#include "commands.h"

#include "ofv/loop/cluster_scripts.h"
#include "ofv/loop/compare.h"
#include "ofv/loop/episode.h"
#include "ofv/loop/scenario_set.h"

#include <filesystem>
#include <iostream>
#include <memory>
#include <optional>

namespace ofv::cli {

namespace fs = std::filesystem;

Command add_compare_command(CLI::App& app) {
  struct Options {
    std::vector<std::string> scenarios;
    std::string grid;
    std::string out;
    int seeds = 0;
    int jobs = 0;
    std::string shard;
    std::vector<std::string> merge;
    bool dry_run = false;
    int slurm_parts = 0;
  };
  auto opt = std::make_shared<Options>();
  CLI::App* sub = app.add_subcommand("compare", "Compare estimator settings and baselines in closed loop");
  sub->add_option("--scenarios", opt->scenarios, "Scenario files, folders of them, or built-in names");
  sub->add_option("--grid", opt->grid, "Settings grid (YAML, see docs/compare.md)");
  sub->add_option("--out", opt->out, "Output folder (not with --dry-run)");
  CLI::Option* seeds = sub->add_option("--seeds", opt->seeds, "Seeds per scenario x variant, 1..1000 (default: the grid's)");
  CLI::Option* jobs = sub->add_option("--jobs", opt->jobs, "Episodes in parallel, 1..256 (default: one per core)");
  sub->add_option("--shard", opt->shard, "Run part K of N of the sweep (K/N, 1-based)");
  sub->add_option("--merge", opt->merge, "Merge the outputs of these runs (shards of one sweep) into --out");
  sub->add_flag("--dry-run", opt->dry_run,
                "List the sweep's episodes (index, shard, scenario, variant, seed, id) as CSV on stdout; run and "
                "write nothing");
  CLI::Option* slurm = sub->add_option(
      "--slurm-script", opt->slurm_parts,
      "Write Slurm job scripts into OUT/slurm for a job array of N tasks (part K/N into OUT/parts/K, --jobs = "
      "CPUs per task = --jobs or 1) and a merge into OUT that waits for it; run nothing (OUT/slurm/submit.sh "
      "submits both)");
  sub->footer(
      "Writes sweep.json (the whole sweep and the part run into this folder), episodes/ (one .json + .csv\n"
      "per finished episode, named <scenario>__<variant>__seed<k>__<fingerprint>), episodes.csv,\n"
      "summary.csv, summary.md and plots/*.png.\n"
      "Resume: run the same command again; finished episodes are kept. A folder holds one part of one\n"
      "sweep: another grid, scenario set, seed count or shard, or an episode file recording other\n"
      "settings, is an error (exit 2, naming the file and what differs), never reused or overwritten.\n"
      "Merge: the folders must be parts of one sweep (else exit 2, naming both sweep.json); an episode\n"
      "found in two folders with different results is an error (exit 2, naming both files). Episodes\n"
      "finished in no folder are listed on stderr and in OUT/missing.csv; the tables of the others are\n"
      "written and the exit status is 1.\n"
      "Provenance: each episode records the ofv (version, git commit) that ran it, the fingerprint of its\n"
      "scenario's files and every setting as resolved; a folder of another ofv or an edited scenario is\n"
      "another sweep. Merge also refuses parts run by another ofv and parts that overlap.\n"
      "Limits: --seeds 1..1000, --jobs 1..256, at most 100000 episodes per sweep, --slurm-script 1..1000.");

  return {sub, [opt, seeds, jobs, slurm]() -> int {
            // Usage errors (exit 2) are all found before anything runs or is written.
            SweepEpisodes merged;
            std::vector<EpisodeSpec> episodes;  // the whole sweep
            Shard part;
            std::vector<std::pair<std::string, std::string>> slurm_scripts;  // --slurm-script: name, text
            try {
              if (opt->out.empty() && !opt->dry_run) throw std::invalid_argument("--out is required");
              if (opt->dry_run && slurm->count() > 0) {
                throw std::invalid_argument("--dry-run and --slurm-script: give one of them");
              }
              if (slurm->count() > 0 && !opt->shard.empty()) {
                throw std::invalid_argument("--slurm-script writes every part's job: no --shard");
              }
              if (!opt->merge.empty()) {
                if (!opt->scenarios.empty() || !opt->grid.empty() || seeds->count() > 0 || jobs->count() > 0 ||
                    !opt->shard.empty() || opt->dry_run || slurm->count() > 0) {
                  throw std::invalid_argument(
                      "--merge takes no --scenarios, --grid, --seeds, --jobs, --shard, --dry-run or --slurm-script");
                }
                merged = read_sweep(opt->merge);
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
                if (!opt->shard.empty()) part = parse_shard(opt->shard);
                (void)shard(episodes, part.k, part.n);  // checks K/N
                if (slurm->count() > 0) {
                  SlurmSweep job;
                  std::error_code error;
                  job.ofv = fs::read_symlink("/proc/self/exe", error).string();
                  if (error) {
                    throw std::invalid_argument("--slurm-script: cannot tell where this ofv program is "
                                                "(/proc/self/exe: " + error.message() + ")");
                  }
                  for (const auto& s : scenarios) job.scenarios.push_back(fs::absolute(s.second).lexically_normal().string());
                  job.grid = fs::absolute(opt->grid).lexically_normal().string();
                  job.seeds = grid.seeds;
                  job.parts = opt->slurm_parts;
                  job.cpus = jobs->count() > 0 ? opt->jobs : 1;
                  job.out = fs::absolute(opt->out).lexically_normal().string();
                  slurm_scripts = slurm_job_scripts(job);
                }
              }
            } catch (const std::invalid_argument& e) {
              std::cerr << "ofv compare: " << e.what() << '\n';
              return kUsage;
            }
            if (opt->dry_run) {
              // Every episode of the part (all of them without --shard), and the part that runs it.
              std::cout << "index,shard,scenario,variant,seed,id\n";
              std::size_t listed = 0;
              for (const auto& e : shard(episodes, part.k, part.n)) {
                std::cout << e.index << ',' << (e.index % part.n + 1) << '/' << part.n << ',' << csv_field(e.scenario)
                          << ',' << csv_field(e.variant.name) << ',' << e.seed << ',' << e.id() << '\n';
                ++listed;
              }
              std::cerr << "ofv compare: dry run: " << listed << " of " << episodes.size()
                        << " episodes listed; nothing run or written\n";
              return kOk;
            }
            if (!slurm_scripts.empty()) {
              try {
                const fs::path dir = fs::path(opt->out) / "slurm";
                fs::create_directories(dir);
                for (const auto& [name, text] : slurm_scripts) {
                  write_file_atomically(dir / name, text);
                  fs::permissions(dir / name, fs::perms::owner_exec | fs::perms::group_exec | fs::perms::others_exec,
                                  fs::perm_options::add);
                }
                std::cout << "ofv compare: " << episodes.size() << " episodes in " << opt->slurm_parts
                          << " array tasks; submit with " << (dir / "submit.sh").string()
                          << " (parts in " << (fs::path(opt->out) / "parts").string() << ", tables in "
                          << opt->out << ")\n";
                return kOk;
              } catch (const std::exception& e) {
                std::cerr << "ofv compare: " << e.what() << '\n';
                return kRuntimeFailure;
              }
            }
            try {
              if (!opt->merge.empty()) {
                std::optional<MergeTarget> target;
                try {
                  target.emplace(opt->out, merged);
                } catch (const std::invalid_argument& e) {  // another sweep's folder, another merge: nothing written
                  std::cerr << "ofv compare: " << e.what() << '\n';
                  return kUsage;
                }
                const auto plots = write_reports(merged.rows, opt->out);
                const fs::path missing_file = fs::path(opt->out) / "missing.csv";
                std::error_code ignored;
                fs::remove(missing_file, ignored);  // from an earlier merge into this folder
                std::cout << "ofv compare: merged " << merged.rows.size() << " of " << merged.planned
                          << " episodes from " << opt->merge.size() << " runs into " << opt->out
                          << "/summary.md (" << plots.size() << " plots)\n";
                if (merged.missing.empty()) return kOk;
                // An unfinished part: the tables of the others are written,
                // the missing episodes listed, and the exit status says so.
                std::string csv = "scenario,variant,seed,index,id\n";
                std::string some;
                for (const auto& m : merged.missing) {
                  csv += csv_field(m.scenario) + "," + csv_field(m.variant.name) + "," + std::to_string(m.seed) + "," +
                         std::to_string(m.index) + "," + m.id() + "\n";
                  if (some.size() < 200) some += (some.empty() ? "" : ", ") + m.id();
                }
                write_file_atomically(missing_file, csv);
                std::cerr << "ofv compare: --merge: " << merged.missing.size() << " of " << merged.planned
                          << " episodes are missing (" << some
                          << (merged.missing.size() > 1 && some.size() >= 200 ? ", ..." : "") << "; all in "
                          << missing_file.string() << "): the tables hold the others\n";
                return kRuntimeFailure;
              }
              SweepOptions options;
              options.jobs = jobs->count() > 0 ? opt->jobs : 0;  // 0: one per core
              options.progress = true;   // drawn only on a terminal
              options.part = part;
              const std::size_t mine = shard(episodes, part.k, part.n).size();
              int ran = 0;
              try {
                ran = run_sweep(episodes, simulation_runner(), opt->out, options);
              } catch (const std::invalid_argument& e) {
                // The output folder holds another sweep: found before anything ran.
                std::cerr << "ofv compare: " << e.what() << '\n';
                return kUsage;
              }
              const auto rows = load_episodes({opt->out});
              const auto plots = write_reports(rows, opt->out);
              std::cout << "ofv compare: " << mine << " episodes (" << ran << " run, "
                        << mine - static_cast<std::size_t>(ran) << " resumed); tables in " << opt->out
                        << "/summary.md, " << plots.size() << " plots in " << opt->out << "/plots\n";
              return kOk;
            } catch (const std::exception& e) {
              std::cerr << "ofv compare: " << e.what() << '\n';
              return kRuntimeFailure;
            }
          }};
}

}  // namespace ofv::cli
