// The comparison sweep (planning, shards, parallel resumable runs, merge)
// with a synthetic, deterministic episode runner.
#include "ofv/loop/compare.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>

#include <unistd.h>

namespace ofv {
namespace {

namespace fs = std::filesystem;

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
    s.status = StepStatus::Converged;
    s.times.estimate = 1e-5;
  }
  return {summarise(steps), steps};
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
    return plan_episodes({{"one", "one.yaml"}, {"two", "two.yaml"}}, grid);
  }
  fs::path dir_;
};

TEST(Grid, ShardsPartitionTheSweep) {
  const Grid g = grid_from_yaml("seeds: 5\naxes:\n  gain: [1, 2, 3]", "g");
  const auto all = plan_episodes({{"a", "a"}, {"b", "b"}}, g);
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
  run_sweep(plan(), synthetic, (dir_ / "one").string(), {1, false});
  run_sweep(plan(), synthetic, (dir_ / "two").string(), {4, false});
  write_reports(load_episodes({(dir_ / "one").string()}), (dir_ / "one").string());
  write_reports(load_episodes({(dir_ / "two").string()}), (dir_ / "two").string());
  EXPECT_EQ(slurp(dir_ / "one" / "episodes.csv"), slurp(dir_ / "two" / "episodes.csv"));
  EXPECT_EQ(slurp(dir_ / "one" / "summary.csv"), slurp(dir_ / "two" / "summary.csv"));
}

TEST_F(Compare, ShardsMergedEqualTheWholeSweep) {
  run_sweep(plan(), synthetic, (dir_ / "whole").string(), {2, false});
  std::vector<std::string> parts;
  for (int k = 1; k <= 3; ++k) {
    parts.push_back((dir_ / ("part" + std::to_string(k))).string());
    run_sweep(shard(plan(), k, 3), synthetic, parts.back(), {1, false});
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
  EXPECT_THROW(run_sweep(all, dies, dir_.string(), {1, false}), std::runtime_error);
  EXPECT_EQ(load_episodes({dir_.string()}).size(), 5U);
  int reruns = 0;
  const EpisodeRunner counts = [&](const EpisodeSpec& s) {
    ++reruns;
    return synthetic(s);
  };
  EXPECT_EQ(run_sweep(all, counts, dir_.string(), {2, false}), static_cast<int>(all.size()) - 5);
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
    run_sweep(all, fails, dir_.string(), {2, false});
    ADD_FAILURE() << "the failure was not reported";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(failing), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("diverged"), std::string::npos) << e.what();
  }
  // Whatever finished is on disk, and a rerun completes the sweep.
  const std::size_t kept = load_episodes({dir_.string()}).size();
  EXPECT_LT(kept, all.size());
  EXPECT_EQ(run_sweep(all, synthetic, dir_.string(), {0, false}), static_cast<int>(all.size() - kept));
  EXPECT_EQ(load_episodes({dir_.string()}).size(), all.size());
}

TEST_F(Compare, ReportsAggregateOverSeeds) {
  run_sweep(plan(), synthetic, dir_.string(), {2, false});
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

}  // namespace
}  // namespace ofv
