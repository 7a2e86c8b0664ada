// The tables of `ofv compare`: episodes.csv, summary.csv, summary.md.
#include "ofv/loop/reports.h"

#include "ofv/loop/plots.h"
#include "ofv/loop/statistics.h"

#include <cmath>
#include <iomanip>
#include <map>
#include <set>
#include <sstream>

namespace ofv {

namespace {

// A name as Markdown text on one line and in a table cell: line breaks
// become spaces, '|' is escaped.
std::string md_text(const std::string& name) {
  std::string out;
  for (const char c : name) {
    if (c == '\n' || c == '\r') {
      out += ' ';
    } else {
      if (c == '|' || c == '\\') out += '\\';
      out += c;
    }
  }
  return out;
}

}  // namespace

namespace fs = std::filesystem;

namespace {

std::string settings_text(const Variant& v) {
  std::string out;
  for (const auto& [k, val] : v.settings) out += (out.empty() ? "" : " ") + k + "=" + val;
  return out;
}

// One row per episode, every setting (a column per name used by any
// variant) and every metric.
std::string episodes_csv(const std::vector<EpisodeRow>& rows) {
  std::set<std::string> setting_names;
  for (const auto& r : rows) {
    for (const auto& kv : r.spec.variant.settings) setting_names.insert(kv.first);
  }
  std::ostringstream csv;
  csv << "scenario,variant,seed";
  for (const auto& s : setting_names) csv << ',' << csv_field(s);
  for (const auto& c : metric_columns()) csv << ',' << c.name;
  csv << ",occlusions,steps,duration_s\n";
  for (const auto& r : rows) {
    csv << csv_field(r.spec.scenario) << ',' << csv_field(r.spec.variant.name) << ',' << r.spec.seed;
    for (const auto& s : setting_names) {
      // The last value wins, as when the settings are applied in order.
      std::string value;
      for (const auto& kv : r.spec.variant.settings) {
        if (kv.first == s) value = kv.second;
      }
      csv << ',' << csv_field(value);
    }
    for (const auto& c : metric_columns()) csv << ',' << csv_number(c.get(r.metrics));
    csv << ',' << r.metrics.occlusions.size() << ',' << r.metrics.steps << ','
        << csv_number(r.metrics.duration) << '\n';
  }
  return csv.str();
}

// The limit of each scenario and seed: the episode of method hindsight
// (its executed path), if the sweep ran one.
class Limits {
 public:
  explicit Limits(const std::vector<EpisodeRow>& rows) {
    for (const EpisodeRow& r : rows) {
      if (r.metrics.hindsight) limit_.emplace(std::make_pair(r.spec.scenario, r.spec.seed), &r.metrics);
    }
  }
  [[nodiscard]] bool any() const { return !limit_.empty(); }
  // A group's distance to the limit in `column`, seed by seed (its value minus the limit's).
  [[nodiscard]] Interval distance(const EpisodeGroup& g, const MetricColumn& column) const {
    std::vector<double> d;
    for (const EpisodeRow& r : g.rows) {
      const auto it = limit_.find(std::make_pair(r.spec.scenario, r.spec.seed));
      if (it != limit_.end()) d.push_back(column.get(r.metrics) - column.get(*it->second));
    }
    return mean_interval(d);
  }

 private:
  std::map<std::pair<std::string, unsigned>, const EpisodeMetrics*> limit_;
};

// The columns compared with the limit: visibility and time below the threshold.
const std::vector<MetricColumn>& limit_columns() {
  static const std::vector<MetricColumn> c{
      {"to_limit_visible_fraction", "to limit: visible", [](const EpisodeMetrics& m) { return m.mean_visible_fraction; }},
      {"to_limit_time_below_threshold_s", "to limit: below 0.9 [s]",
       [](const EpisodeMetrics& m) { return m.time_below_threshold; }},
  };
  return c;
}

std::string md_cell(const Interval& i) {
  if (i.n == 0) return " n/a |";
  return ' ' + csv_number(i.mean, 3) + (i.n >= 2 ? " ± " + csv_number(i.half_width, 2) : "") + " |";
}

}  // namespace

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n") == std::string::npos) return text;
  std::string out = "\"";
  for (char ch : text) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string csv_number(double value, int precision) {
  if (!std::isfinite(value)) return "";
  std::ostringstream s;
  s << std::setprecision(precision) << value;
  return s.str();
}

void write_tables(const std::vector<EpisodeRow>& rows, const std::string& out_dir) {
  const fs::path out(out_dir);
  fs::create_directories(out);
  write_file_atomically(out / "episodes.csv", episodes_csv(rows));

  // summary.csv and summary.md: per scenario x variant, in sweep order;
  // with a hindsight variant, each variant's distance to it (the limit).
  const EpisodeGroups grouped = group_episodes(rows);
  const Limits limits(rows);
  std::ostringstream csv, md;
  csv << "scenario,variant,settings,seeds";
  for (const auto& c : metric_columns()) csv << ',' << c.name << ',' << c.name << "_ci95";
  if (limits.any()) {
    for (const auto& c : limit_columns()) csv << ',' << c.name << ',' << c.name << "_ci95";
  }
  csv << '\n';
  md << "# Closed-loop comparison\n\nMean over seeds, ± the 95 % confidence half-width "
        "(Student t). Visible fraction is the true fraction of the object's surface the "
        "camera sees; recovery is the time from visibility falling below 0.9 until it is "
        "back (dips less than 0.2 s apart are one occlusion).\n";
  if (limits.any()) {
    md << "\nThe limit is the hindsight variant (method hindsight: the best camera path planned with the whole "
          "episode known, followed by the same controller); \"to limit\" is each variant's value minus the "
          "limit's, seed by seed.\n";
  }
  for (const auto& scenario : grouped.scenarios) {
    md << "\n## " << md_text(scenario) << "\n\n| variant | seeds |";
    for (const auto& c : metric_columns()) md << ' ' << c.label << " |";
    if (limits.any()) {
      for (const auto& c : limit_columns()) md << ' ' << c.label << " |";
    }
    md << "\n|---|---|";
    for (std::size_t k = 0; k < metric_columns().size() + (limits.any() ? limit_columns().size() : 0); ++k) md << "---|";
    md << '\n';
    for (const auto& g : grouped.groups) {
      if (g.scenario != scenario) continue;
      csv << csv_field(g.scenario) << ',' << csv_field(g.variant.name) << ','
          << csv_field(settings_text(g.variant)) << ',' << g.rows.size();
      md << "| " << md_text(g.variant.name) << " | " << g.rows.size() << " |";
      const auto cell = [&](const Interval& i) {
        csv << ',' << csv_number(i.mean) << ',' << csv_number(i.half_width);
        md << md_cell(i);
      };
      for (const auto& c : metric_columns()) cell(g.interval(c));
      if (limits.any()) {
        for (const auto& c : limit_columns()) cell(limits.distance(g, c));
      }
      csv << '\n';
      md << '\n';
    }
  }
  write_file_atomically(out / "summary.csv", csv.str());
  write_file_atomically(out / "summary.md", md.str());
}

std::vector<std::string> write_reports(const std::vector<EpisodeRow>& rows,
                                       const std::string& out_dir) {
  write_tables(rows, out_dir);
  return write_plots(rows, out_dir);
}

}  // namespace ofv
