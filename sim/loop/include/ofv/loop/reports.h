/**
 * \file reports.h
 * \brief The tables of `ofv compare` (episodes.csv, summary.csv, summary.md)
 *        and write_reports(), which writes them and the plots.
 */
#pragma once

#include "ofv/loop/episode_store.h"

#include <string>
#include <vector>

namespace ofv {

/// \brief `text` as one CSV field: quoted (quotes doubled) when it holds a
///        comma, a quote or a newline, as is otherwise.
[[nodiscard]] std::string csv_field(const std::string& text);

/// \brief `value` with `precision` significant digits; empty when not finite
///        (an empty CSV cell).
[[nodiscard]] std::string csv_number(double value, int precision = 6);

/**
 * \brief Writes `episodes.csv` (one row per episode, every setting and every
 *        metric), `summary.csv` and `summary.md` (per scenario x variant,
 *        mean and 95 % interval over seeds) into `out_dir`.
 */
void write_tables(const std::vector<EpisodeRow>& rows, const std::string& out_dir);

/**
 * \brief Writes episodes.csv, summary.csv, summary.md and the PNG plots
 *        (gnuplot) into `out_dir`.
 * \return paths of the plots written (empty if gnuplot is unavailable).
 */
std::vector<std::string> write_reports(const std::vector<EpisodeRow>& rows,
                                       const std::string& out_dir);

}  // namespace ofv
