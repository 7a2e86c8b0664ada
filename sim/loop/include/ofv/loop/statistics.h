/**
 * \file statistics.h
 * \brief What the tables and plots of `ofv compare` aggregate: the
 *        per-episode metric columns, the episodes grouped by scenario x
 *        variant, and the mean with its 95 % Student t interval over seeds.
 */
#pragma once

#include "ofv/loop/episode_store.h"

#include <string>
#include <vector>

namespace ofv {

/// \brief Mean and 95 % confidence half-width (Student t) of a sample.
struct Interval {
  double mean = 0.0;        ///< mean of the finite values (NaN if none)
  double half_width = 0.0;  ///< 0 with fewer than two values or no spread
  int n = 0;                ///< finite values used
};

/// \brief Mean and 95 % interval of the finite values of `xs` (NaN mean if none).
[[nodiscard]] Interval mean_interval(const std::vector<double>& xs);

/// \brief One per-episode metric of the reports.
struct MetricColumn {
  const char* name;   ///< CSV column name, with its unit (`_s`, `_ms`, `_m`, `_deg`)
  const char* label;  ///< table heading and plot axis label
  double (*get)(const EpisodeMetrics&);  ///< NaN when the episode has no value
};

/// \brief The metrics the reports aggregate, in column order.
[[nodiscard]] const std::vector<MetricColumn>& metric_columns();

/// \brief The episodes of one scenario x variant: its seeds.
struct EpisodeGroup {
  std::string scenario;          ///< scenario name
  Variant variant;               ///< the variant, with its settings
  std::vector<EpisodeRow> rows;  ///< in the order of the rows grouped
  /// \brief Mean and interval of `column` over the rows.
  [[nodiscard]] Interval interval(const MetricColumn& column) const;
};

/// \brief Episodes grouped by scenario x variant, every list in the order
///        the rows first name it (the sweep order for load_episodes() rows).
struct EpisodeGroups {
  std::vector<std::string> scenarios;  ///< scenario names
  std::vector<std::string> variants;  ///< variant names
  std::vector<EpisodeGroup> groups;   ///< one per scenario x variant that ran
  /// \brief The group of a scenario and variant name; nullptr if none ran.
  [[nodiscard]] const EpisodeGroup* find(const std::string& scenario,
                                         const std::string& variant) const;
};

/// \brief Groups rows by scenario x variant name.
[[nodiscard]] EpisodeGroups group_episodes(const std::vector<EpisodeRow>& rows);

}  // namespace ofv
