#include "file_flags.hpp"

#include <sys/stat.h>

#include <filesystem>

#include "dynid/common/error.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/sim/pid_gains.hpp"

namespace dynid::cli {
namespace {

namespace fs = std::filesystem;

constexpr FileRole kIn = FileRole::kInput;
constexpr FileRole kOut = FileRole::kOutput;
constexpr FileRole kFolder = FileRole::kOutputFolder;

// One line per flag that names a file (tests/cli/output_safety_cli_test.cpp checks that every
// text flag whose help mentions a file is listed here or is known to name none).
const std::vector<FileFlag> kFileFlags = {
    {"model", "--robot", kIn},
    {"model", "--json", kOut},
    {"inverse-dynamics", "--robot", kIn},
    {"inverse-dynamics", "--in", kIn},
    {"inverse-dynamics", "--out", kOut},
    {"identify", "--robot", kIn},
    {"identify", "--data", kIn},
    {"identify", "--params", kIn},
    {"identify", "--friction-known", kIn},
    {"identify", "--noise", kIn},
    {"identify", "--out", kOut},
    {"identify", "--report", kOut},
    {"identify", "--history", kOut},
    {"identify", "--partial", kOut},
    {"validate", "--robot", kIn},
    {"validate", "--params", kIn},
    {"validate", "--data", kIn},
    {"validate", "--trajectory", kIn},
    {"validate", "--gains", kIn},
    {"validate", "--json", kOut},
    {"validate", "--report", kOut},
    {"validate", "--histograms", kOut},
    {"validate", "--predicted", kOut},
    {"excite", "--robot", kIn},
    {"excite", "--out", kOut},
    {"excite", "--json", kOut},
    {"simulate", "--robot", kIn},
    {"simulate", "--trajectory", kIn},
    {"simulate", "--params", kIn},
    {"simulate", "--gains", kIn},
    {"simulate", "--payload", kIn},
    {"simulate", "--out", kOut},
    {"compare-control", "--robot", kIn},
    {"compare-control", "--params", kIn},
    {"compare-control", "--trajectory", kIn},
    {"compare-control", "--gains", kIn},
    {"compare-control", "--json", kOut},
    {"average", "--data", kIn},
    {"average", "--out", kOut},
    {"average", "--json", kOut},
    {"demo", "--robot", kIn},
    {"demo", "--report", kOut},
    {"demo", "--out", kFolder},
    {"payload", "--data", kIn},
    {"payload", "--robot", kIn},
    {"payload", "--reference", kIn},
    {"payload", "--out", kOut},
    {"payload", "--report", kOut},
    {"payload", "--history", kOut},
    {"export", "--robot", kIn},
    {"export", "--params", kIn},
    {"export", "--out", kOut},
    {"report", "--in", kIn},
    {"report", "--out", kOut},
    {"merge", "parts", kIn},
    {"merge", "--robot", kIn},
    {"merge", "--out", kOut},
    {"merge", "--partial", kOut},
    {"merge", "--report", kOut},
    {"compare", "results", kIn},
    {"compare", "--json", kOut},
    {"compare", "--report", kOut},
    {"run", "project", kIn},
    {"run", "--out", kFolder},
};

struct Identity {
  bool exists = false;
  dev_t dev = 0;
  ino_t ino = 0;
  fs::path canonical;
};

Identity identity_of(const std::string& path) {
  Identity id;
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0) {
    id.exists = true;
    id.dev = st.st_dev;
    id.ino = st.st_ino;
  }
  std::error_code ec;
  id.canonical = fs::weakly_canonical(fs::absolute(path, ec), ec);
  if (ec) id.canonical = fs::absolute(path, ec).lexically_normal();
  return id;
}

bool same_file(const Identity& a, const Identity& b) {
  if (a.exists && b.exists) return a.dev == b.dev && a.ino == b.ino;
  return a.canonical == b.canonical;
}

std::string named(const NamedPath& p) {
  return p.flag + " '" + p.path + "'";
}

}  // namespace

const std::vector<FileFlag>& file_flags() {
  return kFileFlags;
}

bool writes_file(const std::string& command, const std::string& flag) {
  for (const FileFlag& f : kFileFlags) {
    if (f.role == kOut && command == f.command && "--" + flag == f.flag) return true;
  }
  return false;
}

void check_outputs_against_inputs(const std::vector<NamedPath>& outputs,
                                  const std::vector<NamedPath>& inputs) {
  std::vector<Identity> out_ids;
  for (const NamedPath& o : outputs) {
    check_output_target(o.path, o.flag);
    out_ids.push_back(identity_of(o.path));
  }
  std::vector<Identity> in_ids;
  for (const NamedPath& i : inputs) in_ids.push_back(identity_of(i.path));
  for (std::size_t k = 0; k < outputs.size(); ++k) {
    for (std::size_t i = 0; i < inputs.size(); ++i) {
      // An input that is not there is no file (a built-in robot name) or fails when it is read.
      if (!in_ids[i].exists || !same_file(out_ids[k], in_ids[i])) continue;
      throw UsageError(named(outputs[k]) + " is the input " + named(inputs[i]) +
                       ": writing it would replace what the command reads; give " +
                       outputs[k].flag + " another file");
    }
    for (std::size_t e = 0; e < k; ++e) {
      if (!same_file(out_ids[k], out_ids[e])) continue;
      throw UsageError(named(outputs[k]) + " is the same file as " + named(outputs[e]) +
                       "; give each output its own file");
    }
  }
}

void check_file_flags(CLI::App& app) {
  CLI::App* root = &app;
  app.parse_complete_callback([root] {
    for (CLI::App* sub : root->get_subcommands()) {
      const std::string command = sub->get_name();
      std::vector<NamedPath> outputs, inputs;
      for (const FileFlag& f : kFileFlags) {
        if (command != f.command || f.role == kFolder) continue;
        const CLI::Option* option = sub->get_option_no_throw(f.flag);
        if (option == nullptr) continue;
        for (const std::string& value : option->results()) {
          if (value.empty()) continue;
          (f.role == kOut ? outputs : inputs).push_back({f.flag, value});
          if (command == "simulate" && std::string(f.flag) == "--out") {
            outputs.push_back({"--out (its gains file)", gains_file_for_run(value)});
          }
          if (command == "validate" && std::string(f.flag) == "--data" &&
              sub->count("--gains") == 0) {
            inputs.push_back({"--data (its gains file)", gains_file_for_run(value)});
          }
        }
      }
      check_outputs_against_inputs(outputs, inputs);
    }
  });
}

}  // namespace dynid::cli
