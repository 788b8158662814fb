#include "dynid/model/robots.hpp"

#include <dlfcn.h>

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

// The file this code was loaded from: libdynid.so, the Python extension dynid/_core*.so, or the
// program it is linked into. For a program glibc reports argv[0], which may be a bare name found
// on PATH: a path that does not resolve is no answer (the caller also asks /proc/self/exe).
fs::path file_of_this_code() {
  Dl_info info{};
  // The address of a function of this file names the object that holds it (dladdr(3)).
  if (dladdr(reinterpret_cast<void*>(&builtin_robots_dir), &info) == 0 ||
      info.dli_fname == nullptr || *info.dli_fname == '\0') {
    return {};
  }
  std::error_code ec;
  const fs::path file = fs::canonical(info.dli_fname, ec);
  return ec ? fs::path() : file;
}

// The robots installed with the code, relative to it so that a moved prefix keeps them:
// `cmake --install` puts them in <prefix>/share/dynid/robots beside <prefix>/bin/dynid and
// <prefix>/lib/libdynid.so; the Python package (setup.py) carries them as dynid/robots beside its
// extension module. The code in a shared object looks beside that object only: the program that
// loaded it (python3, a user's controller) is not dynid's, and its prefix may hold another dynid.
// Empty when none is found (a build tree).
fs::path installed_robots_dir() {
  std::error_code ec;
  const fs::path program = fs::canonical("/proc/self/exe", ec);
  const fs::path code = file_of_this_code();
  std::vector<fs::path> candidates;
  if (!code.empty() && code != program) {
    candidates = {code.parent_path() / ".." / "share" / "dynid" / "robots",
                  code.parent_path() / "robots"};
  } else if (!program.empty()) {
    candidates = {program.parent_path() / ".." / "share" / "dynid" / "robots"};
  }
  for (const fs::path& candidate : candidates) {
    if (fs::is_directory(candidate, ec)) return candidate.lexically_normal();
  }
  return {};
}

}  // namespace

std::string builtin_robots_dir() {
  const char* env = std::getenv("DYNID_ROBOTS_DIR");
  if (env && *env) return env;
  const fs::path installed = installed_robots_dir();
  if (!installed.empty()) return installed.string();
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
