// A comparison sweep: planning, shards, and the parallel resumable run.
#include "ofv/loop/sweep.h"

#include "ofv/loop/episode_store.h"
#include "ofv/loop/progress.h"
#include "ofv/sim/scenario.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <nlohmann/json.hpp>

#include <cctype>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace ofv {

std::string safe_name(const std::string& text) {
  std::string out;
  for (char ch : text) {
    out += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '.') ? ch : '_';
  }
  return out;
}

std::string fingerprint(const std::string& text) {
  std::uint64_t h = 14695981039346656037ULL;  // FNV-1a, 64 bits
  for (const char ch : text) {
    h ^= static_cast<unsigned char>(ch);
    h *= 1099511628211ULL;
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(h));
  return hex;
}

std::string EpisodeSpec::identity() const {
  nlohmann::json settings = nlohmann::json::array();
  for (const auto& [k, v] : variant.settings) settings.push_back({k, v});
  return nlohmann::json{{"scenario", scenario}, {"scenario_hash", scenario_hash}, {"variant", variant.name},
                        {"settings", settings}, {"seed", seed}}
      .dump();
}

std::string scenario_fingerprint(const std::string& path) {
  const sim::Scenario scenario = sim::load_scenario(path);
  std::vector<std::string> files{scenario.path};
  for (const sim::Body& b : scenario.bodies) {
    if (!b.mesh_file.empty()) files.push_back(b.mesh_file);
  }
  std::string all;
  for (const std::string& file : files) {
    std::ifstream in(file, std::ios::binary);
    std::ostringstream bytes;
    bytes << in.rdbuf();
    if (!in) throw std::invalid_argument(file + ": cannot be read");
    all += std::to_string(bytes.str().size()) + ":" + bytes.str();
  }
  return fingerprint(all);
}

std::string EpisodeSpec::id() const {
  // Shortened so that the name stays far below the 255 bytes of a file name.
  return safe_name(scenario).substr(0, 48) + "__" + safe_name(variant.name).substr(0, 96) + "__seed" +
         std::to_string(seed) + "__" + fingerprint(identity());
}

std::string plan_fingerprint(const std::vector<EpisodeSpec>& plan) {
  std::string all;
  for (const auto& s : plan) all += std::to_string(s.index) + " " + s.identity() + "\n";
  return fingerprint(all);
}

void check_sweep_size(std::size_t scenarios, std::size_t variants, int seeds) {
  const std::string what = std::to_string(scenarios) + " scenarios x " + std::to_string(variants) +
                           " variants x " + std::to_string(seeds) + " seeds";
  if (seeds < 1 || seeds > kMaxSeeds) {
    throw std::invalid_argument("seeds: expected an integer in 1.." + std::to_string(kMaxSeeds) + ", got " +
                                std::to_string(seeds));
  }
  if (scenarios == 0 || variants == 0) throw std::invalid_argument(what + ": nothing to run");
  // Overflow-safe: a * b > max exactly when b > max / a (integers, a > 0).
  const auto s = static_cast<std::size_t>(seeds);
  if (variants > kMaxEpisodes / scenarios || s > kMaxEpisodes / (scenarios * variants)) {
    throw std::invalid_argument(what + ": more than " + std::to_string(kMaxEpisodes) + " episodes");
  }
}

std::vector<EpisodeSpec> plan_episodes(
    const std::vector<std::pair<std::string, std::string>>& scenarios, const Grid& grid) {
  check_sweep_size(scenarios.size(), grid.variants.size(), grid.seeds);
  std::vector<EpisodeSpec> out;
  out.reserve(scenarios.size() * grid.variants.size() * static_cast<std::size_t>(grid.seeds));
  for (const auto& [name, path] : scenarios) {
    const std::string hash = scenario_fingerprint(path);
    for (const Variant& v : grid.variants) {
      for (int seed = 0; seed < grid.seeds; ++seed) {
        EpisodeSpec s;
        s.index = static_cast<int>(out.size());
        s.scenario = name;
        s.scenario_path = path;
        s.scenario_hash = hash;
        s.variant = v;
        s.seed = seed;
        out.push_back(s);
      }
    }
  }
  return out;
}

Shard parse_shard(const std::string& text) {
  Shard s;
  char slash = 0;
  std::istringstream in(text);
  if (!(in >> s.k >> slash >> s.n) || slash != '/' || !in.eof()) {
    throw std::invalid_argument("--shard " + text + ": expected K/N, e.g. 2/8");
  }
  return s;
}

std::vector<EpisodeSpec> shard(const std::vector<EpisodeSpec>& all, int k, int n) {
  if (n < 1 || k < 1 || k > n) {
    throw std::invalid_argument("--shard K/N needs 1 <= K <= N, got " + std::to_string(k) + "/" +
                                std::to_string(n));
  }
  std::vector<EpisodeSpec> out;
  for (const auto& s : all) {
    if (s.index % n == k - 1) out.push_back(s);
  }
  return out;
}

int run_sweep(const std::vector<EpisodeSpec>& plan, const EpisodeRunner& runner,
              const std::string& out_dir, const SweepOptions& options) {
  if (options.jobs < 0 || options.jobs > kMaxJobs) {
    throw std::invalid_argument("jobs: expected an integer in 0.." + std::to_string(kMaxJobs) +
                                " (0: one per core), got " + std::to_string(options.jobs));
  }
  const std::vector<EpisodeSpec> episodes = shard(plan, options.part.k, options.part.n);
  // Checks the folder (and the plan) before anything runs.
  const EpisodeStore store(out_dir, plan, options.part);
  std::vector<const EpisodeSpec*> todo;
  for (const auto& s : episodes) {
    if (!store.finished(s)) todo.push_back(&s);
  }
  ProgressBar progress(static_cast<double>(todo.size()), "episodes", options.progress);
  tbb::task_arena arena(options.jobs > 0 ? options.jobs : tbb::task_arena::automatic);
  arena.execute([&] {
    // Grain 1 with the simple partitioner: one task per episode, so a thread
    // that finishes a short episode takes the next one instead of waiting
    // behind a chunk of long ones. With one job the episodes run in order.
    tbb::parallel_for(
        tbb::blocked_range<std::size_t>(0, todo.size(), 1),
        [&](const tbb::blocked_range<std::size_t>& range) {
          for (std::size_t i = range.begin(); i != range.end(); ++i) {
            const EpisodeSpec& spec = *todo[i];
            try {
              // Isolated: a thread waiting on TBB work inside the episode
              // (Embree builds) must not start another episode meanwhile,
              // whose run time would land in this episode's step times.
              const EpisodeOutcome outcome =
                  tbb::this_task_arena::isolate([&] { return runner(spec); });
              store.write(spec, outcome);
            } catch (const std::exception& e) {
              // TBB skips the episodes not yet started and rethrows this in
              // the caller; the episodes running finish and are kept.
              throw std::runtime_error("episode " + spec.id() + ": " + e.what());
            }
            progress.tick();
          }
        },
        tbb::simple_partitioner());
  });
  return static_cast<int>(todo.size());
}

}  // namespace ofv
