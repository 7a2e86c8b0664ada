/**
 * \file grid.h
 * \brief The settings grid of `ofv compare --grid GRID.yaml`: named variants,
 *        optionally crossed with axes of values (see docs/compare.md).
 */
#pragma once

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

}  // namespace ofv
