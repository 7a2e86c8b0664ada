// `ofv compare` end to end through the real binary: usage errors (exit 2,
// one line naming the file or option, the field and the value), resume and
// merge of real output folders.
#include "cli_run.h"

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

}  // namespace
}  // namespace ofv
