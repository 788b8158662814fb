#pragma once

#include <string>
#include <vector>

#include "dynid/model/model.hpp"

namespace dynid {

/// Folder holding the built-in robots: $DYNID_ROBOTS_DIR if set and non-empty, else
/// DYNID_SOURCE_DIR "/examples/robots" (compile definition of robots.cpp).
std::string builtin_robots_dir();

/// Short names of the built-in robots (file stems of the *.urdf, *.yaml, *.yml files in
/// builtin_robots_dir()), sorted. Empty when the folder is missing.
std::vector<std::string> builtin_robot_names();

/// Loads a robot by short name or path and returns a finalized Model. A short name (no '/' and no
/// '.') is a built-in: builtin_robots_dir()/<name>.yaml, .yml or .urdf; its Model::name is the
/// short name. A path ending in .urdf goes to load_urdf, .yaml/.yml to load_yaml_model.
/// Model::source is the file that was read. Throws dynid::Error for an unknown built-in (the
/// message lists the built-in names), an unsupported extension, and every loader error.
Model load_robot(const std::string& name_or_path);

}  // namespace dynid
