#include "io/yaml_file.hpp"

#include <fmt/format.h>

#include <fstream>

#include "common/error.hpp"

namespace hiveslam::io {

YAML::Node loadYamlMap(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw InputError("settings file not found: " + path.string());
  std::ifstream in(path);
  std::string text, line;
  while (std::getline(in, line))
    if (line.rfind('%', 0) != 0) text += line + "\n";
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(fmt::format("{}:{}: YAML error: {}", path.string(), e.mark.line + 1, e.msg));
  }
  if (root.IsNull()) return YAML::Node(YAML::NodeType::Map);
  if (!root.IsMap()) throw InputError(path.string() + ": not a YAML map of keys");
  return root;
}

YAML::Node mapAt(const YAML::Node& parent, const std::string& key, const std::filesystem::path& path) {
  const YAML::Node node = parent[key];
  if (node && !node.IsMap()) throw InputError(path.string() + ": '" + key + "' is not a map of keys");
  return node;
}

}  // namespace hiveslam::io
