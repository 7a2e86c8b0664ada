// The episode files of `ofv compare`: written one by one (resume), read back
// from one or several output folders (merge).
#include "ofv/loop/episode_store.h"

#include "ofv/loop/metrics_json.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <set>
#include <stdexcept>

namespace ofv {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

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

}  // namespace

void write_file_atomically(const fs::path& path, const std::string& text) {
  const fs::path tmp = path.string() + ".tmp";
  {
    std::ofstream out(tmp);
    out << text;
    if (!out) throw std::runtime_error("cannot write " + tmp.string());
  }
  fs::rename(tmp, path);
}

EpisodeStore::EpisodeStore(const std::string& out_dir) : dir_(fs::path(out_dir) / "episodes") {
  fs::create_directories(dir_);
}

bool EpisodeStore::finished(const EpisodeSpec& spec) const {
  return fs::exists(dir_ / (spec.id() + ".json"));
}

void EpisodeStore::write(const EpisodeSpec& spec, const EpisodeOutcome& outcome) const {
  std::string csv = trajectory_csv_header() + "\n";
  for (const auto& step : outcome.steps) csv += trajectory_csv_row(step) + "\n";
  write_file_atomically(dir_ / (spec.id() + ".csv"), csv);
  // The JSON is written last: its presence marks the episode finished.
  json j = spec_to_json(spec);
  j["metrics"] = metrics_to_json(outcome.metrics);
  write_file_atomically(dir_ / (spec.id() + ".json"), j.dump(1) + "\n");
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
      try {
        const json j = json::parse(in);
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

}  // namespace ofv
