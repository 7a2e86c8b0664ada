// The settings grid of `ofv compare`: YAML to a list of named variants.
#include "ofv/loop/grid.h"
#include "ofv/text_file.h"

#include "ofv/sim/yaml_checks.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <fstream>
#include <map>
#include <set>
#include <sstream>
#include <stdexcept>

namespace ofv {

namespace {

[[noreturn]] void grid_error(const std::string& source, const std::string& key,
                             const std::string& what) {
  throw std::invalid_argument(source + ": " + key + ": " + what);
}

std::string scalar_text(const YAML::Node& n, const std::string& source, const std::string& key) {
  if (!n.IsScalar()) grid_error(source, key, "expected a single value (number or word)");
  return n.Scalar();
}

// One `name: value` map of settings, in file order.
std::vector<std::pair<std::string, std::string>> settings_map(const YAML::Node& n,
                                                              const std::string& source,
                                                              const std::string& key) {
  if (!n.IsMap()) grid_error(source, key, "expected a map of setting: value");
  std::vector<std::pair<std::string, std::string>> out;
  for (const auto& item : n) {
    const std::string name = item.first.as<std::string>();
    out.emplace_back(name, scalar_text(item.second, source, key + "." + name));
  }
  return out;
}

}  // namespace

Grid grid_from_yaml(const std::string& text, const std::string& source) {
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw std::invalid_argument(source + ": invalid YAML: " + e.what());
  }
  if (!root.IsMap()) throw std::invalid_argument(source + ": expected a map with 'variants' and/or 'axes'");
  sim::check_yaml(root, source);  // repeated keys, keys that are not words, depth, size
  Grid grid;
  std::vector<Variant> base;
  std::vector<std::pair<std::string, std::string>> common;
  std::vector<std::pair<std::string, std::vector<std::string>>> axes;
  for (const auto& item : root) {
    const std::string key = item.first.as<std::string>();
    const YAML::Node& n = item.second;
    if (key == "name") {
      grid.name = scalar_text(n, source, key);
    } else if (key == "seeds") {
      const std::string range = "expected an integer in 1.." + std::to_string(kMaxSeeds) + ", got ";
      try {
        grid.seeds = n.as<int>();
      } catch (const YAML::Exception&) {
        grid_error(source, key, range + "'" + scalar_text(n, source, key) + "'");
      }
      if (grid.seeds < 1 || grid.seeds > kMaxSeeds) grid_error(source, key, range + std::to_string(grid.seeds));
    } else if (key == "set") {
      common = settings_map(n, source, key);
    } else if (key == "variants") {
      if (!n.IsSequence() || n.size() == 0) grid_error(source, key, "expected a non-empty list of {name, set}");
      if (n.size() > kMaxVariants) {
        grid_error(source, key, std::to_string(n.size()) + " variants, more than " + std::to_string(kMaxVariants));
      }
      for (std::size_t i = 0; i < n.size(); ++i) {
        const std::string at = key + "[" + std::to_string(i) + "]";
        if (!n[i].IsMap()) grid_error(source, at, "expected {name: ..., set: {...}}");
        Variant v;
        for (const auto& f : n[i]) {
          const std::string fk = f.first.as<std::string>();
          if (fk == "name") {
            v.name = scalar_text(f.second, source, at + ".name");
          } else if (fk == "set") {
            v.settings = settings_map(f.second, source, at + ".set");
          } else {
            grid_error(source, at + "." + fk, "unknown key (expected name, set)");
          }
        }
        if (v.name.empty()) grid_error(source, at + ".name", "missing");
        base.push_back(v);
      }
    } else if (key == "axes") {
      if (!n.IsMap() || n.size() == 0) grid_error(source, key, "expected a non-empty map of setting: [values]");
      for (const auto& a : n) {
        const std::string name = a.first.as<std::string>();
        if (!a.second.IsSequence() || a.second.size() == 0) {
          grid_error(source, key + "." + name, "expected a non-empty list of values");
        }
        std::vector<std::string> values;
        for (std::size_t i = 0; i < a.second.size(); ++i) {
          values.push_back(scalar_text(a.second[i], source, key + "." + name + "[" + std::to_string(i) + "]"));
        }
        axes.emplace_back(name, values);
      }
    } else {
      grid_error(source, key, "unknown key (expected name, seeds, set, variants, axes)");
    }
  }
  if (base.empty() && axes.empty()) {
    throw std::invalid_argument(source + ": variants: missing (a grid needs 'variants' and/or 'axes')");
  }
  // Counted before anything is expanded: a few lines of axes can multiply
  // to more variants than memory holds. Overflow-safe: n * size > max
  // exactly when size > max / n.
  std::size_t count = std::max<std::size_t>(base.size(), 1);
  std::string product = std::to_string(count);
  for (const auto& [name, values] : axes) {
    product += " x " + std::to_string(values.size());
    if (values.size() > kMaxVariants / count) {
      grid_error(source, "axes." + name, "the grid would have more than " + std::to_string(kMaxVariants) +
                                             " variants (" + product + (axes.back().first == name ? "" : " x ...") + ")");
    }
    count *= values.size();
  }
  if (base.empty()) base.push_back(Variant{"", {}});
  // The grid's own settings come first: a variant's may override them.
  for (Variant& v : base) v.settings.insert(v.settings.begin(), common.begin(), common.end());
  // Cartesian product of the axes, applied after each variant's own settings.
  std::vector<Variant> expanded = base;
  for (const auto& [name, values] : axes) {
    std::vector<Variant> next;
    for (const Variant& v : expanded) {
      for (const std::string& value : values) {
        Variant w = v;
        w.settings.emplace_back(name, value);
        w.name += (w.name.empty() ? "" : ",") + name + "=" + value;
        next.push_back(w);
      }
    }
    expanded = next;
  }
  std::set<std::string> names;
  for (Variant& v : expanded) {
    if (v.name.empty()) v.name = "default";
    if (!names.insert(v.name).second) {
      throw std::invalid_argument(source + ": variants: the name '" + v.name + "' is used twice");
    }
  }
  grid.variants = expanded;
  return grid;
}

Grid read_grid(const std::string& path) {
  constexpr std::uintmax_t kMaxGridBytes = 1 << 20;
  return grid_from_yaml(read_text_file(path, kMaxGridBytes, "grid"), path);
}

}  // namespace ofv
