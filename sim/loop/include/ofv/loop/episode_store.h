/**
 * \file episode_store.h
 * \brief The finished episodes of `ofv compare` on disk:
 *        `<out_dir>/sweep.json` (the whole sweep and the part run there),
 *        `<out_dir>/episodes/<id>.json` (spec + metrics) and `<id>.csv`
 *        (trajectory). Writing them one by one is what makes a sweep
 *        resumable; reading them back from several folders merges shards.
 */
#pragma once

#include "ofv/loop/sweep.h"

#include <filesystem>
#include <string>
#include <vector>

namespace ofv {

/// \brief Writes `text` to `path` through a temporary file renamed into
///        place, so that an interrupted run never leaves a partial file.
/// \throws std::runtime_error naming the file if it cannot be written.
void write_file_atomically(const std::filesystem::path& path, const std::string& text);

/// \brief The episode files of one `ofv compare` output folder, which
///        belongs to one part of one sweep (recorded in `<out_dir>/sweep.json`).
class EpisodeStore {
 public:
  /**
   * \brief Opens `out_dir` for part `part` of the sweep `plan`: checks what
   *        the folder already holds, then creates `<out_dir>/episodes` and
   *        `<out_dir>/sweep.json` if needed.
   * \throws std::invalid_argument, before anything is written, naming the
   *         file and what differs: a `sweep.json` of another sweep or another
   *         part, episode files without a `sweep.json`, or two episodes of
   *         the plan with one identity.
   */
  EpisodeStore(const std::string& out_dir, const std::vector<EpisodeSpec>& plan, Shard part);
  /// \brief Whether the episode ran to its end: its `.json` exists and
  ///        records the same scenario, variant, settings and seed.
  /// \throws std::invalid_argument naming the file and what differs when it
  ///         records another episode, or cannot be read.
  [[nodiscard]] bool finished(const EpisodeSpec& spec) const;
  /// \brief Writes the trajectory `.csv`, then the `.json` that marks the
  ///        episode finished. Safe to call from several threads for
  ///        different episodes.
  void write(const EpisodeSpec& spec, const EpisodeOutcome& outcome) const;

 private:
  std::filesystem::path dir_;  ///< `<out_dir>/episodes`
};

/// \brief A finished episode as read back from its `<id>.json`.
struct EpisodeRow {
  EpisodeSpec spec;            ///< which episode: scenario, variant, seed
  EpisodeMetrics metrics;      ///< its metrics as recorded
  std::string trajectory_csv;  ///< path of its trajectory file
};

/// \brief The finished episodes of one or several output folders of one sweep.
struct SweepEpisodes {
  std::vector<EpisodeRow> rows;      ///< sorted by their index in the sweep
  std::vector<EpisodeSpec> missing;  ///< episodes of the whole sweep finished in none of the folders
  std::size_t planned = 0;           ///< episodes of the whole sweep (every part)
  std::vector<EpisodeSpec> plan;     ///< the whole sweep's episodes, in order
};

/**
 * \brief Reads every finished episode under each dir's `episodes/`: one run's
 *        folder, or the parts (shards) of one sweep to merge.
 *
 * An episode found in two folders is kept once if both files record the
 * same results, and is an error otherwise.
 * \throws std::invalid_argument naming the folder or file(s): a folder that
 *         is not an `ofv compare` output (no `episodes/`, no `sweep.json`),
 *         folders of different sweeps (naming both `sweep.json` and what
 *         differs), an episode file that is not an episode of the sweep or
 *         whose name does not match its contents, or the same episode with
 *         different results in two folders (naming both files).
 */
[[nodiscard]] SweepEpisodes read_sweep(const std::vector<std::string>& dirs);

/**
 * \brief Where `ofv compare --merge` writes the tables of `merged`, held
 *        for one merge at a time (a lock file `.merge-lock`, removed when
 *        the object goes).
 * \throws std::invalid_argument naming the folder: it holds episodes of
 *         another sweep (its tables would describe other episodes than its
 *         own), or another merge is writing into it.
 */
class MergeTarget {
 public:
  /// \brief Checks `out_dir` against `merged` and takes its lock (creating the folder).
  MergeTarget(const std::string& out_dir, const SweepEpisodes& merged);
  ~MergeTarget();  ///< releases the lock
  MergeTarget(const MergeTarget&) = delete;             ///< one lock, one owner
  MergeTarget& operator=(const MergeTarget&) = delete;  ///< one lock, one owner

 private:
  std::string lock_;
};

/// \brief read_sweep(dirs).rows: the finished episodes, sorted by scenario,
///        variant order, seed.
[[nodiscard]] std::vector<EpisodeRow> load_episodes(const std::vector<std::string>& dirs);

}  // namespace ofv
