// Conversions between Python objects and ofv's value types (convert.h).
#include "convert.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace ofv::python {

namespace {

std::string shape_text(long rows, long cols) {
  return "(" + (rows < 0 ? std::string("N") : std::to_string(rows)) + (cols < 0 ? ",)" : ", " + std::to_string(cols) + ")");
}

std::string array_shape(const py::array& a) {
  std::string s = "(";
  for (py::ssize_t k = 0; k < a.ndim(); ++k) s += (k ? ", " : "") + std::to_string(a.shape(k));
  return s + (a.ndim() == 1 ? ",)" : ")");
}

bool is_real(const py::handle& h) { return PyFloat_Check(h.ptr()) || (PyLong_Check(h.ptr()) && !PyBool_Check(h.ptr())); }

// is_real(), or any other real number but a bool or an array (numpy's float32, say).
bool is_number(const py::handle& h) {
  return is_real(h) || (!PyBool_Check(h.ptr()) && !py::isinstance<py::array>(h) &&
                        py::isinstance(h, py::module_::import("numbers").attr("Real")));
}

bool is_sequence(const py::handle& h) { return py::isinstance<py::list>(h) || py::isinstance<py::tuple>(h); }

[[noreturn]] void wrong_type(const py::handle& obj, const std::string& name, const std::string& expected) {
  std::string got;
  if (py::isinstance<py::array>(obj)) {
    const auto a = py::reinterpret_borrow<py::array>(obj);
    got = "a " + py::str(a.dtype()).cast<std::string>() + " array of shape " + array_shape(a) +
          (a.dtype().kind() == 'f' && a.itemsize() == 8 ? " in non-native byte order" : "");
  } else {
    got = "a " + type_name(obj);
  }
  throw py::type_error(name + ": expected " + expected + ", got " + got + "; convert with np.asarray(" + name +
                       ", dtype=np.float64)");
}

// Reads an array of float64 by its strides (any layout, aligned or not).
double element(const py::array& a, py::ssize_t i, py::ssize_t j) {
  const char* p = static_cast<const char*>(a.data());
  p += i * a.strides(0);
  if (a.ndim() == 2) p += j * a.strides(1);
  double v = 0.0;
  std::memcpy(&v, p, sizeof v);
  return v;
}

}  // namespace

Eigen::MatrixXd matrix_from_python(const py::handle& obj, const std::string& name, long rows, long cols) {
  const std::string expected = "a float64 array of shape " + shape_text(rows, cols);
  if (py::isinstance<py::array>(obj)) {
    const auto a = py::reinterpret_borrow<py::array>(obj);
    const bool float64 = a.dtype().kind() == 'f' && a.itemsize() == 8 && a.dtype().attr("isnative").cast<bool>();
    if (!float64) wrong_type(obj, name, expected);
    const bool dims = cols < 0 ? a.ndim() == 1 : a.ndim() == 2;
    if (!dims || (rows >= 0 && a.shape(0) != rows) || (cols >= 0 && a.shape(1) != cols)) {
      throw py::value_error(name + ": expected " + expected + ", got shape " + array_shape(a));
    }
    const long n = static_cast<long>(a.shape(0));
    const long c = cols < 0 ? 1 : cols;
    Eigen::MatrixXd out(n, c);
    for (long i = 0; i < n; ++i) {
      for (long j = 0; j < c; ++j) out(i, j) = element(a, i, j);
    }
    return out;
  }
  if (!is_sequence(obj)) wrong_type(obj, name, expected + " or a list of numbers");
  const auto seq = py::reinterpret_borrow<py::sequence>(obj);
  const long n = static_cast<long>(py::len(seq));
  if (rows >= 0 && n != rows) {
    throw py::value_error(name + ": expected " + expected + ", got a list of " + std::to_string(n) + " items");
  }
  const long c = cols < 0 ? 1 : cols;
  Eigen::MatrixXd out(n, c);
  for (long i = 0; i < n; ++i) {
    const py::handle item = seq[static_cast<std::size_t>(i)];
    const std::string at = name + "[" + std::to_string(i) + "]";
    if (cols < 0) {
      if (!is_real(item)) wrong_type(item, at, "a number (int or float)");
      out(i, 0) = item.cast<double>();
      continue;
    }
    if (!is_sequence(item) || py::len(item) != static_cast<std::size_t>(cols)) {
      throw py::value_error(at + ": expected " + std::to_string(cols) + " numbers");
    }
    const auto row = py::reinterpret_borrow<py::sequence>(item);
    for (long j = 0; j < cols; ++j) {
      const py::handle v = row[static_cast<std::size_t>(j)];
      if (!is_real(v)) wrong_type(v, at + "[" + std::to_string(j) + "]", "a number (int or float)");
      out(i, j) = v.cast<double>();
    }
  }
  return out;
}

Eigen::VectorXd vector_from_python(const py::handle& obj, const std::string& name, long n) {
  return matrix_from_python(obj, name, n, -1).col(0);
}

Eigen::Matrix3Xd points_from_python(const py::handle& obj, const std::string& name) {
  return matrix_from_python(obj, name, -1, 3).transpose();
}

py::array_t<double> vector_to_numpy(const Eigen::VectorXd& v) {
  py::array_t<double> out(static_cast<py::ssize_t>(v.size()));
  auto w = out.mutable_unchecked<1>();
  for (Eigen::Index i = 0; i < v.size(); ++i) w(i) = v(i);
  return out;
}

py::array_t<double> matrix_to_numpy(const Eigen::MatrixXd& m) {
  py::array_t<double> out({static_cast<py::ssize_t>(m.rows()), static_cast<py::ssize_t>(m.cols())});
  auto w = out.mutable_unchecked<2>();
  for (Eigen::Index i = 0; i < m.rows(); ++i) {
    for (Eigen::Index j = 0; j < m.cols(); ++j) w(i, j) = m(i, j);
  }
  return out;
}

std::string type_name(const py::handle& obj) { return py::str(py::type::of(obj).attr("__name__")).cast<std::string>(); }

std::string text_arg(const py::handle& obj, const std::string& name) {
  if (!PyUnicode_Check(obj.ptr())) throw py::type_error(name + ": expected a str, got a " + type_name(obj));
  Py_ssize_t size = 0;
  const char* utf8 = PyUnicode_AsUTF8AndSize(obj.ptr(), &size);
  if (utf8 == nullptr) {
    PyErr_Clear();
    throw py::value_error(name + ": not valid text (a lone surrogate character cannot be written as UTF-8)");
  }
  std::string text(utf8, static_cast<std::size_t>(size));
  if (text.find('\0') != std::string::npos) throw py::value_error(name + ": contains a NUL character");
  return text;
}

std::string path_arg(const py::handle& obj, const std::string& name) {
  if (PyUnicode_Check(obj.ptr())) return text_arg(obj, name);
  if (py::hasattr(obj, "__fspath__")) {
    const py::object path = py::module_::import("os").attr("fspath")(obj);
    if (PyUnicode_Check(path.ptr())) return text_arg(path, name);
  }
  throw py::type_error(name + ": expected a path (str or os.PathLike of str), got a " + type_name(obj));
}

long long integer_arg(const py::handle& obj, const std::string& name, long long lo, long long hi) {
  const std::string range = "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  if (PyBool_Check(obj.ptr()) || !PyIndex_Check(obj.ptr()) || py::isinstance<py::array>(obj)) {
    throw py::type_error(name + ": expected " + range + ", got a " + type_name(obj));
  }
  const auto index = py::reinterpret_steal<py::object>(PyNumber_Index(obj.ptr()));
  if (!index) throw py::error_already_set();
  int overflow = 0;
  const long long value = PyLong_AsLongLongAndOverflow(index.ptr(), &overflow);
  if (overflow != 0 || value < lo || value > hi) {
    throw py::value_error(name + ": expected " + range + ", got " + py::repr(index).cast<std::string>());
  }
  return value;
}

double number_arg(const py::handle& obj, const std::string& name, double lo, double hi) {
  const std::string range = "a number in [" + format_number(lo) + ", " + format_number(hi) + "]";
  if (!is_number(obj)) throw py::type_error(name + ": expected " + range + ", got a " + type_name(obj));
  const double value = PyFloat_AsDouble(obj.ptr());
  if (value == -1.0 && PyErr_Occurred()) {  // an int too large for a double
    PyErr_Clear();
    throw py::value_error(name + ": expected " + range + ", got " + py::repr(obj).cast<std::string>());
  }
  if (!(value >= lo && value <= hi)) throw py::value_error(name + ": expected " + range + ", got " + format_number(value));
  return value;
}

namespace {

thread_local bool t_in_call = false;  // a Cls(...) call is under way: its __new__ may run

PyTypeObject* pybind11_metaclass() { return py::detail::get_internals().default_metaclass; }

}  // namespace

py::metaclass constructed_only(py::module_& m) {
  if (!py::hasattr(m, "_Type")) {
    const py::handle base(reinterpret_cast<PyObject*>(pybind11_metaclass()));
    py::dict body;
    body["__module__"] = m.attr("__name__");
    body["__doc__"] = "The metaclass of ofv's classes: X.__new__ runs only inside X(...).";
    const py::object meta = py::handle(reinterpret_cast<PyObject*>(&PyType_Type))("_Type", py::make_tuple(base), body);
    meta.attr("__call__") = py::cpp_function(
        [](const py::handle& cls, const py::args& args, const py::kwargs& kwargs) {
          t_in_call = true;
          PyObject* made = pybind11_metaclass()->tp_call(cls.ptr(), args.ptr(), kwargs.ptr());
          t_in_call = false;
          if (made == nullptr) throw py::error_already_set();
          return py::reinterpret_steal<py::object>(made);
        },
        py::is_method(meta));
    m.attr("_Type") = meta;
  }
  return py::metaclass(m.attr("_Type"));
}

void refuse_bare_new(const py::handle& cls) {
  cls.attr("__new__") = py::staticmethod(py::cpp_function([](const py::handle& type, const py::args&, const py::kwargs&) {
    if (!t_in_call) {
      const std::string name = py::str(type.attr("__name__")).cast<std::string>();
      throw py::type_error(name + ".__new__(" + name + ") alone would make a " + name + " without its value: make one with " +
                           name + "(...) or get one from the function that returns it");
    }
    t_in_call = false;  // this call's object only: not one its __init__ would make
    return py::reinterpret_steal<py::object>(py::detail::pybind11_object_new(
        reinterpret_cast<PyTypeObject*>(type.ptr()), nullptr, nullptr));
  }));
}

std::string setting_text(const std::string& name, const py::handle& value) {
  if (PyBool_Check(value.ptr())) return format_bool(value.cast<bool>());
  if (PyLong_Check(value.ptr()) || (PyIndex_Check(value.ptr()) && !py::isinstance<py::array>(value))) {
    return py::str(py::reinterpret_steal<py::object>(PyNumber_Index(value.ptr()))).cast<std::string>();
  }
  if (is_number(value)) return format_number(PyFloat_AsDouble(value.ptr()));
  if (PyUnicode_Check(value.ptr())) return text_arg(value, "setting '" + name + "'");
  throw py::type_error("setting '" + name + "': expected a bool, int, float or str, got a " + type_name(value));
}

py::object typed_value(const SettingDoc& doc, const std::string& text) {
  const auto starts = [&](const char* prefix) { return doc.type.rfind(prefix, 0) == 0; };
  if (doc.type == "bool") return py::bool_(text == "true");
  if (starts("integer")) return py::int_(std::stoll(text));
  if (starts("number") && numeric_field(text) && !text.empty()) return py::float_(std::strtod(text.c_str(), nullptr));
  return py::str(text);
}

std::vector<std::pair<std::string, std::string>> settings_pairs(const py::dict& settings) {
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& [key, value] : settings) {
    const auto name = text_arg(key, "setting name");
    out.emplace_back(name, setting_text(name, value));
  }
  return out;
}

py::list docs_to_python(const std::vector<SettingDoc>& docs) {
  py::list out;
  for (const auto& d : docs) {
    py::dict row;
    row["name"] = d.name;
    row["type"] = d.type;
    row["default"] = d.default_value;
    row["unit"] = d.unit;
    row["doc"] = d.doc;
    out.append(row);
  }
  return out;
}

namespace {

template <class Json>
py::object json_value(const Json& j) {
  switch (j.type()) {
    case nlohmann::json::value_t::null: return py::none();
    case nlohmann::json::value_t::boolean: return py::bool_(j.template get<bool>());
    case nlohmann::json::value_t::number_integer: return py::int_(j.template get<long long>());
    case nlohmann::json::value_t::number_unsigned: return py::int_(j.template get<unsigned long long>());
    case nlohmann::json::value_t::number_float: return py::float_(j.template get<double>());
    case nlohmann::json::value_t::string: return py::str(j.template get<std::string>());
    case nlohmann::json::value_t::array: {
      py::list out;
      for (const auto& item : j) out.append(json_value(item));
      return std::move(out);
    }
    case nlohmann::json::value_t::object: {
      py::dict out;
      for (const auto& item : j.items()) out[py::str(item.key())] = json_value(item.value());
      return std::move(out);
    }
    default: return py::none();  // binary and discarded values do not occur in ofv's JSON
  }
}

}  // namespace

py::object json_to_python(const nlohmann::ordered_json& j) { return json_value(j); }
py::object json_to_python(const nlohmann::json& j) { return json_value(j); }

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out(1);
  for (const char ch : text) {
    if (ch == sep) {
      out.emplace_back();
    } else {
      out.back() += ch;
    }
  }
  return out;
}

bool numeric_field(const std::string& field) {
  if (field.empty()) return true;
  char* end = nullptr;
  (void)std::strtod(field.c_str(), &end);
  return end == field.c_str() + field.size();
}

py::dict csv_columns(const std::vector<std::string>& names, const std::vector<bool>& numeric,
                     const std::vector<std::string>& rows) {
  const std::size_t n = rows.size();
  std::vector<std::vector<double>> numbers(names.size());
  std::vector<py::list> words(names.size());
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (numeric[c]) numbers[c].reserve(n);
  }
  for (std::size_t r = 0; r < n; ++r) {
    const auto fields = split(rows[r], ',');
    if (fields.size() != names.size()) {
      throw std::runtime_error("row " + std::to_string(r + 1) + " has " + std::to_string(fields.size()) +
                               " fields, the header " + std::to_string(names.size()));
    }
    for (std::size_t c = 0; c < names.size(); ++c) {
      if (!numeric[c]) {
        words[c].append(fields[c]);
      } else if (fields[c].empty()) {
        numbers[c].push_back(std::numeric_limits<double>::quiet_NaN());
      } else {
        numbers[c].push_back(std::strtod(fields[c].c_str(), nullptr));
      }
    }
  }
  const py::object np_array = py::module_::import("numpy").attr("array");
  py::dict out;
  for (std::size_t c = 0; c < names.size(); ++c) {
    if (numeric[c]) {
      py::array_t<double> column(static_cast<py::ssize_t>(n));
      std::copy(numbers[c].begin(), numbers[c].end(), column.mutable_data());
      out[py::str(names[c])] = column;
    } else {
      out[py::str(names[c])] = np_array(words[c], py::arg("dtype") = "U");
    }
  }
  return out;
}

}  // namespace ofv::python
