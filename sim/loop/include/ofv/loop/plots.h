/**
 * \file plots.h
 * \brief The PNG plots of `ofv compare`, drawn by gnuplot.
 */
#pragma once

#include "ofv/loop/episode_store.h"

#include <cstddef>

#include <string>
#include <vector>

namespace ofv {

/// \brief The most variants write_plots() draws.
inline constexpr std::size_t kMaxPlottedVariants = 40;

/**
 * \brief Writes into `out_dir`/plots, per scenario, the true visible fraction
 *        over time (seed 0, one line per variant) and, per metric, a bar
 *        chart of the variants with 95 % intervals; the data files and the
 *        gnuplot script `plots.gp` stay beside the PNGs.
 * \return paths of the plots written; empty, with a warning on stderr, if
 *         gnuplot failed or is missing (its log is `plots/gnuplot.log`), or
 *         with more than kMaxPlottedVariants variants (unreadable, and each
 *         plot would take minutes).
 */
std::vector<std::string> write_plots(const std::vector<EpisodeRow>& rows,
                                     const std::string& out_dir);

}  // namespace ofv
