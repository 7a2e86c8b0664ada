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
  std::string scenario_path;  ///< the scenario's file, as the runner loads it
  /// Fingerprint of the scenario's files (scenario_fingerprint()): an edited
  /// scenario or mesh is another episode.
  std::string scenario_hash;
  Variant variant;  ///< its name and settings
  int seed = 0;     ///< the scenario's k-th random world (sim::with_seed)
  /**
   * \brief What makes two episodes the same: the scenario's name and the
   *        fingerprint of its files, the variant's name, its settings in the
   *        order they apply, and the seed — as canonical JSON text, so
   *        different episodes always have different identities (the
   *        scenario's file path and the index are not part of it).
   */
  [[nodiscard]] std::string identity() const;
  /**
   * \brief The episode's file name (without extension):
   *        `<scenario>__<variant>__seed<k>__<fingerprint>`, the names
   *        shortened and made file-name safe for reading, and the
   *        fingerprint of identity() keeping names that differ only in
   *        dropped characters (`a/b`, `a_b`) or contain `__` apart.
   */
  [[nodiscard]] std::string id() const;
};

/// \brief `text` with every character other than a letter, a digit, `-` and
///        `.` replaced by `_`, for use in file names.
[[nodiscard]] std::string safe_name(const std::string& text);

/// \brief 16 hexadecimal digits of a 64-bit FNV-1a hash of `text`: a stable
///        fingerprint for file names and plan checks (not cryptographic;
///        equal fingerprints are always confirmed by comparing the texts).
[[nodiscard]] std::string fingerprint(const std::string& text);

/// \brief The fingerprint of a whole sweep: of every episode's identity and
///        index, in order.
[[nodiscard]] std::string plan_fingerprint(const std::vector<EpisodeSpec>& plan);

/// \brief The most episodes run in parallel (`--jobs`).
inline constexpr int kMaxJobs = 256;

/// \brief Checks the size of a sweep before it is planned: 1..kMaxSeeds
///        seeds, at least one scenario and variant, and at most kMaxEpisodes
///        episodes (computed without overflow).
/// \throws std::invalid_argument giving the counts.
void check_sweep_size(std::size_t scenarios, std::size_t variants, int seeds);

/// \brief The fingerprint of a scenario's files: the scenario file's bytes and
///        those of every mesh it reads, in order (not their paths: a moved
///        folder is the same scenario).
/// \throws std::invalid_argument naming the file when the scenario does not load.
[[nodiscard]] std::string scenario_fingerprint(const std::string& path);

/// \brief Every scenario x variant x seed, in a fixed order, each scenario's
///        files fingerprinted (scenario_fingerprint()).
/// \throws std::invalid_argument from check_sweep_size(), before anything is
///         allocated, or from scenario_fingerprint().
[[nodiscard]] std::vector<EpisodeSpec> plan_episodes(
    const std::vector<std::pair<std::string, std::string>>& scenarios,  // name, path
    const Grid& grid);

/// \brief Part `k` (1-based) of `n` of a sweep.
struct Shard {
  int k = 1;  ///< this part, 1..n
  int n = 1;  ///< parts in all
};

/// \brief Parses `K/N` (e.g. `2/8`), the value of `--shard`.
/// \throws std::invalid_argument naming the text unless it has that form.
[[nodiscard]] Shard parse_shard(const std::string& text);

/// \brief The part K (1-based) of N of a sweep: episodes with index % N == K - 1.
/// \throws std::invalid_argument unless 1 <= k <= n.
[[nodiscard]] std::vector<EpisodeSpec> shard(const std::vector<EpisodeSpec>& all, int k, int n);

/// \brief What an episode gives back.
struct EpisodeOutcome {
  EpisodeMetrics metrics;  ///< the episode's summary (summarise())
  std::vector<StepRecord> steps;  ///< for the time plots and trajectory files
  /// Every setting as the episode resolved it (episode_settings_table()),
  /// recorded with the episode; empty when the runner does not say.
  std::vector<std::pair<std::string, std::string>> settings;
};

/// \brief Runs one episode; must be deterministic given the spec and thread-safe.
using EpisodeRunner = std::function<EpisodeOutcome(const EpisodeSpec&)>;

/// \brief Options of run_sweep().
struct SweepOptions {
  int jobs = 1;           ///< episodes in parallel, 0..kMaxJobs; 0: one per core
  bool progress = false;  ///< progress bar with ETA on stderr (when it is a terminal)
  Shard part;             ///< the part of the sweep to run (`--shard`); 1/1: all of it
};

/**
 * \brief Runs the episodes of part `options.part` of the sweep `plan` not yet
 *        finished in `out_dir`/episodes and writes each as `<id>.json` (spec
 *        + metrics) and `<id>.csv` (trajectory) as soon as it ends, so an
 *        interrupted sweep resumes where it stopped.
 *
 * `out_dir`/sweep.json records the whole plan and the part: a folder belongs
 * to one sweep. Before anything runs, the folder is checked: another sweep's
 * folder (a different plan or part), episodes without a `sweep.json`, or an
 * episode file whose recorded scenario, variant, settings or seed differ
 * from the plan's are errors, never reused. The files do not depend on
 * `options.jobs`: episodes are independent and each is written to its own
 * files.
 * \param plan the whole sweep (every part), e.g. from plan_episodes().
 * \param runner runs one episode (e.g. simulation_runner()), from several threads at once.
 * \param out_dir the sweep's folder, created if missing.
 * \param options jobs, progress bar, part.
 * \return the number of episodes run (not resumed).
 * \throws std::invalid_argument, before anything runs or is written, if
 *         `options.jobs` is outside 0..kMaxJobs, the part is not 1 <= K <= N,
 *         two episodes of the plan share an identity, or the folder holds
 *         something else (the message names the file and what differs).
 * \throws std::runtime_error if an episode fails (its message names the
 *         episode); episodes not yet started are then skipped.
 */
int run_sweep(const std::vector<EpisodeSpec>& plan, const EpisodeRunner& runner,
              const std::string& out_dir, const SweepOptions& options);

}  // namespace ofv
