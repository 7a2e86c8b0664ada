// `ofv compare`: sweep planning, parallel resumable runs, aggregation, plots.
#include "ofv/loop/compare.h"
#include "ofv/loop/metrics_json.h"

#include <nlohmann/json.hpp>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <iostream>
#include <mutex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <thread>

#include <unistd.h>

namespace ofv {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

// ---------------------------------------------------------------- grid YAML

[[noreturn]] void grid_error(const std::string& source, const std::string& key,
                             const std::string& what) {
  throw std::invalid_argument(source + ": " + key + ": " + what);
}

std::string scalar_text(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (!n.IsScalar()) grid_error(source, key, "expected a single value (number or word)");
  return n.Scalar();
}

// One `name: value` map of settings, in file order.
std::vector<std::pair<std::string, std::string>> settings_map(const YAML::Node& n,
                                                              const std::string& source,
                                                              const std::string& key) {
  if (!n.IsMap()) grid_error(source, key, "expected a map of setting: value");
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& item : n) {
    const std::string name = item.first.as<std::string>();
    out.emplace_back(name, scalar_text(item.second, source, key + "." + name));
  }
  return out;
}

std::string safe_name(const std::string& s) {
  std::string out;
  for (char ch : s) {
    out += (std::isalnum(static_cast<unsigned char>(ch)) || ch == '-' || ch == '.') ? ch : '_';
  }
  return out;
}

// ---------------------------------------------------------------- files

void write_atomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

json spec_to_json(const EpisodeSpec& s) {
  json settings = json::array();
  for (const auto& [k, v] : s.variant.settings) settings.push_back({k, v});
  return {{"index", s.index},     {"id", s.id()},           {"scenario", s.scenario},
          {"scenario_path", s.scenario_path}, {"variant", s.variant.name},
          {"settings", settings}, {"seed", s.seed}};
}

EpisodeSpec spec_from_json(const json& j) {
  EpisodeSpec s;
  s.index = j.at("index").get<int>();
  s.scenario = j.at("scenario").get<std::string>();
  s.scenario_path = j.at("scenario_path").get<std::string>();
  s.variant.name = j.at("variant").get<std::string>();
  for (const auto& kv : j.at("settings")) {
    s.variant.settings.emplace_back(kv.at(0).get<std::string>(), kv.at(1).get<std::string>());
  }
  s.seed = j.at("seed").get<int>();
  return s;
}

// ---------------------------------------------------------------- progress

class Progress {
 public:
  Progress(int total, bool enabled) : total_(total), enabled_(enabled && isatty(2) != 0) {}
  void tick() {
    const int done = ++done_;
    if (!enabled_) return;
    const double elapsed =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count();
    const double eta = done > 0 ? elapsed / done * (total_ - done) : 0.0;
    constexpr int kWidth = 30;
    const int filled = total_ > 0 ? kWidth * done / total_ : kWidth;
    std::lock_guard<std::mutex> lock(mutex_);
    std::fprintf(stderr, "\r[%s%s] %d/%d episodes, %.0f s elapsed, ETA %.0f s ",
                 std::string(static_cast<std::size_t>(filled), '#').c_str(),
                 std::string(static_cast<std::size_t>(kWidth - filled), '.').c_str(), done, total_,
                 elapsed, eta);
    if (done == total_) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  int total_;
  bool enabled_;
  std::atomic<int> done_{0};
  std::mutex mutex_;
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
};

// Two-sided 95 % Student t quantiles for 1..30 degrees of freedom.
double t_quantile_95(int dof) {
  static const double table[] = {12.706, 4.303, 2.182, 2.776, 2.571, 2.447, 2.365, 2.306,
                                 2.262,  2.228, 2.201, 2.179, 2.160, 2.145, 2.131, 2.120,
                                 2.110,  2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064,
                                 2.060,  2.056, 2.052, 2.048, 2.045, 2.042};
  if (dof < 1) return 0.0;
  return dof <= 30 ? table[dof - 1] : 1.96;
}

// The per-episode metrics that the reports aggregate: name, unit, getter.
struct Column {
  const char* name;
  const char* label;
  double (*get)(const EpisodeMetrics&);
};

const std::vector<Column>& columns() {
  static const std::vector<Column> c{
      {"mean_visible_fraction", "mean visible fraction", [](const EpisodeMetrics& m) { return m.mean_visible_fraction; }},
      {"min_visible_fraction", "min visible fraction", [](const EpisodeMetrics& m) { return m.min_visible_fraction; }},
      {"time_below_threshold_s", "time below 0.9 [s]", [](const EpisodeMetrics& m) { return m.time_below_threshold; }},
      {"max_recovery_time_s", "worst recovery [s]", [](const EpisodeMetrics& m) {
         return m.max_recovery_time ? *m.max_recovery_time : std::nan("");
       }},
      {"unrecovered_occlusions", "unrecovered", [](const EpisodeMetrics& m) { return static_cast<double>(m.unrecovered_occlusions); }},
      {"mean_angular_error_deg", "angular error [deg]", [](const EpisodeMetrics& m) { return m.mean_angular_error_deg; }},
      {"path_length_m", "path [m]", [](const EpisodeMetrics& m) { return m.path_length; }},
      {"max_sphere_distance_error_m", "max sphere dist. err. [m]", [](const EpisodeMetrics& m) { return m.max_sphere_distance_error; }},
      {"mean_estimate_ms", "estimate [ms]", [](const EpisodeMetrics& m) { return 1e3 * m.mean_times.estimate; }},
      {"mean_step_ms", "whole step [ms]", [](const EpisodeMetrics& m) { return 1e3 * m.mean_times.total(); }},
  };
  return c;
}

std::string csv_field(const std::string& s) {
  if (s.find_first_of(",\"\n") == std::string::npos) return s;
  std::string out = "\"";
  for (char ch : s) out += ch == '"' ? std::string("\"\"") : std::string(1, ch);
  return out + "\"";
}

std::string number(double v, int precision = 6) {
  if (!std::isfinite(v)) return "";
  std::ostringstream s;
  s << std::setprecision(precision) << v;
  return s.str();
}

std::string settings_text(const Variant& v) {
  std::string out;
  for (const auto& [k, val] : v.settings) out += (out.empty() ? "" : " ") + k + "=" + val;
  return out;
}

// Quotes a path for a gnuplot string.
std::string gp(const fs::path& p) {
  std::string out = "'";
  for (char ch : p.string()) out += ch == '\'' ? std::string("''") : std::string(1, ch);
  return out + "'";
}

}  // namespace

// ------------------------------------------------------------------ grid

Grid grid_from_yaml(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": invalid YAML: " + e.what());
  }
  if (!root.IsMap()) throw std::invalid_argument(source + ": expected a map with 'variants' and/or 'axes'");
  Grid grid;
  std::vector<Variant> base;
  std::vector<std::pair<std::string, std::vector<std::string>>> axes;
  for (const auto& item : root) {
    const std::string key = item.first.as<std::string>();
    const YAML::Node& n = item.second;
    if (key == "name") {
      grid.name = scalar_text(n, source, key);
    } else if (key == "seeds") {
      try {
        grid.seeds = n.as<int>();
      } catch (const YAML::Exception&) {
        grid_error(source, key, "expected a positive integer, got '" + scalar_text(n, source, key) + "'");
      }
      if (grid.seeds < 1) grid_error(source, key, "expected a positive integer, got " + std::to_string(grid.seeds));
    } else if (key == "variants") {
      if (!n.IsSequence()) grid_error(source, key, "expected a list of {name, set}");
      for (std::size_t i = 0; i < n.size(); ++i) {
        const std::string at = key + "[" + std::to_string(i) + "]";
        if (!n[i].IsMap()) grid_error(source, at, "expected {name: ..., set: {...}}");
        Variant v;
        for (const auto& f : n[i]) {
          const std::string fk = f.first.as<std::string>();
          if (fk == "name") {
            v.name = scalar_text(f.second, source, at + ".name");
          } else if (fk == "set") {
            v.settings = settings_map(f.second, source, at + ".set");
          } else {
            grid_error(source, at + "." + fk, "unknown key (expected name, set)");
          }
        }
        if (v.name.empty()) grid_error(source, at + ".name", "missing");
        base.push_back(v);
      }
    } else if (key == "axes") {
      if (!n.IsMap()) grid_error(source, key, "expected a map of setting: [values]");
      for (const auto& a : n) {
        const std::string name = a.first.as<std::string>();
        if (!a.second.IsSequence() || a.second.size() == 0) {
          grid_error(source, key + "." + name, "expected a non-empty list of values");
        }
        std::vector<std::string> values;
        for (std::size_t i = 0; i < a.second.size(); ++i) {
          values.push_back(scalar_text(a.second[i], source, key + "." + name + "[" + std::to_string(i) + "]"));
        }
        axes.emplace_back(name, values);
      }
    } else {
      grid_error(source, key, "unknown key (expected name, seeds, variants, axes)");
    }
  }
  if (base.empty()) base.push_back(Variant{"", {}});
  // Cartesian product of the axes, applied after each variant's own settings.
  std::vector<Variant> expanded = base;
  for (const auto& [name, values] : axes) {
    std::vector<Variant> next;
    for (const Variant& v : expanded) {
      for (const std::string& value : values) {
        Variant w = v;
        w.settings.emplace_back(name, value);
        w.name += (w.name.empty() ? "" : ",") + name + "=" + value;
        next.push_back(w);
      }
    }
    expanded = next;
  }
  std::set<std::string> names;
  for (Variant& v : expanded) {
    if (v.name.empty()) v.name = "default";
    if (!names.insert(v.name).second) {
      throw std::invalid_argument(source + ": variants: the name '" + v.name + "' is used twice");
    }
  }
  grid.variants = expanded;
  return grid;
}

Grid read_grid(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::invalid_argument(path + ": cannot read file");
  std::stringstream s;
  s << in.rdbuf();
  return grid_from_yaml(s.str(), path);
}

// ------------------------------------------------------------------ planning

std::string EpisodeSpec::id() const {
  return safe_name(scenario) + "__" + safe_name(variant.name) + "__seed" + std::to_string(seed);
}

std::vector<EpisodeSpec> plan_episodes(
    const std::vector<std::pair<std::string, std::string>>& scenarios, const Grid& grid) {
  std::vector<EpisodeSpec> out;
  for (const auto& [name, path] : scenarios) {
    for (const Variant& v : grid.variants) {
      for (int seed = 0; seed < grid.seeds; ++seed) {
        EpisodeSpec s;
        s.index = static_cast<int>(out.size());
        s.scenario = name;
        s.scenario_path = path;
        s.variant = v;
        s.seed = seed;
        out.push_back(s);
      }
    }
  }
  return out;
}

std::vector<EpisodeSpec> shard(const std::vector<EpisodeSpec>& all, int k, int n) {
  if (n < 1 || k < 1 || k > n) {
    throw std::invalid_argument("--shard K/N needs 1 <= K <= N, got " + std::to_string(k) + "/" +
                                std::to_string(n));
  }
  std::vector<EpisodeSpec> out;
  for (const auto& s : all) {
    if (s.index % n == k - 1) out.push_back(s);
  }
  return out;
}

// ------------------------------------------------------------------ running

int run_sweep(const std::vector<EpisodeSpec>& episodes, const EpisodeRunner& runner,
              const std::string& out_dir, const SweepOptions& options) {
  const fs::path dir = fs::path(out_dir) / "episodes";
  fs::create_directories(dir);
  std::vector<const EpisodeSpec*> todo;
  for (const auto& s : episodes) {
    if (!fs::exists(dir / (s.id() + ".json"))) todo.push_back(&s);
  }
  Progress progress(static_cast<int>(todo.size()), options.progress);
  std::atomic<std::size_t> next{0};
  std::mutex error_mutex;
  std::string first_error;
  auto work = [&] {
    for (std::size_t i = next++; i < todo.size(); i = next++) {
      const EpisodeSpec& spec = *todo[i];
      {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (!first_error.empty()) return;
      }
      try {
        const EpisodeOutcome outcome = runner(spec);
        std::string csv = trajectory_csv_header() + "\n";
        for (const auto& step : outcome.steps) csv += trajectory_csv_row(step) + "\n";
        write_atomically(dir / (spec.id() + ".csv"), csv);
        // The JSON is written last: its presence marks the episode finished.
        json j = spec_to_json(spec);
        j["metrics"] = metrics_to_json(outcome.metrics);
        write_atomically(dir / (spec.id() + ".json"), j.dump(1) + "\n");
      } catch (const std::exception& e) {
        std::lock_guard<std::mutex> lock(error_mutex);
        if (first_error.empty()) first_error = "episode " + spec.id() + ": " + e.what();
        return;
      }
      progress.tick();
    }
  };
  const int jobs = std::max(1, std::min<int>(options.jobs, static_cast<int>(todo.size())));
  std::vector<std::thread> threads;
  for (int j = 1; j < jobs; ++j) threads.emplace_back(work);
  work();
  for (auto& t : threads) t.join();
  if (!first_error.empty()) throw std::runtime_error(first_error);
  return static_cast<int>(todo.size());
}

std::vector<EpisodeRow> load_episodes(const std::vector<std::string>& dirs) {
  std::vector<EpisodeRow> rows;
  std::set<std::string> seen;
  for (const auto& d : dirs) {
    const fs::path dir = fs::path(d) / "episodes";
    if (!fs::is_directory(dir)) throw std::invalid_argument(d + ": no episodes/ folder (not an ofv compare output)");
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().extension() == ".json") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      std::ifstream in(f);
      json j;
      try {
        j = json::parse(in);
        EpisodeRow row;
        row.spec = spec_from_json(j);
        row.metrics = metrics_from_json(j.at("metrics"));
        row.trajectory_csv = (dir / (row.spec.id() + ".csv")).string();
        if (seen.insert(row.spec.id()).second) rows.push_back(row);
      } catch (const std::exception& e) {
        throw std::invalid_argument(f.string() + ": not a finished episode: " + e.what());
      }
    }
  }
  std::stable_sort(rows.begin(), rows.end(), [](const EpisodeRow& a, const EpisodeRow& b) {
    return a.spec.index < b.spec.index;
  });
  return rows;
}

Interval mean_interval(const std::vector<double>& xs) {
  Interval r;
  std::vector<double> v;
  for (double x : xs) {
    if (std::isfinite(x)) v.push_back(x);
  }
  r.n = static_cast<int>(v.size());
  if (v.empty()) {
    r.mean = std::nan("");
    return r;
  }
  double sum = 0.0;
  for (double x : v) sum += x;
  r.mean = sum / r.n;
  if (r.n >= 2) {
    double ss = 0.0;
    for (double x : v) ss += (x - r.mean) * (x - r.mean);
    const double sd = std::sqrt(ss / (r.n - 1));
    // Equal samples may differ in the last bits (times summed differently): no spread.
    if (sd > 1e-12 * std::max(1.0, std::abs(r.mean))) r.half_width = t_quantile_95(r.n - 1) * sd / std::sqrt(r.n);
  }
  return r;
}

// ------------------------------------------------------------------ reports

std::vector<std::string> write_reports(const std::vector<EpisodeRow>& rows,
                                       const std::string& out_dir) {
  const fs::path out(out_dir);
  fs::create_directories(out);

  // episodes.csv: one row per episode, every setting and every metric.
  std::set<std::string> setting_names;
  for (const auto& r : rows) {
    for (const auto& kv : r.spec.variant.settings) setting_names.insert(kv.first);
  }
  {
    std::ostringstream csv;
    csv << "scenario,variant,seed";
    for (const auto& s : setting_names) csv << ',' << csv_field(s);
    for (const auto& c : columns()) csv << ',' << c.name;
    csv << ",occlusions,steps,duration_s\n";
    for (const auto& r : rows) {
      csv << csv_field(r.spec.scenario) << ',' << csv_field(r.spec.variant.name) << ',' << r.spec.seed;
      for (const auto& s : setting_names) {
        std::string value;
        for (const auto& kv : r.spec.variant.settings) {
          if (kv.first == s) value = kv.second;
        }
        csv << ',' << csv_field(value);
      }
      for (const auto& c : columns()) csv << ',' << number(c.get(r.metrics));
      csv << ',' << r.metrics.occlusions.size() << ',' << r.metrics.steps << ','
          << number(r.metrics.duration) << '\n';
    }
    write_atomically(out / "episodes.csv", csv.str());
  }

  // Groups: scenario x variant, in sweep order.
  struct Group {
    std::string scenario;
    const Variant* variant;
    std::vector<const EpisodeRow*> rows;
  };
  std::vector<Group> groups;
  std::vector<std::string> scenarios, variants;
  for (const auto& r : rows) {
    auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) {
      return x.scenario == r.spec.scenario && x.variant->name == r.spec.variant.name;
    });
    if (g == groups.end()) {
      groups.push_back(Group{r.spec.scenario, &r.spec.variant, {}});
      g = groups.end() - 1;
    }
    g->rows.push_back(&r);
    if (std::find(scenarios.begin(), scenarios.end(), r.spec.scenario) == scenarios.end()) scenarios.push_back(r.spec.scenario);
    if (std::find(variants.begin(), variants.end(), r.spec.variant.name) == variants.end()) variants.push_back(r.spec.variant.name);
  }
  auto interval = [](const Group& g, const Column& c) {
    std::vector<double> xs;
    for (const auto* r : g.rows) xs.push_back(c.get(r->metrics));
    return mean_interval(xs);
  };

  {
    std::ostringstream csv, md;
    csv << "scenario,variant,settings,seeds";
    for (const auto& c : columns()) csv << ',' << c.name << ',' << c.name << "_ci95";
    csv << '\n';
    md << "# Closed-loop comparison\n\nMean over seeds, ± the 95 % confidence half-width "
          "(Student t). Visible fraction is the true fraction of the object's surface the "
          "camera sees; recovery is the time from visibility falling below 0.9 until it is "
          "back (dips less than 0.2 s apart are one occlusion).\n";
    for (const auto& scenario : scenarios) {
      md << "\n## " << scenario << "\n\n| variant | seeds |";
      for (const auto& c : columns()) md << ' ' << c.label << " |";
      md << "\n|---|---|";
      for (std::size_t k = 0; k < columns().size(); ++k) md << "---|";
      md << '\n';
      for (const auto& g : groups) {
        if (g.scenario != scenario) continue;
        csv << csv_field(g.scenario) << ',' << csv_field(g.variant->name) << ','
            << csv_field(settings_text(*g.variant)) << ',' << g.rows.size();
        md << "| " << g.variant->name << " | " << g.rows.size() << " |";
        for (const auto& c : columns()) {
          const Interval i = interval(g, c);
          csv << ',' << number(i.mean) << ',' << number(i.half_width);
          if (i.n == 0) {
            md << " n/a |";
          } else {
            md << ' ' << number(i.mean, 3) << (i.n >= 2 ? " ± " + number(i.half_width, 2) : "") << " |";
          }
        }
        csv << '\n';
        md << '\n';
      }
    }
    write_atomically(out / "summary.csv", csv.str());
    write_atomically(out / "summary.md", md.str());
  }

  // Plots with gnuplot: data files and one script, kept beside the PNGs.
  const fs::path plot_dir = out / "plots";
  fs::create_directories(plot_dir);
  std::ostringstream script;
  // gnuplot's default colours repeat after 8: give variants 9-16 their own.
  script << "set terminal pngcairo size 1000,560 font 'Sans,10'\nset datafile separator ','\n"
            "set linetype 9 lc rgb '#8c564b'\nset linetype 10 lc rgb '#17becf'\nset linetype 11 lc rgb '#bcbd22'\n"
            "set linetype 12 lc rgb '#7f7f7f'\nset linetype 13 lc rgb '#ff7f0e'\nset linetype 14 lc rgb '#2ca02c'\n"
            "set linetype 15 lc rgb '#d62728'\nset linetype 16 lc rgb '#9467bd'\nset linetype cycle 16\n"
            "set key outside right\nset grid\n";
  std::vector<std::string> pngs;
  for (std::size_t si = 0; si < scenarios.size(); ++si) {
    const std::string& scenario = scenarios[si];
    // Visible fraction over time: the first seed of each variant.
    const fs::path png = plot_dir / ("visibility_" + safe_name(scenario) + ".png");
    script << "set output " << gp(png) << "\nset title 'True visible fraction over time: "
           << scenario << " (seed 0)' noenhanced\nset xlabel 'time [s]'\nset ylabel 'visible fraction'\n"
           << "set yrange [0:1.05]\nplot ";
    bool first = true;
    for (const auto& g : groups) {
      if (g.scenario != scenario) continue;
      const EpisodeRow* r = g.rows.front();
      script << (first ? "" : ", ") << gp(r->trajectory_csv)
             << " using \"time\":\"visible_fraction\" with lines lw 2 title " << gp(g.variant->name) << " noenhanced";
      first = false;
    }
    script << "\nset yrange [*:*]\n";
    pngs.push_back(png.string());
  }
  // Bar charts per metric: variants side by side, one cluster per scenario.
  const std::vector<std::pair<std::string, std::string>> bars{
      {"mean_visible_fraction", "mean visible fraction"},
      {"max_recovery_time_s", "worst recovery time [s]"},
      {"mean_step_ms", "compute time per step [ms]"},
      {"mean_estimate_ms", "estimator time per frame [ms]"}};
  for (const auto& [metric, label] : bars) {
    const auto col = std::find_if(columns().begin(), columns().end(),
                                  [&](const Column& c) { return metric == c.name; });
    std::ostringstream dat;
    dat << "# scenario";  // a comment, so that gnuplot does not plot it
    for (const auto& v : variants) dat << ',' << csv_field(v) << ',' << csv_field(v + " ci");
    dat << '\n';
    for (const auto& scenario : scenarios) {
      dat << csv_field(scenario);
      for (const auto& v : variants) {
        auto g = std::find_if(groups.begin(), groups.end(), [&](const Group& x) {
          return x.scenario == scenario && x.variant->name == v;
        });
        if (g == groups.end()) {
          dat << ",,";
        } else {
          const Interval i = interval(*g, *col);
          dat << ',' << number(i.mean) << ',' << number(i.half_width);
        }
      }
      dat << '\n';
    }
    const fs::path data = plot_dir / (metric + ".csv");
    write_atomically(data, dat.str());
    const fs::path png = plot_dir / (metric + ".png");
    script << "set output " << gp(png) << "\nset title '" << label
           << " per setting (mean, 95 % CI)'\nset style data histogram\n"
              "set style histogram errorbars gap 1 lw 1\nset style fill solid 0.6 border -1\n"
              "set xtics rotate by -20 noenhanced\nset xlabel ''\nset ylabel '"
           << label << "'\nset yrange [0:*]\nplot ";
    for (std::size_t k = 0; k < variants.size(); ++k) {
      script << (k ? ", " : "") << gp(data) << " using " << 2 + 2 * k << ':' << 3 + 2 * k
             << ":xtic(1) title " << gp(variants[k]) << " noenhanced";
    }
    script << "\nunset style\nset style data lines\nset xtics norotate\nset yrange [*:*]\n";
    pngs.push_back(png.string());
  }
  const fs::path script_path = plot_dir / "plots.gp";
  write_atomically(script_path, script.str());
  const std::string quoted = "gnuplot \"" + script_path.string() + "\" 2>\"" +
                             (plot_dir / "gnuplot.log").string() + "\"";
  if (std::system(quoted.c_str()) != 0) {
    std::cerr << "ofv compare: warning: gnuplot failed or is missing (see "
              << (plot_dir / "gnuplot.log").string() << "); tables were written\n";
    return {};
  }
  return pngs;
}

}  // namespace ofv
