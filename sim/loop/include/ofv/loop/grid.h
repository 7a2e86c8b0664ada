/**
 * \file grid.h
 * \brief The settings grid of `ofv compare --grid GRID.yaml`: named variants,
 *        optionally crossed with axes of values (see docs/compare.md).
 */
#pragma once

#include <cstddef>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

/// \brief The most seeds per scenario x variant (`seeds:` of a grid, `--seeds`).
inline constexpr int kMaxSeeds = 1000;
/// \brief The most episodes (scenarios x variants x seeds) of one sweep.
inline constexpr std::size_t kMaxEpisodes = 100000;
/// \brief The most variants of one grid, after expanding its axes.
inline constexpr std::size_t kMaxVariants = kMaxEpisodes;

/// \brief One column of the comparison: a named list of settings `name=value`.
struct Variant {
  std::string name;  ///< unique in the grid; `variant,axis=value,...` after expanding axes
  std::vector<std::pair<std::string, std::string>> settings;  ///< applied in order
};

/// \brief The settings grid of `ofv compare --grid GRID.yaml` (see docs/compare.md).
struct Grid {
  std::string name = "grid";      ///< a label (`name:` of the file)
  int seeds = 3;                  ///< seeds per scenario x variant, 1..kMaxSeeds (`--seeds` overrides)
  std::vector<Variant> variants;  ///< after expanding `axes` (cartesian product)
};

/// \brief Reads a grid; errors name the file, the key and the value (and
///        the line, for a key that appears twice in a mapping).
/// \throws std::invalid_argument for unknown or repeated keys, an empty list
///         of variants or axes, seeds outside 1..kMaxSeeds, more than
///         kMaxVariants variants (counted before expanding the axes) or a
///         variant name used twice.
[[nodiscard]] Grid read_grid(const std::string& path);
/// \brief Parses a grid from YAML text; `source` names it in errors.
[[nodiscard]] Grid grid_from_yaml(const std::string& text, const std::string& source);

}  // namespace ofv
