// The CSV cells of the `ofv compare` tables.
#include "ofv/loop/reports.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
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

}  // namespace
}  // namespace ofv
