// The settings grid of `ofv compare`: expansion and errors.
#include "ofv/loop/grid.h"

#include <gtest/gtest.h>

#include <stdexcept>

namespace ofv {
namespace {

TEST(Grid, VariantsAndAxesExpandToTheirProduct) {
  const Grid g = grid_from_yaml(R"(
name: readings
seeds: 2
variants:
  - name: paper
    set: {preset: paper}
  - name: authors
    set: {preset: authors_code, step: 0.01}
axes:
  push_radius: [r_sphere, r_seed]
  method: [estimator, sampling]
)", "grid.yaml");
  EXPECT_EQ(g.name, "readings");
  EXPECT_EQ(g.seeds, 2);
  ASSERT_EQ(g.variants.size(), 8U);
  EXPECT_EQ(g.variants[0].name, "paper,push_radius=r_sphere,method=estimator");
  ASSERT_EQ(g.variants[7].settings.size(), 4U);
  EXPECT_EQ(g.variants[7].settings[1], (std::pair<std::string, std::string>("step", "0.01")));
  EXPECT_EQ(g.variants[7].settings[3].second, "sampling");
}

TEST(Grid, CommonSettingsComeFirstInEveryVariant) {
  const Grid g = grid_from_yaml(R"(
set: {perception: ground-truth, gain: 3}
variants:
  - name: a
    set: {gain: 5}
  - name: b
)", "grid.yaml");
  ASSERT_EQ(g.variants.size(), 2U);
  using S = std::vector<std::pair<std::string, std::string>>;
  EXPECT_EQ(g.variants[0].settings, (S{{"perception", "ground-truth"}, {"gain", "3"}, {"gain", "5"}}));
  EXPECT_EQ(g.variants[1].settings, (S{{"perception", "ground-truth"}, {"gain", "3"}}));
}

TEST(Grid, ErrorsNameFileAndKey) {
  const std::vector<std::pair<std::string, std::string>> cases{
      {"seeds: -1", "seeds"},
      {"seeds: many", "seeds"},
      {"colour: red", "colour"},
      {"variants: {a: 1}", "variants"},
      {"variants:\n  - set: {step: 1}", "variants[0].name"},
      {"variants:\n  - name: a\n    sett: {}", "variants[0].sett"},
      {"variants:\n  - name: a\n  - name: a", "used twice"},
      {"axes:\n  step: []", "axes.step"},
      {"axes:\n  step: [[1]]", "axes.step[0]"},
      {"[1, 2", "invalid YAML"},
      {"seeds: 0\naxes: {gain: [1]}", "seeds"},
      {"seeds: 1001\naxes: {gain: [1]}", "1001"},
      {"seeds: 3000000000\naxes: {gain: [1]}", "3000000000"},
      {"variants: []", "variants"},
      {"name: nothing", "variants"},
      {"set: {gain: 2}", "variants"},
      {"axes: {}", "axes"},
      {"? [1, 2]\n: 3", "key"},
  };
  for (const auto& [text, mention] : cases) {
    try {
      (void)grid_from_yaml(text, "g.yaml");
      ADD_FAILURE() << text << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("g.yaml"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(mention), std::string::npos) << e.what();
    }
  }
}

TEST(Grid, RepeatedKeysAreErrorsNamingKeyAndLine) {
  // yaml-cpp itself keeps the first of repeated keys: without the check,
  // `seeds: 5` and `gain: 2` below would be silently ignored.
  const std::vector<std::pair<std::string, std::vector<std::string>>> cases{
      {"seeds: 2\naxes: {gain: [1]}\nseeds: 5\n", {"g.yaml:3", "seeds", "first on line 1"}},
      {"variants:\n  - name: a\n    set:\n      gain: 1\n      gain: 2\n",
       {"g.yaml:5", "variants[0].set.gain", "'gain'", "first on line 4"}},
      {"variants:\n  - name: a\n    name: b\n", {"g.yaml:3", "variants[0].name"}},
      {"axes:\n  gain: [1]\n  step: [1]\n  gain: [2]\n", {"g.yaml:4", "axes.gain"}},
      {"set: {gain: 1, gain: 1}\naxes: {step: [1]}", {"g.yaml:1", "set.gain"}},
  };
  for (const auto& [text, mentions] : cases) {
    try {
      (void)grid_from_yaml(text, "g.yaml");
      ADD_FAILURE() << text << " was accepted";
    } catch (const std::invalid_argument& e) {
      for (const auto& m : mentions) EXPECT_NE(std::string(e.what()).find(m), std::string::npos) << e.what();
    }
  }
}

TEST(Grid, AHugeGridIsRefusedBeforeItIsExpanded) {
  // 10^9 variants: expanding them would exhaust memory (std::bad_alloc).
  std::string text = "axes:\n";
  for (int a = 0; a < 9; ++a) text += "  s" + std::to_string(a) + ": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]\n";
  try {
    (void)grid_from_yaml(text, "g.yaml");
    ADD_FAILURE() << "accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("g.yaml"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("axes.s5"), std::string::npos) << e.what();  // 10^6 > 10^5
    EXPECT_NE(std::string(e.what()).find(std::to_string(kMaxVariants)), std::string::npos) << e.what();
  }
  // The limit itself is allowed: 10^5 variants.
  std::string at_limit = "axes:\n";
  for (int a = 0; a < 5; ++a) at_limit += "  s" + std::to_string(a) + ": [0, 1, 2, 3, 4, 5, 6, 7, 8, 9]\n";
  EXPECT_EQ(grid_from_yaml(at_limit, "g.yaml").variants.size(), kMaxVariants);
}

TEST(Grid, SeedsRangeIsOneToTheLimit) {
  EXPECT_EQ(grid_from_yaml("seeds: 1\naxes: {gain: [1]}", "g").seeds, 1);
  EXPECT_EQ(grid_from_yaml("seeds: " + std::to_string(kMaxSeeds) + "\naxes: {gain: [1]}", "g").seeds, kMaxSeeds);
}

}  // namespace
}  // namespace ofv
