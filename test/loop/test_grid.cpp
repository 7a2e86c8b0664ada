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

}  // namespace
}  // namespace ofv
