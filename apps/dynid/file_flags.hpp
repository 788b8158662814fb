#pragma once

// Which flags of which command name files it reads or writes (file_flags.cpp: one line per flag),
// and the check that no command writes over one of its own inputs or writes two outputs to one
// file (issue 27 item 2): `export -o result.json -p result.json` is refused before any work.

#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace dynid::cli {

/// What a flag's value names.
enum class FileRole {
  kInput,         ///< a file the command reads (a built-in robot name is no file: never compared)
  kOutput,        ///< a file the command writes (atomically, replacing what is there)
  kOutputFolder,  ///< a folder the command writes into (demo, run: they check it themselves)
};

/// One flag that names a file: `flag` is the long name with "--" (or a positional's name).
struct FileFlag {
  const char* command;
  const char* flag;
  FileRole role;
};

/// Every flag that names a file, for every command.
const std::vector<FileFlag>& file_flags();

/// True when `flag` (long name without "--", as project files spell it) of `command` names a file
/// the command writes (role kOutput).
bool writes_file(const std::string& command, const std::string& flag);

/// The files a command writes and reads, as given on its command line (and the ones it derives:
/// simulate's <out>.gains.json, validate's <data>.gains.json). Throws dynid::UsageError, one line
/// naming both flags and the fix, when an output is the same file as an input that exists (same
/// device and inode: hard links and symbolic links included) or as another output (same inode or
/// same canonical path, for files not written yet); dynid::Error when an output exists as a
/// directory, device, FIFO or socket.
struct NamedPath {
  std::string flag, path;
};
void check_outputs_against_inputs(const std::vector<NamedPath>& outputs,
                                  const std::vector<NamedPath>& inputs);

/// Installs on `app` (the root) the check above for whichever subcommand was given, run after the
/// flags are parsed and before the command's callback. Call once, after all subcommands exist.
void check_file_flags(CLI::App& app);

}  // namespace dynid::cli
