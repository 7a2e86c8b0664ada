// The comparison sweep (planning, shards, parallel resumable runs, merge)
// with a synthetic, deterministic episode runner.
#include "ofv/loop/compare.h"
#include "ofv/version.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>

#include <unistd.h>

namespace ofv {
namespace {

namespace fs = std::filesystem;

// The scenario file of every planned episode (the synthetic runner does not
// run it; planning fingerprints its files).
const std::string kScenario = std::string(OFV_TEST_DATA_DIR) + "/loop/hand-on-initial-ray.yaml";

std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

// Visibility drops when an "occluder" arrives at 0.3 s and recovers after a
// delay that depends on the variant's `gain` and on the seed.
EpisodeOutcome synthetic(const EpisodeSpec& spec) {
  double gain = 1.0;
  for (const auto& [k, v] : spec.variant.settings) {
    if (k == "gain") gain = std::stod(v);
  }
  std::mt19937 rng(static_cast<unsigned>(spec.seed * 7919 + spec.index));
  std::uniform_real_distribution<double> jitter(0.0, 0.05);
  std::vector<StepRecord> steps(20);
  const double recovery = 0.4 / gain + jitter(rng);
  for (std::size_t k = 0; k < steps.size(); ++k) {
    StepRecord& s = steps[k];
    s.time = 0.05 * static_cast<double>(k);
    s.occluders_in_sphere = s.time >= 0.3 ? 1 : 0;
    s.visible_fraction = (s.time >= 0.3 && s.time < 0.3 + recovery) ? 0.5 : 1.0;
    s.status = servo::StepStatus::Converged;
    s.times.estimate = 1e-5;
  }
  return {summarise(steps), steps, {}};
}

class Compare : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() /
           ("ofv_compare_" + std::string(testing::UnitTest::GetInstance()->current_test_info()->name()) +
            "_" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }
  std::vector<EpisodeSpec> plan() const {
    const Grid grid = grid_from_yaml("name: g\nseeds: 3\naxes:\n  gain: [0.5, 1, 2]\n", "g.yaml");
    return plan_episodes({{"one", kScenario}, {"two", kScenario}}, grid);
  }
  fs::path dir_;
};

TEST(Grid, ShardsPartitionTheSweep) {
  const Grid g = grid_from_yaml("seeds: 5\naxes:\n  gain: [1, 2, 3]", "g");
  const auto all = plan_episodes({{"a", kScenario}, {"b", kScenario}}, g);
  ASSERT_EQ(all.size(), 30U);
  std::size_t total = 0;
  for (int k = 1; k <= 4; ++k) total += shard(all, k, 4).size();
  EXPECT_EQ(total, all.size());
  EXPECT_THROW((void)shard(all, 0, 4), std::invalid_argument);
  EXPECT_THROW((void)shard(all, 5, 4), std::invalid_argument);
}

TEST(Sweep, ShardTextIsKOverN) {
  const Shard s = parse_shard("2/8");
  EXPECT_EQ(s.k, 2);
  EXPECT_EQ(s.n, 8);
  for (const std::string text : {"2-8", "2/8x", "/8", "two/8"}) {
    try {
      (void)parse_shard(text);
      ADD_FAILURE() << text << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  }
}

TEST_F(Compare, ResultsDoNotDependOnTheJobCount) {
  run_sweep(plan(), synthetic, (dir_ / "one").string(), {1, false, {}});
  run_sweep(plan(), synthetic, (dir_ / "two").string(), {4, false, {}});
  write_reports(load_episodes({(dir_ / "one").string()}), (dir_ / "one").string());
  write_reports(load_episodes({(dir_ / "two").string()}), (dir_ / "two").string());
  EXPECT_EQ(slurp(dir_ / "one" / "episodes.csv"), slurp(dir_ / "two" / "episodes.csv"));
  EXPECT_EQ(slurp(dir_ / "one" / "summary.csv"), slurp(dir_ / "two" / "summary.csv"));
}

TEST_F(Compare, ShardsMergedEqualTheWholeSweep) {
  run_sweep(plan(), synthetic, (dir_ / "whole").string(), {2, false, {}});
  std::vector<std::string> parts;
  for (int k = 1; k <= 3; ++k) {
    parts.push_back((dir_ / ("part" + std::to_string(k))).string());
    run_sweep(plan(), synthetic, parts.back(), {1, false, {k, 3}});
  }
  write_reports(load_episodes({(dir_ / "whole").string()}), (dir_ / "whole").string());
  write_reports(load_episodes(parts), (dir_ / "merged").string());
  EXPECT_EQ(slurp(dir_ / "whole" / "episodes.csv"), slurp(dir_ / "merged" / "episodes.csv"));
  EXPECT_EQ(slurp(dir_ / "whole" / "summary.md"), slurp(dir_ / "merged" / "summary.md"));
}

TEST_F(Compare, AnInterruptedSweepResumes) {
  const auto all = plan();
  // The first run dies after 5 episodes.
  int calls = 0;
  const EpisodeRunner dies = [&](const EpisodeSpec& s) {
    if (++calls > 5) throw std::runtime_error("killed");
    return synthetic(s);
  };
  EXPECT_THROW(run_sweep(all, dies, dir_.string(), {1, false, {}}), std::runtime_error);
  EXPECT_EQ(load_episodes({dir_.string()}).size(), 5U);
  int reruns = 0;
  const EpisodeRunner counts = [&](const EpisodeSpec& s) {
    ++reruns;
    return synthetic(s);
  };
  EXPECT_EQ(run_sweep(all, counts, dir_.string(), {2, false, {}}), static_cast<int>(all.size()) - 5);
  EXPECT_EQ(reruns, static_cast<int>(all.size()) - 5);
  EXPECT_EQ(load_episodes({dir_.string()}).size(), all.size());
}

TEST_F(Compare, AFailedEpisodeIsNamedAndTheOthersAreKept) {
  const auto all = plan();
  const std::string failing = all[7].id();
  const EpisodeRunner fails = [&](const EpisodeSpec& s) {
    if (s.id() == failing) throw std::runtime_error("diverged");
    return synthetic(s);
  };
  try {
    run_sweep(all, fails, dir_.string(), {2, false, {}});
    ADD_FAILURE() << "the failure was not reported";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(failing), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("diverged"), std::string::npos) << e.what();
  }
  // Whatever finished is on disk, and a rerun completes the sweep.
  const std::size_t kept = load_episodes({dir_.string()}).size();
  EXPECT_LT(kept, all.size());
  EXPECT_EQ(run_sweep(all, synthetic, dir_.string(), {0, false, {}}), static_cast<int>(all.size() - kept));
  EXPECT_EQ(load_episodes({dir_.string()}).size(), all.size());
}

TEST_F(Compare, ReportsAggregateOverSeeds) {
  run_sweep(plan(), synthetic, dir_.string(), {2, false, {}});
  const auto rows = load_episodes({dir_.string()});
  const auto pngs = write_reports(rows, dir_.string());
  const std::string summary = slurp(dir_ / "summary.csv");
  // 2 scenarios x 3 gains, plus the header.
  EXPECT_EQ(std::count(summary.begin(), summary.end(), '\n'), 7);
  const std::string md = slurp(dir_ / "summary.md");
  EXPECT_NE(md.find("## one"), std::string::npos);
  EXPECT_NE(md.find("gain=2"), std::string::npos);
  // A higher gain recovers faster in the synthetic runner: the table says so.
  EXPECT_NE(md.find("±"), std::string::npos);
  for (const auto& p : pngs) {
    EXPECT_GT(fs::file_size(p), 1000U) << p;
  }
}


TEST_F(Compare, NamesCannotBreakTheTablesAndTooManyVariantsAreNotPlotted) {
  // Axis values become variant names: '|' and line breaks stay inside their cell.
  const Grid grid = grid_from_yaml("name: g\nseeds: 1\naxes:\n  note: [\"a|b\", \"c\\nd\"]\n", "g.yaml");
  const EpisodeRunner runner = [&](const EpisodeSpec& s) { return synthetic(s); };
  run_sweep(plan_episodes({{"one", kScenario}}, grid), runner, dir_.string(), {1, false, {}});
  (void)write_reports(load_episodes({dir_.string()}), dir_.string());
  const std::string md = slurp(dir_ / "summary.md");
  EXPECT_NE(md.find("| note=a\\|b | 1 |"), std::string::npos) << md;
  EXPECT_NE(md.find("| note=c d | 1 |"), std::string::npos) << md;
  // More variants than a plot can show: the tables, no plots.
  std::string values;
  for (std::size_t k = 0; k <= kMaxPlottedVariants; ++k) values += (k ? ", " : "") + std::to_string(k + 1);
  const fs::path many = dir_ / "many";
  run_sweep(plan_episodes({{"one", kScenario}}, grid_from_yaml("seeds: 1\naxes:\n  gain: [" + values + "]\n", "m.yaml")),
            runner, many.string(), {2, false, {}});
  EXPECT_TRUE(write_reports(load_episodes({many.string()}), many.string()).empty());
  EXPECT_TRUE(fs::exists(many / "summary.md"));
  EXPECT_FALSE(fs::exists(many / "plots" / "plots.gp"));
}

// The episode files, resume and merge: a folder holds one part of one sweep.
class SweepFiles : public Compare {
 protected:
  static std::vector<EpisodeSpec> plan_of(const std::string& yaml) {
    return plan_episodes({{"one", kScenario}, {"two", kScenario}}, grid_from_yaml(yaml, "g.yaml"));
  }
  static std::size_t json_files(const fs::path& dir) {
    std::size_t n = 0;
    for (const auto& e : fs::directory_iterator(dir / "episodes")) n += e.path().extension() == ".json";
    return n;
  }
  // Runs and expects std::invalid_argument before any episode runs; returns its message.
  static std::string refused(const std::vector<EpisodeSpec>& plan, const fs::path& dir, Shard part = {}) {
    int runs = 0;
    const EpisodeRunner counts = [&](const EpisodeSpec& s) {
      ++runs;
      return synthetic(s);
    };
    try {
      run_sweep(plan, counts, dir.string(), {1, false, part});
      ADD_FAILURE() << "accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(runs, 0) << "episodes ran before the error";
      return e.what();
    }
    return {};
  }
  static std::string contains(const std::string& text, const std::vector<std::string>& parts) {
    for (const auto& p : parts) {
      if (text.find(p) == std::string::npos) return "'" + p + "' not in: " + text;
    }
    return {};
  }
};

TEST_F(SweepFiles, NamesThatLookAlikeInFileNamesKeepTheirOwnEpisodes) {
  // `a/b` and `a_b` are one file-name-safe text, `x__seed0` contains the
  // separator; each variant must run and be its own row.
  const auto plan = plan_of(R"(seeds: 2
variants:
  - {name: a/b, set: {gain: 1}}
  - {name: a_b, set: {gain: 2}}
  - {name: a b, set: {gain: 3}}
  - {name: x__seed0, set: {gain: 4}}
  - {name: x, set: {gain: 5}}
)");
  std::set<std::string> ids;
  for (const auto& e : plan) ids.insert(e.id());
  EXPECT_EQ(ids.size(), plan.size());
  EXPECT_EQ(run_sweep(plan, synthetic, dir_.string(), {2, false, {}}), static_cast<int>(plan.size()));
  EXPECT_EQ(json_files(dir_), plan.size());
  const auto rows = load_episodes({dir_.string()});
  ASSERT_EQ(rows.size(), plan.size());
  for (std::size_t i = 0; i < rows.size(); ++i) {
    EXPECT_EQ(rows[i].spec.identity(), plan[i].identity());
    EXPECT_EQ(rows[i].spec.variant.settings, plan[i].variant.settings);
  }
  // The file records the identity: scenario, variant, settings and seed.
  const std::string json = slurp(dir_ / "episodes" / (plan[0].id() + ".json"));
  for (const char* field : {"\"scenario\"", "\"variant\": \"a/b\"", "\"gain\"", "\"seed\""}) {
    EXPECT_NE(json.find(field), std::string::npos) << field << " in " << json;
  }
  // Ids are readable, stable and short enough for any file system.
  EXPECT_EQ(plan[0].id().rfind("one__a_b__seed0__", 0), 0U) << plan[0].id();
  EpisodeSpec long_name = plan[0];
  long_name.variant.name = std::string(1000, 'v');
  EXPECT_LT(long_name.id().size() + 9, 255U);
}

TEST_F(SweepFiles, ResumingIntoTheFolderOfAnotherGridIsAnError) {
  run_sweep(plan_of("seeds: 2\nvariants:\n  - {name: fast, set: {gain: 2}}\n  - {name: slow, set: {gain: 0.5}}\n"),
            synthetic, dir_.string(), {1, false, {}});
  const std::string before = slurp(dir_ / "sweep.json");
  // Same names, other settings: the old episodes must not pass for the new ones.
  std::string e = refused(plan_of("seeds: 2\nvariants:\n  - {name: fast, set: {gain: 3}}\n  - {name: slow, set: {gain: 0.5}}\n"), dir_);
  EXPECT_EQ(contains(e, {"sweep.json", "fast", "gain=2", "gain=3"}), "");
  // Other variants, seeds or scenarios.
  e = refused(plan_of("seeds: 2\nvariants:\n  - {name: quick, set: {gain: 2}}\n"), dir_);
  EXPECT_EQ(contains(e, {"sweep.json", "variants", "quick"}), "");
  e = refused(plan_of("seeds: 3\nvariants:\n  - {name: fast, set: {gain: 2}}\n  - {name: slow, set: {gain: 0.5}}\n"), dir_);
  EXPECT_EQ(contains(e, {"sweep.json", "seeds"}), "");
  // Another part of the same sweep.
  e = refused(plan_of("seeds: 2\nvariants:\n  - {name: fast, set: {gain: 2}}\n  - {name: slow, set: {gain: 0.5}}\n"), dir_, {1, 2});
  EXPECT_EQ(contains(e, {"sweep.json", "1/1", "1/2"}), "");
  EXPECT_EQ(slurp(dir_ / "sweep.json"), before);
  EXPECT_EQ(json_files(dir_), 8U);
}

TEST_F(SweepFiles, AnEpisodeFileRecordingOtherSettingsIsAnError) {
  const auto all = plan();
  run_sweep(all, synthetic, dir_.string(), {1, false, {}});
  // The file of episode 4 now says it was made with another gain.
  const fs::path file = dir_ / "episodes" / (all[4].id() + ".json");
  std::string text = slurp(file);
  const auto at = text.find("\"gain\",");
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(text.find('"', at + 7), text.find('"', text.find('"', at + 7) + 1) - text.find('"', at + 7) + 1, "\"9\"");
  std::ofstream(file) << text;
  const std::string e = refused(all, dir_);
  EXPECT_EQ(contains(e, {file.string(), "gain"}), "");
}

TEST_F(SweepFiles, EpisodesWithoutASweepRecordAreNotReused) {
  const auto all = plan();
  run_sweep(all, synthetic, dir_.string(), {1, false, {}});
  fs::remove(dir_ / "sweep.json");  // e.g. a folder of an older ofv
  EXPECT_EQ(contains(refused(all, dir_), {"episodes", ".json", "sweep.json"}), "");
  EXPECT_THROW((void)load_episodes({dir_.string()}), std::invalid_argument);
}

TEST_F(SweepFiles, APlanWithTheSameEpisodeTwiceIsAnError) {
  auto all = plan();
  all[3].variant = all[0].variant;
  all[3].seed = all[0].seed;
  all[3].scenario = all[0].scenario;
  EXPECT_EQ(contains(refused(all, dir_), {"same episode"}), "");
}

TEST_F(SweepFiles, MergeRefusesPartsOfDifferentSweeps) {
  run_sweep(plan(), synthetic, (dir_ / "p1").string(), {1, false, {1, 2}});
  run_sweep(plan_of("seeds: 3\naxes:\n  gain: [0.5, 1, 3]\n"), synthetic, (dir_ / "p2").string(), {1, false, {2, 2}});
  try {
    (void)read_sweep({(dir_ / "p1").string(), (dir_ / "p2").string()});
    ADD_FAILURE() << "merged";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(contains(e.what(), {(dir_ / "p1" / "sweep.json").string(), (dir_ / "p2" / "sweep.json").string(),
                                  "different sweeps", "gain=3"}),
              "");
  }
}

TEST_F(SweepFiles, MergeWritesOnlyWhereNoOtherSweepOrMergeIs) {
  run_sweep(plan(), synthetic, (dir_ / "p1").string(), {1, false, {1, 2}});
  run_sweep(plan(), synthetic, (dir_ / "p2").string(), {1, false, {2, 2}});
  const SweepEpisodes merged = read_sweep({(dir_ / "p1").string(), (dir_ / "p2").string()});
  // Into a part of the same sweep, or a new folder: yes, one merge at a time.
  { const MergeTarget into_part((dir_ / "p1").string(), merged); }
  {
    const MergeTarget first((dir_ / "whole").string(), merged);
    try {
      const MergeTarget second((dir_ / "whole").string(), merged);
      ADD_FAILURE() << "two merges into one folder at once";
    } catch (const std::invalid_argument& e) {
      EXPECT_EQ(contains(e.what(), {".merge-lock", "another merge is writing"}), "");
    }
  }
  { const MergeTarget again((dir_ / "whole").string(), merged); }  // the lock went with the first
  // Into the folder of another sweep: its tables would describe other episodes than its own.
  run_sweep(plan_of("seeds: 3\naxes:\n  gain: [0.5, 1, 3]\n"), synthetic, (dir_ / "other").string(), {1, false, {}});
  try {
    const MergeTarget wrong((dir_ / "other").string(), merged);
    ADD_FAILURE() << "merged into another sweep's folder";
  } catch (const std::invalid_argument& e) {
    EXPECT_EQ(contains(e.what(), {(dir_ / "other" / "sweep.json").string(), "another sweep", "gain=3"}), "");
  }
  EXPECT_FALSE(fs::exists(dir_ / "other" / ".merge-lock"));
}

// Replaces the first `from` in a file by `to`.
void edit(const fs::path& file, const std::string& from, const std::string& to) {
  std::string text = slurp(file);
  const auto at = text.find(from);
  ASSERT_NE(at, std::string::npos) << file << " has no " << from;
  text.replace(at, from.size(), to);
  std::ofstream(file) << text;
}

TEST_F(SweepFiles, MergeRefusesOverlappingPartsAndPartsOfOtherCode) {
  // Shards 1/2 and 1/3 overlap (episodes 0, 6, 12, ...).
  run_sweep(plan(), synthetic, (dir_ / "p1").string(), {1, false, {1, 2}});
  run_sweep(plan(), synthetic, (dir_ / "p2").string(), {1, false, {1, 3}});
  const auto refused_merge = [&](const std::vector<std::string>& dirs) {
    try {
      (void)read_sweep(dirs);
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("merged");
  };
  const std::string p1 = (dir_ / "p1").string(), p2 = (dir_ / "p2").string();
  EXPECT_EQ(contains(refused_merge({p1, p2}), {p1 + "/sweep.json", p2 + "/sweep.json", "1/2", "1/3", "overlap",
                                               "episode 0", plan()[0].id()}),
            "");
  // A part given twice, or a copy of it, overlaps itself.
  fs::copy(dir_ / "p1", dir_ / "copy", fs::copy_options::recursive);
  EXPECT_EQ(contains(refused_merge({p1, (dir_ / "copy").string()}), {"1/2", "overlap"}), "");
  EXPECT_EQ(contains(refused_merge({p1, p1}), {"overlap"}), "");
  // Part 2/2 run by another build of ofv.
  run_sweep(plan(), synthetic, (dir_ / "q2").string(), {1, false, {2, 2}});
  EXPECT_EQ(read_sweep({p1, (dir_ / "q2").string()}).rows.size(), plan().size());
  const std::string ours = std::string(version()) + " (git " + git_commit() + ")";
  edit(dir_ / "q2" / "sweep.json", ours, "0.0.9 (git 0123abc)");
  EXPECT_EQ(contains(refused_merge({p1, (dir_ / "q2").string()}),
                     {p1 + "/sweep.json", "q2/sweep.json", "different ofv", ours, "0.0.9 (git 0123abc)"}),
            "");
  // An episode file that another ofv wrote, in a folder of this one.
  edit(dir_ / "q2" / "sweep.json", "0.0.9 (git 0123abc)", ours);
  const fs::path episode = dir_ / "q2" / "episodes" / (plan()[1].id() + ".json");
  edit(episode, ours, "0.0.9 (git 0123abc)");
  EXPECT_EQ(contains(refused_merge({p1, (dir_ / "q2").string()}), {episode.string(), "0.0.9 (git 0123abc)"}), "");
  // An episode of part 1/2 copied into the folder of part 2/2.
  edit(episode, "0.0.9 (git 0123abc)", ours);
  const fs::path stray = dir_ / "q2" / "episodes" / (plan()[0].id() + ".json");
  fs::copy_file(dir_ / "p1" / "episodes" / (plan()[0].id() + ".json"), stray);
  EXPECT_EQ(contains(refused_merge({p1, (dir_ / "q2").string()}), {stray.string(), "part 2/2"}), "");
}

TEST_F(SweepFiles, ResumeRefusesAFolderOfOtherCodeOrAnEditedScenario) {
  const auto all = plan();
  run_sweep(all, synthetic, dir_.string(), {1, false, {}});
  const std::string ours = std::string(version()) + " (git " + git_commit() + ")";
  edit(dir_ / "sweep.json", ours, "0.0.9 (git 0123abc)");
  EXPECT_EQ(contains(refused(all, dir_), {"sweep.json", "0.0.9 (git 0123abc)", ours, "another --out"}), "");
  edit(dir_ / "sweep.json", "0.0.9 (git 0123abc)", ours);
  EXPECT_EQ(run_sweep(all, synthetic, dir_.string(), {1, false, {}}), 0);
  // The same scenario name, its file edited: another sweep.
  const fs::path edited = dir_ / "one.yaml";
  fs::copy_file(kScenario, edited);
  std::ofstream(edited, std::ios::app) << "# edited\n";
  const Grid grid = grid_from_yaml("name: g\nseeds: 3\naxes:\n  gain: [0.5, 1, 2]\n", "g.yaml");
  const auto changed = plan_episodes({{"one", edited.string()}, {"two", kScenario}}, grid);
  EXPECT_EQ(contains(refused(changed, dir_), {"sweep.json", "scenario 'one'", "edited"}), "");
}

TEST_F(SweepFiles, MergeNamesTheMissingEpisodes) {
  const auto all = plan();
  // Part 1 of 3 stops after 2 episodes, part 2 finishes, part 3 is not given.
  int calls = 0;
  const EpisodeRunner dies = [&](const EpisodeSpec& s) {
    if (++calls > 2) throw std::runtime_error("killed");
    return synthetic(s);
  };
  EXPECT_THROW(run_sweep(all, dies, (dir_ / "p1").string(), {1, false, {1, 3}}), std::runtime_error);
  run_sweep(all, synthetic, (dir_ / "p2").string(), {1, false, {2, 3}});
  const SweepEpisodes merged = read_sweep({(dir_ / "p1").string(), (dir_ / "p2").string()});
  EXPECT_EQ(merged.planned, all.size());
  EXPECT_EQ(merged.rows.size(), 2 + all.size() / 3);
  ASSERT_EQ(merged.missing.size(), all.size() - merged.rows.size());
  std::set<int> missing;
  for (const auto& m : merged.missing) missing.insert(m.index);
  for (const auto& r : merged.rows) EXPECT_EQ(missing.count(r.spec.index), 0U);
  for (const auto& s : all) {
    if (s.index % 3 == 2) {
      EXPECT_EQ(missing.count(s.index), 1U) << "episode of the absent part " << s.index;
    }
  }
}


TEST_F(SweepFiles, PlotsRunNoShellAndQuoteEveryName) {
  // An output folder, a scenario and a variant whose names would run
  // commands if pasted into a shell or into the gnuplot script unquoted.
  const fs::path marker = dir_ / "marker";
  const std::string touch = "touch " + marker.string();
  const fs::path out = dir_ / ("o'$(" + touch + ")'\";" + touch + ";\"`" + touch + "`");
  Grid grid = grid_from_yaml("seeds: 1\naxes: {gain: [1, 2]}\n", "g.yaml");
  grid.variants[1].name = "v'\nsystem '" + touch + "'\n'";
  const auto all = plan_episodes({{"s' . system('" + touch + "') . '", kScenario}}, grid);
  run_sweep(all, synthetic, out.string(), {1, false, {}});
  const auto pngs = write_reports(load_episodes({out.string()}), out.string());
  EXPECT_FALSE(fs::exists(marker)) << "a name ran a command";
  ASSERT_EQ(pngs.size(), 5U) << "gnuplot failed: " << slurp(out / "plots" / "gnuplot.log");
  for (const auto& p : pngs) EXPECT_GT(fs::file_size(p), 1000U) << p;
  // The script names only files of the plots folder.
  EXPECT_EQ(slurp(out / "plots" / "plots.gp").find((dir_ / "o").string()), std::string::npos);
}

TEST_F(SweepFiles, AMetricWithNoValueHasNoChartAndTheOthersAreDrawn) {
  // Nothing recovers (worst recovery is n/a everywhere): gnuplot would
  // refuse the whole script over that one empty chart.
  const EpisodeRunner never = [](const EpisodeSpec& s) {
    EpisodeOutcome o = synthetic(s);
    for (auto& step : o.steps) step.visible_fraction = step.time >= 0.3 ? 0.5 : 1.0;
    o.metrics = summarise(o.steps);
    return o;
  };
  const auto all = plan_episodes({{"hidden", kScenario}}, grid_from_yaml("seeds: 1\naxes: {gain: [1, 2]}\n", "g.yaml"));
  run_sweep(all, never, dir_.string(), {1, false, {}});
  const auto pngs = write_reports(load_episodes({dir_.string()}), dir_.string());
  ASSERT_EQ(pngs.size(), 4U) << "gnuplot failed: " << slurp(dir_ / "plots" / "gnuplot.log");
  for (const auto& p : pngs) EXPECT_EQ(p.find("max_recovery_time"), std::string::npos) << p;
}

}  // namespace
}  // namespace ofv
