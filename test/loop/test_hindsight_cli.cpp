// Method hindsight end to end: `ofv simulate` plans, follows and reports the
// limit; it is at least what the other methods reach; `ofv run` refuses it.
#include "cli_run.h"

#include <nlohmann/json.hpp>

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <string>

namespace ofv {
namespace {

namespace fs = std::filesystem;

nlohmann::json simulate(const std::string& scenario, const std::string& settings, const std::string& name) {
  const fs::path out = fs::path(test::scratch_dir()) / ("hindsight_" + name);
  fs::remove_all(out);
  const CommandRun r = run("simulate " + scenario + " --no-pictures --set duration=2 " + settings + " --out " + out.string());
  EXPECT_EQ(r.code, 0) << r.err;
  std::ifstream in(out / "metrics.json");
  return nlohmann::json::parse(in, nullptr, false);
}

// The sweeping arm (its first 2 s): the limit is at least every other
// method, and following the plan gives what it planned.
TEST(HindsightCli, TheLimitIsAtLeastEveryMethodAndIsExecuted) {
  for (const char* scenario : {"sweep"}) {
    const nlohmann::json limit = simulate(scenario, "--set method=hindsight", std::string(scenario) + "_limit");
    ASSERT_TRUE(limit.contains("hindsight_bound") && limit["hindsight_bound"].is_object()) << scenario;
    const double planned = limit["hindsight_bound"]["planned"].get<double>();
    const double executed = limit["mean_visible_fraction"].get<double>();
    EXPECT_NEAR(executed, planned, 0.005) << scenario;
    EXPECT_GE(limit["hindsight_bound"]["unlimited_speed"].get<double>(), planned) << scenario;
    EXPECT_EQ(limit["status_counts"]["planned"].get<int>(), limit["steps"].get<int>()) << scenario;
    for (const char* method : {"--set perception=ground-truth", "--set method=static", "--set method=sampling --set perception=ground-truth"}) {
      const nlohmann::json other = simulate(scenario, method, std::string(scenario) + "_other");
      EXPECT_GE(executed + 1e-9, other["mean_visible_fraction"].get<double>()) << scenario << ' ' << method;
    }
  }
}

TEST(HindsightCli, OfvRunRefusesIt) {
  const CommandRun r = run("run --source sim:dvd-one-hand --robot viper850 --dry-run --set method=hindsight");
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_NE(r.err.find("method = hindsight"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("ofv simulate"), std::string::npos) << r.err;
}

TEST(HindsightCli, ASpacingTheCameraCannotCrossIsAUsageError) {
  const CommandRun r = run("simulate dvd-one-hand --no-pictures --set method=hindsight --set hindsight_spacing=0.06 --out " +
                           (fs::path(test::scratch_dir()) / "hindsight_bad").string());
  EXPECT_EQ(r.code, 2) << r.err;
  EXPECT_NE(r.err.find("hindsight_spacing"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace ofv
