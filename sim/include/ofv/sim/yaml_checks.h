/**
 * \file yaml_checks.h
 * \brief Checks of a loaded YAML document that yaml-cpp does not make:
 *        repeated keys (yaml-cpp keeps the first one silently), nesting depth
 *        and size (aliases are walked as often as they are used).
 */
#pragma once

#include <cstddef>
#include <string>

namespace YAML {
class Node;
}

namespace ofv::sim {

/// \brief Deepest nesting of maps and sequences check_yaml() accepts (a scenario needs 6).
constexpr int kMaxYamlDepth = 32;
/// \brief Most nodes (keys, values, items; aliases counted each time) check_yaml() accepts.
constexpr std::size_t kMaxYamlNodes = 100000;

/**
 * \brief Checks a document read from `source` (a file name, for the messages).
 * \throws std::invalid_argument "SOURCE:LINE: duplicate key 'KEY' at PATH
 *         (first on line N)" for a key repeated in one map; naming the file
 *         and line for a key that is not a word, and when the document nests
 *         deeper than kMaxYamlDepth or has more than kMaxYamlNodes nodes.
 */
void check_yaml(const YAML::Node& root, const std::string& source);

}  // namespace ofv::sim
