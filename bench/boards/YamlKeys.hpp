// YAML files the bench reads (board files, scenarios): yaml-cpp keeps one of
// two equal keys silently; the bench makes that a file:line error.
#pragma once

#include <yaml-cpp/yaml.h>

#include <string>

namespace avrbench {

// Throws BadInput "path:line: duplicate key 'k'" for a key a map holds twice,
// at any depth, and for a key that is not a single value.
void check_unique_keys(const YAML::Node& node, const std::string& path);

}  // namespace avrbench
