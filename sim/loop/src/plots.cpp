// The plots of `ofv compare`: data files and one gnuplot script, run once.
#include "ofv/loop/plots.h"

#include "gnuplot.h"

#include "ofv/loop/reports.h"
#include "ofv/loop/statistics.h"

#include <algorithm>
#include <cmath>
#include <iostream>
#include <set>
#include <sstream>

namespace ofv {

namespace fs = std::filesystem;

namespace {

using detail::gnuplot_string;

// Visible fraction over time: the first seed of each variant. gnuplot runs
// in the plots folder and the script names only files there, so that no
// path (the user's --out, the folders of merged parts) enters the script:
// the trajectories are copied beside it as `<stem>_<k>.csv`.
void visibility_plot(const EpisodeGroups& grouped, const std::string& scenario, const fs::path& plot_dir,
                     const std::string& stem, std::ostream& script) {
  script << "set output " << gnuplot_string(stem + ".png") << "\nset title "
         << gnuplot_string("True visible fraction over time: " + scenario + " (seed 0)")
         << " noenhanced\nset xlabel 'time [s]'\nset ylabel 'visible fraction'\n"
         << "set yrange [0:1.05]\nplot ";
  bool first = true;
  int k = 0;
  for (const auto& g : grouped.groups) {
    if (g.scenario != scenario) continue;
    const std::string data = stem + "_" + std::to_string(k++) + ".csv";
    fs::copy_file(g.rows.front().trajectory_csv, plot_dir / data, fs::copy_options::overwrite_existing);
    script << (first ? "" : ", ") << gnuplot_string(data)
           << " using \"time\":\"visible_fraction\" with lines lw 2 title " << gnuplot_string(g.variant.name)
           << " noenhanced";
    first = false;
  }
  script << "\nset yrange [*:*]\n";
}

// A metric's bar chart: variants side by side, one cluster per scenario,
// from a data file with a mean and a half-width column per variant. None
// when no episode has a value (worst recovery where none recovered): gnuplot
// cannot plot an empty chart.
bool bar_chart(const EpisodeGroups& grouped, const MetricColumn& column, const std::string& label,
               const fs::path& plot_dir, const std::string& stem, std::ostream& script) {
  const std::string data = stem + ".csv";
  std::ostringstream dat;
  bool any = false;
  dat << "# scenario";  // a comment, so that gnuplot does not plot it
  for (const auto& v : grouped.variants) dat << ',' << csv_field(v) << ',' << csv_field(v + " ci");
  dat << '\n';
  for (const auto& scenario : grouped.scenarios) {
    dat << csv_field(scenario);
    for (const auto& v : grouped.variants) {
      const EpisodeGroup* g = grouped.find(scenario, v);
      if (g == nullptr) {
        dat << ",,";
      } else {
        const Interval i = g->interval(column);
        any = any || std::isfinite(i.mean);
        dat << ',' << csv_number(i.mean) << ',' << csv_number(i.half_width);
      }
    }
    dat << '\n';
  }
  if (!any) return false;
  write_file_atomically(plot_dir / data, dat.str());
  script << "set output " << gnuplot_string(stem + ".png") << "\nset title '" << label
         << " per setting (mean, 95 % CI)'\nset style data histogram\n"
            "set style histogram errorbars gap 1 lw 1\nset style fill solid 0.6 border -1\n"
            "set xtics rotate by -20 noenhanced\nset xlabel ''\nset ylabel '"
         << label << "'\nset yrange [0:*]\nplot ";
  for (std::size_t k = 0; k < grouped.variants.size(); ++k) {
    script << (k ? ", " : "") << gnuplot_string(data) << " using " << 2 + 2 * k << ':' << 3 + 2 * k
           << ":xtic(1) title " << gnuplot_string(grouped.variants[k]) << " noenhanced";
  }
  script << "\nunset style\nset style data lines\nset xtics norotate\nset yrange [*:*]\n";
  return true;
}

}  // namespace

std::vector<std::string> write_plots(const std::vector<EpisodeRow>& rows,
                                     const std::string& out_dir) {
  const EpisodeGroups grouped = group_episodes(rows);
  const std::size_t variants = grouped.variants.size();
  if (variants > kMaxPlottedVariants) {
    std::cerr << "ofv compare: " << variants << " variants: no plots (they are drawn for at most "
              << kMaxPlottedVariants << "); the tables have them all\n";
    return {};
  }
  const fs::path plot_dir = fs::path(out_dir) / "plots";
  fs::create_directories(plot_dir);
  std::ostringstream script;
  // gnuplot's default colours repeat after 8: give variants 9-16 their own.
  script << "set terminal pngcairo size 1000,560 font 'Sans,10'\nset datafile separator ','\n"
            "set linetype 9 lc rgb '#8c564b'\nset linetype 10 lc rgb '#17becf'\nset linetype 11 lc rgb '#bcbd22'\n"
            "set linetype 12 lc rgb '#7f7f7f'\nset linetype 13 lc rgb '#ff7f0e'\nset linetype 14 lc rgb '#2ca02c'\n"
            "set linetype 15 lc rgb '#d62728'\nset linetype 16 lc rgb '#9467bd'\nset linetype cycle 16\n"
            "set key outside right\nset grid\n";
  std::vector<std::string> pngs;
  std::set<std::string> stems;
  for (const auto& scenario : grouped.scenarios) {
    // Scenario names that differ only in characters a file name drops get their own file.
    std::string stem = "visibility_" + safe_name(scenario);
    for (int n = 2; !stems.insert(stem).second; ++n) stem = "visibility_" + safe_name(scenario) + "-" + std::to_string(n);
    visibility_plot(grouped, scenario, plot_dir, stem, script);
    pngs.push_back((plot_dir / (stem + ".png")).string());
  }
  const std::vector<std::pair<std::string, std::string>> bars{
      {"mean_visible_fraction", "mean visible fraction"},
      {"max_recovery_time_s", "worst recovery time [s]"},
      {"mean_step_ms", "compute time per step [ms]"},
      {"mean_estimate_ms", "estimator time per frame [ms]"}};
  for (const auto& [metric, label] : bars) {
    const auto column = std::find_if(metric_columns().begin(), metric_columns().end(),
                                     [&](const MetricColumn& c) { return metric == c.name; });
    if (bar_chart(grouped, *column, label, plot_dir, metric, script)) pngs.push_back((plot_dir / (metric + ".png")).string());
  }
  write_file_atomically(plot_dir / "plots.gp", script.str());
  if (!detail::run_gnuplot(plot_dir, "plots.gp", plot_dir / "gnuplot.log")) {
    std::cerr << "ofv compare: warning: gnuplot failed or is missing (see "
              << (plot_dir / "gnuplot.log").string() << "); tables were written\n";
    return {};
  }
  return pngs;
}

}  // namespace ofv
