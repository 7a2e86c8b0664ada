// The CSV cells of the `ofv compare` tables.
#include "ofv/loop/reports.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

#include <unistd.h>

namespace ofv {
namespace {

TEST(Reports, CsvFieldsAreQuotedOnlyWhenNeeded) {
  EXPECT_EQ(csv_field("paper"), "paper");
  EXPECT_EQ(csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(csv_field("say \"hi\""), "\"say \"\"hi\"\"\"");
  EXPECT_EQ(csv_number(std::nan("")), "");
  EXPECT_EQ(csv_number(2.0 / 3.0, 3), "0.667");
}

TEST(Reports, TablesQuoteNamesWithCommas) {
  const auto dir = std::filesystem::temp_directory_path() / ("ofv_reports_" + std::to_string(::getpid()));
  std::vector<EpisodeRow> rows(2);
  for (int seed = 0; seed < 2; ++seed) {
    rows[seed].spec.scenario = "one";
    rows[seed].spec.variant = {"t0 only, blind", {{"method", "initial_view"}}};
    rows[seed].spec.seed = seed;
    rows[seed].spec.index = seed;
  }
  write_tables(rows, dir.string());
  std::ifstream summary(dir / "summary.csv");
  std::string header, line;
  std::getline(summary, header);
  std::getline(summary, line);
  EXPECT_EQ(line.rfind("one,\"t0 only, blind\",method=initial_view,2,", 0), 0U) << line;
  std::ifstream episodes(dir / "episodes.csv");
  std::getline(episodes, header);
  EXPECT_EQ(header.rfind("scenario,variant,seed,method,", 0), 0U) << header;
  std::getline(episodes, line);
  EXPECT_EQ(line.rfind("one,\"t0 only, blind\",0,initial_view,", 0), 0U) << line;
  std::filesystem::remove_all(dir);
}

// The perception scores are columns of every table: means over the
// episode's frames, n/a for an episode without a front end (ground truth).
TEST(Reports, TablesHaveThePerceptionScores) {
  const auto dir = std::filesystem::temp_directory_path() / ("ofv_reports_scores_" + std::to_string(::getpid()));
  std::vector<EpisodeRow> rows(2);
  for (int k = 0; k < 2; ++k) {
    rows[k].spec.scenario = "one";
    rows[k].spec.variant = {k == 0 ? "full" : "ground-truth", {}};
    rows[k].spec.index = k;
  }
  rows[0].metrics.perception.object_precision.mean = 0.75;
  rows[0].metrics.perception.object_recall.mean = 0.5;
  rows[0].metrics.perception.object_recall.frames = 1;
  rows[0].metrics.perception.centroid_error.mean = 0.012;
  write_tables(rows, dir.string());
  std::ifstream summary(dir / "summary.csv");
  std::string header, full, truth;
  std::getline(summary, header);
  std::getline(summary, full);
  std::getline(summary, truth);
  for (const char* column : {"object_precision", "object_recall", "occluder_precision", "occluder_recall",
                             "centroid_error_cm"}) {
    EXPECT_NE(header.find(column), std::string::npos) << column;
  }
  EXPECT_NE(full.find(",0.75,"), std::string::npos) << full;
  EXPECT_NE(full.find(",1.2,"), std::string::npos) << full;  // centroid error in cm
  std::ifstream md(dir / "summary.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("obj. precision"), std::string::npos);
  EXPECT_NE(text.find("| ground-truth | 1 |"), std::string::npos);
  EXPECT_NE(text.find("n/a"), std::string::npos);  // ground truth has no front end to score
  std::filesystem::remove_all(dir);
}

// With a hindsight variant in the sweep, every variant's distance to it,
// seed by seed, in both tables; without one, no such columns.
TEST(Reports, TablesShowTheDistanceToTheLimit) {
  const auto dir = std::filesystem::temp_directory_path() / ("ofv_reports_limit_" + std::to_string(::getpid()));
  std::vector<EpisodeRow> rows(4);
  const double visible[4] = {0.8, 0.9, 0.95, 1.0};  // variant a on seeds 0, 1; the limit on seeds 0, 1
  const double below[4] = {1.0, 0.5, 0.2, 0.0};
  for (int k = 0; k < 4; ++k) {
    rows[k].spec.scenario = "one";
    rows[k].spec.variant = {k < 2 ? "a" : "limit", {{"method", k < 2 ? "estimator" : "hindsight"}}};
    rows[k].spec.seed = static_cast<unsigned>(k % 2);
    rows[k].spec.index = k;
    rows[k].metrics.mean_visible_fraction = visible[k];
    rows[k].metrics.time_below_threshold = below[k];
    if (k >= 2) rows[k].metrics.hindsight = HindsightBound{visible[k] + 0.001, 1.0};
  }
  write_tables(rows, dir.string());
  std::ifstream summary(dir / "summary.csv");
  std::string header, a, limit;
  std::getline(summary, header);
  std::getline(summary, a);
  std::getline(summary, limit);
  EXPECT_NE(header.find(",to_limit_visible_fraction,to_limit_visible_fraction_ci95,"), std::string::npos) << header;
  EXPECT_NE(header.find(",hindsight_bound,"), std::string::npos) << header;
  // a - limit: (0.8 - 0.95 + 0.9 - 1.0) / 2 = -0.125; below 0.9: (0.8 + 0.5) / 2 = 0.65; the limit's own: 0.
  EXPECT_NE(a.find(",-0.125,"), std::string::npos) << a;
  EXPECT_NE(a.find(",0.65,"), std::string::npos) << a;
  EXPECT_NE(limit.find(",0,0,0,0"), std::string::npos) << limit;
  std::ifstream md(dir / "summary.md");
  const std::string text((std::istreambuf_iterator<char>(md)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("to limit: visible"), std::string::npos);
  EXPECT_NE(text.find("-0.125"), std::string::npos);

  rows.resize(2);  // no limit
  write_tables(rows, dir.string());
  std::ifstream without(dir / "summary.csv");
  std::getline(without, header);
  EXPECT_EQ(header.find("to_limit"), std::string::npos) << header;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace ofv
