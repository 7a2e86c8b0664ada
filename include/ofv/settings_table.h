/**
 * \file settings_table.h
 * \brief Settings by name: one table per component (name, type, default,
 *        unit, one-line doc, setter) is the single source for `--set
 *        name=value`, scenario and grid files, validation messages, `--help`
 *        texts and the settings tables in the docs.
 *
 * A default is written once, in the settings struct's member initialiser;
 * a table row formats it from a default-constructed struct.
 *
 * \code
 * ofv::SettingsTable<MySettings> table;
 * const MySettings d{};
 * table.add({"gain", "number", ofv::format_number(d.gain), "1/s", "controller gain"},
 *           [](MySettings& s, const std::string& v) { s.gain = ofv::parse_number("gain", v, 0.0, 1e3, false); });
 * table.set(settings, "gain", "4");   // throws std::invalid_argument naming "gain" and the value
 * \endcode
 */
#pragma once

#include <functional>
#include <initializer_list>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace ofv {

/// \brief The documentation of one setting: what `--help` and the docs show.
struct SettingDoc {
  std::string name;           ///< as in `--set name=value`, scenario and grid files
  std::string type;           ///< `number`, `integer`, `bool`, or the words it takes (`a \| b`)
  std::string default_value;  ///< the default, as text
  std::string unit;           ///< `m`, `m/s`, `s` ... or empty
  std::string doc;            ///< one line
};

/**
 * \brief Named settings of a struct T.
 * \tparam T the settings (or a struct holding them) the setters write into.
 */
template <class T>
class SettingsTable {
 public:
  /// \brief Parses `value` and writes it into the settings.
  /// \throws std::invalid_argument naming the setting and the value.
  using Setter = std::function<void(T&, const std::string& value)>;
  /// \brief The setting's value as text that the setter reads back (the
  ///        resolved value: a preset's or scenario's, where they apply).
  using Getter = std::function<std::string(const T&)>;

  /// \brief Adds a row.
  SettingsTable& add(SettingDoc doc, Setter set, Getter get) {
    rows_.push_back({std::move(doc), std::move(set), std::move(get)});
    return *this;
  }

  /// \brief Adds every row of another table, reading and writing through
  ///        `part`, which returns the sub-settings of a T, const or not
  ///        (e.g. `[](auto& l) -> auto& { return l.estimator; }`).
  template <class U, class Part>
  SettingsTable& include(const SettingsTable<U>& other, Part part) {
    for (const auto& row : other.rows()) {
      rows_.push_back({row.doc, [set = row.set, part](T& t, const std::string& v) { set(part(t), v); },
                       [get = row.get, part](const T& t) { return get(part(t)); }});
    }
    return *this;
  }

  /// \brief Sets one setting by name.
  /// \throws std::invalid_argument for an unknown name (listing the known ones) or a bad value.
  void set(T& target, const std::string& name, const std::string& value) const {
    for (const auto& row : rows_) {
      if (row.doc.name == name) {
        row.set(target, value);
        return;
      }
    }
    throw std::invalid_argument("unknown parameter '" + name + "' (expected one of: " + names_text() + ")");
  }

  /// \brief Applies `name=value` pairs in order.
  void apply(T& target, const std::vector<std::pair<std::string, std::string>>& settings) const {
    for (const auto& [name, value] : settings) set(target, name, value);
  }

  /// \brief Every setting's value, in table order: `apply()` of them gives
  ///        the same values again.
  [[nodiscard]] std::vector<std::pair<std::string, std::string>> values(const T& source) const {
    std::vector<std::pair<std::string, std::string>> out;
    for (const auto& row : rows_) out.emplace_back(row.doc.name, row.get(source));
    return out;
  }

  /// \brief The row named `name`, or nullptr.
  [[nodiscard]] const SettingDoc* find(const std::string& name) const {
    for (const auto& row : rows_) {
      if (row.doc.name == name) return &row.doc;
    }
    return nullptr;
  }

  /// \brief Every row's documentation, in table order.
  [[nodiscard]] std::vector<SettingDoc> docs() const {
    std::vector<SettingDoc> out;
    for (const auto& row : rows_) out.push_back(row.doc);
    return out;
  }

  /// \brief One setting: its documentation and how to write and read it.
  struct Row {
    SettingDoc doc;  ///< name, type, default, unit, meaning
    Setter set;      ///< parses a value and writes it into a T
    Getter get;      ///< reads it from a T as text
  };
  /// \brief Every row, in table order.
  [[nodiscard]] const std::vector<Row>& rows() const { return rows_; }

 private:
  [[nodiscard]] std::string names_text() const {
    std::string list;
    for (const auto& row : rows_) list += (list.empty() ? "" : ", ") + row.doc.name;
    return list;
  }

  std::vector<Row> rows_;
};

/// \name Parsing setting values; errors name the setting and quote the value.
/// \{

/**
 * \brief A finite number in [lo, hi], or in (lo, hi] when `lo_open`.
 * \throws std::invalid_argument e.g. `setting 'gain' must be a number in (0, 1000], got "abc"`.
 */
[[nodiscard]] double parse_number(const std::string& name, const std::string& value, double lo, double hi,
                                  bool lo_open);
/// \brief An integer in [lo, hi].
[[nodiscard]] long parse_integer(const std::string& name, const std::string& value, long lo, long hi);
/// \brief `true` or `false`.
[[nodiscard]] bool parse_bool(const std::string& name, const std::string& value);
/// \brief One of the listed words.
template <class E>
[[nodiscard]] E parse_word(const std::string& name, const std::string& value,
                           std::initializer_list<std::pair<const char*, E>> words) {
  std::string list;
  for (const auto& [word, e] : words) {
    if (value == word) return e;
    list += (list.empty() ? "" : ", ") + std::string(word);
  }
  throw std::invalid_argument("setting '" + name + "' must be one of " + list + ", got \"" + value + "\"");
}
/// \}

/// \brief `name=value` split at the first `=`.
/// \throws std::invalid_argument quoting the text when there is no `=` or no name.
[[nodiscard]] std::pair<std::string, std::string> split_assignment(const std::string& text);

/// \brief Shortest text that reads back as the same double (`0.02`, `500`, `1e-09`).
[[nodiscard]] std::string format_number(double v);
/// \brief `true` or `false`.
[[nodiscard]] inline std::string format_bool(bool b) { return b ? "true" : "false"; }

/// \brief The rows as `--help` text: `name  type  default [unit]` and the doc on the next line.
[[nodiscard]] std::string settings_help(const std::vector<SettingDoc>& docs);
/// \brief The rows as a Markdown table (name, type, default, unit, meaning), for the docs.
[[nodiscard]] std::string settings_markdown(const std::vector<SettingDoc>& docs);

}  // namespace ofv
