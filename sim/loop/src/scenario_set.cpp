// The scenarios of a simulated comparison, and the grid checked against them.
#include "ofv/loop/scenario_set.h"

#include "ofv/loop/episode.h"

#include <algorithm>
#include <filesystem>
#include <stdexcept>

namespace ofv {

namespace fs = std::filesystem;

std::vector<std::pair<std::string, std::string>> scenario_set(const std::vector<std::string>& args) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& a : args) {
    if (fs::is_directory(a)) {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(a)) {
        if (e.path().extension() == ".yaml") files.push_back(e.path());
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) throw std::invalid_argument("--scenarios " + a + ": no .yaml scenario in this folder");
      for (const auto& f : files) out.emplace_back(f.stem().string(), f.string());
    } else {
      const sim::Scenario s = sim::load_scenario(a);  // validates, and resolves built-in names
      out.emplace_back(s.name, s.path);
    }
  }
  // Scenario names key the episodes and the tables: two files of the same
  // name (a/x.yaml, b/x.yaml) would be one row.
  for (std::size_t i = 0; i < out.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      if (out[i].first == out[j].first) {
        throw std::invalid_argument("--scenarios " + out[i].second + ": the scenario name '" + out[i].first +
                                    "' is used twice (also " + out[j].second + ")");
      }
    }
  }
  return out;
}

void check_grid(const std::vector<std::pair<std::string, std::string>>& scenarios,
                const Grid& grid, const std::string& grid_source) {
  for (const auto& [name, path] : scenarios) {
    const sim::Scenario s = sim::load_scenario(path);
    for (const auto& v : grid.variants) {
      try {
        (void)resolve_episode(s, v.settings);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(grid_source + ": variant '" + v.name + "': " + e.what());
      }
    }
  }
}

}  // namespace ofv
