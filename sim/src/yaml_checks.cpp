// Checks of a loaded YAML document (ofv/sim/yaml_checks.h).
#include "ofv/sim/yaml_checks.h"

#include <yaml-cpp/yaml.h>

#include <set>
#include <stdexcept>

namespace ofv::sim {

namespace {

[[noreturn]] void fail(const YAML::Node& at, const std::string& source, const std::string& what) {
  throw std::invalid_argument(source + ":" + std::to_string(at.Mark().line + 1) + ": " + what);
}

void walk(const YAML::Node& node, const std::string& source, int depth, std::size_t& nodes) {
  if (++nodes > kMaxYamlNodes) {
    fail(node, source, "more than " + std::to_string(kMaxYamlNodes) + " nodes");
  }
  if (depth > kMaxYamlDepth) {
    fail(node, source, "nested deeper than " + std::to_string(kMaxYamlDepth) + " levels");
  }
  if (node.IsMap()) {
    std::set<std::string> keys;
    for (const auto& item : node) {
      if (item.first.IsScalar() && !keys.insert(item.first.Scalar()).second) {
        std::string key = item.first.Scalar();
        fail(item.first, source,
             "duplicate key '" + (key.size() > 60 ? key.substr(0, 60) + "..." : key) + "'");
      }
      walk(item.first, source, depth + 1, nodes);
      walk(item.second, source, depth + 1, nodes);
    }
  } else if (node.IsSequence()) {
    for (const auto& item : node) {
      walk(item, source, depth + 1, nodes);
    }
  }
}

}  // namespace

void check_yaml(const YAML::Node& root, const std::string& source) {
  std::size_t nodes = 0;
  walk(root, source, 0, nodes);
}

}  // namespace ofv::sim
