// Scenario YAML (docs/scenarios.md), motion and built-in scenarios.
#include "ofv/sim/scenario.h"
#include "ofv/text_file.h"
#include "ofv/constants.h"

#include "ofv/io/scene_json.h"
#include "ofv/sim/yaml_checks.h"

#include <yaml-cpp/yaml.h>

#include <dlfcn.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <stdexcept>

namespace ofv::sim {

namespace fs = std::filesystem;

namespace {

constexpr double kDegToRad = kPi / 180.0;

// Upper bounds of the scenario's numbers (docs/scenarios.md, "Limits"): a
// scenario file is input, and a typo must not allocate or loop for ever.
constexpr std::uintmax_t kMaxFileBytes = 1 << 20;  // the YAML text
constexpr double kMaxDuration = 3600.0;            // duration, |waypoint t| [s]
constexpr double kMaxRate = 1000.0;                // frame rate [Hz]
constexpr double kMaxLength = 100.0;               // positions, sizes, depths, wave length [m]
constexpr double kMaxAngle = 3600.0;               // rpy_deg [deg]
constexpr int kMaxImageSide = 4096;                // sensor width, height [px]
constexpr double kMaxPixels = 1e5;                 // fx, fy, |cx|, |cy| [px]
constexpr int kMaxGrid = 512;                      // cloth and sheet cells a side
constexpr double kMaxScale = 1000.0;               // mesh scale
constexpr double kMaxGain = 100.0;                 // controller gain [1/s]
constexpr double kMaxSpeed = 10.0;                 // controller speed limits [m/s], [rad/s]

// A YAML map read strictly: every key must be known, errors name file and key.
class Node {
 public:
  Node(YAML::Node node, std::string source, std::string key)
      : node_(std::move(node)), source_(std::move(source)), key_(std::move(key)) {}

  [[noreturn]] void fail(const std::string& what) const {
    throw std::invalid_argument(source_ + ": " + (key_.empty() ? "scenario" : key_) + ": " + what);
  }
  [[nodiscard]] std::string value_text() const {
    YAML::Emitter e;
    e << YAML::Flow << node_;
    std::string s = e.c_str();
    return s.size() > 60 ? s.substr(0, 60) + "..." : s;
  }
  void require_map(std::initializer_list<const char*> keys) const {
    if (!node_.IsMap()) fail("expected a map, got " + value_text());
    for (const auto& item : node_) {
      const std::string k = item.first.as<std::string>();
      if (std::none_of(keys.begin(), keys.end(), [&](const char* x) { return k == x; })) {
        std::string list;
        for (const char* x : keys) list += (list.empty() ? "" : ", ") + std::string(x);
        child(k).fail("unknown key (expected one of: " + list + ")");
      }
    }
  }
  [[nodiscard]] bool has(const char* k) const { return node_.IsMap() && node_[k].IsDefined(); }
  [[nodiscard]] Node child(const std::string& k) const {
    return Node(node_[k], source_, key_.empty() ? k : key_ + "." + k);
  }
  [[nodiscard]] Node item(std::size_t i) const {
    return Node(node_[i], source_, key_ + "[" + std::to_string(i) + "]");
  }
  [[nodiscard]] std::size_t size() const { return node_.size(); }
  [[nodiscard]] bool is_sequence() const { return node_.IsSequence(); }

  [[nodiscard]] double number() const {
    double v = 0.0;
    if (!node_.IsScalar() || !YAML::convert<double>::decode(node_, v) || !std::isfinite(v)) {
      fail("expected a number, got " + value_text());
    }
    return v;
  }
  [[nodiscard]] double positive(double hi) const {
    const double v = number();
    if (!(v > 0.0) || v > hi) fail("expected a number in (0, " + std::to_string(hi) + "], got " + value_text());
    return v;
  }
  [[nodiscard]] double in_range(double lo, double hi) const {
    const double v = number();
    if (v < lo || v > hi) fail("expected a number in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + value_text());
    return v;
  }
  [[nodiscard]] int integer(int lo, int hi) const {
    int v = 0;  // decode fails on values outside int's range
    if (!node_.IsScalar() || !YAML::convert<int>::decode(node_, v) || v < lo || v > hi) {
      fail("expected an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " + value_text());
    }
    return v;
  }
  [[nodiscard]] bool boolean() const {
    bool v = false;
    if (!node_.IsScalar() || !YAML::convert<bool>::decode(node_, v)) fail("expected true or false, got " + value_text());
    return v;
  }
  [[nodiscard]] std::string word(std::initializer_list<const char*> allowed) const {
    if (!node_.IsScalar()) fail("expected a word, got " + value_text());
    const std::string v = node_.Scalar();
    if (allowed.size() != 0 && std::none_of(allowed.begin(), allowed.end(), [&](const char* x) { return v == x; })) {
      std::string list;
      for (const char* x : allowed) list += (list.empty() ? "" : ", ") + std::string(x);
      fail("expected one of " + list + ", got " + value_text());
    }
    return v;
  }
  /// A list of n numbers in [-limit, limit].
  [[nodiscard]] Eigen::VectorXd vector(int n, double limit) const {
    if (!node_.IsSequence() || static_cast<int>(node_.size()) != n) {
      fail("expected a list of " + std::to_string(n) + " numbers, got " + value_text());
    }
    Eigen::VectorXd v(n);
    for (int k = 0; k < n; ++k) v(k) = item(static_cast<std::size_t>(k)).in_range(-limit, limit);
    return v;
  }
  [[nodiscard]] const std::string& source() const { return source_; }
  [[nodiscard]] const std::string& key() const { return key_; }

 private:
  YAML::Node node_;
  std::string source_;
  std::string key_;
};

Eigen::Vector3f colour(const Node& n) {
  const Eigen::VectorXd c = n.vector(3, 255.0);
  if ((c.array() < 0.0).any() || (c.array() > 255.0).any()) n.fail("expected R, G, B in [0, 255], got " + n.value_text());
  return (c / 255.0).cast<float>();
}

Motion motion(const Node& n, const std::string& base_dir) {
  (void)base_dir;
  Motion m;
  Waypoint start;
  if (n.has("position")) start.position = n.child("position").vector(3, kMaxLength);
  if (n.has("rpy_deg")) start.rpy_deg = n.child("rpy_deg").vector(3, kMaxAngle);
  if (!n.has("waypoints")) {
    m.waypoints.push_back(start);
    return m;
  }
  const Node w = n.child("waypoints");
  if (!w.is_sequence() || w.size() == 0) w.fail("expected a non-empty list of {t, position, rpy_deg}");
  for (std::size_t i = 0; i < w.size(); ++i) {
    const Node p = w.item(i);
    p.require_map({"t", "position", "rpy_deg"});
    Waypoint wp = m.waypoints.empty() ? start : m.waypoints.back();
    if (!p.has("t")) p.fail("missing 't'");
    wp.t = p.child("t").in_range(-kMaxDuration, kMaxDuration);
    if (p.has("position")) wp.position = p.child("position").vector(3, kMaxLength);
    if (p.has("rpy_deg")) wp.rpy_deg = p.child("rpy_deg").vector(3, kMaxAngle);
    if (!m.waypoints.empty() && !(wp.t > m.waypoints.back().t)) p.child("t").fail("waypoint times must increase, got " + p.child("t").value_text());
    m.waypoints.push_back(wp);
  }
  return m;
}

Body body(const Node& n, Role role, const std::string& default_name, const std::string& base_dir) {
  n.require_map({"name", "shape", "size", "radius", "length", "thickness", "grid", "file", "scale",
                 "colour", "position", "rpy_deg", "waypoints", "wave", "bend", "dropout"});
  Body b;
  b.role = role;
  b.name = n.has("name") ? n.child("name").word({}) : default_name;
  if (!n.has("shape")) n.fail("missing 'shape' (box, sphere, capsule, sheet, cloth, mesh)");
  b.shape = n.child("shape").word({"box", "sphere", "capsule", "sheet", "cloth", "mesh"});
  auto size = [&](int k, const Eigen::VectorXd& def) -> Eigen::VectorXd {
    if (!n.has("size")) return def;
    const Eigen::VectorXd s = n.child("size").vector(k, kMaxLength);
    if (!(s.array() > 0.0).all()) n.child("size").fail("expected positive sizes, got " + n.child("size").value_text());
    return s;
  };
  const double radius = n.has("radius") ? n.child("radius").positive(kMaxLength) : 0.03;
  const double length = n.has("length") ? n.child("length").positive(kMaxLength) : 0.12;
  const double thickness = n.has("thickness") ? n.child("thickness").positive(kMaxLength) : 0.002;
  Eigen::Vector2i grid(16, 12);
  if (n.has("grid")) {
    const Node g = n.child("grid");
    if (!g.is_sequence() || g.size() != 2) g.fail("expected [nx, ny], got " + g.value_text());
    grid = {g.item(0).integer(1, kMaxGrid), g.item(1).integer(1, kMaxGrid)};
  }
  if (b.shape == "box") {
    b.mesh = make_box(size(3, Eigen::Vector3d(0.19, 0.135, 0.015)));
  } else if (b.shape == "sphere") {
    b.mesh = make_sphere(radius);
  } else if (b.shape == "capsule") {
    b.mesh = make_capsule(radius, length);
  } else if (b.shape == "sheet" || b.shape == "cloth") {
    const Eigen::VectorXd s = size(2, Eigen::Vector2d(0.3, 0.2));
    b.mesh = make_sheet(s(0), s(1), thickness, grid.x(), grid.y());
  } else {  // mesh
    if (!n.has("file")) n.fail("missing 'file' for a mesh");
    fs::path file = n.child("file").word({});
    if (file.is_relative()) file = fs::path(base_dir) / file;
    const double scale = n.has("scale") ? n.child("scale").positive(kMaxScale) : 1.0;
    try {
      b.mesh = read_mesh(file.string(), scale);
      b.mesh_file = file.string();
    } catch (const std::runtime_error& e) {
      n.child("file").fail(e.what());
    }
  }
  if (n.has("colour")) b.colour = colour(n.child("colour"));
  b.motion = motion(n, base_dir);
  if (n.has("wave")) {
    if (b.shape != "cloth") n.child("wave").fail("only a cloth waves");
    const Node w = n.child("wave");
    w.require_map({"amplitude", "length", "frequency"});
    if (w.has("amplitude")) b.wave_amplitude = w.child("amplitude").in_range(0.0, 1.0);
    if (w.has("length")) b.wave_length = w.child("length").positive(kMaxLength);
    if (w.has("frequency")) b.wave_frequency = w.child("frequency").in_range(0.0, 100.0);
  }
  if (n.has("dropout")) b.dropout = n.child("dropout").in_range(0.0, 1.0);
  if (n.has("bend")) {
    if (b.shape != "cloth") n.child("bend").fail("only a cloth bends");
    b.bend = n.child("bend").in_range(-100.0, 100.0);
  }
  return b;
}

}  // namespace

Eigen::Matrix3d rpy_deg_to_matrix(const Eigen::Vector3d& rpy_deg) {
  const Eigen::Vector3d r = rpy_deg * kDegToRad;
  return (Eigen::AngleAxisd(r.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(r.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(r.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Isometry3d Motion::at(double t) const {
  const auto pose = [](const Waypoint& w) {
    Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
    m.linear() = rpy_deg_to_matrix(w.rpy_deg);
    m.translation() = w.position;
    return m;
  };
  if (waypoints.size() == 1 || t <= waypoints.front().t) return pose(waypoints.front());
  if (t >= waypoints.back().t) return pose(waypoints.back());
  std::size_t k = 1;
  while (waypoints[k].t < t) ++k;
  const Waypoint& a = waypoints[k - 1];
  const Waypoint& b = waypoints[k];
  const double s = (t - a.t) / (b.t - a.t);
  const Eigen::Quaterniond qa(rpy_deg_to_matrix(a.rpy_deg)), qb(rpy_deg_to_matrix(b.rpy_deg));
  Eigen::Isometry3d m = Eigen::Isometry3d::Identity();
  m.linear() = qa.slerp(s, qb).toRotationMatrix();
  m.translation() = (1.0 - s) * a.position + s * b.position;
  return m;
}

TriangleMesh Body::world_mesh(double t) const {
  TriangleMesh out;
  if (deformable()) {
    deform_sheet(mesh, wave_amplitude, wave_length, wave_frequency, bend, t, out);
  } else {
    out = mesh;
  }
  const Eigen::Isometry3f wMb = motion.at(t).cast<float>();
  for (auto& v : out.vertices) v = wMb * v;
  return out;
}

CameraIntrinsics intrinsics_preset(const std::string& name) {
  CameraIntrinsics k;
  if (name == "d435-640") {
    k = {640, 480, 615.0, 615.0, 320.0, 240.0};
  } else if (name == "fast-320") {
    k = {320, 240, 307.5, 307.5, 160.0, 120.0};
  } else {
    throw std::invalid_argument("unknown intrinsics preset '" + name + "' (expected d435-640, fast-320)");
  }
  return k;
}

Scenario scenario_from_yaml(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": invalid YAML: " + e.what());
  }
  check_yaml(root, source);
  const Node top(root, source, "");
  top.require_map({"description", "duration", "rate", "seed", "variation", "sensor", "camera", "object",
                   "holder", "occluders", "table", "estimator", "robot", "controller"});
  Scenario s;
  s.path = source;
  s.name = fs::path(source).stem().string();
  const std::string base_dir = fs::path(source).parent_path().string();
  if (top.has("duration")) s.duration = top.child("duration").positive(kMaxDuration);
  if (top.has("rate")) s.rate = top.child("rate").positive(kMaxRate);
  if (top.has("seed")) s.seed = static_cast<unsigned>(top.child("seed").integer(0, std::numeric_limits<int>::max()));
  if (top.has("variation")) {
    const Node n = top.child("variation");
    n.require_map({"time", "position"});
    if (n.has("time")) s.variation.time = n.child("time").in_range(0.0, 1e3);
    if (n.has("position")) s.variation.position = n.child("position").in_range(0.0, 10.0);
  }

  s.sensor.intrinsics = intrinsics_preset("fast-320");
  if (top.has("sensor")) {
    const Node n = top.child("sensor");
    n.require_map({"preset", "width", "height", "fx", "fy", "cx", "cy", "min_depth", "max_depth", "noise"});
    if (n.has("preset")) s.sensor.intrinsics = intrinsics_preset(n.child("preset").word({"d435-640", "fast-320"}));
    CameraIntrinsics& k = s.sensor.intrinsics;
    if (n.has("width")) k.width = n.child("width").integer(8, kMaxImageSide);
    if (n.has("height")) k.height = n.child("height").integer(8, kMaxImageSide);
    if (n.has("fx")) k.fx = n.child("fx").positive(kMaxPixels);
    if (n.has("fy")) k.fy = n.child("fy").positive(kMaxPixels);
    if (n.has("cx")) k.cx = n.child("cx").in_range(-kMaxPixels, kMaxPixels);
    if (n.has("cy")) k.cy = n.child("cy").in_range(-kMaxPixels, kMaxPixels);
    if (n.has("min_depth")) s.sensor.min_depth = n.child("min_depth").positive(kMaxLength);
    if (n.has("max_depth")) s.sensor.max_depth = n.child("max_depth").positive(kMaxLength);
    if (!(s.sensor.max_depth > s.sensor.min_depth)) n.child("max_depth").fail("must exceed min_depth");
    if (n.has("noise")) {
      const Node z = n.child("noise");
      z.require_map({"enabled", "depth_sigma", "grazing_deg", "edge_jump", "edge_dropout"});
      NoiseModel& m = s.sensor.noise;
      if (z.has("enabled")) m.enabled = z.child("enabled").boolean();
      if (z.has("depth_sigma")) m.depth_sigma = z.child("depth_sigma").in_range(0.0, 0.1);
      if (z.has("grazing_deg")) m.grazing_deg = z.child("grazing_deg").in_range(0.0, 90.0);
      if (z.has("edge_jump")) m.edge_jump = z.child("edge_jump").positive(kMaxLength);
      if (z.has("edge_dropout")) m.edge_dropout = z.child("edge_dropout").in_range(0.0, 1.0);
    }
  }

  // Camera start: looking from `position` at `look_at`, world `up` up.
  Eigen::Vector3d position = Eigen::Vector3d::Zero(), look_at(0, 0, 0.5), up(0, -1, 0);
  if (top.has("camera")) {
    const Node n = top.child("camera");
    n.require_map({"position", "look_at", "up"});
    if (n.has("position")) position = n.child("position").vector(3, kMaxLength);
    if (n.has("look_at")) look_at = n.child("look_at").vector(3, kMaxLength);
    if (n.has("up")) up = n.child("up").vector(3, kMaxLength);
  }
  const Eigen::Vector3d z = look_at - position;
  if (z.norm() < 1e-6) top.child("camera").fail("look_at must differ from position");
  const Eigen::Vector3d zc = z.normalized();
  Eigen::Vector3d yc = -(up - up.dot(zc) * zc);
  if (yc.norm() < 1e-6) top.child("camera").fail("up must not be parallel to the viewing direction");
  yc.normalize();
  s.wMc_start.linear() << yc.cross(zc), yc, zc;
  s.wMc_start.translation() = position;

  if (!top.has("object")) top.fail("missing 'object'");
  s.bodies.push_back(body(top.child("object"), Role::Object, "object", base_dir));
  if (top.has("holder")) s.bodies.push_back(body(top.child("holder"), Role::Interacting, "holder", base_dir));
  if (top.has("occluders")) {
    const Node o = top.child("occluders");
    if (!o.is_sequence()) o.fail("expected a list of occluders");
    for (std::size_t i = 0; i < o.size(); ++i) {
      s.bodies.push_back(body(o.item(i), Role::Occluder, "occluder" + std::to_string(i), base_dir));
    }
  }
  if (top.has("table")) {
    const Node t = top.child("table");
    t.require_map({"position", "size", "colour"});
    Eigen::Vector3d size(1.2, 0.02, 1.0);
    Body table;
    table.name = "table";
    table.role = Role::Background;
    table.shape = "box";
    if (t.has("size")) size = t.child("size").vector(3, kMaxLength);
    if (!(size.array() > 0.0).all()) t.child("size").fail("expected positive sizes");
    table.mesh = make_box(size);
    table.colour = {0.55f, 0.42f, 0.3f};
    if (t.has("colour")) table.colour = colour(t.child("colour"));
    Waypoint w;
    w.position = t.has("position") ? Eigen::Vector3d(t.child("position").vector(3, kMaxLength)) : Eigen::Vector3d(0, 0.12, 0.6);
    table.motion.waypoints.push_back(w);
    s.bodies.push_back(table);
  }
  if (top.has("estimator")) {
    const Node e = top.child("estimator");
    if (!root["estimator"].IsMap()) e.fail("expected a map of estimator settings");
    for (const auto& item : root["estimator"]) {
      const std::string name = item.first.as<std::string>();
      const Node v = e.child(name);
      try {
        set_param(s.estimator, name, v.word({}));
      } catch (const std::invalid_argument& err) {
        v.fail(err.what());
      }
    }
    try {
      (void)s.estimator.resolve();
    } catch (const std::invalid_argument& err) {
      e.fail(err.what());
    }
  }
  if (top.has("robot")) s.robot = top.child("robot").word({"camera", "viper850", "afma6"});
  if (top.has("controller")) {
    const Node c = top.child("controller");
    c.require_map({"law", "gain", "max_linear_speed", "max_angular_speed", "target_filter"});
    if (c.has("law")) s.controller["law"] = c.child("law").word({"pbvs", "sphere"});
    if (c.has("gain")) s.controller["gain"] = std::to_string(c.child("gain").positive(kMaxGain));
    for (const char* k : {"max_linear_speed", "max_angular_speed"}) {
      if (c.has(k)) s.controller[k] = std::to_string(c.child(k).positive(kMaxSpeed));
    }
    if (c.has("target_filter")) s.controller["target_filter"] = std::to_string(c.child("target_filter").in_range(0.0, 10.0));
  }
  return s;
}

namespace {

// Splits a ':'-separated list of paths (from the build's compile definitions).
std::vector<fs::path> split_paths(const std::string& list) {
  std::vector<fs::path> paths;
  std::stringstream in(list);
  for (std::string p; std::getline(in, p, ':');) {
    if (!p.empty()) paths.emplace_back(p);
  }
  return paths;
}

// The folder of the file this code was loaded from: libofv_sim.so, or the
// program when ofv is linked statically. Empty if unknown.
fs::path loaded_from_dir() {
  static const char anchor = 0;  // any object of this library
  Dl_info info{};
  if (dladdr(&anchor, &info) == 0 || info.dli_fname == nullptr) {
    return {};
  }
  std::error_code ec;
  const fs::path file = fs::canonical(info.dli_fname, ec);
  return ec ? fs::path() : file.parent_path();
}

bool same_dir(const fs::path& a, const fs::path& b) {
  std::error_code ec;
  return fs::equivalent(a, b, ec) && !ec;
}

}  // namespace

// The installed prefix can move (a relocated install, the Debian package under
// /usr, a build configured for /usr/local): the library looks next to itself
// rather than at the path compiled in.
std::string builtin_scenario_dir() {
  // An explicit choice: OFV_DATA_DIR is share/ofv (OFV_SCENARIO_DIR, the
  // scenario folder itself, is kept for older set-ups).
  if (const char* env = std::getenv("OFV_DATA_DIR"); env != nullptr && *env != '\0') {
    return (fs::path(env) / "scenarios").string();
  }
  if (const char* env = std::getenv("OFV_SCENARIO_DIR"); env != nullptr && *env != '\0') return env;

  const fs::path here = loaded_from_dir();
  if (!here.empty()) {
    // Running from this build's output folders: the source tree's scenarios.
    for (const fs::path& out : split_paths(OFV_BUILD_OUTPUT_DIRS)) {
      if (same_dir(here, out) && fs::is_directory(OFV_SOURCE_SCENARIO_DIR)) return OFV_SOURCE_SCENARIO_DIR;
    }
    // Installed: PREFIX/lib/libofv_sim.so -> PREFIX/share/ofv/scenarios.
    for (const fs::path& rel : split_paths(OFV_RELATIVE_SCENARIO_DIRS)) {
      const fs::path dir = (here / rel).lexically_normal();
      if (fs::is_directory(dir)) return dir.string();
    }
  }
  return OFV_INSTALLED_SCENARIO_DIR;
}

std::vector<std::string> builtin_scenarios() {
  std::vector<std::string> names;
  if (fs::is_directory(builtin_scenario_dir())) {
    for (const auto& e : fs::directory_iterator(builtin_scenario_dir())) {
      if (e.path().extension() == ".yaml") names.push_back(e.path().stem().string());
    }
  }
  std::sort(names.begin(), names.end());
  return names;
}

Scenario with_seed(const Scenario& scenario, unsigned k) {
  Scenario s = scenario;
  s.seed = scenario.seed + k;
  if (k == 0) return s;
  std::mt19937_64 rng((static_cast<std::uint64_t>(scenario.seed) << 32) ^ (0x5DEECE66Dull * k));
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  for (Body& b : s.bodies) {
    if (b.role != Role::Occluder) continue;
    const double delay = s.variation.time * uniform(rng);
    Eigen::Vector3d shift;
    do {
      shift = Eigen::Vector3d(uniform(rng), uniform(rng), uniform(rng));
    } while (shift.squaredNorm() > 1.0);
    for (Waypoint& w : b.motion.waypoints) {
      w.t += delay;
      w.position += s.variation.position * shift;
    }
  }
  return s;
}

Scenario load_scenario(const std::string& path_or_name) {
  fs::path path = path_or_name;
  if (!fs::exists(path)) {
    const fs::path builtin = fs::path(builtin_scenario_dir()) / (path_or_name + ".yaml");
    if (!fs::exists(builtin)) {
      std::string list;
      for (const auto& n : builtin_scenarios()) list += (list.empty() ? "" : ", ") + n;
      throw std::invalid_argument(path_or_name + ": no such file or built-in scenario (built-in: " + list + ")");
    }
    path = builtin;
  }
  return scenario_from_yaml(read_text_file(path.string(), kMaxFileBytes, "scenario"), path.string());
}

}  // namespace ofv::sim
