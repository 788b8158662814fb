#include "dynid/model/robots.hpp"

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <system_error>

#include "dynid/common/error.hpp"
#include "dynid/model/mdh_loader.hpp"
#include "dynid/model/urdf_loader.hpp"

namespace dynid {

namespace fs = std::filesystem;

namespace {

bool robot_extension(const std::string& ext) {
  return ext == ".urdf" || ext == ".yaml" || ext == ".yml";
}

std::string join(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

}  // namespace

std::string builtin_robots_dir() {
  const char* env = std::getenv("DYNID_ROBOTS_DIR");
  if (env && *env) return env;
  return std::string(DYNID_SOURCE_DIR) + "/examples/robots";
}

std::vector<std::string> builtin_robot_names() {
  std::vector<std::string> names;
  std::error_code ec;
  for (fs::directory_iterator it(builtin_robots_dir(), ec), end; !ec && it != end;
       it.increment(ec)) {
    if (it->is_regular_file() && robot_extension(it->path().extension().string())) {
      names.push_back(it->path().stem().string());
    }
  }
  std::sort(names.begin(), names.end());
  names.erase(std::unique(names.begin(), names.end()), names.end());
  return names;
}

namespace {

Model load_robot_file(const std::string& name_or_path, std::vector<std::string>* warnings) {
  if (name_or_path.empty()) {
    throw Error("empty robot name; give a built-in name (" + join(builtin_robot_names()) +
                ") or a path to a .urdf or .yaml file");
  }
  const bool short_name = name_or_path.find('/') == std::string::npos &&
                          name_or_path.find('\\') == std::string::npos &&
                          name_or_path.find('.') == std::string::npos;
  if (short_name) {
    const fs::path dir = builtin_robots_dir();
    for (const char* ext : {".yaml", ".yml", ".urdf"}) {
      const fs::path p = dir / (name_or_path + ext);
      if (fs::is_regular_file(p)) {
        Model m = load_robot_file(p.string(), warnings);
        m.name = name_or_path;
        return m;
      }
    }
    throw Error("unknown built-in robot '" + name_or_path + "'; built-in robots are: " +
                join(builtin_robot_names()) + " (or give a path to a .urdf or .yaml file)");
  }
  const std::string ext = fs::path(name_or_path).extension().string();
  if (ext == ".urdf") return load_urdf(name_or_path, warnings);
  if (ext == ".yaml" || ext == ".yml") return load_yaml_model(name_or_path, warnings);
  throw Error("robot file '" + name_or_path + "' has extension '" + ext +
              "'; use a .urdf or a .yaml/.yml file (or a built-in name)");
}

}  // namespace

Model load_robot(const std::string& name_or_path) {
  return load_robot_file(name_or_path, nullptr);
}

LoadedRobot load_robot(const std::string& name_or_path, const RobotOptions& options) {
  LoadedRobot out;
  out.model = lock_joints(load_robot_file(name_or_path, options.strict ? nullptr : &out.warnings),
                          options.selection);
  return out;
}

}  // namespace dynid
