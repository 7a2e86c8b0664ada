/**
 * \file compare.h
 * \brief Comparing settings in closed loop: scenario set x settings grid x
 *        seeds, run as independent episodes (parallel, sharded, resumable),
 *        then aggregated into tables and plots.
 *
 * The harness knows nothing of how an episode runs: it takes an
 * EpisodeRunner, so the same code drives the simulator, and tests drive it
 * with a synthetic runner.
 */
#pragma once

#include "ofv/loop/metrics.h"

#include <functional>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

/// \brief One column of the comparison: a named list of settings `name=value`.
struct Variant {
  std::string name;
  std::vector<std::pair<std::string, std::string>> settings;  ///< applied in order
};

/// \brief The settings grid of `ofv compare --grid GRID.yaml` (see docs/compare.md).
struct Grid {
  std::string name = "grid";
  int seeds = 3;                  ///< seeds per scenario x variant (`--seeds` overrides)
  std::vector<Variant> variants;  ///< after expanding `axes` (cartesian product)
};

/// \brief Reads a grid; errors name the file, the key and the value.
[[nodiscard]] Grid read_grid(const std::string& path);
/// \brief Parses a grid from YAML text; `source` names it in errors.
[[nodiscard]] Grid grid_from_yaml(const std::string& text, const std::string& source);

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

/// \brief Every scenario x variant x seed, in a fixed order.
[[nodiscard]] std::vector<EpisodeSpec> plan_episodes(
    const std::vector<std::pair<std::string, std::string>>& scenarios,  // name, path
    const Grid& grid);

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
  int jobs = 1;           ///< episodes in parallel
  bool progress = false;  ///< progress bar with ETA on stderr
};

/**
 * \brief Runs the episodes not yet finished in `out_dir`/episodes and writes
 *        each as `<id>.json` (spec + metrics) and `<id>.csv` (trajectory) as
 *        soon as it ends, so an interrupted sweep resumes where it stopped.
 * \return the number of episodes run (not resumed).
 * \throws std::runtime_error if an episode fails (its message names the episode).
 */
int run_sweep(const std::vector<EpisodeSpec>& episodes, const EpisodeRunner& runner,
              const std::string& out_dir, const SweepOptions& options);

/// \brief A finished episode as read back from its `<id>.json`.
struct EpisodeRow {
  EpisodeSpec spec;
  EpisodeMetrics metrics;
  std::string trajectory_csv;  ///< path of its trajectory file
};

/// \brief Reads every finished episode under each dir's `episodes/`, sorted
///        by scenario, variant order, seed. Duplicates (same id) are kept once.
[[nodiscard]] std::vector<EpisodeRow> load_episodes(const std::vector<std::string>& dirs);

/// \brief Mean and 95 % confidence half-width (Student t) of a sample.
struct Interval {
  double mean = 0.0;
  double half_width = 0.0;
  int n = 0;
};
[[nodiscard]] Interval mean_interval(const std::vector<double>& xs);

/**
 * \brief Writes episodes.csv, summary.csv, summary.md and the PNG plots
 *        (gnuplot) into `out_dir`.
 * \return paths of the plots written (empty if gnuplot is unavailable).
 */
std::vector<std::string> write_reports(const std::vector<EpisodeRow>& rows,
                                       const std::string& out_dir);

}  // namespace ofv
