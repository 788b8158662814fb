#include "dynid/io/atomic_file.hpp"

#include <fcntl.h>
#include <sys/random.h>
#include <sys/stat.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <cstring>
#include <mutex>
#include <streambuf>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"

namespace dynid {
namespace {

// ---- The process-wide registry of temporary files being written --------------------------------
//
// A fixed array, so that the signal handler reads it without allocating or locking: a slot is
// free (0), being filled (1) or holds a temporary file the handler must remove (2). The handler
// removes with unlinkat relative to the directory descriptor the writer holds open, so a change of
// working directory (dynid run changes it per stage) cannot redirect it.

constexpr int kSlots = 64;
constexpr std::size_t kNameBytes = 256;  // NAME_MAX + 1 on Linux

struct Slot {
  std::atomic<int> state{0};
  int dirfd = -1;
  char name[kNameBytes] = {};
};

Slot g_slots[kSlots];
std::atomic<int> g_in_flight{0};
static_assert(std::atomic<int>::is_always_lock_free, "the signal handler needs lock-free atomics");

extern "C" void remove_temporary_files_and_reraise(int sig) {
  const int saved = errno;
  for (Slot& s : g_slots) {
    if (s.state.load(std::memory_order_acquire) == 2) ::unlinkat(s.dirfd, s.name, 0);
  }
  errno = saved;
  // The signal is blocked while this handler runs: raised again with the default action, it ends
  // the process (with the status a shell reports for that signal) as soon as the handler returns.
  std::signal(sig, SIG_DFL);
  std::raise(sig);
}

// Installed once, over a default disposition only: a program embedding the library (Python) that
// handles or ignores these signals itself keeps its own handling.
void install_signal_handlers() {
  static std::once_flag once;
  std::call_once(once, [] {
    for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
      struct sigaction old {};
      if (::sigaction(sig, nullptr, &old) != 0) continue;
      if ((old.sa_flags & SA_SIGINFO) != 0 || old.sa_handler != SIG_DFL) continue;
      struct sigaction sa {};
      sa.sa_handler = &remove_temporary_files_and_reraise;
      sigfillset(&sa.sa_mask);
      sa.sa_flags = 0;
      ::sigaction(sig, &sa, nullptr);
    }
  });
}

// A slot holding `name` (state 1, not yet removed by the handler), or -1 when all are taken: the
// file is then written without signal cleanup.
int reserve_slot(int dirfd, const std::string& name) {
  if (name.size() >= kNameBytes) return -1;
  for (int i = 0; i < kSlots; ++i) {
    int expected = 0;
    if (g_slots[i].state.compare_exchange_strong(expected, 1, std::memory_order_acq_rel)) {
      g_slots[i].dirfd = dirfd;
      std::memcpy(g_slots[i].name, name.c_str(), name.size() + 1);
      return i;
    }
  }
  return -1;
}

void release_slot(int slot) {
  if (slot >= 0) g_slots[slot].state.store(0, std::memory_order_release);
}

// ---- Paths --------------------------------------------------------------------------------------

std::string directory_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  if (slash == std::string::npos) return ".";
  return slash == 0 ? "/" : path.substr(0, slash);
}

std::string base_of(const std::string& path) {
  const auto slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string flag_prefix(const std::string& flag) {
  return flag.empty() ? "" : flag + " ";
}

// What an existing entry is, for the message; empty for a regular file (or nothing there).
const char* special_kind(mode_t mode) {
  if (S_ISREG(mode)) return "";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISFIFO(mode)) return "a FIFO (named pipe)";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a regular file";
}

// Throws when the entry `base` of `dirfd` (or what a symbolic link there points to) is a
// directory, device, FIFO or socket. Nothing there, a regular file, or a dangling link is fine.
void check_target_at(int dirfd, const std::string& base, const std::string& path,
                     const std::string& flag) {
  struct stat st {};
  if (::fstatat(dirfd, base.c_str(), &st, AT_SYMLINK_NOFOLLOW) != 0) return;
  if (S_ISLNK(st.st_mode) && ::fstatat(dirfd, base.c_str(), &st, 0) != 0) return;
  const char* kind = special_kind(st.st_mode);
  if (*kind == '\0') return;
  if (S_ISDIR(st.st_mode)) {
    throw Error(flag_prefix(flag) + "'" + path +
                "' is a directory; give the path of a file to write (e.g. " +
                (path.empty() || path.back() == '/' ? path : path + "/") + "result.json)");
  }
  throw Error(flag_prefix(flag) + "'" + path + "' is " + kind +
              ", not a regular file; dynid writes an output as a new file renamed into place and "
              "will not replace it: give the path of a regular file");
}

// A name for the temporary file: the target's name (shortened so that the result stays within
// NAME_MAX), the pid and 64 random bits.
std::string temporary_name(const std::string& base) {
  std::uint64_t r = 0;
  if (::getrandom(&r, sizeof r, GRND_NONBLOCK) != static_cast<ssize_t>(sizeof r)) {
    static std::atomic<std::uint64_t> counter{0};
    r = static_cast<std::uint64_t>(std::chrono::steady_clock::now().time_since_epoch().count()) ^
        (counter.fetch_add(1) * 0x9E3779B97F4A7C15ull);
  }
  char hex[17];
  std::snprintf(hex, sizeof hex, "%016llx", static_cast<unsigned long long>(r));
  return base.substr(0, 200) + ".tmp." + std::to_string(static_cast<long>(::getpid())) + "." + hex;
}

// ---- Writing to a file descriptor ---------------------------------------------------------------

class FdBuf : public std::streambuf {
 public:
  explicit FdBuf(int fd) : fd_(fd), buffer_(1 << 16) { reset(); }
  int error() const { return error_; }

 protected:
  int_type overflow(int_type c) override {
    if (!drain()) return traits_type::eof();
    if (!traits_type::eq_int_type(c, traits_type::eof())) {
      *pptr() = traits_type::to_char_type(c);
      pbump(1);
    }
    return traits_type::not_eof(c);
  }
  int sync() override { return drain() ? 0 : -1; }

 private:
  bool drain() {
    const char* p = pbase();
    std::size_t left = static_cast<std::size_t>(pptr() - pbase());
    while (left > 0) {
      const ssize_t n = ::write(fd_, p, left);
      if (n < 0) {
        if (errno == EINTR) continue;
        error_ = errno;
        return false;
      }
      p += n;
      left -= static_cast<std::size_t>(n);
    }
    reset();
    return true;
  }
  void reset() { setp(buffer_.data(), buffer_.data() + buffer_.size()); }
  int fd_;
  int error_ = 0;
  std::vector<char> buffer_;
};

// Closes a descriptor once.
struct Fd {
  int fd = -1;
  ~Fd() { close(); }
  int close() {
    const int r = fd >= 0 ? ::close(fd) : 0;
    fd = -1;
    return r;
  }
};

}  // namespace

// A file written completely to its temporary name, waiting for OutputBatch::commit().
struct OutputBatch::Pending {
  int dirfd = -1;  // owned: closed when the entry is done
  int slot = -1;
  std::string tmp, base, path;
};

namespace {

thread_local std::vector<OutputBatch::Pending>* t_batch = nullptr;

void finish_pending(OutputBatch::Pending& p, bool remove) {
  if (remove) ::unlinkat(p.dirfd, p.tmp.c_str(), 0);
  release_slot(p.slot);
  g_in_flight.fetch_sub(1);
  ::close(p.dirfd);
}

}  // namespace

OutputBatch::OutputBatch() : pending_(new std::vector<Pending>) {
  if (t_batch != nullptr) {
    delete pending_;
    throw Error("internal: an output batch is already open on this thread");
  }
  t_batch = pending_;
}

OutputBatch::~OutputBatch() {
  if (t_batch == pending_) t_batch = nullptr;
  for (Pending& p : *pending_) finish_pending(p, true);
  delete pending_;
}

void OutputBatch::commit() {
  t_batch = nullptr;
  std::vector<Pending> pending = std::move(*pending_);
  pending_->clear();
  std::size_t done = 0;
  try {
    for (; done < pending.size(); ++done) {
      Pending& p = pending[done];
      check_target_at(p.dirfd, p.base, p.path, "");
      if (::renameat(p.dirfd, p.tmp.c_str(), p.dirfd, p.base.c_str()) != 0) {
        throw Error(p.path + ": cannot rename the temporary file into place (" +
                    std::strerror(errno) + "); check that the path is not a directory");
      }
      finish_pending(p, false);
    }
  } catch (...) {
    for (std::size_t i = done; i < pending.size(); ++i) finish_pending(pending[i], true);
    throw;
  }
}

void check_output_target(const std::string& path, const std::string& flag) {
  if (path.empty()) return;
  check_target_at(AT_FDCWD, path, path, flag);
}

int temporary_files_in_flight() {
  return g_in_flight.load();
}

void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write) {
  if (path.empty()) throw Error("output path is empty; give a file name");
  const std::string dir = directory_of(path), base = base_of(path);
  if (base.empty() || base == "." || base == "..") {
    throw Error("'" + path + "' is a directory; give the path of a file to write");
  }
  Fd dirfd;
  dirfd.fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (dirfd.fd < 0) {
    throw Error(path + ": cannot write (" + std::strerror(errno) + "); check that directory '" +
                dir + "' exists and is writable");
  }
  check_target_at(dirfd.fd, base, path, "");
  install_signal_handlers();

  // O_EXCL|O_NOFOLLOW: an entry already at the name (a planted symbolic link, a FIFO, a file) is
  // never opened; another random name is tried.
  Fd fd;
  std::string tmp;
  int slot = -1;
  for (int attempt = 0; attempt < 100 && fd.fd < 0; ++attempt) {
    tmp = temporary_name(base);
    slot = reserve_slot(dirfd.fd, tmp);
    fd.fd = ::openat(dirfd.fd, tmp.c_str(),
                     O_WRONLY | O_CREAT | O_EXCL | O_NOFOLLOW | O_CLOEXEC | O_NOCTTY, 0666);
    if (fd.fd >= 0) {
      if (slot >= 0) g_slots[slot].state.store(2, std::memory_order_release);
      break;
    }
    const int err = errno;
    release_slot(slot);
    slot = -1;
    if (err != EEXIST) {
      throw Error(path + ": cannot write (" + std::strerror(err) + "); check that directory '" +
                  dir + "' exists and is writable");
    }
  }
  if (fd.fd < 0) {
    throw Error(path + ": cannot create a temporary file in '" + dir +
                "' (every name tried exists); clean the folder of *.tmp.* files");
  }
  g_in_flight.fetch_add(1);
  const auto discard = [&] {
    fd.close();
    ::unlinkat(dirfd.fd, tmp.c_str(), 0);
    release_slot(slot);
    g_in_flight.fetch_sub(1);
  };
  try {
    FdBuf buf(fd.fd);
    std::ostream out(&buf);
    write(out);
    out.flush();
    if (!out) {
      throw Error(path + ": write failed (" +
                  (buf.error() ? std::strerror(buf.error()) : "stream error") +
                  "); free disk space or choose another output path");
    }
    if (fd.close() != 0) {
      throw Error(path + ": write failed on close (" + std::strerror(errno) + "); check the disk");
    }
    if (t_batch != nullptr) {
      // Renamed by OutputBatch::commit(), with the other outputs of the command.
      t_batch->push_back({dirfd.fd, slot, tmp, base, path});
      dirfd.fd = -1;
      return;
    }
    // Again just before the rename: a device or FIFO created at the name meanwhile is refused.
    check_target_at(dirfd.fd, base, path, "");
    if (::renameat(dirfd.fd, tmp.c_str(), dirfd.fd, base.c_str()) != 0) {
      throw Error(path + ": cannot rename the temporary file into place (" + std::strerror(errno) +
                  "); check that the path is not a directory");
    }
  } catch (...) {
    discard();
    throw;
  }
  release_slot(slot);
  g_in_flight.fetch_sub(1);
}

void write_text_atomic(const std::string& path, const std::string& text) {
  write_file_atomic(path, [&](std::ostream& out) {
    out.write(text.data(), static_cast<std::streamsize>(text.size()));
  });
}

}  // namespace dynid
