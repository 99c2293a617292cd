// YAML files the bench reads (board files, scenarios), parsed with bounds.
// yaml-cpp keeps one of two equal keys silently, resolves an alias to the
// very node it names - so `a: &x [*x]` is a node that contains itself - and
// shares aliased nodes, so ten nested aliases of ten can stand for 10^10
// nodes. The bench makes all of these a file:line error before anything
// walks the tree.
#pragma once

#include <yaml-cpp/yaml.h>

#include <cstddef>
#include <string>

namespace avrbench {

// Nodes a file may expand to, aliases counted at each use (docs/CLI.md,
// "Limits"); the largest standard board has about 600.
inline constexpr std::size_t kMaxYamlNodes = 1'000'000;
// Nesting deeper than this is no board or scenario (they use 4 levels).
inline constexpr std::size_t kMaxYamlDepth = 64;

// Parses `text` (read from `path`) and checks it: syntax errors, an alias
// that refers to a node containing it, more than kMaxYamlNodes nodes once
// aliases are expanded, nesting deeper than kMaxYamlDepth, a key that is not
// a single value, a key given twice - each a BadInput "path:line: ...".
YAML::Node load_yaml(const std::string& text, const std::string& path);

// Throws BadInput "path:line: duplicate key 'k'" for a key a map holds twice,
// at any depth, and for a key that is not a single value. (load_yaml does
// this; for nodes built otherwise.)
void check_unique_keys(const YAML::Node& node, const std::string& path);

// "path:line" of a node.
std::string yaml_where(const std::string& path, const YAML::Node& node);

// A node's single value, or BadInput "path:line: <what> must be a single value".
std::string yaml_scalar(const YAML::Node& node, const std::string& path, const std::string& what);

}  // namespace avrbench
