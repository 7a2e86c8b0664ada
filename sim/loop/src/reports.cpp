// The tables of `ofv compare`: episodes.csv, summary.csv, summary.md.
#include "ofv/loop/reports.h"

#include "ofv/loop/plots.h"
#include "ofv/loop/statistics.h"

#include <cmath>
#include <iomanip>
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

  // summary.csv and summary.md: per scenario x variant, in sweep order.
  const EpisodeGroups grouped = group_episodes(rows);
  std::ostringstream csv, md;
  csv << "scenario,variant,settings,seeds";
  for (const auto& c : metric_columns()) csv << ',' << c.name << ',' << c.name << "_ci95";
  csv << '\n';
  md << "# Closed-loop comparison\n\nMean over seeds, ± the 95 % confidence half-width "
        "(Student t). Visible fraction is the true fraction of the object's surface the "
        "camera sees; recovery is the time from visibility falling below 0.9 until it is "
        "back (dips less than 0.2 s apart are one occlusion).\n";
  for (const auto& scenario : grouped.scenarios) {
    md << "\n## " << md_text(scenario) << "\n\n| variant | seeds |";
    for (const auto& c : metric_columns()) md << ' ' << c.label << " |";
    md << "\n|---|---|";
    for (std::size_t k = 0; k < metric_columns().size(); ++k) md << "---|";
    md << '\n';
    for (const auto& g : grouped.groups) {
      if (g.scenario != scenario) continue;
      csv << csv_field(g.scenario) << ',' << csv_field(g.variant.name) << ','
          << csv_field(settings_text(g.variant)) << ',' << g.rows.size();
      md << "| " << md_text(g.variant.name) << " | " << g.rows.size() << " |";
      for (const auto& c : metric_columns()) {
        const Interval i = g.interval(c);
        csv << ',' << csv_number(i.mean) << ',' << csv_number(i.half_width);
        if (i.n == 0) {
          md << " n/a |";
        } else {
          md << ' ' << csv_number(i.mean, 3) << (i.n >= 2 ? " ± " + csv_number(i.half_width, 2) : "") << " |";
        }
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
