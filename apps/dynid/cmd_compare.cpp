// `dynid compare`: which parameters changed significantly between identifications of one robot
// (issue 31 item 3; docs/methods/fleet.md): text summary, JSON and an HTML page.
#include <iostream>
#include <memory>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/report/drift_report.hpp"
#include "dynid/report/html_report.hpp"

namespace dynid::cli {
namespace {

struct CompareCliOptions {
  std::vector<std::string> results;
  std::string json, report;
  double alpha = 0.01;
};

void run(const CompareCliOptions& o) {
  if (o.results.size() < 2) {
    throw UsageError("give at least two result JSONs: the baseline first, then the later ones");
  }
  if (!(o.alpha > 0.0 && o.alpha < 1.0)) {
    throw UsageError("--alpha must be in (0, 1), e.g. 0.01");
  }
  for (const std::string& path : {o.json, o.report}) {
    if (!path.empty()) check_output_target(path);
  }
  std::vector<DriftInput> inputs;
  std::vector<std::string> covariances, robots;
  std::vector<ReportInput> pages;
  for (const std::string& path : o.results) {
    const ReportInput in = read_report_input(path);
    std::string covariance;
    inputs.push_back(drift_input_of_result(in.result, path, &covariance));
    covariances.push_back(covariance);
    robots.push_back(robot_of_result(in.result));
    if (!robots.back().empty() && !robots.front().empty() && robots.back() != robots.front()) {
      throw Error("'" + path + "' is a result of robot '" + robots.back() + "', '" +
                  o.results.front() + "' of '" + robots.front() +
                  "'; compare results of one robot type");
    }
  }
  for (std::size_t r = 0; r < covariances.size(); ++r) {
    if (covariances[r].rfind("white", 0) == 0) {
      std::cerr << "warning: '" << o.results[r]
                << "' has white-noise standard deviations (identify --stream or merge): too "
                   "narrow if its residuals are correlated, so the false-alarm rate may be "
                   "exceeded; identify in memory for HAC intervals\n";
    }
  }
  DriftOptions options;
  options.alpha = o.alpha;
  const DriftComparison c = compare_estimates(inputs, options);
  std::cout << drift_table(inputs, c);
  const nlohmann::json out = drift_to_json(inputs, covariances, robots, c);
  OutputBatch outputs;  // the JSON and the page, or neither
  if (!o.json.empty()) {
    write_json(o.json, out);
    std::cout << "wrote " << o.json << '\n';
  }
  if (!o.report.empty()) {
    HtmlReportOptions page;
    page.title = "dynid compare";
    write_html_report(o.report, {{o.results.back(), out}}, page);
    std::cout << "wrote " << o.report << '\n';
  }
  outputs.commit();
}

}  // namespace

void add_compare_command(CLI::App& app) {
  auto o = std::make_shared<CompareCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare",
      "Per parameter, the change between identification results of one robot (the first is "
      "the baseline), its standard deviation from both results, a z-score and a verdict at a "
      "family-wise false-alarm rate (Holm's correction over every parameter tested); friction "
      "and payload changes are listed first");
  cmd->add_option("results", o->results,
                  "Result JSONs of identify, merge or payload: the baseline, then one or more "
                  "later results")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--alpha", o->alpha,
                  "Family-wise false-alarm rate: the probability that any unchanged parameter is "
                  "flagged")
      ->capture_default_str();
  cmd->add_option("--json", o->json, "Write the comparison as JSON");
  cmd->add_option("--report", o->report,
                  "Write an HTML page: the changes with their intervals, and trend plots when more "
                  "than two results are given");
  cmd->callback([o] { run(*o); });
}

}  // namespace dynid::cli
