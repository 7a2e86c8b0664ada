/**
 * \file estimator_settings.h
 * \brief The estimator's settings by name (ESTIMATOR-SPEC §4, §7): the table
 *        behind scene files' `params`, `--set`, grids, `--help` and the docs.
 */
#pragma once

#include "ofv/estimator.h"
#include "ofv/settings_table.h"

namespace ofv {

/**
 * \brief preset, r_seed, r_sphere, initial_view, clearance, push_radius,
 *        push_weighting, step, max_iterations, warm_start.
 *
 * Lengths other than the radii may be given as `r_seed` or `r_sphere`: the
 * radius set so far (or its default). Values are range-checked by
 * EstimatorParams::resolve() (spec §7: finite and positive).
 */
[[nodiscard]] const SettingsTable<EstimatorParams>& estimator_settings_table();

}  // namespace ofv
