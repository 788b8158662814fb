// `dynid run project.yaml`: a whole study from a project file (workflow/project.hpp). The project
// keys are checked against the flags the commands register here, so there is no second list.
#include <algorithm>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/progress.hpp"
#include "dynid/workflow/project.hpp"
#include "file_flags.hpp"

namespace dynid::cli {
namespace {

struct RunCliOptions {
  std::string project, out;
  bool quiet = false;
};

CommandTable command_table() {
  CommandTable table;
  table.flags = [](const std::string& command, std::vector<CommandFlag>& flags) {
    CLI::App app;
    add_commands(app);
    const auto subs = app.get_subcommands({});
    const auto sub = std::find_if(subs.begin(), subs.end(),
                                  [&](const CLI::App* s) { return s->get_name() == command; });
    if (sub == subs.end()) return false;
    for (const CLI::Option* o : (*sub)->get_options()) {
      for (const std::string& name : o->get_lnames()) {
        flags.push_back({name, o->get_expected_max() > 0,
                         o->get_multi_option_policy() == CLI::MultiOptionPolicy::TakeAll,
                         writes_file(command, name)});
      }
    }
    return true;
  };
  table.run = [](const std::vector<std::string>& args) {
    CLI::App app{"dynid", "dynid"};
    app.require_subcommand(1, 1);
    add_commands(app);
    std::vector<std::string> reversed(args.rbegin(), args.rend());  // CLI11 parses from the back
    try {
      app.parse(reversed);
    } catch (const CLI::ParseError& e) {
      throw UsageError(std::string(e.what()) + " (project keys are the flags without --)");
    }
  };
  return table;
}

void run(const RunCliOptions& c) {
  ProjectOptions o;
  o.project_file = c.project;
  o.output = c.out;
  // One counting line per stage, ended: the stages print their own lines on stderr, which a line
  // redrawn in place would run into.
  ProgressCallback progress;
  if (progress_wanted(c.quiet)) {
    progress = [](double fraction, const std::string& what) {
      std::cerr << "run: " << static_cast<int>(100.0 * fraction) << " % " << what << std::endl;
    };
  }
  const ProjectResult r = run_project(o, command_table(), progress);
  std::cout << "study written to " << r.output_dir << " (" << r.commands.size()
            << " stages; the project file and commands.txt beside the results)\n";
}

}  // namespace

void add_run_command(CLI::App& app) {
  auto c = std::make_shared<RunCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "run",
      "Run a whole study from a YAML project file: each stage (model, excite, simulate or data, "
      "identify, validate) is a mapping of that command's flags without --; everything is "
      "written into the output folder with the project file copied beside it (docs/cli.md)");
  cmd->add_option("project", c->project, "Project YAML file")->required();
  cmd->add_option("--out,-o", c->out, "Output folder instead of the project's output: key");
  cmd->add_flag("--quiet,-q", c->quiet,
                "No progress line on stderr (shown only when stderr is a terminal)");
  cmd->callback([c] { run(*c); });
}

}  // namespace dynid::cli
