// Settings by name: parsing, errors that name the setting and value, defaults from the structs.
#include "ofv/estimator_settings.h"
#include "ofv/settings_table.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ofv {
namespace {

std::string message_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "";
}

TEST(SettingsTable, NumbersAreParsedWhole) {
  EXPECT_EQ(parse_number("gain", "2e-2", 0.0, 10.0, true), 0.02);
  EXPECT_EQ(message_of([] { (void)parse_number("gain", "0.02m", 0.0, 10.0, true); }),
            "setting 'gain' must be a number in (0, 10], got \"0.02m\"");
  EXPECT_NE(message_of([] { (void)parse_number("gain", "0", 0.0, 10.0, true); }), "");
  EXPECT_NE(message_of([] { (void)parse_number("gain", "nan", 0.0, 10.0, true); }), "");
  EXPECT_NE(message_of([] { (void)parse_number("gain", "1e999", 0.0, INFINITY, true); }), "");
  EXPECT_NE(message_of([] { (void)parse_number("gain", " 1", 0.0, 10.0, true); }), "");
  EXPECT_EQ(parse_integer("n", "12", 0, 20), 12);
  EXPECT_NE(message_of([] { (void)parse_integer("n", "1.5", 0, 20); }), "");
  EXPECT_NE(message_of([] { (void)parse_integer("n", "21", 0, 20); }), "");
  EXPECT_TRUE(parse_bool("b", "true"));
  EXPECT_EQ(message_of([] { (void)parse_bool("b", "yes"); }), "setting 'b' must be true or false, got \"yes\"");
}

TEST(SettingsTable, FormattedNumbersReadBackExactly) {
  for (double v : {0.02, 0.5, 500.0, 1.0 / 3.0, 1e-9, 4.0}) {
    EXPECT_EQ(std::stod(format_number(v)), v);
  }
  EXPECT_EQ(format_number(0.02), "0.02");
  EXPECT_EQ(format_number(500.0), "500");
}

TEST(SettingsTable, UnknownNamesListTheKnownOnes) {
  EstimatorParams p;
  const std::string m = message_of([&] { estimator_settings_table().set(p, "r_seeds", "0.02"); });
  EXPECT_NE(m.find("unknown parameter 'r_seeds'"), std::string::npos);
  EXPECT_NE(m.find("push_weighting"), std::string::npos);
}

TEST(SettingsTable, EstimatorDefaultsComeFromTheSettingsStruct) {
  const EstimatorSettings d;
  const auto docs = estimator_settings_table().docs();
  ASSERT_EQ(docs.size(), 11U);
  for (const auto& doc : docs) {
    EstimatorParams p;
    estimator_settings_table().set(p, doc.name, doc.default_value);
    EXPECT_EQ(p.resolve().r_seed, d.r_seed) << doc.name;
  }
  EstimatorParams p;
  estimator_settings_table().apply(p, {{"r_seed", "0.03"}, {"push_radius", "r_seed"}, {"max_iterations", "7"}});
  const EstimatorSettings s = p.resolve();
  EXPECT_EQ(s.push_radius, 0.03);
  EXPECT_EQ(s.max_iterations, 7);
}

TEST(SettingsTable, HelpAndMarkdownShowEveryRow) {
  const auto docs = estimator_settings_table().docs();
  const std::string help = settings_help(docs), md = settings_markdown(docs);
  for (const auto& d : docs) {
    EXPECT_NE(help.find(d.name), std::string::npos);
    EXPECT_NE(md.find("`" + d.name + "`"), std::string::npos);
  }
  EXPECT_NE(md.find("paper \\| authors_code"), std::string::npos);  // pipes escaped in cells
}

}  // namespace
}  // namespace ofv
