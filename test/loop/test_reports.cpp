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

}  // namespace
}  // namespace ofv
