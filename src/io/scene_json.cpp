// Scene and result JSON (ESTIMATOR-SPEC.md §8).
#include "ofv/io/scene_json.h"
#include "ofv/text_file.h"

#include "ofv/estimator_settings.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <stdexcept>
#include <vector>

namespace ofv {
namespace {

using nlohmann::json;
using nlohmann::ordered_json;

// Error context: "<source>: <field>".
struct Where {
  const std::string& source;
  std::string field;
  [[nodiscard]] Where operator[](const std::string& key) const {
    return {source, field.empty() ? key : field + "." + key};
  }
  [[nodiscard]] Where operator[](std::size_t index) const {
    return {source, field + "[" + std::to_string(index) + "]"};
  }
};

// Text from the document, cut short: error messages never print a document.
std::string clip(std::string text) {
  constexpr std::size_t kMax = 60;
  if (text.size() > kMax) {
    text = text.substr(0, kMax) + "...";
  }
  return text;
}

std::string shown(const json& j) {
  const bool flat = j.size() <= 8 && std::none_of(j.begin(), j.end(), [](const json& item) {
                      return item.is_structured();
                    });
  if (j.is_array() && !flat) {
    return "an array of " + std::to_string(j.size()) + " items";
  }
  if (j.is_object() && !flat) {
    return "an object of " + std::to_string(j.size()) + " keys";
  }
  return clip(j.dump());  // a value or a short flat array
}

[[noreturn]] void fail(const Where& at, const std::string& what) {
  throw std::invalid_argument(at.source + ": " + at.field + ": " + what);
}

[[noreturn]] void fail(const Where& at, const std::string& expected, const json& got) {
  fail(at, "expected " + expected + ", got " + shown(got));
}

double number(const json& j, const Where& at) {
  if (!j.is_number()) {
    fail(at, "a number", j);
  }
  return j.get<double>();
}

Eigen::Vector3d vec3(const json& j, const Where& at) {
  if (!j.is_array() || j.size() != 3 || !j[0].is_number() || !j[1].is_number() ||
      !j[2].is_number()) {
    fail(at, "an array of 3 numbers", j);
  }
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()};
}

void check_keys(const json& j, const Where& at, std::initializer_list<const char*> allowed) {
  for (const auto& item : j.items()) {
    bool known = false;
    for (const char* key : allowed) {
      known = known || item.key() == key;
    }
    if (!known) {
      std::string list;
      for (const char* key : allowed) {
        list += list.empty() ? key : std::string(", ") + key;
      }
      fail(at[clip(item.key())], "unknown key (expected one of: " + list + ")");
    }
  }
}

int iterations_param(const json& j, const Where& at) {
  if (j.is_number_integer()) {
    if (j.is_number_unsigned() ? j.get<std::uint64_t>() <= INT_MAX
                               : (j.get<std::int64_t>() >= 0 && j.get<std::int64_t>() <= INT_MAX)) {
      return j.get<int>();
    }
  }
  fail(at, "a non-negative integer", j);
}

// One parameter of a scene's `params`: the JSON type the setting's row
// asks for, then the estimator's settings table.
void set_param_json(EstimatorParams& p, const std::string& name, const json& j, const Where& at) {
  const SettingDoc* row = estimator_settings_table().find(name);
  if (row == nullptr) {
    std::string list;
    for (const auto& known : param_names()) {
      list += list.empty() ? known : ", " + known;
    }
    fail(at, "unknown parameter (expected one of: " + list + ")");
  }
  std::string text;
  if (row->type == "bool") {
    if (!j.is_boolean()) fail(at, "true or false", j);
    text = format_bool(j.get<bool>());
  } else if (row->type.rfind("integer", 0) == 0) {
    text = std::to_string(iterations_param(j, at));
  } else if (row->type.rfind("number", 0) == 0) {
    text = format_number(number(j, at));  // range checked by EstimatorParams::resolve()
  } else {
    if (!j.is_string()) fail(at, "one of " + row->type, j);
    text = j.get<std::string>();
  }
  try {
    estimator_settings_table().set(p, name, text);
  } catch (const std::invalid_argument& e) {
    fail(at, e.what());
  }
}

Eigen::Matrix3Xd points(const json& j, const Where& at) {
  if (!j.is_array()) {
    fail(at, "an array of [x, y, z] points", j);
  }
  Eigen::Matrix3Xd m(3, static_cast<Eigen::Index>(j.size()));
  for (std::size_t k = 0; k < j.size(); ++k) {
    m.col(static_cast<Eigen::Index>(k)) = vec3(j[k], at[k]);
  }
  return m;
}

ordered_json to_json(const Eigen::Vector3d& v) { return ordered_json::array({v.x(), v.y(), v.z()}); }

ordered_json to_json(const std::optional<AngularErrorStats>& e) {
  if (!e) {
    return ordered_json{{"mean", nullptr}, {"std", nullptr}};
  }
  return ordered_json{{"mean", e->mean}, {"std", e->std}};
}

}  // namespace

const std::vector<std::string>& param_names() {
  static const std::vector<std::string> names = [] {
    std::vector<std::string> out;
    for (const auto& doc : estimator_settings_table().docs()) out.push_back(doc.name);
    return out;
  }();
  return names;
}

Scene scene_from_json(const json& j, const std::string& source) {
  const Where root{source, ""};
  if (!j.is_object()) {
    fail(Where{source, "scene"}, "a JSON object", j);
  }
  check_keys(j, root,
             {"supervoxels", "occluders", "centroid", "axes", "camera", "previous_view", "params"});
  Scene scene;
  ViewProblem& pb = scene.problem;

  if (!j.contains("supervoxels")) {
    fail(root["supervoxels"], "missing (an array of {\"position\", \"normal\"} objects is required)");
  }
  const json& svs = j["supervoxels"];
  const Where at_svs = root["supervoxels"];
  if (!svs.is_array()) {
    fail(at_svs, "an array of {\"position\", \"normal\"} objects", svs);
  }
  pb.positions.resize(3, static_cast<Eigen::Index>(svs.size()));
  pb.normals.resize(3, static_cast<Eigen::Index>(svs.size()));
  for (std::size_t k = 0; k < svs.size(); ++k) {
    const Where at = at_svs[k];
    const json& sv = svs[k];
    if (!sv.is_object()) {
      fail(at, "an object with \"position\" and \"normal\"", sv);
    }
    check_keys(sv, at, {"position", "normal"});
    for (const char* key : {"position", "normal"}) {
      if (!sv.contains(key)) {
        fail(at[key], "missing");
      }
    }
    pb.positions.col(static_cast<Eigen::Index>(k)) = vec3(sv["position"], at["position"]);
    pb.normals.col(static_cast<Eigen::Index>(k)) = vec3(sv["normal"], at["normal"]);
  }

  pb.occluders = j.contains("occluders") ? points(j["occluders"], root["occluders"])
                                          : Eigen::Matrix3Xd(3, 0);
  if (j.contains("centroid")) pb.centroid = vec3(j["centroid"], root["centroid"]);
  if (j.contains("camera")) pb.camera = vec3(j["camera"], root["camera"]);
  if (j.contains("previous_view")) {
    pb.previous_view = vec3(j["previous_view"], root["previous_view"]);
  }
  if (j.contains("axes")) {
    const json& a = j["axes"];
    if (!a.is_array() || a.size() != 3) {
      fail(root["axes"], "an array of 3 axes [[e1], [e2], [e3]]", a);
    }
    Eigen::Matrix3d axes;
    for (std::size_t k = 0; k < 3; ++k) {
      axes.col(static_cast<Eigen::Index>(k)) = vec3(a[k], root["axes"][k]);
    }
    pb.axes = axes;
  }
  if (j.contains("params")) {
    const json& params = j["params"];
    if (!params.is_object()) {
      fail(root["params"], "an object", params);
    }
    for (const auto& item : params.items()) {
      set_param_json(scene.params, item.key(), item.value(), root["params"][item.key()]);
    }
  }
  return scene;
}

namespace {

// What scene_from_text() checks before parsing: containers nested at most
// kMaxSceneDepth deep, no key twice in one object. Linear in the text.
class SceneChecks final : public nlohmann::json_sax<json> {
 public:
  bool null() override { return true; }
  bool boolean(bool /*value*/) override { return true; }
  bool number_integer(number_integer_t /*value*/) override { return true; }
  bool number_unsigned(number_unsigned_t /*value*/) override { return true; }
  bool number_float(number_float_t /*value*/, const string_t& /*text*/) override { return true; }
  bool string(string_t& /*value*/) override { return true; }
  bool binary(binary_t& /*value*/) override { return true; }
  bool start_object(std::size_t /*size*/) override {
    keys_.emplace_back();
    return enter();
  }
  bool key(string_t& name) override {
    if (keys_.back().insert(name).second) return true;
    problem = "duplicate key \"" + clip(name) + "\"";
    return false;
  }
  bool end_object() override {
    keys_.pop_back();
    --depth_;
    return true;
  }
  bool start_array(std::size_t /*size*/) override { return enter(); }
  bool end_array() override {
    --depth_;
    return true;
  }
  // A syntax error is reported by the parse that follows.
  bool parse_error(std::size_t /*position*/, const std::string& /*token*/,
                   const nlohmann::detail::exception& /*error*/) override {
    return false;
  }

  std::string problem;  ///< why the check stopped, empty for a syntax error

 private:
  bool enter() {
    if (++depth_ <= kMaxSceneDepth) return true;
    problem = "nested deeper than " + std::to_string(kMaxSceneDepth) + " levels";
    return false;
  }
  int depth_ = 0;
  std::vector<std::set<std::string>> keys_;  // of the objects being read
};

}  // namespace

Scene read_scene(const std::string& path) {
  return scene_from_text(read_text_file(path, kMaxSceneBytes, "scene"), path);
}

Scene scene_from_text(const std::string& text, const std::string& source) {
  if (text.size() > kMaxSceneBytes) {
    throw std::invalid_argument(source + ": " + std::to_string(text.size()) + " bytes, more than " +
                                std::to_string(kMaxSceneBytes));
  }
  // The text is checked before it is parsed: nesting deeper than
  // kMaxSceneDepth and a key repeated in one object stop the check there.
  // (nlohmann's parse with a callback would do it in one pass, but it scans
  // the enclosing array at every object's end: quadratic in the supervoxels.)
  SceneChecks checks;
  if (!json::sax_parse(text, &checks) && !checks.problem.empty()) {
    throw std::invalid_argument(source + ": invalid JSON: " + checks.problem);
  }
  json j;
  try {
    j = json::parse(text);
  } catch (const json::exception& e) {  // syntax errors and number overflow (1e999)
    throw std::invalid_argument(source + ": invalid JSON: " + clip(e.what()));
  }
  return scene_from_json(j, source);
}

void set_param(EstimatorParams& params, const std::string& name, const std::string& value) {
  try {
    estimator_settings_table().set(params, name, value);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument("--set " + name + "=" + value + ": " + e.what());
  }
}

ordered_json scene_to_json(const Scene& scene) {
  const ViewProblem& pb = scene.problem;
  ordered_json j;
  j["supervoxels"] = ordered_json::array();
  for (Eigen::Index k = 0; k < pb.positions.cols(); ++k) {
    j["supervoxels"].push_back(ordered_json{{"position", to_json(pb.positions.col(k))},
                                            {"normal", to_json(pb.normals.col(k))}});
  }
  j["occluders"] = ordered_json::array();
  for (Eigen::Index k = 0; k < pb.occluders.cols(); ++k) {
    j["occluders"].push_back(to_json(pb.occluders.col(k)));
  }
  if (pb.centroid) j["centroid"] = to_json(*pb.centroid);
  if (pb.axes) {
    j["axes"] = ordered_json::array(
        {to_json(pb.axes->col(0)), to_json(pb.axes->col(1)), to_json(pb.axes->col(2))});
  }
  if (pb.camera) j["camera"] = to_json(*pb.camera);
  if (pb.previous_view) j["previous_view"] = to_json(*pb.previous_view);

  const EstimatorParams& p = scene.params;
  ordered_json params;
  params["preset"] = to_string(p.preset);
  if (p.r_seed) params["r_seed"] = *p.r_seed;
  if (p.r_sphere) params["r_sphere"] = *p.r_sphere;
  if (p.initial_view) params["initial_view"] = to_string(*p.initial_view);
  if (p.clearance) params["clearance"] = *p.clearance;
  if (p.push_radius) params["push_radius"] = *p.push_radius;
  if (p.push_weighting) params["push_weighting"] = to_string(*p.push_weighting);
  if (p.step) params["step"] = *p.step;
  if (p.max_iterations) params["max_iterations"] = *p.max_iterations;
  if (p.warm_start) params["warm_start"] = *p.warm_start;
  if (p.time_budget) params["time_budget"] = *p.time_budget;
  j["params"] = params;
  return j;
}

ordered_json estimate_to_json(const ViewEstimate& e) {
  ordered_json j;
  j["t0"] = to_json(e.t0);
  j["tf"] = to_json(e.tf);
  j["status"] = to_string(e.status);
  j["iterations"] = e.iterations;
  j["initial_view_used"] = to_string(e.initial_view_used);
  j["skipped_supervoxels"] = e.skipped_supervoxels;
  j["skipped_occluders"] = e.skipped_occluders;
  j["angular_error_deg"] = ordered_json{{"t0", to_json(e.error_t0)}, {"tf", to_json(e.error_tf)}};
  j["tf_to_t0_deg"] = e.tf_to_t0_deg;
  j["centroid"] = to_json(e.centroid);
  j["axes"] = ordered_json::array(
      {to_json(e.axes.col(0)), to_json(e.axes.col(1)), to_json(e.axes.col(2))});
  j["axes_from_world"] = e.axes_from_world;
  j["occlusion_points"] = e.occlusion_points;
  j["clearance_points"] = e.clearance_points;
  if (!e.path.empty()) {
    j["path"] = ordered_json::array();
    for (const auto& t : e.path) {
      j["path"].push_back(to_json(t));
    }
  }
  return j;
}

namespace {

// An array of numbers, or of at most three arrays of numbers (axes).
bool is_flat(const ordered_json& j, bool nested = false) {
  if (!j.is_array()) return false;
  for (const auto& item : j) {
    const bool ok = item.is_number() || item.is_null() ||
                    (!nested && j.size() <= 3 && is_flat(item, true));
    if (!ok) return false;
  }
  return true;
}

void write_pretty(std::string& out, const ordered_json& j, int depth) {
  const std::string pad(static_cast<std::size_t>(2 * depth), ' ');
  if (j.is_object() && !j.empty()) {
    out += "{\n";
    std::size_t k = 0;
    for (const auto& item : j.items()) {
      out += pad + "  " + ordered_json(item.key()).dump() + ": ";
      write_pretty(out, item.value(), depth + 1);
      out += ++k < j.size() ? ",\n" : "\n";
    }
    out += pad + "}";
  } else if (j.is_array() && !j.empty() && !is_flat(j)) {
    out += "[\n";
    for (std::size_t k = 0; k < j.size(); ++k) {
      out += pad + "  ";
      write_pretty(out, j[k], depth + 1);
      out += k + 1 < j.size() ? ",\n" : "\n";
    }
    out += pad + "]";
  } else {
    std::string flat = j.dump();
    if (j.is_array()) {  // one space after each comma, as people write it
      std::string spaced;
      for (char ch : flat) spaced += ch == ',' ? std::string(", ") : std::string(1, ch);
      flat = spaced;
    }
    out += flat;
  }
}

}  // namespace

std::string to_pretty_string(const ordered_json& j) {
  std::string out;
  write_pretty(out, j, 0);
  return out;
}

}  // namespace ofv
