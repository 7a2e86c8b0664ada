/**
 * \file episode_store.h
 * \brief The finished episodes of `ofv compare` on disk:
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

/// \brief The episode files of one `ofv compare` output folder.
class EpisodeStore {
 public:
  /// \brief Creates `<out_dir>/episodes` if needed.
  explicit EpisodeStore(const std::string& out_dir);
  /// \brief Whether the episode ran to its end: its `.json` exists.
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
  EpisodeSpec spec;
  EpisodeMetrics metrics;
  std::string trajectory_csv;  ///< path of its trajectory file
};

/// \brief Reads every finished episode under each dir's `episodes/`, sorted
///        by scenario, variant order, seed. Duplicates (same id) are kept once.
/// \throws std::invalid_argument naming the folder or file that is not an
///         `ofv compare` output.
[[nodiscard]] std::vector<EpisodeRow> load_episodes(const std::vector<std::string>& dirs);

}  // namespace ofv
