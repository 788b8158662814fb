#include "dynid/common/input_file.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "dynid/common/error.hpp"

namespace dynid {

std::string read_regular_file(const std::string& path, std::size_t cap, const std::string& what,
                              bool no_follow) {
  const std::string shown = what + " '" + path + "'";
  const int fd = ::open(
      path.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC | O_NOCTTY | (no_follow ? O_NOFOLLOW : 0));
  if (fd < 0) {
    throw Error(shown + ": cannot open (" + std::strerror(errno) + "); check the path");
  }
  struct Close {
    int fd;
    ~Close() { ::close(fd); }
  } closer{fd};
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    throw Error(shown + " is not a regular file (a folder, device or FIFO); give a file");
  }
  const auto too_large = [&] {
    throw Error(shown + " is larger than " + std::to_string(cap >> 20) +
                " MiB, the limit for this input; give a smaller file or split it");
  };
  if (static_cast<std::size_t>(st.st_size) > cap) too_large();
  std::string text;
  char buffer[1 << 16];
  for (;;) {
    const ssize_t n = ::read(fd, buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) throw Error(shown + ": read error (" + std::strerror(errno) + "); check the file");
    if (n == 0) break;
    if (text.size() + static_cast<std::size_t>(n) > cap) too_large();
    text.append(buffer, static_cast<std::size_t>(n));
  }
  return text;
}

void require_regular_file(const std::string& path, const std::string& what) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return;
  if (S_ISREG(st.st_mode)) return;
  throw Error(what + " '" + path + "' is not a regular file (" +
              (S_ISDIR(st.st_mode)    ? "a folder"
               : S_ISFIFO(st.st_mode) ? "a FIFO"
               : S_ISSOCK(st.st_mode) ? "a socket"
                                      : "a device") +
              "): reading it could wait or run forever; give a file");
}

}  // namespace dynid
