#pragma once
// The YAML files hiveslam reads (settings, EuRoC sensor.yaml) are maps of keys. Anything else
// would make yaml-cpp throw its own exceptions on the first lookup, without the file's name (a
// fuzzer finding: a file holding one word); these readers turn every such case into one
// InputError line naming the file.
#include <filesystem>
#include <string>

#include <yaml-cpp/yaml.h>

namespace hiveslam::io {

// The file's top-level map; an empty file is an empty map. OpenCV-written files start with
// "%YAML:1.0", which YAML parsers reject: directive lines are dropped first.
YAML::Node loadYamlMap(const std::filesystem::path& path);

// parent[key] where it is a map (`camera:`, `T_BS:`); an undefined node where it is absent.
YAML::Node mapAt(const YAML::Node& parent, const std::string& key, const std::filesystem::path& path);

}  // namespace hiveslam::io
