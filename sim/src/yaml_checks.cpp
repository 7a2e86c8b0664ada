// Checks of a loaded YAML document (ofv/sim/yaml_checks.h).
#include "ofv/sim/yaml_checks.h"

#include <yaml-cpp/yaml.h>

#include <map>
#include <stdexcept>

namespace ofv::sim {

namespace {

[[noreturn]] void fail(const YAML::Node& at, const std::string& source, const std::string& what) {
  throw std::invalid_argument(source + ":" + std::to_string(at.Mark().line + 1) + ": " + what);
}

// `path`: where the node is (variants[0].set), for the messages.
void walk(const YAML::Node& node, const std::string& source, const std::string& path, int depth, std::size_t& nodes) {
  if (++nodes > kMaxYamlNodes) {
    fail(node, source, "more than " + std::to_string(kMaxYamlNodes) + " nodes");
  }
  if (depth > kMaxYamlDepth) {
    fail(node, source, "nested deeper than " + std::to_string(kMaxYamlDepth) + " levels");
  }
  if (node.IsMap()) {
    std::map<std::string, int> first_line;
    for (const auto& item : node) {
      if (!item.first.IsScalar()) fail(item.first, source, "a key must be a word, not a list or a map");
      std::string key = item.first.Scalar();
      if (key.size() > 60) key = key.substr(0, 60) + "...";
      const std::string at = path.empty() ? key : path + "." + key;
      const auto [first, inserted] = first_line.emplace(key, item.first.Mark().line + 1);
      if (!inserted) {
        fail(item.first, source,
             "duplicate key '" + key + "' at " + at + " (first on line " + std::to_string(first->second) + ")");
      }
      walk(item.second, source, at, depth + 1, nodes);
    }
  } else if (node.IsSequence()) {
    std::size_t i = 0;
    for (const auto& item : node) {
      walk(item, source, path + "[" + std::to_string(i++) + "]", depth + 1, nodes);
    }
  }
}

}  // namespace

void check_yaml(const YAML::Node& root, const std::string& source) {
  std::size_t nodes = 0;
  walk(root, source, "", 0, nodes);
}

}  // namespace ofv::sim
