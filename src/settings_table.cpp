// Parsing and formatting of settings by name.
#include "ofv/settings_table.h"

#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <sstream>

namespace ofv {

namespace {

[[noreturn]] void bad_value(const std::string& name, const std::string& what, const std::string& value) {
  throw std::invalid_argument("setting '" + name + "' must be " + what + ", got \"" + value + "\"");
}

std::string range_text(double lo, double hi, bool lo_open) {
  return std::string(lo_open ? "(" : "[") + format_number(lo) + ", " + format_number(hi) + "]";
}

}  // namespace

double parse_number(const std::string& name, const std::string& value, double lo, double hi, bool lo_open) {
  const char* begin = value.c_str();
  char* end = nullptr;
  errno = 0;
  const double v = value.empty() || std::isspace(static_cast<unsigned char>(value[0])) ? NAN : std::strtod(begin, &end);
  const bool parsed = end == begin + value.size() && errno != ERANGE && std::isfinite(v);
  const bool in_range = parsed && (lo_open ? v > lo : v >= lo) && v <= hi;
  if (!in_range) {
    const bool bounded = std::isfinite(lo) || std::isfinite(hi);
    bad_value(name, bounded ? "a number in " + range_text(lo, hi, lo_open) : std::string("a finite number"), value);
  }
  return v;
}

long parse_integer(const std::string& name, const std::string& value, long lo, long hi) {
  const char* begin = value.c_str();
  char* end = nullptr;
  errno = 0;
  const long v = value.empty() || std::isspace(static_cast<unsigned char>(value[0])) ? lo - 1 : std::strtol(begin, &end, 10);
  if (end != begin + value.size() || errno == ERANGE || v < lo || v > hi) {
    bad_value(name, "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]", value);
  }
  return v;
}

bool parse_bool(const std::string& name, const std::string& value) {
  if (value == "true") return true;
  if (value == "false") return false;
  bad_value(name, "true or false", value);
}

std::pair<std::string, std::string> split_assignment(const std::string& text) {
  const auto eq = text.find('=');
  if (eq == std::string::npos || eq == 0) throw std::invalid_argument("--set " + text + ": expected name=value");
  return {text.substr(0, eq), text.substr(eq + 1)};
}

std::string format_number(double v) {
  if (std::isinf(v)) return v > 0 ? "inf" : "-inf";
  char buffer[32];
  const auto end = std::to_chars(buffer, buffer + sizeof buffer, v).ptr;  // shortest text that reads back
  return std::string(buffer, end);
}

std::string settings_help(const std::vector<SettingDoc>& docs) {
  std::ostringstream out;
  for (const auto& d : docs) {
    out << "  " << d.name << std::string(d.name.size() < 26 ? 26 - d.name.size() : 1, ' ') << d.type
        << ", default " << (d.default_value.empty() ? "none" : d.default_value) << (d.unit.empty() ? "" : " [" + d.unit + "]")
        << "\n      " << d.doc << '\n';
  }
  return out.str();
}

std::string settings_markdown(const std::vector<SettingDoc>& docs) {
  auto cell = [](const std::string& s) {
    std::string out;
    for (char ch : s) out += ch == '|' ? std::string("\\|") : std::string(1, ch);
    return out;
  };
  std::ostringstream out;
  out << "| setting | type | default | unit | meaning |\n|---|---|---|---|---|\n";
  for (const auto& d : docs) {
    out << "| `" << d.name << "` | " << cell(d.type) << " | " << (d.default_value.empty() ? "—" : "`" + d.default_value + "`")
        << " | " << cell(d.unit) << " | " << cell(d.doc) << " |\n";
  }
  return out.str();
}

}  // namespace ofv
