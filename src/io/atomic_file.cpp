#include "dynid/io/atomic_file.hpp"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include "dynid/common/error.hpp"

namespace dynid {
namespace {

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

}  // namespace

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty()) throw Error("output path is empty; give a file name");
  const std::string tmp = path + ".tmp." + std::to_string(static_cast<long>(::getpid()));
  std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
  if (!out) {
    throw Error(path + ": cannot write (" + std::strerror(errno) + "); check that directory '" +
                directory_of(path) + "' exists and is writable");
  }
  try {
    write(out);
    out.flush();
    if (!out) {
      throw Error(path + ": write failed (disk full?); free space or choose another output path");
    }
    out.close();
    if (out.fail()) throw Error(path + ": write failed on close; check the disk");
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
      throw Error(path + ": cannot rename the temporary file into place (" + std::strerror(errno) +
                  "); check that the path is not a directory");
    }
  } catch (...) {
    if (out.is_open()) out.close();
    std::remove(tmp.c_str());
    throw;
  }
}

void write_text_atomic(const std::string& path, const std::string& text) {
  write_file_atomic(path, [&](std::ostream& out) {
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  });
}

}  // namespace dynid
