/**
 * \file scenario_set.h
 * \brief The scenarios of a simulated comparison (`ofv compare --scenarios`)
 *        and the check of a grid against them before anything runs.
 */
#pragma once

#include "ofv/loop/grid.h"

#include <string>
#include <utility>
#include <vector>

namespace ofv {

/**
 * \brief Scenario names and paths, as plan_episodes() takes them, from
 *        scenario files, folders (their `*.yaml`, sorted) and built-in names.
 * \throws std::invalid_argument naming the argument: an empty folder, a
 *         scenario that does not load, or two scenarios of the same name.
 */
[[nodiscard]] std::vector<std::pair<std::string, std::string>> scenario_set(
    const std::vector<std::string>& args);

/**
 * \brief Checks that every variant's settings apply to every scenario, so a
 *        typo fails at once rather than hours into a sweep.
 * \param scenarios   names and paths, as scenario_set() gives them
 * \param grid        the variants to check
 * \param grid_source the grid's file, named in errors with the variant
 * \throws std::invalid_argument naming the grid file, the variant, the
 *         setting and the value.
 */
void check_grid(const std::vector<std::pair<std::string, std::string>>& scenarios,
                const Grid& grid, const std::string& grid_source);

}  // namespace ofv
