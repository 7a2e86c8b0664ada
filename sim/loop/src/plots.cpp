// The plots of `ofv compare`: data files and one gnuplot script, run once.
#include "ofv/loop/plots.h"

#include "ofv/loop/reports.h"
#include "ofv/loop/statistics.h"

#include <algorithm>
#include <cstdlib>
#include <iostream>
#include <sstream>

namespace ofv {

namespace fs = std::filesystem;

namespace {

// Quotes a path or title for a gnuplot string.
std::string gp(const fs::path& p) {
  std::string out = "'";
  for (char ch : p.string()) out += ch == '\'' ? std::string("''") : std::string(1, ch);
  return out + "'";
}

// Visible fraction over time: the first seed of each variant.
void visibility_plot(const EpisodeGroups& grouped, const std::string& scenario,
                     const fs::path& png, std::ostream& script) {
  script << "set output " << gp(png) << "\nset title 'True visible fraction over time: "
         << scenario << " (seed 0)' noenhanced\nset xlabel 'time [s]'\nset ylabel 'visible fraction'\n"
         << "set yrange [0:1.05]\nplot ";
  bool first = true;
  for (const auto& g : grouped.groups) {
    if (g.scenario != scenario) continue;
    script << (first ? "" : ", ") << gp(g.rows.front().trajectory_csv)
           << " using \"time\":\"visible_fraction\" with lines lw 2 title " << gp(g.variant.name) << " noenhanced";
    first = false;
  }
  script << "\nset yrange [*:*]\n";
}

// A metric's bar chart: variants side by side, one cluster per scenario,
// from a data file with a mean and a half-width column per variant.
void bar_chart(const EpisodeGroups& grouped, const MetricColumn& column, const std::string& label,
               const fs::path& data, const fs::path& png, std::ostream& script) {
  std::ostringstream dat;
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
        dat << ',' << csv_number(i.mean) << ',' << csv_number(i.half_width);
      }
    }
    dat << '\n';
  }
  write_file_atomically(data, dat.str());
  script << "set output " << gp(png) << "\nset title '" << label
         << " per setting (mean, 95 % CI)'\nset style data histogram\n"
            "set style histogram errorbars gap 1 lw 1\nset style fill solid 0.6 border -1\n"
            "set xtics rotate by -20 noenhanced\nset xlabel ''\nset ylabel '"
         << label << "'\nset yrange [0:*]\nplot ";
  for (std::size_t k = 0; k < grouped.variants.size(); ++k) {
    script << (k ? ", " : "") << gp(data) << " using " << 2 + 2 * k << ':' << 3 + 2 * k
           << ":xtic(1) title " << gp(grouped.variants[k]) << " noenhanced";
  }
  script << "\nunset style\nset style data lines\nset xtics norotate\nset yrange [*:*]\n";
}

}  // namespace

std::vector<std::string> write_plots(const std::vector<EpisodeRow>& rows,
                                     const std::string& out_dir) {
  const EpisodeGroups grouped = group_episodes(rows);
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
  for (const auto& scenario : grouped.scenarios) {
    const fs::path png = plot_dir / ("visibility_" + safe_name(scenario) + ".png");
    visibility_plot(grouped, scenario, png, script);
    pngs.push_back(png.string());
  }
  const std::vector<std::pair<std::string, std::string>> bars{
      {"mean_visible_fraction", "mean visible fraction"},
      {"max_recovery_time_s", "worst recovery time [s]"},
      {"mean_step_ms", "compute time per step [ms]"},
      {"mean_estimate_ms", "estimator time per frame [ms]"}};
  for (const auto& [metric, label] : bars) {
    const auto column = std::find_if(metric_columns().begin(), metric_columns().end(),
                                     [&](const MetricColumn& c) { return metric == c.name; });
    const fs::path png = plot_dir / (metric + ".png");
    bar_chart(grouped, *column, label, plot_dir / (metric + ".csv"), png, script);
    pngs.push_back(png.string());
  }
  const fs::path script_path = plot_dir / "plots.gp";
  write_file_atomically(script_path, script.str());
  const std::string command = "gnuplot \"" + script_path.string() + "\" 2>\"" +
                              (plot_dir / "gnuplot.log").string() + "\"";
  if (std::system(command.c_str()) != 0) {
    std::cerr << "ofv compare: warning: gnuplot failed or is missing (see "
              << (plot_dir / "gnuplot.log").string() << "); tables were written\n";
    return {};
  }
  return pngs;
}

}  // namespace ofv
