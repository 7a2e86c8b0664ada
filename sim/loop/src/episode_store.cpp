// The episode files of `ofv compare`: written one by one (resume), read back
// from one or several output folders (merge).
#include "ofv/loop/episode_store.h"
#include "ofv/text_file.h"

#include "ofv/loop/metrics_json.h"
#include "ofv/version.h"

#include <nlohmann/json.hpp>

#include <fcntl.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <stdexcept>

namespace ofv {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr const char* kSweepFormat = "ofv compare sweep 2";

// Which ofv ran a folder's episodes: `0.1.0 (git <commit>)`.
std::string this_ofv() { return std::string(version()) + " (git " + git_commit() + ")"; }

json settings_to_json(const std::vector<std::pair<std::string, std::string>>& settings) {
  json out = json::array();
  for (const auto& [k, v] : settings) out.push_back({k, v});
  return out;
}

std::vector<std::pair<std::string, std::string>> settings_from_json(const json& j) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& kv : j) out.emplace_back(kv.at(0).get<std::string>(), kv.at(1).get<std::string>());
  return out;
}

json spec_to_json(const EpisodeSpec& s) {
  return {{"index", s.index},
          {"id", s.id()},
          {"scenario", s.scenario},
          {"scenario_path", s.scenario_path},
          {"scenario_hash", s.scenario_hash},
          {"variant", s.variant.name},
          {"settings", settings_to_json(s.variant.settings)},
          {"seed", s.seed}};
}

EpisodeSpec spec_from_json(const json& j) {
  EpisodeSpec s;
  s.index = j.at("index").get<int>();
  s.scenario = j.at("scenario").get<std::string>();
  s.scenario_path = j.at("scenario_path").get<std::string>();
  s.scenario_hash = j.at("scenario_hash").get<std::string>();
  s.variant.name = j.at("variant").get<std::string>();
  s.variant.settings = settings_from_json(j.at("settings"));
  s.seed = j.at("seed").get<int>();
  return s;
}

// An episode's record (its JSON, a few kB).
std::string slurp(const fs::path& p) {
  constexpr std::uintmax_t kMaxRecordBytes = 64 << 20;
  return read_text_file(p.string(), kMaxRecordBytes, "episode record");
}

// `a=1 b=2`, or `none`.
std::string settings_text(const std::vector<std::pair<std::string, std::string>>& settings) {
  std::string out;
  for (const auto& [k, v] : settings) out += (out.empty() ? "" : " ") + k + "=" + v;
  return out.empty() ? "none" : out;
}

// What differs between the episode a file records (there) and the one
// expected (here); empty when they are the same episode.
std::string episode_difference(const EpisodeSpec& there, const EpisodeSpec& here) {
  if (there.scenario != here.scenario) return "scenario '" + there.scenario + "' there, '" + here.scenario + "' here";
  if (there.scenario_hash != here.scenario_hash) {
    return "scenario '" + here.scenario + "' with files of fingerprint " + there.scenario_hash + " there, " +
           here.scenario_hash + " here (the scenario or a mesh was edited)";
  }
  if (there.variant.name != here.variant.name) {
    return "variant '" + there.variant.name + "' there, '" + here.variant.name + "' here";
  }
  if (there.variant.settings != here.variant.settings) {
    return "variant '" + here.variant.name + "' with settings " + settings_text(there.variant.settings) +
           " there, " + settings_text(here.variant.settings) + " here";
  }
  if (there.seed != here.seed) return "seed " + std::to_string(there.seed) + " there, " + std::to_string(here.seed) + " here";
  return {};
}

// The names in first-seen order, for messages: `a, b, c` (and how many more).
template <class Get>
std::vector<std::string> distinct(const std::vector<EpisodeSpec>& plan, Get get) {
  std::vector<std::string> out;
  std::set<std::string> seen;
  for (const auto& s : plan) {
    if (seen.insert(get(s)).second) out.push_back(get(s));
  }
  return out;
}

std::string list_text(const std::vector<std::string>& names) {
  std::string out;
  for (std::size_t i = 0; i < names.size() && i < 4; ++i) out += (i ? ", " : "") + names[i];
  if (names.size() > 4) out += ", ... (" + std::to_string(names.size()) + ")";
  return out.empty() ? "none" : out;
}

// What differs between two plans, first difference first; empty when equal.
std::string plan_difference(const std::vector<EpisodeSpec>& there, const std::vector<EpisodeSpec>& here) {
  if (plan_fingerprint(there) == plan_fingerprint(here) && there.size() == here.size()) {
    bool same = true;
    for (std::size_t i = 0; i < there.size() && same; ++i) {
      same = there[i].index == here[i].index && there[i].identity() == here[i].identity();
    }
    if (same) return {};
  }
  const auto scenario = [](const EpisodeSpec& s) { return s.scenario; };
  const auto variant = [](const EpisodeSpec& s) { return s.variant.name; };
  const auto seed = [](const EpisodeSpec& s) { return std::to_string(s.seed); };
  for (const auto& [what, get] : {std::pair<const char*, std::function<std::string(const EpisodeSpec&)>>{"scenarios", scenario},
                                  {"variants", variant}, {"seeds", seed}}) {
    const auto a = distinct(there, get), b = distinct(here, get);
    if (a != b) return std::string(what) + " " + list_text(a) + " there, " + list_text(b) + " here";
  }
  std::map<std::string, const EpisodeSpec*> by_scenario;
  for (const auto& s : there) by_scenario.emplace(s.scenario, &s);
  for (const auto& s : here) {
    const auto it = by_scenario.find(s.scenario);
    if (it != by_scenario.end() && it->second->scenario_hash != s.scenario_hash) {
      return episode_difference(*it->second, s);
    }
  }
  std::map<std::string, const EpisodeSpec*> by_name;
  for (const auto& s : there) by_name.emplace(s.variant.name, &s);
  for (const auto& s : here) {
    const auto it = by_name.find(s.variant.name);
    if (it != by_name.end() && it->second->variant.settings != s.variant.settings) {
      return episode_difference(*it->second, s);
    }
  }
  return std::to_string(there.size()) + " episodes there, " + std::to_string(here.size()) +
         " here, in another order";
}

std::string part_text(const Shard& p) { return std::to_string(p.k) + "/" + std::to_string(p.n); }

// sweep.json: the whole plan (scenario and variant tables, then one
// [scenario, variant, seed, index] per episode) and the part of this folder.
json plan_to_json(const std::vector<EpisodeSpec>& plan, const Shard& part) {
  json scenarios = json::array(), variants = json::array(), episodes = json::array();
  std::map<std::string, std::size_t> scenario_at, variant_at;
  for (const auto& s : plan) {
    const auto [si, new_scenario] = scenario_at.emplace(s.scenario, scenario_at.size());
    if (new_scenario) scenarios.push_back({{"name", s.scenario}, {"hash", s.scenario_hash}});
    const std::string vkey = json{s.variant.name, settings_to_json(s.variant.settings)}.dump();
    const auto [vi, new_variant] = variant_at.emplace(vkey, variant_at.size());
    if (new_variant) variants.push_back({{"name", s.variant.name}, {"settings", settings_to_json(s.variant.settings)}});
    episodes.push_back({si->second, vi->second, s.seed, s.index});
  }
  return {{"format", kSweepFormat}, {"ofv", this_ofv()},          {"fingerprint", plan_fingerprint(plan)},
          {"part", part_text(part)},  {"scenarios", scenarios}, {"variants", variants},
          {"episodes", episodes}};
}

struct SweepRecord {
  std::vector<EpisodeSpec> plan;
  Shard part;
  std::string ofv;  ///< which ofv ran the folder's episodes
};

SweepRecord read_record(const fs::path& file) {
  SweepRecord r;
  try {
    const json j = json::parse(slurp(file));
    if (j.at("format") != kSweepFormat) {
      throw std::runtime_error("format is not '" + std::string(kSweepFormat) + "' (a folder of an older ofv?)");
    }
    r.part = parse_shard(j.at("part").get<std::string>());
    r.ofv = j.at("ofv").get<std::string>();
    const json& scenarios = j.at("scenarios");
    const json& variants = j.at("variants");
    for (const auto& e : j.at("episodes")) {
      EpisodeSpec s;
      const json& scenario = scenarios.at(e.at(0).get<std::size_t>());
      s.scenario = scenario.at("name").get<std::string>();
      s.scenario_hash = scenario.at("hash").get<std::string>();
      const json& v = variants.at(e.at(1).get<std::size_t>());
      s.variant.name = v.at("name").get<std::string>();
      s.variant.settings = settings_from_json(v.at("settings"));
      s.seed = e.at(2).get<int>();
      s.index = e.at(3).get<int>();
      if (s.index != static_cast<int>(r.plan.size())) {
        throw std::runtime_error("episode " + std::to_string(r.plan.size()) + " has index " + std::to_string(s.index));
      }
      r.plan.push_back(std::move(s));
    }
    if (plan_fingerprint(r.plan) != j.at("fingerprint").get<std::string>()) {
      throw std::runtime_error("its fingerprint does not match its episodes");
    }
  } catch (const std::exception& e) {
    throw std::invalid_argument(file.string() + ": not a sweep record of ofv compare: " + e.what());
  }
  return r;
}

// An episode's .json: the spec it records (checked against its file name)
// and the whole object.
std::pair<EpisodeSpec, json> read_episode(const fs::path& file) {
  try {
    json j = json::parse(slurp(file));
    EpisodeSpec spec = spec_from_json(j);
    if (spec.id() != file.stem().string()) {
      throw std::runtime_error("it records " + spec.id() + " (scenario '" + spec.scenario + "', variant '" +
                               spec.variant.name + "', seed " + std::to_string(spec.seed) + ")");
    }
    return {spec, j};
  } catch (const std::exception& e) {
    throw std::invalid_argument(file.string() + ": not a finished episode of this name: " + e.what());
  }
}

// What is wrong with the trajectory file of a finished episode of `steps`
// steps (its header and one row per step), or nothing.
std::string trajectory_problem(const fs::path& csv, int steps) {
  std::error_code ec;
  if (!fs::is_regular_file(csv, ec)) return "missing";
  std::ifstream in(csv, std::ios::binary);
  long lines = 0;
  char buffer[1 << 16];
  while (in.read(buffer, sizeof buffer) || in.gcount() > 0) lines += std::count(buffer, buffer + in.gcount(), '\n');
  if (lines == steps + 1L) return {};
  return "cut short or grown: " + std::to_string(std::max(0L, lines - 1)) + " rows for " + std::to_string(steps) + " steps";
}

int steps_of(const json& episode) {
  try {
    return episode.at("metrics").at("steps").get<int>();
  } catch (const json::exception&) {
    return -1;
  }
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

EpisodeStore::EpisodeStore(const std::string& out_dir, const std::vector<EpisodeSpec>& plan, Shard part)
    : dir_(fs::path(out_dir) / "episodes") {
  std::map<std::string, const EpisodeSpec*> ids;
  for (const auto& s : plan) {
    const auto [it, inserted] = ids.emplace(s.id(), &s);
    if (!inserted) {
      throw std::invalid_argument("episodes " + std::to_string(it->second->index) + " and " +
                                  std::to_string(s.index) + " of the sweep are the same episode " + s.identity());
    }
  }
  (void)shard(plan, part.k, part.n);  // checks the part
  const fs::path record = fs::path(out_dir) / "sweep.json";
  const bool recorded = fs::exists(record);
  if (recorded) {
    const SweepRecord there = read_record(record);
    const std::string diff = plan_difference(there.plan, plan);
    if (!diff.empty()) {
      throw std::invalid_argument(record.string() + ": the folder holds another sweep (" + diff +
                                  "): give another --out");
    }
    if (there.part.k != part.k || there.part.n != part.n) {
      throw std::invalid_argument(record.string() + ": the folder holds part " + part_text(there.part) +
                                  " of this sweep, not " + part_text(part) + ": give another --out");
    }
    if (there.ofv != this_ofv()) {
      throw std::invalid_argument(record.string() + ": the folder's episodes were run by ofv " + there.ofv +
                                  ", this is ofv " + this_ofv() + " (results of other code are not mixed): give "
                                  "another --out");
    }
  } else if (fs::is_directory(dir_)) {
    for (const auto& e : fs::directory_iterator(dir_)) {
      if (e.path().extension() == ".json") {
        throw std::invalid_argument(e.path().string() + ": an episode without " + record.string() +
                                    " (another sweep, or an older ofv): give another --out");
      }
    }
  }
  fs::create_directories(dir_);
  if (!recorded) write_file_atomically(record, plan_to_json(plan, part).dump() + "\n");
}

bool EpisodeStore::finished(const EpisodeSpec& spec) const {
  const fs::path file = dir_ / (spec.id() + ".json");
  if (!fs::exists(file)) return false;
  const auto [recorded, j] = read_episode(file);
  const std::string diff = episode_difference(recorded, spec);
  if (!diff.empty()) throw std::invalid_argument(file.string() + ": another episode (" + diff + ")");
  // A trajectory missing or damaged since: the episode runs again.
  return trajectory_problem(dir_ / (spec.id() + ".csv"), steps_of(j)).empty();
}

void EpisodeStore::write(const EpisodeSpec& spec, const EpisodeOutcome& outcome) const {
  std::string csv = trajectory_csv_header() + "\n";
  for (const auto& step : outcome.steps) csv += trajectory_csv_row(step) + "\n";
  write_file_atomically(dir_ / (spec.id() + ".csv"), csv);
  // The JSON is written last: its presence marks the episode finished.
  json j = spec_to_json(spec);
  // Every setting as resolved, in the order that applies them again.
  j["provenance"] = {{"ofv", this_ofv()}, {"settings", settings_to_json(outcome.settings)}};
  j["metrics"] = metrics_to_json(outcome.metrics);
  write_file_atomically(dir_ / (spec.id() + ".json"), j.dump(1) + "\n");
}

SweepEpisodes read_sweep(const std::vector<std::string>& dirs) {
  SweepEpisodes out;
  struct Part {
    fs::path record;
    SweepRecord sweep;
  };
  std::vector<Part> parts;
  parts.reserve(dirs.size());  // `planned` points into the first part's plan
  std::map<std::string, const EpisodeSpec*> planned;  // id -> the plan's episode
  std::vector<int> run_by;                            // episode index -> the part that runs it
  std::set<std::string> found;
  for (const auto& d : dirs) {
    const fs::path dir = fs::path(d) / "episodes";
    if (!fs::is_directory(dir)) throw std::invalid_argument(d + ": no episodes/ folder (not an ofv compare output)");
    const fs::path record = fs::path(d) / "sweep.json";
    if (!fs::exists(record)) {
      throw std::invalid_argument(record.string() + ": missing (not an ofv compare output, or one of an older ofv)");
    }
    parts.push_back({record, read_record(record)});
    const Part& part = parts.back();
    if (parts.size() == 1) {
      for (const auto& s : part.sweep.plan) planned.emplace(s.id(), &s);
    }
    if (parts.size() > 1) {  // the same sweep and ofv as the first part, so as every other
      const Part& first = parts.front();
      const std::string both = first.record.string() + " and " + record.string();
      const std::string diff = plan_difference(first.sweep.plan, part.sweep.plan);
      if (!diff.empty()) throw std::invalid_argument(both + ": parts of different sweeps (" + diff + ")");
      if (first.sweep.ofv != part.sweep.ofv) {
        throw std::invalid_argument(both + ": parts run by different ofv (" + first.sweep.ofv + " there, " +
                                    part.sweep.ofv + " here): results of other code are not mixed");
      }
    }
    // No episode in two parts: each remembers the part that runs it.
    const Shard mine = part.sweep.part;
    for (const auto& s : part.sweep.plan) {
      if (s.index % mine.n != mine.k - 1) continue;
      if (static_cast<std::size_t>(s.index) >= run_by.size()) run_by.resize(static_cast<std::size_t>(s.index) + 1, -1);
      int& owner = run_by[static_cast<std::size_t>(s.index)];
      if (owner >= 0) {
        const Part& earlier = parts[static_cast<std::size_t>(owner)];
        throw std::invalid_argument(earlier.record.string() + " and " + record.string() + ": parts " +
                                    part_text(earlier.sweep.part) + " and " + part_text(mine) +
                                    " overlap (both run episode " + std::to_string(s.index) + ", " + s.id() +
                                    "): merge parts that share no episode");
      }
      owner = static_cast<int>(parts.size() - 1);
    }
    std::vector<fs::path> files;
    for (const auto& e : fs::directory_iterator(dir)) {
      if (e.path().extension() == ".json") files.push_back(e.path());
    }
    std::sort(files.begin(), files.end());
    for (const auto& f : files) {
      auto [spec, j] = read_episode(f);
      const auto plan = planned.find(spec.id());
      if (plan == planned.end() || !episode_difference(*plan->second, spec).empty() ||
          plan->second->index % mine.n != mine.k - 1) {
        throw std::invalid_argument(f.string() + ": not an episode of part " + part_text(mine) +
                                    " of the sweep of " + record.string());
      }
      EpisodeRow row;
      row.spec = spec;
      row.spec.index = plan->second->index;
      try {
        const std::string ran_by = j.at("provenance").at("ofv").get<std::string>();
        if (ran_by != part.sweep.ofv) {
          throw std::runtime_error("run by ofv " + ran_by + ", its folder's by " + part.sweep.ofv);
        }
        row.metrics = metrics_from_json(j.at("metrics"));
      } catch (const std::exception& e) {
        throw std::invalid_argument(f.string() + ": not a finished episode of this folder: " + e.what());
      }
      row.trajectory_csv = (dir / (spec.id() + ".csv")).string();
      if (const std::string why = trajectory_problem(row.trajectory_csv, row.metrics.steps); !why.empty()) {
        throw std::invalid_argument(row.trajectory_csv + ": the trajectory of a finished episode is " + why +
                                    ": run its part again (ofv compare with the same --out runs it again)");
      }
      found.insert(spec.id());
      out.rows.push_back(row);
    }
  }
  if (!parts.empty()) {
    out.plan = parts.front().sweep.plan;
    out.planned = parts.front().sweep.plan.size();
    for (const auto& s : parts.front().sweep.plan) {
      if (found.count(s.id()) == 0) out.missing.push_back(s);
    }
  }
  std::stable_sort(out.rows.begin(), out.rows.end(), [](const EpisodeRow& a, const EpisodeRow& b) {
    return a.spec.index < b.spec.index;
  });
  return out;
}

std::vector<EpisodeRow> load_episodes(const std::vector<std::string>& dirs) { return read_sweep(dirs).rows; }

MergeTarget::MergeTarget(const std::string& out_dir, const SweepEpisodes& merged) {
  const fs::path out(out_dir);
  const fs::path record = out / "sweep.json";
  if (fs::exists(record)) {
    const std::string diff = plan_difference(read_record(record).plan, merged.plan);
    if (!diff.empty()) {
      throw std::invalid_argument(record.string() + ": the folder holds another sweep (" + diff +
                                  "): merge into another --out");
    }
  } else if (fs::is_directory(out / "episodes") && !fs::is_empty(out / "episodes")) {
    throw std::invalid_argument((out / "episodes").string() + ": episodes without sweep.json (another sweep, or an "
                                "older ofv): merge into another --out");
  }
  fs::create_directories(out);
  lock_ = (out / ".merge-lock").string();
  const int fd = ::open(lock_.c_str(), O_WRONLY | O_CREAT | O_EXCL, 0644);
  if (fd < 0) {
    const std::string why = errno == EEXIST ? "another merge is writing into " + out_dir +
                                                  " (if none is, one was stopped: remove the file)"
                                            : std::string("cannot create it: ") + std::strerror(errno);
    lock_.clear();
    throw std::invalid_argument((out / ".merge-lock").string() + ": " + why);
  }
  ::close(fd);
}

MergeTarget::~MergeTarget() {
  if (lock_.empty()) return;
  std::error_code ignored;
  fs::remove(lock_, ignored);
}

}  // namespace ofv
