#pragma once

// A study described by a project file (`dynid run project.yaml`, issue 15 item 5): each stage is a
// dynid command whose flags are the stage's keys, run in order into one output folder.

#include <functional>
#include <string>
#include <vector>

#include "dynid/common/progress.hpp"

namespace dynid {

/// One flag of a dynid command as the command line registers it.
struct CommandFlag {
  std::string name;         ///< long name without "--", e.g. "estimator"
  bool takes_value = true;  ///< false for a switch (`--physical`)
  bool repeatable = false;  ///< a list is given as the flag repeated (`--data a --data b`)
  bool writes = false;      ///< names a file the command writes (`--report`, `--history`)
};

/// The command line the project runner drives. The project keys are checked against `flags`, so
/// the only list of options is the one the commands register.
struct CommandTable {
  /// The flags of `command`; false when no such command is registered (then `flags` is unused).
  std::function<bool(const std::string& command, std::vector<CommandFlag>& flags)> flags;
  /// Runs one command, args[0] being its name (e.g. {"identify", "--robot", "planar2", ...});
  /// throws dynid::Error like the command does on the command line.
  std::function<void(const std::vector<std::string>& args)> run;
};

/// How one stage is wired into the study: which files it takes from earlier stages and which it
/// writes into the output folder. The stage's YAML key is its command's name.
struct StageWiring {
  /// A flag filled from an earlier stage's file (or the project's `robot`).
  struct Input {
    std::string flag;      ///< e.g. "params"
    std::string artefact;  ///< e.g. "result"; skipped when no stage has written it
  };
  /// A flag the runner sets to a file in the output folder; the file becomes `artefact`.
  struct Output {
    std::string flag;      ///< e.g. "out"
    std::string file;      ///< name inside the output folder, e.g. "result.json"
    std::string artefact;  ///< what later stages call it, e.g. "result"
  };
  std::string command;
  std::vector<Input> inputs;
  std::vector<Output> outputs;
};

/// The stages of a study, in the order they run (project.cpp: one line per stage). A stage whose
/// command is not registered (CommandTable::flags false) is not a valid key.
const std::vector<StageWiring>& project_stages();

/// Options of one project run.
struct ProjectOptions {
  std::string project_file;  ///< the YAML file; relative paths in it are relative to its folder
  std::string output;        ///< output folder overriding the file's `output:` ("" = the file's)
};

/// What a project run did.
struct ProjectResult {
  std::string output_dir;                          ///< the folder written
  std::vector<std::vector<std::string>> commands;  ///< each stage's command line, in order
};

/// Runs the study in `options.project_file`: reads and checks every key (unknown keys at the top
/// level and in each stage are a dynid::UsageError naming the key and the valid ones), then runs
/// each stage present through `table.run` with the stage's keys as flags, the wired inputs from
/// earlier stages, and its outputs in the output folder. Relative values that name a file beside
/// the project file are made absolute; every stage runs with the output folder as the working
/// directory, so any other file it writes lands there. The folder is built under
/// "<output>.partial" and renamed to <output> (replacing an earlier run) only when every stage
/// succeeded, with the project file and commands.txt (the command lines) copied beside the
/// results. `progress` is told before each stage (fraction of the stages done, the command line).
/// Throws dynid::UsageError for a malformed project, dynid::Error for a missing data file or a
/// failing stage (the partial folder removed).
ProjectResult run_project(const ProjectOptions& options, const CommandTable& table,
                          const ProgressCallback& progress = {});

}  // namespace dynid
