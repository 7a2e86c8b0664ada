// Scene/result JSON: every field, every error names source, field and value.
#include "ofv/io/scene_json.h"
#include "ofv/estimator_settings.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <stdexcept>

namespace ofv {
namespace {

using nlohmann::json;

const char* kMinimal = R"({"supervoxels": [{"position": [0, 0, 1], "normal": [0, 0, -1]}]})";

// The message of the std::invalid_argument that parsing `text` throws.
std::string error_of(const std::string& text) {
  try {
    (void)scene_from_json(json::parse(text), "scene.json").params.resolve();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "no error";
}

TEST(SceneJson, MinimalSceneHasDefaults) {
  const Scene s = scene_from_json(json::parse(kMinimal), "scene.json");
  EXPECT_EQ(s.problem.positions.cols(), 1);
  EXPECT_EQ(s.problem.occluders.cols(), 0);
  EXPECT_FALSE(s.problem.centroid);
  EXPECT_FALSE(s.problem.axes);
  EXPECT_FALSE(s.problem.camera);
  EXPECT_FALSE(s.problem.previous_view);
  const EstimatorSettings d = s.params.resolve();
  const EstimatorSettings expected;
  EXPECT_EQ(d.r_seed, expected.r_seed);
  EXPECT_EQ(d.r_sphere, expected.r_sphere);
  EXPECT_EQ(d.clearance, expected.clearance);
  EXPECT_EQ(d.push_radius, expected.push_radius);
  EXPECT_EQ(d.step, expected.step);
  EXPECT_EQ(d.max_iterations, expected.max_iterations);
  EXPECT_EQ(d.warm_start, expected.warm_start);
}

TEST(SceneJson, EveryFieldIsRead) {
  const Scene s = scene_from_json(json::parse(R"({
    "supervoxels": [{"position": [1, 2, 3], "normal": [0, 1, 0]}],
    "occluders": [[0.1, 0.2, 0.3], [0.4, 0.5, 0.6]],
    "centroid": [1, 1, 1], "axes": [[0, 0, 1], [1, 0, 0], [0, 1, 0]],
    "camera": [0, 0, -1], "previous_view": [2, 2, 2],
    "params": {"preset": "authors_code", "r_seed": 0.03, "r_sphere": 0.6,
               "initial_view": "vector_mean", "clearance": 0.01, "push_radius": 0.03,
               "push_weighting": "inverse_distance", "step": 0.005, "max_iterations": 9,
               "warm_start": true, "time_budget": 0.25}})"),
                                  "s.json");
  EXPECT_EQ(s.problem.positions.col(0), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(s.problem.occluders.col(1), Eigen::Vector3d(0.4, 0.5, 0.6));
  EXPECT_EQ(*s.problem.centroid, Eigen::Vector3d(1, 1, 1));
  EXPECT_EQ(s.problem.axes->col(0), Eigen::Vector3d(0, 0, 1));
  EXPECT_EQ(*s.problem.camera, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(*s.problem.previous_view, Eigen::Vector3d(2, 2, 2));
  const EstimatorSettings r = s.params.resolve();
  EXPECT_EQ(s.params.preset, Preset::AuthorsCode);
  EXPECT_EQ(r.r_seed, 0.03);
  EXPECT_EQ(r.r_sphere, 0.6);
  EXPECT_EQ(r.initial_view, InitialView::VectorMean);
  EXPECT_EQ(r.clearance, 0.01);
  EXPECT_EQ(r.push_radius, 0.03);
  EXPECT_EQ(r.push_weighting, PushWeighting::InverseDistance);
  EXPECT_EQ(r.step, 0.005);
  EXPECT_EQ(r.max_iterations, 9);
  EXPECT_TRUE(r.warm_start);
  EXPECT_EQ(r.time_budget, 0.25);

  // And back: scene_to_json writes what scene_from_json reads, every setting.
  const Scene again = scene_from_json(json::parse(scene_to_json(s).dump()), "again");
  EXPECT_EQ(again.problem.positions, s.problem.positions);
  EXPECT_EQ(again.problem.occluders, s.problem.occluders);
  EXPECT_EQ(*again.problem.axes, *s.problem.axes);
  for (const auto& row : estimator_settings_table().rows()) {
    EXPECT_EQ(row.get(again.params), row.get(s.params)) << row.doc.name;
  }
}

struct BadCase {
  const char* text;
  std::vector<const char*> mentions;  // what the message must name
};

TEST(SceneJson, BadInputNamesFieldAndValue) {
  const std::vector<BadCase> cases{
      {R"({})", {"scene.json", "supervoxels", "missing"}},
      {R"([])", {"scene.json", "JSON object"}},
      {R"({"supervoxels": {}})", {"supervoxels", "array"}},
      {R"({"supervoxels": [], "colour": 1})", {"colour", "unknown key"}},
      {R"({"supervoxels": [{"position": [0, 0], "normal": [0, 0, 1]}]})",
       {"supervoxels[0].position", "[0,0]"}},
      {R"({"supervoxels": [{"position": [0, 0, "a"], "normal": [0, 0, 1]}]})",
       {"supervoxels[0].position"}},
      {R"({"supervoxels": [{"position": [0, 0, 0]}]})", {"supervoxels[0].normal", "missing"}},
      {R"({"supervoxels": [{"position": [0, 0, 0], "normal": [0, 0, 1], "size": 2}]})",
       {"supervoxels[0].size", "unknown key"}},
      {R"({"supervoxels": [], "occluders": [[0, 0, 0], 7]})", {"occluders[1]", "7"}},
      {R"({"supervoxels": [], "centroid": "middle"})", {"centroid", "\"middle\""}},
      {R"({"supervoxels": [], "axes": [[1, 0, 0]]})", {"axes"}},
      {R"({"supervoxels": [], "params": {"r_seed": -0.02}})", {"r_seed", "-0.02"}},
      {R"({"supervoxels": [], "params": {"r_sphere": 0}})", {"r_sphere", "0"}},
      {R"({"supervoxels": [], "params": {"step": "big"}})", {"params.step", "\"big\""}},
      {R"({"supervoxels": [], "params": {"clearance": null}})", {"params.clearance", "null"}},
      {R"({"supervoxels": [], "params": {"max_iterations": -1}})", {"params.max_iterations", "-1"}},
      {R"({"supervoxels": [], "params": {"max_iterations": 2.5}})", {"params.max_iterations", "2.5"}},
      {R"({"supervoxels": [], "params": {"initial_view": "median"}})",
       {"params.initial_view", "\"median\"", "spherical_mean"}},
      {R"({"supervoxels": [], "params": {"push_weighting": "max"}})", {"params.push_weighting", "\"max\""}},
      {R"({"supervoxels": [], "params": {"preset": "fast"}})", {"params.preset", "\"fast\""}},
      {R"({"supervoxels": [], "params": {"warm_start": "yes"}})", {"params.warm_start", "\"yes\""}},
      {R"({"supervoxels": [], "params": {"speed": 1}})", {"params.speed", "unknown parameter"}},
      {R"({"supervoxels": [], "params": []})", {"params", "object"}},
  };
  for (const auto& c : cases) {
    const std::string message = error_of(c.text);
    for (const char* m : c.mentions) {
      EXPECT_NE(message.find(m), std::string::npos) << c.text << "\n  -> " << message;
    }
  }
}

TEST(SceneJson, TextIsCheckedAsAFileIs) {
  EXPECT_EQ(scene_from_text(kMinimal, "text.json").problem.positions.cols(), 1);
  const auto message = [](const std::string& text) {
    try {
      (void)scene_from_text(text, "text.json");
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message(R"({"supervoxels": [], "supervoxels": []})").find("text.json: invalid JSON: duplicate key"),
            std::string::npos);
  EXPECT_NE(message(std::string(40, '[') + std::string(40, ']')).find("nested deeper than"), std::string::npos);
  EXPECT_NE(message("{").find("text.json: invalid JSON"), std::string::npos);
}

TEST(SceneJson, SetParamParsesEachType) {
  EstimatorParams p;
  set_param(p, "preset", "authors_code");
  set_param(p, "r_seed", "2e-2");
  set_param(p, "max_iterations", "12");
  set_param(p, "warm_start", "true");
  set_param(p, "initial_view", "vector_mean");
  set_param(p, "push_weighting", "inverse_distance");
  EXPECT_EQ(p.preset, Preset::AuthorsCode);
  EXPECT_EQ(*p.r_seed, 0.02);
  EXPECT_EQ(*p.max_iterations, 12);
  EXPECT_TRUE(*p.warm_start);
  for (const auto& [name, value] : std::vector<std::pair<std::string, std::string>>{
           {"speed", "1"}, {"r_seed", "abc"}, {"r_seed", "0.02m"}, {"r_seed", "-1"},
           {"step", "nan"}, {"step", "1e999"}, {"step", "0"}, {"max_iterations", "1.5"}, {"warm_start", "maybe"},
           {"preset", "quick"}, {"r_sphere", "1e300"}, {"time_budget", "0"}, {"time_budget", "1e9"}}) {
    try {
      EstimatorParams q = p;
      set_param(q, name, value);  // a number of the wrong range fails at resolve()
      (void)q.resolve();
      ADD_FAILURE() << name << "=" << value << " was accepted";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(name), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(param_names().size(), 11U);
}

TEST(SceneJson, ResultHasEverySpecField) {
  const Scene s = scene_from_json(json::parse(kMinimal), "scene.json");
  const json j = json::parse(estimate_to_json(estimate_view(s.problem, s.params.resolve())).dump());
  for (const char* key : {"t0", "tf", "status", "iterations", "initial_view_used",
                          "skipped_supervoxels", "skipped_occluders", "angular_error_deg"}) {
    EXPECT_TRUE(j.contains(key)) << key;
  }
  EXPECT_EQ(j["status"], "no_occluders");
  EXPECT_TRUE(j["angular_error_deg"]["tf"]["mean"].is_number());

  ViewEstimate none;  // no supervoxel left: null errors
  const json k = json::parse(estimate_to_json(none).dump());
  EXPECT_TRUE(k["angular_error_deg"]["t0"]["mean"].is_null());
  EXPECT_TRUE(k["angular_error_deg"]["tf"]["std"].is_null());

  const json nothing = json::parse(estimate_to_json(estimate_view(ViewProblem{}, {})).dump());
  EXPECT_EQ(nothing["status"], "no_supervoxels");
  EXPECT_TRUE(nothing["angular_error_deg"]["tf"]["mean"].is_null());
}

TEST(SceneJson, PrettyPrintingKeepsTheValue) {
  const nlohmann::ordered_json j = nlohmann::ordered_json::parse(
      R"({"a": [1, 2.5, -3e-7], "b": {"c": null, "d": [[1, 2, 3], [4, 5, 6]]},
          "path": [[0, 0, 1], [0, 1, 0], [1, 0, 0], [1, 1, 1]], "e": [], "f": {}, "s": "x,y"})");
  const std::string text = to_pretty_string(j);
  EXPECT_EQ(nlohmann::ordered_json::parse(text), j);
  EXPECT_NE(text.find("\"a\": [1, 2.5, -3e-07]"), std::string::npos) << text;
  EXPECT_NE(text.find("\"s\": \"x,y\""), std::string::npos) << text;  // strings untouched
  EXPECT_NE(text.find("    [1, 1, 1]"), std::string::npos) << text;  // long lists one per line
}

}  // namespace
}  // namespace ofv
