// libFuzzer harness for project files (`dynid run`, workflow/project.hpp) and the atomic writer
// behind every output (io/atomic_file.hpp), issue 27. The input is a project YAML, written into a
// sandbox project folder beside two small CSV files (for `data:` and `data: {join: ...}`); the
// output folder is a sibling of the project folder (ProjectOptions::output), so the output key of
// the file is not followed outside the sandbox. The stages do not compute: the command table
// registers a fixed set of flags like the real commands and its run() writes, through
// write_file_atomic inside an OutputBatch (as the real commands do), every file the stage's
// arguments name as outputs; an output named fail* makes the stage fail halfway through writing
// it (the temporary-file path of a failing command).
//
// Invariants: the project folder is never written (its files keep their bytes, nothing appears in
// it); every output a stage is asked to write is a plain file name (it lands in the output
// folder); a failing stage leaves no temporary file, checked before the runner removes its
// `.partial` folder; no `.partial` folder and no temporary file is left anywhere in the sandbox;
// an accepted project leaves a folder with dynid's marker; the working directory is restored.

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <ostream>
#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "dynid/io/atomic_file.hpp"
#include "dynid/workflow/project.hpp"
#include "fuzz_support.hpp"

namespace {

namespace fs = std::filesystem;

// A name of write_file_atomic's temporary files (<name>.tmp.<pid>.<random>) anywhere in `folder`.
bool has_temporary_file(const fs::path& folder) {
  const std::string tmp = ".tmp." + std::to_string(::getpid()) + ".";
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(folder, ec);
       !ec && it != fs::recursive_directory_iterator(); it.increment(ec)) {
    if (it->path().filename().string().find(tmp) != std::string::npos) return true;
  }
  return false;
}

// command -> its flags: {name, takes a value, repeatable, writes}.
const std::map<std::string, std::vector<dynid::CommandFlag>>& command_flags() {
  static const std::map<std::string, std::vector<dynid::CommandFlag>> flags = {
      {"model", {{"robot"}, {"json", true, false, true}, {"base", false}, {"help", false}}},
      {"excite",
       {{"robot"}, {"out", true, false, true}, {"json", true, false, true}, {"harmonics"}}},
      {"simulate", {{"robot"}, {"trajectory"}, {"out", true, false, true}, {"periods"}}},
      {"identify",
       {{"robot"},
        {"data", true, true},
        {"out", true, false, true},
        {"report", true, false, true},
        {"history", true, false, true},
        {"estimator"},
        {"physical", false}}},
      {"validate",
       {{"robot"},
        {"params"},
        {"data"},
        {"json", true, false, true},
        {"report", true, false, true},
        {"histograms", true, false, true},
        {"predicted", true, false, true}}},
      {"export", {{"robot"}, {"params"}, {"out", true, false, true}}},
      {"report", {{"in", true, true}, {"out", true, false, true}, {"title"}}},
  };
  return flags;
}

dynid::CommandTable fake_table() {
  dynid::CommandTable table;
  table.flags = [](const std::string& command, std::vector<dynid::CommandFlag>& flags) {
    const auto it = command_flags().find(command);
    if (it == command_flags().end()) return false;
    flags = it->second;
    return true;
  };
  table.run = [](const std::vector<std::string>& args) {
    const auto& flags = command_flags().at(args.at(0));
    std::string failure;
    try {
      dynid::OutputBatch batch;  // like the real commands: all outputs or none
      for (std::size_t i = 1; i + 1 < args.size(); ++i) {
        if (args[i].rfind("--", 0) != 0) continue;
        for (const auto& f : flags) {
          if (!f.writes || "--" + f.name != args[i]) continue;
          const std::string& name = args[i + 1];
          dynid::fuzz::require(!name.empty() && name.find('/') == std::string::npos,
                               "a stage output is not a plain file name in the output folder");
          dynid::write_file_atomic(name, [&](std::ostream& out) {
            out << "written by " << args[0] << "\n";
            // An output named fail* stands for a command that fails halfway through a file:
            // bytes are already in its temporary file, and earlier outputs wait in the batch.
            if (name.rfind("fail", 0) == 0) {
              out.flush();
              throw dynid::Error("failed while writing " + name);
            }
          });
        }
      }
      batch.commit();
    } catch (const dynid::Error& e) {
      failure = e.what();
    }
    if (failure.empty()) return;
    // Checked here, before the runner removes its .partial folder (the working directory): the
    // writer and the batch themselves left no temporary file.
    dynid::fuzz::require(dynid::temporary_files_in_flight() == 0,
                         "a failed stage left a temporary file in flight");
    dynid::fuzz::require(!has_temporary_file(fs::current_path()),
                         "a failed stage left a temporary file in the output folder");
    throw dynid::Error(failure);
  };
  return table;
}

std::map<std::string, std::string> contents(const fs::path& folder) {
  std::map<std::string, std::string> files;
  for (const auto& e : fs::recursive_directory_iterator(folder)) {
    std::ifstream in(e.path(), std::ios::binary);
    files[e.path().string()] = std::string(std::istreambuf_iterator<char>(in), {});
  }
  return files;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const fs::path sandbox =
      fs::temp_directory_path() / ("dynid_fuzz_project_" + std::to_string(::getpid()));
  static const fs::path project_dir = sandbox / "project", output = sandbox / "out";
  static const fs::path cwd = fs::current_path();
  static const bool cleanup = [] {
    return std::atexit([] {
             std::error_code e;
             fs::remove_all(sandbox, e);
           }) == 0;
  }();
  (void)cleanup;
  std::error_code ec;
  fs::remove_all(sandbox, ec);
  fs::create_directories(project_dir);
  std::ofstream(project_dir / "a.csv") << "t,q1\n0,1\n0.1,2\n";
  std::ofstream(project_dir / "b.csv") << "tau1\n3\n4\n";
  std::ofstream(project_dir / "p.yaml", std::ios::binary)
      .write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
  const auto before = contents(project_dir);

  bool accepted = false;
  dynid::fuzz::expect_clean([&] {
    dynid::ProjectOptions options;
    options.project_file = (project_dir / "p.yaml").string();
    options.output = output.string();
    dynid::run_project(options, fake_table());
    accepted = true;
  });

  dynid::fuzz::require(fs::current_path() == cwd, "the working directory was not restored");
  dynid::fuzz::require(contents(project_dir) == before, "the project folder was written");
  dynid::fuzz::require(!fs::exists(sandbox / "out.partial"), "a .partial folder was left");
  dynid::fuzz::require(dynid::temporary_files_in_flight() == 0, "a temporary file is in flight");
  dynid::fuzz::require(!has_temporary_file(sandbox), "a temporary file was left in the sandbox");
  if (accepted) {
    dynid::fuzz::require(fs::is_regular_file(output / ".dynid-run"), "no marker in the output");
  } else {
    dynid::fuzz::require(!fs::exists(output), "a refused project left an output folder");
  }
  return 0;
}
