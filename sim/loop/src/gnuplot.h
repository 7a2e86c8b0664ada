// gnuplot without a shell: no user text (paths, names) ever reaches a
// command line, and script strings are quoted the gnuplot way.
#pragma once

#include <filesystem>
#include <string>

namespace ofv::detail {

/// \brief `text` as a gnuplot string literal: single-quoted, a quote doubled,
///        control characters (a newline would end the command) replaced by
///        spaces. gnuplot expands nothing inside single quotes.
[[nodiscard]] std::string gnuplot_string(const std::string& text);

/**
 * \brief Runs `gnuplot SCRIPT` with `dir` as working directory, by argument
 *        vector (posix_spawnp), no shell: the script refers to its files by
 *        names relative to `dir`.
 * \param script the script's name in `dir`
 * \param log    receives gnuplot's stderr (created or truncated); empty: discarded
 * \return whether gnuplot ran and exited with status 0.
 */
[[nodiscard]] bool run_gnuplot(const std::filesystem::path& dir, const std::string& script,
                               const std::filesystem::path& log);

}  // namespace ofv::detail
