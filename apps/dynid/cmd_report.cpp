// `dynid report`: one self-contained HTML page from result JSON files (report/html_report.hpp).
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/report/html_report.hpp"

namespace dynid::cli {
namespace {

struct ReportCliOptions {
  std::vector<std::string> inputs;
  std::string out, title = "dynid report";
};

void run(const ReportCliOptions& o) {
  namespace fs = std::filesystem;
  const fs::path parent = fs::path(o.out).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw Error("--out '" + o.out + "': folder '" + parent.string() +
                "' does not exist; create it or write elsewhere");
  }
  std::vector<ReportInput> inputs;
  for (const auto& path : o.inputs) {
    if (fs::is_directory(path, ec)) {
      throw Error("--in '" + path + "' is a folder; give a result JSON file");
    }
    inputs.push_back(read_report_input(path));
  }
  HtmlReportOptions options;
  options.title = o.title;
  write_html_report(o.out, inputs, options);
  std::cout << "wrote " << o.out << '\n';
}

}  // namespace

void add_report_command(CLI::App& app) {
  auto o = std::make_shared<ReportCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "report",
      "One self-contained HTML page (opens offline) with plots of dynid results: identify, "
      "validate, payload, average, excite and the dedicated experiments");
  cmd->add_option("--in,-i", o->inputs,
                  "Result JSON written by dynid (identify, validate --json, payload, average "
                  "--json, excite --json); repeat for several, shown in the order given")
      ->required()
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--out,-o", o->out, "HTML file to write (atomically)")->required();
  cmd->add_option("--title", o->title, "Heading of the page")->capture_default_str();
  cmd->callback([o] { run(*o); });
}

}  // namespace dynid::cli
