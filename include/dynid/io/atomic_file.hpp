#pragma once

#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace dynid {

/// Writes a file atomically (docs/design.md section 4): `write(out)` fills a temporary file
/// `<name>.tmp.<pid>.<random>` in the directory of `path`, which is then flushed and renamed onto
/// `path`. If `write` throws, or the stream fails, the temporary file is removed and `path` is
/// untouched (an existing file keeps its old content); the exception propagates.
///
/// The temporary file cannot be hijacked: it is created with O_CREAT|O_EXCL|O_NOFOLLOW relative to
/// the directory opened once (a file or symbolic link planted at its name is never opened; another
/// random name is tried), and the final rename goes into that same directory. An existing `path`
/// that is (or links to) a device node, a FIFO or a socket is refused before anything is written
/// and checked again just before the rename, so `-o /dev/null` never replaces a system file; a
/// symbolic link at `path` is replaced by the new file, never written through.
///
/// While the file is being written it is listed in a process-wide registry: SIGINT, SIGTERM and
/// SIGHUP (when their disposition is the default one) remove every registered temporary file
/// with async-signal-safe calls, then end the process with the same signal.
///
/// Throws dynid::Error when the directory does not exist or is not writable, `path` is a
/// directory or a special file, or writing fails.
void write_file_atomic(const std::string& path, const std::function<void(std::ostream&)>& write);

/// write_file_atomic with a ready string.
void write_text_atomic(const std::string& path, const std::string& text);

/// Throws dynid::Error when `path` exists and is (or is a symbolic link to) something an output
/// must not replace: a directory, a device node, a FIFO or a socket. `flag` ("--out", or empty)
/// is named in the message. write_file_atomic calls it; commands may call it before their work.
void check_output_target(const std::string& path, const std::string& flag = "");

/// The outputs of one command, all or none: while a batch is open on this thread,
/// write_file_atomic writes each file completely to its temporary file but postpones the rename
/// to commit(), which renames them in the order they were written. A batch destroyed without
/// commit() (an exception between two outputs: a later file's folder is missing, a later step
/// fails) removes every temporary file, so no output of the command appears. A rename that fails
/// inside commit() (the file system refuses after every write succeeded) can leave the earlier
/// ones in place. Batches do not nest: opening one while another is open throws dynid::Error.
class OutputBatch {
 public:
  OutputBatch();
  ~OutputBatch();
  OutputBatch(const OutputBatch&) = delete;
  OutputBatch& operator=(const OutputBatch&) = delete;
  /// Renames every pending file into place. Throws dynid::Error as write_file_atomic's rename.
  void commit();

  struct Pending;  ///< a file written to its temporary name (atomic_file.cpp)

 private:
  std::vector<Pending>* pending_;
};

/// Number of temporary files write_file_atomic is writing right now (all threads); for tests.
int temporary_files_in_flight();

}  // namespace dynid
