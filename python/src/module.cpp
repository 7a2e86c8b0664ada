// The Python module ofv._ofv: the estimator, its settings and scene files
// (this file), and the simulator side (sim_bindings.cpp). The package
// python/ofv/__init__.py re-exports it.
#include "convert.h"

#include "ofv/estimator.h"
#include "ofv/estimator_settings.h"
#include "ofv/io/scene_json.h"
#include "ofv/version.h"

#include <nlohmann/json.hpp>
#include <pybind11/stl.h>

#include <cstring>
#include <fstream>
#include <sstream>
#include <stdexcept>

namespace ofv::python {

namespace {

// --- EstimatorSettings: ofv::EstimatorParams (a preset plus explicit values),
// every attribute a row of estimator_settings_table(): read with the row's
// getter (the resolved value, the preset's where none was given), written
// with its setter.

const SettingsTable<EstimatorParams>::Row& row_named(const std::string& name) {
  for (const auto& row : estimator_settings_table().rows()) {
    if (row.doc.name == name) return row;
  }
  throw std::invalid_argument("unknown parameter '" + name + "'");
}

py::object get_setting(const EstimatorParams& p, const std::string& name) {
  const auto& row = row_named(name);
  return typed_value(row.doc, row.get(p));
}

// Sets one setting through the table, then checks the ranges (resolve(), spec
// §7) as `ofv estimate` does; on an error the settings are left unchanged.
void set_setting(EstimatorParams& p, const std::string& name, const py::handle& value) {
  EstimatorParams changed = p;
  estimator_settings_table().set(changed, name, setting_text(name, value));
  (void)changed.resolve();
  p = changed;
}

void apply_settings(EstimatorParams& p, const py::dict& settings) {
  for (const auto& [key, value] : settings) set_setting(p, text_arg(key, "setting name"), value);
}

// `settings=`: None (the defaults), an EstimatorSettings (copied) or a dict of settings by name.
EstimatorParams params_arg(const py::handle& base) {
  if (base.is_none()) return {};
  if (py::isinstance<EstimatorParams>(base)) return base.cast<EstimatorParams>();
  if (py::isinstance<py::dict>(base)) {
    EstimatorParams p;
    apply_settings(p, py::reinterpret_borrow<py::dict>(base));
    return p;
  }
  throw py::type_error("settings: expected an ofv.EstimatorSettings or a dict, got a " + type_name(base));
}

py::dict settings_dict(const EstimatorParams& p) { return typed_values(estimator_settings_table(), p); }

// --- Scene: a scene file of `ofv estimate` (scene_json.h) and where it came from.

struct PyScene {
  Scene scene;
  std::string source;  ///< the file it was read from, named in errors; empty when built in Python
};

std::optional<Eigen::Vector3d> optional_point(const py::handle& obj, const std::string& name) {
  if (obj.is_none()) return std::nullopt;
  return Eigen::Vector3d(vector_from_python(obj, name, 3));
}

std::optional<Eigen::Matrix3d> optional_axes(const py::handle& obj) {
  if (obj.is_none()) return std::nullopt;
  return Eigen::Matrix3d(matrix_from_python(obj, "axes", 3, 3).transpose());  // rows e1, e2, e3 -> columns
}

py::object point_or_none(const std::optional<Eigen::Vector3d>& v) {
  if (!v) return py::none();
  return vector_to_numpy(*v);
}

ViewProblem make_problem(const py::handle& positions, const py::handle& normals, const py::handle& occluders,
                         const py::handle& centroid, const py::handle& axes, const py::handle& camera,
                         const py::handle& previous_view) {
  ViewProblem pb;
  pb.positions = points_from_python(positions, "positions");
  pb.normals = points_from_python(normals, "normals");
  pb.occluders = occluders.is_none() ? Eigen::Matrix3Xd(3, 0) : points_from_python(occluders, "occluders");
  if (pb.positions.cols() != pb.normals.cols()) {
    throw py::value_error("normals: expected one normal per position (" + std::to_string(pb.positions.cols()) +
                          "), got " + std::to_string(pb.normals.cols()));
  }
  pb.centroid = optional_point(centroid, "centroid");
  pb.axes = optional_axes(axes);
  pb.camera = optional_point(camera, "camera");
  pb.previous_view = optional_point(previous_view, "previous_view");
  return pb;
}

// The estimate with the GIL released; errors prefixed with the scene's file as `ofv estimate` does.
ViewEstimate run_estimate(const ViewProblem& problem, const EstimatorParams& params, bool record_path,
                          const std::string& source) {
  py::gil_scoped_release release;
  try {
    EstimateOptions options;
    options.record_path = record_path;
    return estimate_view(problem, params.resolve(), options);
  } catch (const std::invalid_argument& e) {
    if (source.empty()) throw;
    throw std::invalid_argument(source + ": " + e.what());
  }
}

// The scene as `ofv estimate` reads it. A setting scene_to_json() leaves out
// (time_budget) is added from its value, so that saving never loses one.
nlohmann::ordered_json scene_json(const Scene& scene) {
  const auto& pb = scene.problem;
  if (pb.positions.cols() != pb.normals.cols()) {
    throw py::value_error("normals: expected one normal per position (" + std::to_string(pb.positions.cols()) +
                          "), got " + std::to_string(pb.normals.cols()));
  }
  return scene_to_json(scene);
}

std::string settings_class_doc() {
  return "Settings of the occlusion-free view estimator (ESTIMATOR-SPEC.md), by the names of\n"
         "`ofv settings`, scene files' \"params\" and `--set`: a preset plus explicit values.\n\n"
         "EstimatorSettings(**settings) sets them in the order given, as `--set` does (a length\n"
         "given as 'r_seed' or 'r_sphere' takes that radius as set so far). Reading an attribute\n"
         "gives the value in force (the preset's when none was given). Values are checked as\n"
         "`ofv estimate` checks them; a bad one raises ValueError with the same message and\n"
         "leaves the settings unchanged.\n\n" +
         settings_help(estimator_settings_table().docs());
}

}  // namespace

// An enum pickles as its class called with its value (not through __new__, which refuse_bare_new() guards).
template <class Enum>
void finish_enum(py::enum_<Enum>& e) {
  e.def("__reduce__", [](const py::object& self) { return py::make_tuple(py::type::of(self), py::make_tuple(py::int_(self))); });
  refuse_bare_new(e);
}

void bind_estimator(py::module_& m) {
  const py::metaclass meta = constructed_only(m);

  py::enum_<ViewStatus> status(m, "ViewStatus",
                               "Outcome of one estimate (spec §4, §8); a member's name is its word in "
                               "`ofv estimate`'s JSON ('converged', ...).", meta);
  for (auto v : {ViewStatus::Converged, ViewStatus::NotConverged, ViewStatus::OutOfTime, ViewStatus::NoOccluders,
                 ViewStatus::NoSupervoxels}) {
    status.value(to_string(v), v);
  }
  finish_enum(status);
  py::enum_<InitialViewUsed> used(m, "InitialViewUsed",
                                  "Which rule produced t0 after the spec's fallbacks (spec §2); the name is its word.", meta);
  for (auto v : {InitialViewUsed::SphericalMean, InitialViewUsed::VectorMean, InitialViewUsed::Camera}) {
    used.value(to_string(v), v);
  }
  finish_enum(used);

  py::class_<AngularErrorStats> stats(m, "AngularErrorStats", "Mean and population standard deviation of an angular error (eq. 9) [deg].", meta);
  refuse_bare_new(stats);
  stats
      .def_readonly("mean", &AngularErrorStats::mean, "mean [deg]")
      .def_readonly("std", &AngularErrorStats::std, "population standard deviation [deg]")
      .def("__repr__", [](const AngularErrorStats& a) {
        return "AngularErrorStats(mean=" + format_number(a.mean) + ", std=" + format_number(a.std) + ")";
      });

  // --- EstimatorSettings
  py::class_<EstimatorParams> settings(m, "EstimatorSettings", settings_class_doc().c_str(), meta);
  refuse_bare_new(settings);
  settings.def(py::init([](const py::kwargs& kw) {
                 EstimatorParams p;
                 apply_settings(p, kw);
                 return p;
               }),
               "EstimatorSettings(**settings): the defaults (preset 'paper'), then each setting in the order given.");
  for (const auto& row : estimator_settings_table().rows()) {
    const std::string name = row.doc.name;
    const std::string doc = row.doc.doc + " (" + row.doc.type + ", default " + row.doc.default_value +
                            (row.doc.unit.empty() ? "" : " " + row.doc.unit) + ")";
    settings.def_property(
        name.c_str(), [name](const EstimatorParams& p) { return get_setting(p, name); },
        [name](EstimatorParams& p, const py::object& v) { set_setting(p, name, v); }, doc.c_str());
  }
  settings
      .def("to_dict", &settings_dict, "Every setting's value in force, by name, in the table's order.")
      .def("set", [](EstimatorParams& p, const py::kwargs& kw) { apply_settings(p, kw); },
           "Sets settings by name, in the order given (as attributes do).")
      .def("copy", [](const EstimatorParams& p) { return p; }, "An independent copy.")
      .def("__copy__", [](const EstimatorParams& p) { return p; })
      .def("__deepcopy__", [](const EstimatorParams& p, const py::dict&) { return p; })
      .def("__eq__", [](const EstimatorParams& a, const py::object& b) -> py::object {
        if (!py::isinstance<EstimatorParams>(b)) return py::reinterpret_borrow<py::object>(Py_NotImplemented);
        return py::bool_(settings_dict(a).equal(settings_dict(b.cast<EstimatorParams>())));
      })
      .def("__repr__", [](const EstimatorParams& p) {
        std::string out = "EstimatorSettings(";
        bool first = true;
        for (const auto& [key, value] : settings_dict(p)) {
          out += (first ? "" : ", ") + py::str(key).cast<std::string>() + "=" + py::repr(value).cast<std::string>();
          first = false;
        }
        return out + ")";
      })
      .def_static("docs", [] { return docs_to_python(estimator_settings_table().docs()); },
                  "Every setting: a list of dicts with name, type, default, unit and doc (as `ofv settings`).")
      // Pickled as EstimatorSettings() and then every setting as an
      // attribute, in the table's order (pickle's "slot state").
      .def("__reduce__", [](const py::object& self) {
        return py::make_tuple(py::type::of(self), py::tuple(), py::make_tuple(py::none(), settings_dict(self.cast<EstimatorParams>())));
      });
  settings.attr("__hash__") = py::none();

  // --- ViewEstimate
  py::class_<ViewEstimate> estimate(m, "ViewEstimate",
                           "The estimator's result for one frame (spec §8), world frame, metres. Points are float64\n"
                           "arrays of shape (3,); axes and path have one point per row.", meta);
  refuse_bare_new(estimate);
  estimate
      .def_property_readonly("t0", [](const ViewEstimate& e) { return vector_to_numpy(e.t0); }, "initial (occlusion-blind) view t0 [m]")
      .def_property_readonly("tf", [](const ViewEstimate& e) { return vector_to_numpy(e.tf); }, "final (occlusion-free) view t_f [m]")
      .def_readonly("status", &ViewEstimate::status, "ViewStatus: converged, not_converged, out_of_time, no_occluders, no_supervoxels")
      .def_property_readonly("is_free", [](const ViewEstimate& e) { return is_free(e.status); },
                             "True when t_f is free of occlusion (converged or no occluders)")
      .def_readonly("iterations", &ViewEstimate::iterations, "push steps taken (0 when the start is clear)")
      .def_readonly("initial_view_used", &ViewEstimate::initial_view_used, "InitialViewUsed: the rule that gave t0")
      .def_readonly("skipped_supervoxels", &ViewEstimate::skipped_supervoxels, "non-finite, zero normal, or at/outside the sphere")
      .def_readonly("skipped_occluders", &ViewEstimate::skipped_occluders, "non-finite occluders")
      .def_readonly("error_t0", &ViewEstimate::error_t0, "AngularErrorStats of t0 (eq. 9), or None when no supervoxel is left")
      .def_readonly("error_tf", &ViewEstimate::error_tf, "AngularErrorStats of t_f (eq. 9), or None when no supervoxel is left")
      .def_property_readonly("centroid", [](const ViewEstimate& e) { return vector_to_numpy(e.centroid); }, "object centroid C used [m]")
      .def_property_readonly("axes", [](const ViewEstimate& e) { return matrix_to_numpy(Eigen::MatrixXd(e.axes.transpose())); },
                             "object axes used, shape (3, 3): axes[k] is e_(k+1)")
      .def_readonly("axes_from_world", &ViewEstimate::axes_from_world, "PCA could not determine e1: the world axes stood in")
      .def_readonly("tf_to_t0_deg", &ViewEstimate::tf_to_t0_deg, "angle between t_f and t0 seen from C [deg]")
      .def_readonly("occlusion_points", &ViewEstimate::occlusion_points, "N_C: occlusion-to-sphere points used")
      .def_readonly("clearance_points", &ViewEstimate::clearance_points, "projected points within `clearance` of t_f")
      .def_property_readonly("path", [](const ViewEstimate& e) {
            Eigen::MatrixXd p(static_cast<Eigen::Index>(e.path.size()), 3);
            for (std::size_t k = 0; k < e.path.size(); ++k) p.row(static_cast<Eigen::Index>(k)) = e.path[k].transpose();
            return matrix_to_numpy(p);
          }, "every visited iterate, start first, shape (K, 3) (K = 0 unless record_path=True)")
      .def("to_dict", [](const ViewEstimate& e) { return json_to_python(estimate_to_json(e)); },
           "The result as `ofv estimate` prints it (the same JSON object, as Python dicts and lists).")
      .def("__repr__", [](const ViewEstimate& e) {
        std::ostringstream out;
        out.precision(6);
        out << "ViewEstimate(status=" << to_string(e.status) << ", iterations=" << e.iterations << ", t0=["
            << e.t0.x() << ", " << e.t0.y() << ", " << e.t0.z() << "], tf=[" << e.tf.x() << ", " << e.tf.y() << ", "
            << e.tf.z() << "])";
        return out.str();
      });

  // --- estimate_view
  m.def(
      "estimate_view",
      [](const py::object& positions, const py::object& normals, const py::object& occluders, const py::object& centroid,
         const py::object& axes, const py::object& camera, const py::object& previous_view, const py::object& base,
         bool record_path, const py::kwargs& kw) {
        const ViewProblem problem = make_problem(positions, normals, occluders, centroid, axes, camera, previous_view);
        EstimatorParams params = params_arg(base);
        apply_settings(params, kw);
        return run_estimate(problem, params, record_path, "");
      },
      py::arg("positions"), py::arg("normals"), py::arg("occluders") = py::none(), py::kw_only(),
      py::arg("centroid") = py::none(), py::arg("axes") = py::none(), py::arg("camera") = py::none(),
      py::arg("previous_view") = py::none(), py::arg("settings") = py::none(), py::arg("record_path") = false,
      R"(Estimates the occlusion-free view of one frame (ESTIMATOR-SPEC.md §1-§6).

positions: (N, 3) supervoxel centroids v_n [m]; normals: (N, 3) their normals p_n
(towards the sensor side, any length > 1e-12); occluders: (B, 3) occluder points q_b
or None. Arrays must be float64 numpy arrays (any strides) or lists of numbers:
other dtypes raise TypeError, other shapes ValueError. Optional, (3,) each:
centroid C, camera (t0's last fallback), previous_view (used with warm_start);
axes (3, 3), axes[k] = e_(k+1). settings: an EstimatorSettings (or a dict) to start from;
**settings: settings by name on top (e.g. r_sphere=0.4, preset='authors_code').
record_path: also return every visited iterate (ViewEstimate.path).

Returns a ViewEstimate. No usable supervoxel and no centroid is an outcome, not
an error: status no_supervoxels (`ofv estimate` exits 2 on it). Raises ValueError,
with the message of `ofv estimate`, on invalid settings or input. The GIL is
released while the estimator runs.)");

  // --- Scene
  py::class_<PyScene> scene(m, "Scene",
                      "One frame as `ofv estimate` reads it (ESTIMATOR-SPEC.md §8): supervoxels, occluders, the\n"
                      "optional centroid, axes, camera and previous view, and the settings (\"params\").\n"
                      "Scene.load(path) / save(path) read and write the scene JSON of `ofv estimate`.", meta);
  refuse_bare_new(scene);
  scene
      .def(py::init([](const py::object& positions, const py::object& normals, const py::object& occluders,
                       const py::object& centroid, const py::object& axes, const py::object& camera,
                       const py::object& previous_view, const py::object& base, const py::kwargs& kw) {
             PyScene s;
             s.scene.problem = make_problem(positions, normals, occluders, centroid, axes, camera, previous_view);
             s.scene.params = params_arg(base);
             apply_settings(s.scene.params, kw);
             return s;
           }),
           py::arg("positions"), py::arg("normals"), py::arg("occluders") = py::none(), py::kw_only(),
           py::arg("centroid") = py::none(), py::arg("axes") = py::none(), py::arg("camera") = py::none(),
           py::arg("previous_view") = py::none(), py::arg("settings") = py::none(),
           "Scene(positions, normals, occluders=None, *, centroid=None, axes=None, camera=None, previous_view=None,\n"
           "settings=None, **settings): arguments as estimate_view().")
      .def_static("load", [](const py::object& path_obj) {
            const std::string path = path_arg(path_obj, "path");
            PyScene s;
            {
              py::gil_scoped_release release;
              s.scene = read_scene(path);
            }
            s.source = path;
            try {
              (void)s.scene.params.resolve();
            } catch (const std::invalid_argument& e) {
              throw std::invalid_argument(path + ": " + e.what());
            }
            return s;
          }, py::arg("path"), "Reads a scene file (the JSON of `ofv estimate`); ValueError naming the file, field and value.")
      .def_static("from_json", [](const py::object& text_obj, const py::object& source_obj) {
            const std::string text = text_arg(text_obj, "text");
            const std::string source = text_arg(source_obj, "source");
            PyScene s;
            s.scene = scene_from_text(text, source);
            s.source = source;
            (void)s.scene.params.resolve();
            return s;
          }, py::arg("text"), py::arg("source") = "<string>", "Parses a scene from JSON text; `source` names it in errors.")
      .def("to_json", [](const PyScene& s) { return to_pretty_string(scene_json(s.scene)) + "\n"; },
           "The scene file's text (every explicitly given setting in \"params\").")
      .def("save", [](const PyScene& s, const py::object& path_obj) {
            const std::string path = path_arg(path_obj, "path");
            const std::string text = to_pretty_string(scene_json(s.scene)) + "\n";
            std::ofstream out(path, std::ios::binary);
            out << text;
            if (!out.flush()) throw std::runtime_error(path + ": cannot write");
          }, py::arg("path"), "Writes the scene file that `ofv estimate` and Scene.load read back.")
      .def("estimate", [](const PyScene& s, bool record_path, const py::kwargs& kw) {
            EstimatorParams params = s.scene.params;
            apply_settings(params, kw);
            return run_estimate(s.scene.problem, params, record_path, s.source);
          }, py::kw_only(), py::arg("record_path") = false,
          "estimate(*, record_path=False, **settings): the estimate with the scene's settings and these on top,\n"
          "as `ofv estimate SCENE --set ...`; errors name the scene's file as it does.")
      .def_property("positions", [](const PyScene& s) { return matrix_to_numpy(Eigen::MatrixXd(s.scene.problem.positions.transpose())); },
                    [](PyScene& s, const py::object& v) { s.scene.problem.positions = points_from_python(v, "positions"); },
                    "(N, 3) supervoxel centroids [m] (a copy; assign to change)")
      .def_property("normals", [](const PyScene& s) { return matrix_to_numpy(Eigen::MatrixXd(s.scene.problem.normals.transpose())); },
                    [](PyScene& s, const py::object& v) { s.scene.problem.normals = points_from_python(v, "normals"); },
                    "(N, 3) supervoxel normals (a copy; assign to change)")
      .def_property("occluders", [](const PyScene& s) { return matrix_to_numpy(Eigen::MatrixXd(s.scene.problem.occluders.transpose())); },
                    [](PyScene& s, const py::object& v) {
                      s.scene.problem.occluders = v.is_none() ? Eigen::Matrix3Xd(3, 0) : points_from_python(v, "occluders");
                    }, "(B, 3) occluder points [m] (a copy; assign to change)")
      .def_property("centroid", [](const PyScene& s) { return point_or_none(s.scene.problem.centroid); },
                    [](PyScene& s, const py::object& v) { s.scene.problem.centroid = optional_point(v, "centroid"); },
                    "object centroid C (3,) [m], or None: the mean of the usable positions")
      .def_property("axes", [](const PyScene& s) -> py::object {
            if (!s.scene.problem.axes) return py::none();
            return matrix_to_numpy(Eigen::MatrixXd(s.scene.problem.axes->transpose()));
          }, [](PyScene& s, const py::object& v) { s.scene.problem.axes = optional_axes(v); },
          "object axes (3, 3), axes[k] = e_(k+1), or None: PCA of the positions")
      .def_property("camera", [](const PyScene& s) { return point_or_none(s.scene.problem.camera); },
                    [](PyScene& s, const py::object& v) { s.scene.problem.camera = optional_point(v, "camera"); },
                    "current camera position (3,) [m] or None")
      .def_property("previous_view", [](const PyScene& s) { return point_or_none(s.scene.problem.previous_view); },
                    [](PyScene& s, const py::object& v) { s.scene.problem.previous_view = optional_point(v, "previous_view"); },
                    "previous t_f (3,) [m] or None (used with warm_start)")
      .def_property("settings", [](PyScene& s) -> EstimatorParams& { return s.scene.params; },
                    [](PyScene& s, const EstimatorParams& p) { s.scene.params = p; }, py::return_value_policy::reference_internal,
                    "the scene's EstimatorSettings (\"params\"); changing it changes the scene")
      .def_readonly("source", &PyScene::source, "the file the scene was read from ('' when built in Python)")
      .def("__repr__", [](const PyScene& s) {
        return "Scene(" + std::to_string(s.scene.problem.positions.cols()) + " supervoxels, " +
               std::to_string(s.scene.problem.occluders.cols()) + " occluders" +
               (s.source.empty() ? "" : ", from " + s.source) + ")";
      });

  m.def("estimator_settings", [] { return docs_to_python(estimator_settings_table().docs()); },
        "The estimator's settings: a list of dicts with name, type, default, unit and doc (`ofv settings`).");
}

}  // namespace ofv::python

namespace {

// A message that quotes a file's bytes may not be UTF-8: raised with those bytes replaced, never as a decoding error.
void set_error(PyObject* type, const char* message) {
  PyObject* text = PyUnicode_DecodeUTF8(message, static_cast<Py_ssize_t>(std::strlen(message)), "replace");
  if (text == nullptr) return;  // out of memory: that error stands
  PyErr_SetObject(type, text);
  Py_DECREF(text);
}

}  // namespace

PYBIND11_MODULE(_ofv, m) {
  namespace py = pybind11;
  m.doc() = "ofv's C++ core (the package ofv re-exports it): the occlusion-free view estimator, "
            "scene files, and the simulated closed loop.";
  // ValueError for std::invalid_argument (bad input, the messages of the
  // command line), RuntimeError for every other failure.
  py::register_local_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const py::builtin_exception&) {
      throw;
    } catch (const py::error_already_set&) {
      throw;
    } catch (const std::bad_alloc&) {
      throw;
    } catch (const std::invalid_argument& e) {
      set_error(PyExc_ValueError, e.what());
    } catch (const std::exception& e) {
      set_error(PyExc_RuntimeError, e.what());
    }
  });
  m.attr("__version__") = ofv::version();
  m.attr("git_commit") = ofv::git_commit();
  ofv::python::bind_estimator(m);
#ifdef OFV_HAVE_LOOP
  ofv::python::bind_simulation(m);
#endif
}
