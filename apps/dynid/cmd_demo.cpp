// `dynid demo`: the whole identification loop on a simulated robot (workflow/demo.hpp).
#include <chrono>
#include <ctime>
#include <filesystem>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/workflow/demo.hpp"

namespace dynid::cli {
namespace {

struct DemoCliOptions {
  std::string out, robot = "puma560";
  int periods = 25;
  bool native = false;
  unsigned seed = 7;
  std::string report;  // --report; default <out>/report.html
  bool quiet = false;  // --quiet: no stage lines on stderr
};

std::string default_folder() {
  const std::time_t now = std::time(nullptr);
  char buf[64];
  std::strftime(buf, sizeof(buf), "dynid-demo-%Y%m%d-%H%M%S", std::localtime(&now));
  return buf;
}

void run(const DemoCliOptions& c) {
  DemoOptions o;
  o.robot = c.robot;
  o.out_dir = c.out.empty() ? default_folder() : c.out;
  o.periods = c.periods;
  o.mujoco = !c.native;
  o.seed = c.seed;
  // A --report into a missing folder fails before the demo's work, not after it.
  if (const auto folder = std::filesystem::path(c.report).parent_path();
      !folder.empty() && !std::filesystem::is_directory(folder)) {
    throw Error("--report '" + c.report + "': folder '" + folder.string() +
                "' does not exist; create it or write elsewhere");
  }
  // Nothing of a failed demo stays behind: every file waits in the batch until the report is
  // written too, and a folder the demo created is removed again.
  namespace fs = std::filesystem;
  std::error_code ec;
  const bool folder_existed = fs::exists(o.out_dir, ec);
  const auto start = std::chrono::steady_clock::now();
  DemoResult r;
  std::string report;
  try {
    OutputBatch outputs;
    r = run_demo(o, [&](const std::string& line) {
      const double s =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      if (!c.quiet) std::cerr << "[" << static_cast<int>(s) << " s] " << line << std::endl;
    });
    // The report of the files the demo wrote, as `dynid report --in` would make it.
    report = c.report.empty() ? (fs::path(o.out_dir) / "report.html").string() : c.report;
    HtmlReportOptions options;
    options.title = "dynid demo: " + o.robot;
    write_html_report(report, r.reports, options);
    outputs.commit();
  } catch (...) {
    if (!folder_existed) fs::remove(o.out_dir, ec);  // only when empty: never a user's file
    throw;
  }
  std::cout << r.table << "files written to " << o.out_dir << "; report " << report << '\n';
}

}  // namespace

void add_demo_command(CLI::App& app) {
  auto c = std::make_shared<DemoCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "demo",
      "End-to-end demo: optimise an excitation, run it on a simulated robot (MuJoCo) with noise, "
      "average the periods, identify the base parameters with confidence intervals, validate");
  cmd->add_option("--out,-o", c->out, "Output folder (default: a new dynid-demo-<date> folder)");
  cmd->add_option("--robot,-r", c->robot, "Built-in robot or model file")->capture_default_str();
  cmd->add_option("--periods", c->periods, "Excitation periods run on the plant")
      ->capture_default_str();
  cmd->add_flag("--native", c->native, "Use dynid's own plant instead of MuJoCo");
  cmd->add_option("--seed", c->seed, "Noise and optimiser seed")->capture_default_str();
  cmd->add_option("--report", c->report,
                  "HTML report of the run (excitation, identification, validation); default "
                  "report.html in the output folder");
  cmd->add_flag("--quiet,-q", c->quiet, "No stage lines (elapsed time, stage) on stderr");
  cmd->callback([c] { run(*c); });
}

}  // namespace dynid::cli
