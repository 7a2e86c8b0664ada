/**
 * \file sweep.h
 * \brief A comparison sweep: every scenario x variant x seed as one
 *        independent episode, planned in a fixed order, split into shards and
 *        run in parallel (oneTBB), each episode stored as soon as it ends.
 *
 * The sweep knows nothing of how an episode runs: it takes an EpisodeRunner,
 * so the same code drives the simulator, and tests drive it with a synthetic
 * runner.
 */
#pragma once

#include "ofv/loop/grid.h"
#include "ofv/loop/metrics.h"

#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

/// \brief One closed-loop episode to run.
struct EpisodeSpec {
  int index = 0;           ///< position in the whole sweep (sharding and ordering)
  std::string scenario;    ///< scenario name (file stem)
  std::string scenario_path;
  Variant variant;
  int seed = 0;
  /// \brief Stable file-name-safe identifier: scenario, variant and seed.
  [[nodiscard]] std::string id() const;
};

/// \brief `text` with every character other than a letter, a digit, `-` and
///        `.` replaced by `_`, for use in file names.
[[nodiscard]] std::string safe_name(const std::string& text);

/// \brief The most episodes run in parallel (`--jobs`).
inline constexpr int kMaxJobs = 256;

/// \brief Checks the size of a sweep before it is planned: 1..kMaxSeeds
///        seeds, at least one scenario and variant, and at most kMaxEpisodes
///        episodes (computed without overflow).
/// \throws std::invalid_argument giving the counts.
void check_sweep_size(std::size_t scenarios, std::size_t variants, int seeds);

/// \brief Every scenario x variant x seed, in a fixed order.
/// \throws std::invalid_argument from check_sweep_size(), before anything is allocated.
[[nodiscard]] std::vector<EpisodeSpec> plan_episodes(
    const std::vector<std::pair<std::string, std::string>>& scenarios,  // name, path
    const Grid& grid);

/// \brief Part `k` (1-based) of `n` of a sweep.
struct Shard {
  int k = 1;
  int n = 1;
};

/// \brief Parses `K/N` (e.g. `2/8`), the value of `--shard`.
/// \throws std::invalid_argument naming the text unless it has that form.
[[nodiscard]] Shard parse_shard(const std::string& text);

/// \brief The part K (1-based) of N of a sweep: episodes with index % N == K - 1.
/// \throws std::invalid_argument unless 1 <= k <= n.
[[nodiscard]] std::vector<EpisodeSpec> shard(const std::vector<EpisodeSpec>& all, int k, int n);

/// \brief What an episode gives back.
struct EpisodeOutcome {
  EpisodeMetrics metrics;
  std::vector<StepRecord> steps;  ///< for the time plots and trajectory files
};

/// \brief Runs one episode; must be deterministic given the spec and thread-safe.
using EpisodeRunner = std::function<EpisodeOutcome(const EpisodeSpec&)>;

/// \brief Options of run_sweep().
struct SweepOptions {
  int jobs = 1;           ///< episodes in parallel, 0..kMaxJobs; 0: one per core
  bool progress = false;  ///< progress bar with ETA on stderr (when it is a terminal)
};

/**
 * \brief Runs the episodes not yet finished in `out_dir`/episodes and writes
 *        each as `<id>.json` (spec + metrics) and `<id>.csv` (trajectory) as
 *        soon as it ends, so an interrupted sweep resumes where it stopped.
 *
 * The files do not depend on `options.jobs`: episodes are independent and
 * each is written to its own files.
 * \return the number of episodes run (not resumed).
 * \throws std::runtime_error if an episode fails (its message names the
 *         episode); episodes not yet started are then skipped.
 * \throws std::invalid_argument if `options.jobs` is outside 0..kMaxJobs.
 */
int run_sweep(const std::vector<EpisodeSpec>& episodes, const EpisodeRunner& runner,
              const std::string& out_dir, const SweepOptions& options);

}  // namespace ofv
