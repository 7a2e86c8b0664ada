// `ofv compare` end to end through the real binary: usage errors (exit 2,
// one line naming the file or option, the field and the value), resume and
// merge of real output folders.
#include "cli_run.h"
#include "ofv/loop/episode.h"
#include "ofv/loop/sweep.h"
#include "ofv/version.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

namespace ofv {
namespace {

namespace fs = std::filesystem;

// `text` as one word of a POSIX shell command line.
std::string sh(const std::string& text) {
  std::string out = "'";
  for (char ch : text) out += ch == '\'' ? std::string("'\\''") : std::string(1, ch);
  return out + "'";
}

class SweepCli : public testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::path(test::scratch_dir()) / testing::UnitTest::GetInstance()->current_test_info()->name();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  fs::path write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p;
  }
  // A usage error: exit 2, nothing on stdout, one line on stderr with every mention.
  void expect_usage_error(const std::string& args, const std::vector<std::string>& mentions) const {
    const CommandRun r = run("compare " + args);
    EXPECT_EQ(r.code, 2) << args << ": " << r.err;
    EXPECT_TRUE(r.out.empty()) << args << ": " << r.out;
    EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << args << ": " << r.err;
    for (const auto& m : mentions) EXPECT_NE(r.err.find(m), std::string::npos) << args << ": " << r.err;
  }
  fs::path dir_;
};

// Short ground-truth episodes: a real sweep in a second or two.
const std::string kShort = "set: {perception: ground-truth, duration: 0.2}\n";

TEST_F(SweepCli, OutOfRangeCountsExitTwoNamingOptionAndValue) {
  const std::string grid = sh(write("g.yaml", kShort + "axes: {gain: [1, 2]}\n").string());
  const std::string out = " --out " + sh((dir_ / "out").string());
  const std::string base = "--scenarios dvd-one-hand --grid " + grid + out;
  expect_usage_error(base + " --jobs 0", {"--jobs", "0", "1..256"});
  expect_usage_error(base + " --jobs 257", {"--jobs", "257"});
  expect_usage_error(base + " --jobs -3", {"--jobs", "-3"});
  expect_usage_error(base + " --seeds 0", {"--seeds", "0", "1..1000"});
  expect_usage_error(base + " --seeds 1001", {"--seeds", "1001"});
  // 1000 variants x 101 seeds > 100000 episodes: refused before planning.
  std::string axes = kShort + "axes:\n";
  for (int a = 0; a < 3; ++a) axes += "  step" + std::string(1, static_cast<char>('a' + a)) + ": [0.01, 0.02, 0.03, 0.04, 0.05, 0.06, 0.07, 0.08, 0.09, 0.1]\n";
  const std::string big = sh(write("big.yaml", axes).string());  // 1000 variants
  expect_usage_error("--scenarios dvd-one-hand --grid " + big + " --seeds 101" + out,
                     {"big.yaml", "--seeds", "101 seeds", "100000"});
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "a usage error wrote files";
}

TEST_F(SweepCli, BadGridsExitTwoNamingFileKeyAndValue) {
  const std::string out = " --out " + sh((dir_ / "out").string());
  auto grid = [&](const std::string& name, const std::string& text) {
    return "--scenarios dvd-one-hand --grid " + sh(write(name, text).string()) + out;
  };
  expect_usage_error(grid("empty.yaml", kShort + "variants: []\n"), {"empty.yaml", "variants"});
  expect_usage_error(grid("none.yaml", kShort), {"none.yaml", "variants"});
  expect_usage_error(grid("twice.yaml", kShort + "axes: {gain: [1]}\nseeds: 2\nseeds: 4\n"),
                     {"twice.yaml:4", "seeds", "line 3"});
  expect_usage_error(grid("seeds.yaml", kShort + "axes: {gain: [1]}\nseeds: 5000\n"), {"seeds.yaml", "seeds", "5000"});
  std::string huge = "axes:\n";
  for (int a = 0; a < 9; ++a) huge += "  s" + std::to_string(a) + ": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]\n";
  expect_usage_error(grid("huge.yaml", huge), {"huge.yaml", "axes.s5", "100000"});
  EXPECT_FALSE(fs::exists(dir_ / "out")) << "a usage error wrote files";
}

TEST_F(SweepCli, TwoScenariosOfTheSameNameExitTwo) {
  const fs::path scenario = fs::path(OFV_SOURCE_DIR) / "sim" / "scenarios" / "dvd-static.yaml";
  fs::create_directories(dir_ / "a");
  fs::create_directories(dir_ / "b");
  fs::copy_file(scenario, dir_ / "a" / "x.yaml");
  fs::copy_file(scenario, dir_ / "b" / "x.yaml");
  const std::string grid = sh(write("g.yaml", kShort + "axes: {gain: [1]}\n").string());
  expect_usage_error("--scenarios " + sh((dir_ / "a" / "x.yaml").string()) + " " + sh((dir_ / "b" / "x.yaml").string()) +
                         " --grid " + grid + " --out " + sh((dir_ / "out").string()),
                     {"b/x.yaml", "'x'", "a/x.yaml"});
}


// Lines of a file, the header included.
std::size_t lines(const fs::path& p) {
  std::ifstream in(p);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);) ++n;
  return n;
}

TEST_F(SweepCli, LookAlikeVariantNamesAreRowsOfTheirOwn) {
  const std::string grid = sh(write("g.yaml", kShort + "seeds: 1\nvariants:\n  - {name: a/b, set: {gain: 1}}\n"
                                                       "  - {name: a_b, set: {gain: 2}}\n"
                                                       "  - {name: a__seed0, set: {gain: 3}}\n").string());
  const CommandRun r = run("compare --scenarios dvd-one-hand --grid " + grid + " --jobs 2 --out " + sh((dir_ / "o").string()));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_NE(r.out.find("3 episodes (3 run, 0 resumed)"), std::string::npos) << r.out;
  EXPECT_EQ(lines(dir_ / "o" / "episodes.csv"), 4U);
  EXPECT_EQ(lines(dir_ / "o" / "summary.csv"), 4U);
}

TEST_F(SweepCli, ResumeRunsTheRestAndRefusesAnotherGridsFolder) {
  const std::string g1 = sh(write("g1.yaml", kShort + "seeds: 1\nvariants:\n  - {name: fast, set: {gain: 2}}\n").string());
  const std::string g2 = sh(write("g2.yaml", kShort + "seeds: 1\nvariants:\n  - {name: fast, set: {gain: 3}}\n").string());
  const std::string out = " --out " + sh((dir_ / "o").string());
  ASSERT_EQ(run("compare --scenarios dvd-one-hand --grid " + g1 + out).code, 0);
  // The episode records what produced it: this ofv and every setting as resolved.
  for (const auto& e : fs::directory_iterator(dir_ / "o" / "episodes")) {
    if (e.path().extension() != ".json") continue;
    std::ifstream in(e.path());
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j.at("provenance").at("ofv"), std::string(version()) + " (git " + git_commit() + ")");
    const auto& settings = j.at("provenance").at("settings");
    EXPECT_EQ(settings.size(), episode_settings_table().docs().size());
    EXPECT_NE(std::find(settings.begin(), settings.end(), nlohmann::json{"gain", "2"}), settings.end()) << settings;
    EXPECT_NE(std::find(settings.begin(), settings.end(), nlohmann::json{"seed", "0"}), settings.end()) << settings;
    EXPECT_EQ(j.at("scenario_hash"), scenario_fingerprint("dvd-one-hand"));
  }
  const CommandRun again = run("compare --scenarios dvd-one-hand --grid " + g1 + out);
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.out.find("(0 run, 1 resumed)"), std::string::npos) << again.out;
  expect_usage_error("--scenarios dvd-one-hand --grid " + g2 + out, {"sweep.json", "fast", "gain=2", "gain=3"});
  expect_usage_error("--scenarios dvd-one-hand --grid " + g1 + " --seeds 2" + out, {"sweep.json", "seeds"});
}

TEST_F(SweepCli, MergeRefusesOtherSweepsAndConflictsAndNamesWhatIsMissing) {
  const std::string g1 = sh(write("g1.yaml", kShort + "seeds: 2\nvariants:\n  - {name: fast, set: {gain: 2}}\n").string());
  const std::string g2 = sh(write("g2.yaml", kShort + "seeds: 2\nvariants:\n  - {name: fast, set: {gain: 3}}\n").string());
  auto part = [&](const std::string& grid, const std::string& shard, const std::string& name) {
    const CommandRun r = run("compare --scenarios dvd-one-hand --grid " + grid + " --jobs 1 --shard " + shard +
                             " --out " + sh((dir_ / name).string()));
    EXPECT_EQ(r.code, 0) << r.err;
    return sh((dir_ / name).string());
  };
  const std::string p1 = part(g1, "1/2", "p1"), p2 = part(g1, "2/2", "p2"), q2 = part(g2, "2/2", "q2");
  const std::string whole = part(g1, "1/1", "whole");
  const CommandRun ok = run("compare --merge " + p1 + " " + p2 + " --out " + sh((dir_ / "m").string()));
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(lines(dir_ / "m" / "episodes.csv"), 3U);
  // Parts of two grids.
  expect_usage_error("--merge " + p1 + " " + q2 + " --out " + sh((dir_ / "m2").string()),
                     {(dir_ / "p1" / "sweep.json").string(), (dir_ / "q2" / "sweep.json").string(), "gain=3"});
  // Overlapping parts: part 1/2 and the whole sweep both ran episode 0.
  expect_usage_error("--merge " + p1 + " " + whole + " --out " + sh((dir_ / "m3").string()),
                     {(dir_ / "p1" / "sweep.json").string(), (dir_ / "whole" / "sweep.json").string(), "1/2", "1/1",
                      "overlap"});
  expect_usage_error("--merge " + p1 + " " + p2 + " --jobs 2 --out " + sh((dir_ / "m2").string()), {"--merge", "--jobs"});
  EXPECT_FALSE(fs::exists(dir_ / "m2"));
  EXPECT_FALSE(fs::exists(dir_ / "m3"));
  // Part 2 not given: its episode is named, the tables hold the others, exit 1.
  const CommandRun partial = run("compare --merge " + p1 + " --out " + sh((dir_ / "m4").string()));
  EXPECT_EQ(partial.code, 1) << partial.err;
  EXPECT_EQ(std::count(partial.err.begin(), partial.err.end(), '\n'), 1) << partial.err;
  EXPECT_NE(partial.err.find("1 of 2 episodes are missing"), std::string::npos) << partial.err;
  EXPECT_NE(partial.err.find("dvd-one-hand__fast__seed1__"), std::string::npos) << partial.err;
  EXPECT_NE(partial.err.find("missing.csv"), std::string::npos) << partial.err;
  EXPECT_EQ(lines(dir_ / "m4" / "episodes.csv"), 2U);
  EXPECT_EQ(lines(dir_ / "m4" / "missing.csv"), 2U);
}


// A part whose trajectory files were cut short or lost since: the merge
// refuses it naming the file; running the part again runs those episodes again.
TEST_F(SweepCli, MergeRefusesDamagedTrajectoriesAndResumeRunsThemAgain) {
  const std::string grid = sh(write("g.yaml", kShort + "seeds: 2\nvariants:\n  - {name: fast, set: {gain: 2}}\n").string());
  const auto part = [&](const std::string& shard, const std::string& name) {
    return run("compare --scenarios dvd-one-hand --grid " + grid + " --jobs 1 --shard " + shard + " --out " +
               sh((dir_ / name).string()));
  };
  ASSERT_EQ(part("1/2", "p1").code, 0);
  ASSERT_EQ(part("2/2", "p2").code, 0);
  fs::path csv;
  for (const auto& e : fs::directory_iterator(dir_ / "p2" / "episodes")) {
    if (e.path().extension() == ".csv") csv = e.path();
  }
  ASSERT_FALSE(csv.empty());
  const std::string merge = "--merge " + sh((dir_ / "p1").string()) + " " + sh((dir_ / "p2").string()) + " --out ";
  fs::resize_file(csv, fs::file_size(csv) / 2);
  expect_usage_error(merge + sh((dir_ / "m1").string()), {csv.string(), "cut short"});
  fs::remove(csv);
  expect_usage_error(merge + sh((dir_ / "m2").string()), {csv.string(), "missing"});
  EXPECT_FALSE(fs::exists(dir_ / "m1"));
  const CommandRun again = part("2/2", "p2");
  EXPECT_EQ(again.code, 0) << again.err;
  EXPECT_NE(again.out.find("(1 run, 0 resumed)"), std::string::npos) << again.out;
  const CommandRun ok = run("compare " + merge + sh((dir_ / "m3").string()));
  EXPECT_EQ(ok.code, 0) << ok.err;
  EXPECT_EQ(lines(dir_ / "m3" / "episodes.csv"), 3U);
}

TEST_F(SweepCli, DryRunListsThePartAndSlurmScriptWritesTheJobs) {
  const std::string grid = sh(write("g.yaml", kShort + "seeds: 2\nvariants:\n  - {name: fast, set: {gain: 2}}\n"
                                                       "  - {name: slow, set: {gain: 1}}\n").string());
  const std::string sweep = "compare --scenarios dvd-one-hand dvd-static --grid " + grid;
  // 8 episodes; part 2/3 runs those of index 1, 4, 7. Nothing is written.
  const CommandRun dry = run(sweep + " --dry-run --shard 2/3");
  ASSERT_EQ(dry.code, 0) << dry.err;
  EXPECT_EQ(dry.out.substr(0, dry.out.find('\n')), "index,shard,scenario,variant,seed,id");
  EXPECT_EQ(std::count(dry.out.begin(), dry.out.end(), '\n'), 4) << dry.out;
  EXPECT_NE(dry.out.find("\n1,2/3,dvd-one-hand,fast,1,dvd-one-hand__fast__seed1__"), std::string::npos) << dry.out;
  EXPECT_NE(dry.out.find("\n4,2/3,dvd-static,fast,0,"), std::string::npos) << dry.out;
  EXPECT_NE(dry.out.find("\n7,2/3,dvd-static,slow,1,"), std::string::npos) << dry.out;
  EXPECT_NE(dry.err.find("3 of 8 episodes listed"), std::string::npos) << dry.err;
  // The job scripts, for an output folder whose name needs quoting.
  const fs::path out = dir_ / "it's here";
  const CommandRun slurm = run(sweep + " --jobs 3 --slurm-script 3 --out " + sh(out.string()));
  ASSERT_EQ(slurm.code, 0) << slurm.err;
  EXPECT_FALSE(fs::exists(out / "sweep.json"));
  for (const char* name : {"sweep.sbatch", "merge.sbatch", "submit.sh"}) {
    EXPECT_NE(fs::status(out / "slurm" / name).permissions() & fs::perms::owner_exec, fs::perms::none) << name;
  }
  const auto text = [&](const char* name) {
    std::ifstream in(out / "slurm" / name);
    return std::string(std::istreambuf_iterator<char>(in), {});
  };
  const std::string quoted = sh(out.string());
  for (const std::string& part : {std::string("#SBATCH --array=1-3\n"), std::string("#SBATCH --cpus-per-task=3\n"),
                                  std::string("--shard \"${SLURM_ARRAY_TASK_ID}/3\""),
                                  std::string("--jobs \"${SLURM_CPUS_PER_TASK:-1}\""), std::string("--seeds 2"),
                                  quoted + "/parts/\"${SLURM_ARRAY_TASK_ID}\"", std::string("dvd-static.yaml'")}) {
    EXPECT_NE(text("sweep.sbatch").find(part), std::string::npos) << part << "\n" << text("sweep.sbatch");
  }
  for (const std::string& part : {quoted + "/parts/1 ", quoted + "/parts/3 ", "--out " + quoted}) {
    EXPECT_NE(text("merge.sbatch").find(part), std::string::npos) << part << "\n" << text("merge.sbatch");
  }
  EXPECT_NE(text("submit.sh").find("--dependency=afterok:"), std::string::npos) << text("submit.sh");
  // Usage errors.
  expect_usage_error(sweep.substr(8) + " --slurm-script 0 --out " + sh(out.string()), {"--slurm-script", "1..1000"});
  expect_usage_error(sweep.substr(8) + " --slurm-script 2 --shard 1/2 --out " + sh(out.string()), {"--shard"});
  expect_usage_error(sweep.substr(8) + " --dry-run --slurm-script 2 --out " + sh(out.string()), {"--dry-run"});
  expect_usage_error(sweep.substr(8), {"--out"});
}

TEST_F(SweepCli, SimulateOutIsNeverPastedIntoAShell) {
  const fs::path marker = dir_ / "marker";
  const fs::path out = dir_ / ("o'$(touch " + marker.string() + ")'\"`touch " + marker.string() + "`\"");
  const CommandRun r = run("simulate dvd-one-hand --set duration=0.2 --set perception=ground-truth --out " + sh(out.string()));
  ASSERT_EQ(r.code, 0) << r.err;
  EXPECT_FALSE(fs::exists(marker)) << "--out ran a command";
  EXPECT_GT(fs::file_size(out / "visibility.png"), 1000U);
}

}  // namespace
}  // namespace ofv
