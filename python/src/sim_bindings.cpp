// The simulator side of ofv._ofv: scenarios, closed-loop episodes (the
// files of `ofv simulate`), rendered frames (`ofv render`) and comparison
// sweeps (`ofv compare`). Everything long runs with the GIL released.
#include "convert.h"

#include "ofv/loop/compare.h"
#include "ofv/loop/episode.h"
#include "ofv/loop/episode_files.h"
#include "ofv/loop/episode_store.h"
#include "ofv/loop/frame_files.h"
#include "ofv/loop/grid.h"
#include "ofv/loop/reports.h"
#include "ofv/loop/scenario_set.h"
#include "ofv/loop/sweep.h"
#include "ofv/sim/renderer.h"
#include "ofv/sim/scenario.h"

#include <nlohmann/json.hpp>
#include <pybind11/stl.h>

#include <Eigen/Geometry>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>

namespace ofv::python {

namespace fs = std::filesystem;

namespace {

// --- arguments

sim::Scenario scenario_arg(const py::handle& obj) {
  if (py::isinstance<sim::Scenario>(obj)) return obj.cast<sim::Scenario>();
  if (py::isinstance<py::str>(obj) || py::hasattr(obj, "__fspath__")) return sim::load_scenario(path_arg(obj, "scenario"));
  throw py::type_error("scenario: expected a Scenario, a built-in scenario's name or a scenario file, got a " + type_name(obj));
}

py::array_t<double> pose_matrix(const Eigen::Isometry3d& wMc) { return matrix_to_numpy(Eigen::MatrixXd(wMc.matrix())); }

py::dict intrinsics_dict(const CameraIntrinsics& k) {
  py::dict d;
  d["width"] = k.width;
  d["height"] = k.height;
  d["fx"] = k.fx;
  d["fy"] = k.fy;
  d["cx"] = k.cx;
  d["cy"] = k.cy;
  return d;
}

// --- trajectory.csv's columns, from the functions that write it (metrics.h)

struct TrajectoryColumns {
  std::vector<std::string> names;
  std::vector<bool> numeric;
};

const TrajectoryColumns& trajectory_columns() {
  static const TrajectoryColumns c = [] {
    TrajectoryColumns out;
    out.names = split(trajectory_csv_header(), ',');
    // A column is a number (an empty field: none) unless a record writes a
    // word there (status, safety: None writes nothing, so a record with an
    // action; pose_status: the simulator's pose writes nothing, so a record with one).
    StepRecord words;
    words.safety = servo::SafetyAction::SpeedLimit;
    words.pose.emplace().status = "ok";
    for (const auto& field : split(trajectory_csv_row(words), ',')) out.numeric.push_back(numeric_field(field));
    if (out.names.size() != out.numeric.size()) throw std::logic_error("trajectory.csv: header and row differ in length");
    return out;
  }();
  return c;
}

py::dict step_dict(const StepRecord& rec) {
  const auto& c = trajectory_columns();
  const auto fields = split(trajectory_csv_row(rec), ',');
  py::dict out;
  for (std::size_t k = 0; k < c.names.size(); ++k) {
    if (!c.numeric[k]) {
      out[py::str(c.names[k])] = fields[k];
    } else {
      out[py::str(c.names[k])] = fields[k].empty() ? std::nan("") : std::strtod(fields[k].c_str(), nullptr);
    }
  }
  return out;
}

// --- a scratch folder for an episode's files when the caller wants none

struct ScratchDir {
  fs::path path;
  ScratchDir() {
    std::string pattern = (fs::temp_directory_path() / "ofv-python-XXXXXX").string();
    if (mkdtemp(pattern.data()) == nullptr) throw std::runtime_error(pattern + ": cannot create a temporary folder");
    path = pattern;
  }
  ~ScratchDir() {
    std::error_code ignored;
    fs::remove_all(path, ignored);
  }
  ScratchDir(const ScratchDir&) = delete;
  ScratchDir& operator=(const ScratchDir&) = delete;
};

// Thrown through run_episode when the Python callback raised (or Ctrl-C):
// the Python error is kept and raised once the GIL is back.
struct CallbackAborted {};

struct Episode {
  py::dict settings;  ///< every setting of the episode, resolved
  py::object metrics;
  py::dict trajectory;
  std::string out;                 ///< the folder of the files, '' when none were kept
  std::vector<std::string> files;  ///< the files written there
};

Episode simulate(const py::object& scenario_obj, const py::object& out, bool pictures, bool video,
                 const py::object& record, const py::object& callback, const py::kwargs& kw) {
  const sim::Scenario scenario = scenario_arg(scenario_obj);
  const EpisodeSetup setup = resolve_episode(scenario, settings_pairs(kw));
  EpisodeFiles files;
  files.pictures = pictures;
  files.video = video;
  if (!record.is_none()) files.record_dir = path_arg(record, "record");
  if (out.is_none() && (pictures || video)) {
    throw py::value_error("pictures and video are written into out: give out=FOLDER");
  }
  std::unique_ptr<ScratchDir> scratch;
  std::string dir;
  if (out.is_none()) {
    scratch = std::make_unique<ScratchDir>();
    dir = scratch->path.string();
  } else {
    dir = path_arg(out, "out");
  }
  const bool has_callback = !callback.is_none();
  if (has_callback && !PyCallable_Check(callback.ptr())) {
    throw py::type_error("callback: expected a callable, got a " + type_name(callback));
  }
  // Ctrl-C reaches Python only in the main thread: there the episode looks
  // for it every 0.2 s of wall time (one GIL acquisition).
  const auto threading = py::module_::import("threading");
  const bool main_thread = threading.attr("current_thread")().is(threading.attr("main_thread")());
  (void)trajectory_columns();

  std::optional<py::error_already_set> error;
  EpisodeOutcome outcome;
  std::vector<std::string> written;
  bool aborted = false;
  {
    py::gil_scoped_release release;
    try {
      EpisodeWriter writer(dir, setup, files);
      auto next_check = std::chrono::steady_clock::now();
      outcome = run_episode(setup, [&](const StepRecord& rec, const StepDetail& detail) {
        writer.observe(rec, detail);
        const auto now = std::chrono::steady_clock::now();
        const bool check_signals = main_thread && now >= next_check;
        if (!has_callback && !check_signals) return;
        py::gil_scoped_acquire gil;
        try {
          if (check_signals) {
            next_check = now + std::chrono::milliseconds(200);
            if (PyErr_CheckSignals() != 0) throw py::error_already_set();
          }
          if (has_callback) (void)callback(step_dict(rec));
        } catch (py::error_already_set& e) {
          error.emplace(std::move(e));
          throw CallbackAborted{};
        }
      });
      written = writer.finish(outcome);
    } catch (const CallbackAborted&) {
      aborted = true;
    }
  }
  if (aborted) throw *error;

  Episode result;
  result.settings = typed_values(episode_settings_table(), setup);
  {
    std::ifstream in(fs::path(dir) / "metrics.json", std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    if (!in) throw std::runtime_error((fs::path(dir) / "metrics.json").string() + ": cannot read");
    result.metrics = json_to_python(nlohmann::ordered_json::parse(text.str()));
  }
  std::vector<std::string> rows;
  rows.reserve(outcome.steps.size());
  for (const auto& s : outcome.steps) rows.push_back(trajectory_csv_row(s));
  const auto& c = trajectory_columns();
  result.trajectory = csv_columns(c.names, c.numeric, rows);
  if (!scratch) {
    result.out = dir;
    result.files = written;
  }
  return result;
}

// --- render

struct Frame {
  py::array depth;
  py::array colour;
  py::array labels;
  py::array_t<double> wMc;
  py::dict intrinsics;
  double time = 0.0;
  double max_depth = 0.0;
  double visible_fraction = 0.0;
  int occluders_in_sphere = 0;
  int occluders_in_view = 0;
  std::vector<std::string> files;
};

Eigen::Isometry3d pose_arg(const py::handle& pose) {
  // Embree aborts on non-finite rays: every value finite, positions within 1 km (as `ofv render --pose`).
  auto check = [](const Eigen::MatrixXd& values) {
    for (Eigen::Index i = 0; i < values.size(); ++i) {
      if (!(std::abs(values(i)) <= 1e3)) {
        throw py::value_error("pose: value " + std::to_string(i + 1) + " is " + format_number(values(i)) +
                              ", expected a finite number in [-1000, 1000]");
      }
    }
  };
  Eigen::Isometry3d wMc = Eigen::Isometry3d::Identity();
  const bool matrix = (py::isinstance<py::array>(pose) && py::reinterpret_borrow<py::array>(pose).ndim() == 2) ||
                      ((py::isinstance<py::list>(pose) || py::isinstance<py::tuple>(pose)) && py::len(pose) == 4);
  if (matrix) {
    const Eigen::MatrixXd M = matrix_from_python(pose, "pose", 4, 4);
    check(M);
    const Eigen::Matrix3d R = M.topLeftCorner<3, 3>();
    if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0.0 ||
        !M.row(3).isApprox(Eigen::RowVector4d(0, 0, 0, 1))) {
      throw py::value_error("pose: expected a homogeneous transform wMc (a rotation and a translation, last row 0 0 0 1)");
    }
    wMc.linear() = R;
    wMc.translation() = M.topRightCorner<3, 1>();
    return wMc;
  }
  const Eigen::VectorXd p = vector_from_python(pose, "pose", 6);
  check(p);
  const Eigen::Vector3d tu = p.tail<3>();
  if (tu.norm() > 0.0) wMc.linear() = Eigen::AngleAxisd(tu.norm(), tu.normalized()).toRotationMatrix();
  wMc.translation() = p.head<3>();
  return wMc;
}

Frame render(const py::object& scenario_obj, const py::object& time_obj, const py::object& pose, const py::object& size,
             bool noise, const py::object& out) {
  const sim::Scenario scenario = scenario_arg(scenario_obj);
  const double time = number_arg(time_obj, "time", 0.0, 3600.0);
  CameraIntrinsics k = scenario.sensor.intrinsics;
  if (!size.is_none()) {
    if (!py::isinstance<py::tuple>(size) && !py::isinstance<py::list>(size)) {
      throw py::type_error("size: expected (width, height)");
    }
    const auto wh = py::reinterpret_borrow<py::sequence>(size);
    if (py::len(wh) != 2) throw py::value_error("size: expected (width, height), got " + py::repr(size).cast<std::string>());
    const long long w = integer_arg(wh[0], "size: the width", 8, 4096);
    const long long h = integer_arg(wh[1], "size: the height", 8, 4096);
    k.fx *= static_cast<double>(w) / k.width;
    k.fy *= static_cast<double>(h) / k.height;
    k.cx *= static_cast<double>(w) / k.width;
    k.cy *= static_cast<double>(h) / k.height;
    k.width = static_cast<int>(w);
    k.height = static_cast<int>(h);
  }
  const Eigen::Isometry3d wMc = pose.is_none() ? scenario.wMc_start : pose_arg(pose);
  const std::string dir = out.is_none() ? std::string() : path_arg(out, "out");

  sim::RenderedFrame r;
  sim::ObjectTruth truth;
  Frame f;
  {
    py::gil_scoped_release release;
    sim::Renderer renderer(scenario);
    renderer.set_time(time);
    const long frame_index = std::lround(time * scenario.rate);  // the noise of the episode's frame there
    r = renderer.render(wMc, frame_index, k, noise);
    truth = renderer.truth(wMc, scenario.r_sphere());
    if (!dir.empty()) f.files = write_frame_pictures(dir, r, scenario.sensor.max_depth);
  }
  const auto h = static_cast<py::ssize_t>(k.height);
  const auto w = static_cast<py::ssize_t>(k.width);
  py::array_t<float> depth({h, w});
  std::copy(r.frame.depth.begin(), r.frame.depth.end(), depth.mutable_data());
  py::array_t<std::uint8_t> colour({h, w, py::ssize_t{3}});
  std::copy(r.frame.rgb.begin(), r.frame.rgb.end(), colour.mutable_data());
  py::array_t<std::uint16_t> labels({h, w});
  std::copy(r.frame.labels.begin(), r.frame.labels.end(), labels.mutable_data());
  f.depth = depth;
  f.colour = colour;
  f.labels = labels;
  f.wMc = pose_matrix(wMc);
  f.intrinsics = intrinsics_dict(k);
  f.time = time;
  f.max_depth = scenario.sensor.max_depth;
  f.visible_fraction = truth.visible_fraction;
  f.occluders_in_sphere = truth.occluders_in_sphere;
  f.occluders_in_view = sim::occluders_seen(r.frame.labels);
  return f;
}

// --- compare: `ofv compare` without the printing

py::dict compare(const py::object& scenarios, const py::object& grid_obj, const py::object& out_obj,
                 const py::object& seeds, const py::object& jobs, const py::object& shard_text, bool plots) {
  std::vector<std::string> args;
  if (py::isinstance<py::str>(scenarios) || py::hasattr(scenarios, "__fspath__")) {
    args.push_back(path_arg(scenarios, "scenarios"));
  } else {
    for (const auto& s : scenarios) args.push_back(path_arg(s, "scenarios"));
  }
  if (args.empty()) throw py::value_error("scenarios: expected at least one scenario");
  const std::string out = path_arg(out_obj, "out");
  auto int_arg = [](const py::object& v, const std::string& name, int hi) -> std::optional<int> {
    if (v.is_none()) return std::nullopt;
    return static_cast<int>(integer_arg(v, name, 1, hi));
  };
  const auto n_seeds = int_arg(seeds, "seeds", kMaxSeeds);
  const auto n_jobs = int_arg(jobs, "jobs", kMaxJobs);
  Grid grid;
  std::string source;
  if (py::isinstance<py::dict>(grid_obj)) {
    // JSON is YAML: the grid of docs/compare.md as Python dicts and lists.
    source = "grid";
    grid = grid_from_yaml(text_arg(py::module_::import("json").attr("dumps")(grid_obj), source), source);
  } else {
    source = path_arg(grid_obj, "grid");
    grid = read_grid(source);
  }
  if (n_seeds) grid.seeds = *n_seeds;
  const auto set = scenario_set(args);
  try {
    check_sweep_size(set.size(), grid.variants.size(), grid.seeds);
  } catch (const std::invalid_argument& e) {
    throw std::invalid_argument(source + (n_seeds ? " with seeds: " : ": ") + e.what());
  }
  check_grid(set, grid, source);
  const auto plan = plan_episodes(set, grid);
  Shard part;
  if (!shard_text.is_none()) part = parse_shard(text_arg(shard_text, "shard"));
  SweepOptions options;
  options.jobs = n_jobs.value_or(0);
  options.part = part;
  const std::size_t mine = shard(plan, part.k, part.n).size();
  int ran = 0;
  {
    py::gil_scoped_release release;
    ran = run_sweep(plan, simulation_runner(), out, options);
    const auto rows = load_episodes({out});
    if (plots) {
      (void)write_reports(rows, out);
    } else {
      write_tables(rows, out);
    }
  }
  py::dict d;
  d["planned"] = plan.size();
  d["episodes"] = mine;
  d["ran"] = ran;
  d["resumed"] = mine - static_cast<std::size_t>(ran);
  d["out"] = out;
  return d;
}

}  // namespace

void bind_simulation(py::module_& m) {
  const py::metaclass meta = constructed_only(m);
  m.attr("LABEL_NONE") = static_cast<int>(sim::kLabelNone);
  m.attr("LABEL_OBJECT") = static_cast<int>(sim::kLabelObject);
  m.attr("LABEL_INTERACTING") = static_cast<int>(sim::kLabelInteracting);
  m.attr("LABEL_BACKGROUND") = static_cast<int>(sim::kLabelBackground);
  m.attr("LABEL_OCCLUDER0") = static_cast<int>(sim::kLabelOccluder0);

  py::class_<sim::Scenario> scenario(m, "Scenario",
                            "A simulated world (docs/scenarios.md): object, occluders and their motion, sensor, camera\n"
                            "start, and the scenario's own settings. load_scenario() reads one.", meta);
  refuse_bare_new(scenario);
  scenario
      .def_readonly("name", &sim::Scenario::name, "file stem, e.g. 'dvd-one-hand'")
      .def_readonly("path", &sim::Scenario::path, "the file it came from")
      .def_readonly("duration", &sim::Scenario::duration, "episode length [s]")
      .def_readonly("rate", &sim::Scenario::rate, "sensor rate [Hz]")
      .def_readonly("seed", &sim::Scenario::seed, "sensor noise seed")
      .def_readonly("robot", &sim::Scenario::robot, "camera, viper850 or afma6")
      .def_property_readonly("r_sphere", &sim::Scenario::r_sphere, "radius of the solution sphere [m]")
      .def_property_readonly("r_seed", &sim::Scenario::r_seed, "supervoxel seed resolution [m]")
      .def_property_readonly("estimator", [](const sim::Scenario& s) { return s.estimator; },
                             "the scenario's EstimatorSettings (a copy)")
      .def_property_readonly("controller", [](const sim::Scenario& s) { return s.controller; },
                             "the scenario's controller section, name -> value text")
      .def_property_readonly("intrinsics", [](const sim::Scenario& s) { return intrinsics_dict(s.sensor.intrinsics); },
                             "the sensor's width, height [px], fx, fy, cx, cy [px]")
      .def_property_readonly("max_depth", [](const sim::Scenario& s) { return s.sensor.max_depth; }, "sensor range [m]")
      .def_property_readonly("wMc_start", [](const sim::Scenario& s) { return pose_matrix(s.wMc_start); },
                             "camera start pose, 4 x 4 homogeneous (camera to world)")
      .def_property_readonly("bodies", [](const sim::Scenario& s) {
            std::vector<std::string> names;
            for (const auto& b : s.bodies) names.push_back(b.name);
            return names;
          }, "names of the bodies, the object first")
      .def("with_seed", [](const sim::Scenario& s, const py::object& k) {
            return sim::with_seed(s, static_cast<unsigned>(integer_arg(k, "k", 0, 1000000000)));  // the range of the setting seed
          }, py::arg("k"),
           "The scenario's k-th random world (0: as written), as `--seed k`.")
      .def_static("from_yaml", [](const py::object& text, const py::object& source) {
            return sim::scenario_from_yaml(text_arg(text, "text"), text_arg(source, "source"));
          }, py::arg("text"), py::arg("source") = "<string>",
                  "Parses a scenario from YAML text; `source` names it in errors.")
      .def("__repr__", [](const sim::Scenario& s) {
        return "Scenario('" + s.name + "', " + format_number(s.duration) + " s at " + format_number(s.rate) + " Hz, " +
               std::to_string(s.bodies.size()) + " bodies)";
      });

  m.def("load_scenario", [](const py::object& name_or_path) { return sim::load_scenario(path_arg(name_or_path, "scenario")); },
        py::arg("name_or_path"),
        "Loads a scenario file (YAML, docs/scenarios.md) or a built-in scenario by name (builtin_scenarios()).\n"
        "Raises ValueError naming the file, the key and the value.");
  m.def("builtin_scenarios", &sim::builtin_scenarios, "Names of the built-in scenarios, sorted.");
  m.def("episode_settings", [] { return docs_to_python(episode_settings_table().docs()); },
        "Every setting of an episode (simulate()'s keywords, `ofv simulate --set`): a list of dicts with name,\n"
        "type, default, unit and doc.");

  py::class_<Episode> episode(m, "Episode", "A closed-loop episode's results, as `ofv simulate` writes them.", meta);
  refuse_bare_new(episode);
  episode
      .def_readonly("settings", &Episode::settings,
                    "every setting the episode ran with, resolved (the scenario's, then the keywords), by the\n"
                    "names of episode_settings(): simulate(scenario, **episode.settings) runs it again")
      .def_readonly("metrics", &Episode::metrics, "metrics.json as a dict (same keys and values)")
      .def_readonly("trajectory", &Episode::trajectory,
                    "trajectory.csv as a dict of numpy columns (same names and values; float64, NaN for an empty\n"
                    "field, str for status and safety): pandas.DataFrame(episode.trajectory) reads it")
      .def_readonly("out", &Episode::out, "the folder of the episode's files ('' when out was None)")
      .def_readonly("files", &Episode::files, "the files written there")
      .def("__repr__", [](const Episode& e) {
        return "Episode(" + std::to_string(py::len(e.trajectory[py::str("time")])) + " steps" +
               (e.out.empty() ? "" : ", files in " + e.out) + ")";
      });

  static const std::string simulate_doc = std::string(R"(Runs one closed-loop episode, as `ofv simulate` (ofv::resolve_episode, ofv::run_episode).

scenario: a Scenario, a built-in scenario's name or a scenario file. **settings: every
setting of episode_settings() by name, applied after the scenario's own, in the order
given, e.g. duration=0.5, perception='ground-truth', robot='viper850', seed=1, gain=2.
out: a folder for trajectory.csv and metrics.json (then pictures=True: the PNG
pictures, video=True: episode.avi); None keeps no files. record: a folder for the
frames as a TUM RGB-D recording (`ofv simulate --record`).
callback(step): called after every step with the step's trajectory.csv row as a dict;
the GIL is taken only for it. An exception it raises ends the episode and propagates
(so does Ctrl-C in the main thread).

Returns an Episode: metrics (dict, the keys of metrics.json) and trajectory (dict of
numpy columns, those of trajectory.csv). Raises ValueError on a bad setting (the
message of `ofv simulate`), RuntimeError when the episode cannot run. The GIL is
released while it runs: Python threads can run episodes in parallel.

)") + settings_help(episode_settings_table().docs());
  m.def("simulate", &simulate, py::arg("scenario"), py::kw_only(), py::arg("out") = py::none(),
        py::arg("pictures") = false, py::arg("video") = false, py::arg("record") = py::none(),
        py::arg("callback") = py::none(), simulate_doc.c_str());

  py::class_<Frame> frame(m, "Frame", "One rendered RGB-D frame (ViSP's camera frame: X right, Y down, Z forward).", meta);
  refuse_bare_new(frame);
  frame
      .def_readonly("depth", &Frame::depth, "(H, W) float32 Z depth [m]; 0 or NaN where missing")
      .def_readonly("colour", &Frame::colour, "(H, W, 3) uint8 RGB")
      .def_readonly("labels", &Frame::labels,
                    "(H, W) uint16: LABEL_NONE, LABEL_OBJECT, LABEL_INTERACTING, LABEL_BACKGROUND, LABEL_OCCLUDER0 + k")
      .def_readonly("wMc", &Frame::wMc, "camera pose, 4 x 4 homogeneous (camera to world)")
      .def_readonly("intrinsics", &Frame::intrinsics, "width, height, fx, fy, cx, cy [px]")
      .def_readonly("time", &Frame::time, "simulated time [s]")
      .def_readonly("max_depth", &Frame::max_depth, "the sensor's range [m]")
      .def_readonly("visible_fraction", &Frame::visible_fraction, "ground truth: fraction of the object's surface seen")
      .def_readonly("occluders_in_sphere", &Frame::occluders_in_sphere, "ground truth: occluders within r_sphere of the object")
      .def_readonly("occluders_in_view", &Frame::occluders_in_view, "ground truth: occluders the sensor sees")
      .def_readonly("files", &Frame::files, "PNG files written (when out was given)")
      .def("__repr__", [](const Frame& f) {
        return "Frame(" + std::to_string(f.depth.shape(1)) + "x" + std::to_string(f.depth.shape(0)) + " at t=" +
               format_number(f.time) + " s, visible fraction " + format_number(f.visible_fraction) + ")";
      });
  m.def("render", &render, py::arg("scenario"), py::arg("time"), py::arg("pose") = py::none(), py::kw_only(),
        py::arg("size") = py::none(), py::arg("noise") = true, py::arg("out") = py::none(),
        R"(Renders one simulated frame, as `ofv render` (sim::Renderer, Embree).

scenario: a Scenario, a built-in name or a file; time [s] in [0, 3600]. pose: the
camera pose wMc, as a 4 x 4 homogeneous matrix or (x, y, z, tux, tuy, tuz) (metres,
theta-u radians, as `--pose`); None: the scenario's start. size: (width, height), the
intrinsics scaled (default: the scenario's sensor). noise: the sensor noise, drawn as
for the episode's frame at that time. out: also write colour.png, depth.png and
labels.png there. Returns a Frame (depth, colour, labels as numpy arrays, and the
ground truth). The GIL is released while it renders.)");

  m.def("_compare", &compare, py::arg("scenarios"), py::arg("grid"), py::arg("out"), py::arg("seeds") = py::none(),
        py::arg("jobs") = py::none(), py::arg("shard") = py::none(), py::arg("plots") = true,
        "The sweep of `ofv compare` into `out` (see ofv.compare, which also reads its tables).");
}

}  // namespace ofv::python
