// Conversions between Python objects and ofv's value types, shared by the
// module's translation units. Every check names the Python argument.
#pragma once

#include "ofv/settings_table.h"

#include <Eigen/Core>
#include <nlohmann/json_fwd.hpp>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>

#include <string>
#include <utility>
#include <vector>

namespace ofv::python {

namespace py = pybind11;

/**
 * \brief An N x `cols` matrix of numbers from Python, as rows: a float64
 *        numpy array of that shape (any strides, read as strided, never
 *        reinterpreted), or nested lists/tuples of Python int and float.
 *
 * Arrays of another dtype (int, float32, object, non-native byte order) are
 * refused, not converted: convert with `np.asarray(x, dtype=np.float64)`.
 * \param rows the required number of rows, or -1 for any.
 * \throws py::type_error for another type or dtype, py::value_error for another shape.
 */
Eigen::MatrixXd matrix_from_python(const py::handle& obj, const std::string& name, long rows, long cols);

/// \brief A vector of `n` numbers: a float64 array of shape (n,) or a list/tuple of numbers.
Eigen::VectorXd vector_from_python(const py::handle& obj, const std::string& name, long n);

/// \brief Points as the estimator takes them (3 x N) from an N x 3 array.
Eigen::Matrix3Xd points_from_python(const py::handle& obj, const std::string& name);

/// \brief A new float64 numpy array (a copy) of a vector.
py::array_t<double> vector_to_numpy(const Eigen::VectorXd& v);
/// \brief A new float64 numpy array (a copy) of a matrix, same shape.
py::array_t<double> matrix_to_numpy(const Eigen::MatrixXd& m);

/// \brief The name of `obj`'s type, for error messages ("got a list").
std::string type_name(const py::handle& obj);

/**
 * \brief A Python str as UTF-8 text.
 * \throws py::type_error naming `name` for anything but a str; py::value_error
 *         for a str that is no text a file or a setting can hold (a lone
 *         surrogate, which UTF-8 cannot write, or a NUL character).
 */
std::string text_arg(const py::handle& obj, const std::string& name);

/// \brief A path: a str or an os.PathLike giving one, checked as text_arg() does.
std::string path_arg(const py::handle& obj, const std::string& name);

/// \brief A Python int (or numpy integer; not a bool) in [lo, hi].
/// \throws py::type_error for another type, py::value_error naming the range otherwise.
long long integer_arg(const py::handle& obj, const std::string& name, long long lo, long long hi);

/// \brief A real number (int, float or numpy floating; not a bool), finite and in [lo, hi].
/// \throws py::type_error for another type, py::value_error naming the range otherwise.
double number_arg(const py::handle& obj, const std::string& name, double lo, double hi);

/**
 * \brief The module's metaclass: `Cls(...)` as pybind11's, and `Cls.__new__`
 *        usable only inside such a call. Alone, `__new__` would give an
 *        object without its C++ value (its methods would read uninitialised
 *        memory). Made once per module (kept as its attribute `_Type`).
 */
py::metaclass constructed_only(py::module_& m);

/// \brief Gives `cls` (made with constructed_only()'s metaclass) the `__new__` that refuses to run alone.
void refuse_bare_new(const py::handle& cls);

/**
 * \brief A setting's value as the text its table's setter parses: bool as
 *        `true`/`false`, int as digits, float as the shortest text that
 *        reads back the same, str as it is.
 * \throws py::type_error naming the setting for any other type.
 */
std::string setting_text(const std::string& name, const py::handle& value);

/// \brief A setting's value text (a table row's getter) as the Python value of
///        its type: float for `number...`, int for `integer...`, bool, else str.
py::object typed_value(const SettingDoc& doc, const std::string& text);

/// \brief Every setting of a table as {name: value}, typed by typed_value().
template <class T>
py::dict typed_values(const SettingsTable<T>& table, const T& source) {
  py::dict out;
  for (const auto& row : table.rows()) out[py::str(row.doc.name)] = typed_value(row.doc, row.get(source));
  return out;
}

/// \brief `**settings` as `name=value` pairs in the order given.
std::vector<std::pair<std::string, std::string>> settings_pairs(const py::dict& settings);

/// \brief Documentation rows as a list of dicts (name, type, default, unit, doc).
py::list docs_to_python(const std::vector<SettingDoc>& docs);

/// \brief A JSON value as Python objects (dict, list, str, int, float, bool, None).
py::object json_to_python(const nlohmann::ordered_json& j);
/// \brief The same for nlohmann::json.
py::object json_to_python(const nlohmann::json& j);

/**
 * \brief CSV text with a header (no quoted fields) as a dict of numpy
 *        columns, in header order: float64 where `kinds[i]` is true (an
 *        empty field is NaN), str otherwise.
 * \throws std::runtime_error when a row has another number of fields.
 */
py::dict csv_columns(const std::vector<std::string>& names, const std::vector<bool>& numeric,
                     const std::vector<std::string>& rows);

/// \brief `text` split at every `sep`.
std::vector<std::string> split(const std::string& text, char sep);

/// \brief Whether the field reads as a number (or is empty: a missing value).
bool numeric_field(const std::string& field);

/// \brief Binds the module's estimator part (module.cpp).
void bind_estimator(py::module_& m);
/// \brief Binds the module's simulator part (sim_bindings.cpp), when built with the loop.
void bind_simulation(py::module_& m);

}  // namespace ofv::python
