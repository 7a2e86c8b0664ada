// Intervals and grouping of the `ofv compare` reports.
#include "ofv/loop/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace ofv {
namespace {

TEST(Interval95, StudentT) {
  const Interval i = mean_interval({1.0, 2.0, 3.0});
  EXPECT_DOUBLE_EQ(i.mean, 2.0);
  EXPECT_NEAR(i.half_width, 4.303 * 1.0 / std::sqrt(3.0), 1e-9);
  EXPECT_EQ(mean_interval({std::nan(""), 4.0}).n, 1);
  // Equal up to rounding (2.1 - 1.7666... vs 2.4333... - 2.1): no interval.
  EXPECT_EQ(mean_interval({2.1 - 53.0 / 30.0, 73.0 / 30.0 - 2.1}).half_width, 0.0);
  EXPECT_GT(mean_interval({0.3, 0.3 + 1e-9}).half_width, 0.0);
}

EpisodeRow row(const std::string& scenario, const std::string& variant, int seed, double visible) {
  EpisodeRow r;
  r.spec.scenario = scenario;
  r.spec.variant.name = variant;
  r.spec.seed = seed;
  r.metrics.mean_visible_fraction = visible;
  return r;
}

TEST(EpisodeGroups, KeepTheOrderOfFirstAppearance) {
  const EpisodeGroups g = group_episodes({row("b", "x", 0, 0.5), row("b", "y", 0, 0.7),
                                          row("a", "y", 0, 0.9), row("b", "x", 1, 0.6)});
  EXPECT_EQ(g.scenarios, (std::vector<std::string>{"b", "a"}));
  EXPECT_EQ(g.variants, (std::vector<std::string>{"x", "y"}));
  ASSERT_EQ(g.groups.size(), 3U);
  ASSERT_NE(g.find("b", "x"), nullptr);
  EXPECT_EQ(g.find("b", "x")->rows.size(), 2U);
  EXPECT_EQ(g.find("a", "x"), nullptr);
  const MetricColumn& visible = metric_columns().front();
  EXPECT_DOUBLE_EQ(g.find("b", "x")->interval(visible).mean, 0.55);
}

}  // namespace
}  // namespace ofv
