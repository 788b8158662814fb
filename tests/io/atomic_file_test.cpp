// write_file_atomic (issue 27 item 2): a temporary file that a planted link cannot redirect, a
// rename that never replaces a FIFO, socket or device, a symbolic link at the target replaced and
// not written through, the usual permissions, and SIGINT/SIGTERM/SIGHUP removing the temporary
// file before the process ends with that signal. Special files are made in the test's own
// folder (a FIFO, a socket, a device node, a link to /dev/null); /dev is never written.
#include "dynid/io/atomic_file.hpp"

#include <sys/socket.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>
#include <sys/un.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include <gtest/gtest.h>

#include "io/io_test_support.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;
using test::error_of;
using test::TempDir;

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

bool is_fifo(const std::string& path) {
  struct stat st {};
  return ::lstat(path.c_str(), &st) == 0 && S_ISFIFO(st.st_mode);
}

TEST(AtomicFile, PlantedLinksAtThePredictableTemporaryNameAreNotFollowed) {
  TempDir dir;
  const std::string victim = dir.write("victim.txt", "precious\n");
  const std::string path = dir.file("result.json");
  // The names an attacker could predict: the old <out>.tmp.<pid> and <out>.tmp.
  const std::string old_name = path + ".tmp." + std::to_string(::getpid());
  fs::create_symlink(victim, old_name);
  fs::create_symlink(victim, path + ".tmp");
  write_text_atomic(path, "result\n");
  EXPECT_EQ(slurp(path), "result\n");
  EXPECT_EQ(slurp(victim), "precious\n");
  EXPECT_TRUE(fs::is_symlink(old_name));  // left as it was, not written through or removed
  EXPECT_EQ(dir.entries(), 4);            // victim, two links, the result: no temporary file
  EXPECT_EQ(temporary_files_in_flight(), 0);
}

TEST(AtomicFile, TemporaryFileIsNewInTheTargetFolder) {
  TempDir dir;
  fs::create_directories(dir.path() / "sub");
  const std::string path = dir.file("sub/out.csv");
  std::string seen;
  write_file_atomic(path, [&](std::ostream& out) {
    out << "a,b\n";
    for (const auto& e : fs::directory_iterator(dir.path() / "sub")) {
      seen += e.path().filename().string() + ";";
    }
    EXPECT_EQ(temporary_files_in_flight(), 1);
  });
  // One entry while writing, named after the target, the pid and a random part.
  const std::string prefix = "out.csv.tmp." + std::to_string(::getpid()) + ".";
  EXPECT_EQ(seen.rfind(prefix, 0), 0u) << seen;
  EXPECT_EQ(seen.find(';'), seen.size() - 1) << seen;
  EXPECT_EQ(slurp(path), "a,b\n");
  EXPECT_EQ(dir.entries(), 1);
}

TEST(AtomicFile, NewFileHasTheUsualPermissions) {
  TempDir dir;
  const mode_t mask = ::umask(022);
  const std::string path = dir.file("x.json");
  write_text_atomic(path, "{}\n");
  ::umask(mask);
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 0777, 0644u);  // 0666 less the umask, as an ordinary open would give
}

TEST(AtomicFile, RefusesToReplaceAFifoOrASocket) {
  TempDir dir;
  const std::string fifo = dir.file("pipe");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  bool called = false;
  std::string m = error_of([&] {
    write_file_atomic(fifo, [&](std::ostream& out) {
      called = true;
      out << "x";
    });
  });
  EXPECT_HAS(m, "pipe' is a FIFO (named pipe), not a regular file");
  EXPECT_HAS(m, "give the path of a regular file");
  EXPECT_EQ(m.find('\n'), std::string::npos) << m;
  EXPECT_FALSE(called);  // refused before any work
  EXPECT_TRUE(is_fifo(fifo));
  EXPECT_EQ(dir.entries(), 1);

  // A link to the FIFO is refused as well (rename would replace the link, but the user meant the
  // FIFO's file: nothing is written and the link stays).
  fs::create_symlink(fifo, dir.file("alias"));
  EXPECT_HAS(error_of([&] { write_text_atomic(dir.file("alias"), "x"); }), "is a FIFO");
  EXPECT_TRUE(fs::is_symlink(dir.file("alias")));

  const std::string sock = dir.file("sock");
  const int fd = ::socket(AF_UNIX, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_un addr{};
  addr.sun_family = AF_UNIX;
  if (sock.size() < sizeof(addr.sun_path)) {
    std::strcpy(addr.sun_path, sock.c_str());
    ASSERT_EQ(::bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0);
    EXPECT_HAS(error_of([&] { write_text_atomic(sock, "x"); }), "sock' is a socket");
    EXPECT_TRUE(fs::is_socket(sock));
  }
  ::close(fd);
  EXPECT_HAS(error_of([&] { check_output_target(fifo, "--out"); }), "--out '");
  EXPECT_EQ(temporary_files_in_flight(), 0);
}

// As root, `-o /dev/null` replaced the system's /dev/null. Through a link in the test's folder
// (were the check missing, the rename would replace the link, never /dev/null itself), and as a
// character device made in the test's folder where the process may create one (root).
TEST(AtomicFile, RefusesToReplaceADeviceNode) {
  TempDir dir;
  fs::create_symlink("/dev/null", dir.file("null"));
  bool called = false;
  const std::string m = error_of([&] {
    write_file_atomic(dir.file("null"), [&](std::ostream& out) {
      called = true;
      out << "x";
    });
  });
  EXPECT_HAS(m, "null' is a character device, not a regular file");
  EXPECT_FALSE(called);  // refused before any work
  EXPECT_TRUE(fs::is_symlink(dir.file("null")));
  EXPECT_HAS(error_of([&] { check_output_target("/dev/null", "-o"); }), "a character device");
  EXPECT_EQ(dir.entries(), 1);
  const std::string node = dir.file("device");
  if (::mknod(node.c_str(), S_IFCHR | 0600, makedev(1, 3)) != 0) {
    GTEST_SKIP() << "mknod is not permitted here (" << std::strerror(errno)
                 << "); the link case above ran";
  }
  EXPECT_HAS(error_of([&] { write_text_atomic(node, "x"); }), "device' is a character device");
  EXPECT_TRUE(fs::is_character_file(node));
  EXPECT_EQ(dir.entries(), 2);
  EXPECT_EQ(temporary_files_in_flight(), 0);
}

TEST(AtomicFile, SymbolicLinkAtTheTargetIsReplacedNotWrittenThrough) {
  TempDir dir;
  const std::string elsewhere = dir.write("elsewhere.csv", "keep\n");
  const std::string path = dir.file("out.csv");
  fs::create_symlink(elsewhere, path);
  write_text_atomic(path, "new\n");
  EXPECT_FALSE(fs::is_symlink(path));
  EXPECT_EQ(slurp(path), "new\n");
  EXPECT_EQ(slurp(elsewhere), "keep\n");
}

TEST(AtomicFile, DirectoryTargetIsRefusedBeforeAnyWork) {
  TempDir dir;
  fs::create_directories(dir.path() / "d");
  const std::string m = error_of([&] { write_text_atomic(dir.file("d"), "x"); });
  EXPECT_HAS(m, "is a directory");
  EXPECT_HAS(error_of([&] { write_text_atomic(dir.file("d") + "/", "x"); }), "is a directory");
  EXPECT_EQ(dir.entries(), 1);
}

// In a child process: write `path` and raise `sig` halfway; the child must end by that signal
// with no temporary file left.
void expect_signal_removes_temporary(int sig, bool old_content) {
  TempDir dir;
  const std::string path = dir.file("result.json");
  if (old_content) write_text_atomic(path, "old\n");
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    struct sigaction now {};
    ::sigaction(sig, nullptr, &now);
    if (now.sa_handler == SIG_IGN) ::_exit(9);  // the test runs under nohup or the like
    try {
      write_file_atomic(path, [&](std::ostream& out) {
        out << std::string(100000, 'x');
        out.flush();
        if (temporary_files_in_flight() != 1) ::_exit(4);
        std::raise(sig);
        ::_exit(5);  // not reached: the signal ends the process
      });
    } catch (...) {
      ::_exit(6);
    }
    ::_exit(7);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  if (WIFEXITED(status) && WEXITSTATUS(status) == 9) {
    std::cout << "signal " << sig << " is ignored by this test process; not checked\n";
    return;
  }
  ASSERT_TRUE(WIFSIGNALED(status))
      << "signal " << sig << ": exit code " << (WIFEXITED(status) ? WEXITSTATUS(status) : -1);
  EXPECT_EQ(WTERMSIG(status), sig);
  EXPECT_EQ(dir.entries(), old_content ? 1 : 0) << "signal " << sig;
  if (old_content) {
    EXPECT_EQ(slurp(path), "old\n");
  }
}

TEST(AtomicFile, SigintSigtermSighupRemoveTheTemporaryFileThenEndTheProcess) {
  for (int sig : {SIGINT, SIGTERM, SIGHUP}) {
    expect_signal_removes_temporary(sig, false);
    expect_signal_removes_temporary(sig, true);
  }
}

TEST(AtomicFile, AnIgnoredSignalStaysIgnored) {
  // A program that ignores SIGHUP (nohup) keeps ignoring it while dynid writes.
  TempDir dir;
  const pid_t child = ::fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    std::signal(SIGHUP, SIG_IGN);
    write_file_atomic(dir.file("a.txt"), [](std::ostream& out) {
      out << "a";
      std::raise(SIGHUP);
    });
    ::_exit(0);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  // The parent test process may have installed the handler already (fork inherits it); the child
  // then ignores SIGHUP because it set SIG_IGN itself after the fork.
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0);
  EXPECT_EQ(slurp(dir.file("a.txt")), "a");
}

// OutputBatch (issue 27 item 5): the outputs of one command appear together or not at all.
TEST(AtomicFile, BatchRenamesOnlyOnCommitAndRemovesEverythingOtherwise) {
  TempDir dir;
  const std::string old = dir.write("b.json", "old b\n");
  {
    OutputBatch batch;
    write_text_atomic(dir.file("a.json"), "new a\n");
    write_text_atomic(old, "new b\n");
    EXPECT_FALSE(fs::exists(dir.file("a.json")));  // pending until commit
    EXPECT_EQ(slurp(old), "old b\n");
    EXPECT_EQ(temporary_files_in_flight(), 2);
    // A later output whose folder is missing: the command fails before commit.
    EXPECT_NE(error_of([&] { write_text_atomic(dir.file("missing/c.json"), "c\n"); }), "");
  }
  EXPECT_FALSE(fs::exists(dir.file("a.json")));
  EXPECT_EQ(slurp(old), "old b\n");
  EXPECT_EQ(dir.entries(), 1);  // b.json only: no temporary file left
  EXPECT_EQ(temporary_files_in_flight(), 0);
  {
    OutputBatch batch;
    write_text_atomic(dir.file("a.json"), "new a\n");
    write_text_atomic(old, "new b\n");
    batch.commit();
  }
  EXPECT_EQ(slurp(dir.file("a.json")), "new a\n");
  EXPECT_EQ(slurp(old), "new b\n");
  EXPECT_EQ(dir.entries(), 2);
  EXPECT_EQ(temporary_files_in_flight(), 0);
  write_text_atomic(dir.file("c.json"), "c\n");  // no batch open: written at once
  EXPECT_EQ(slurp(dir.file("c.json")), "c\n");
}

}  // namespace
}  // namespace dynid
