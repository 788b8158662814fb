// `dynid merge`: partial results of identify --stream --partial combined exactly and solved
// (issue 31 item 1; docs/methods/fleet.md).
#include <iostream>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/identification/streaming_partial.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/report/identification_report.hpp"
#include "partial_support.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {
namespace {

struct MergeCliOptions {
  std::vector<std::string> parts;
  std::string out, partial, report, robot;
  RobotFlags robot_flags;  // --joints, --lock, --strict
};

void run(const MergeCliOptions& o) {
  if (o.out.empty() && o.partial.empty()) {
    throw UsageError("give --out result.json, --partial merged.dpart, or both");
  }
  if (!o.report.empty() && o.out.empty()) throw UsageError("--report needs --out");
  for (const std::string& path : {o.out, o.partial, o.report}) {
    if (!path.empty()) check_output_target(path);
  }
  StreamPartial merged = read_stream_partial(o.parts.front());
  for (std::size_t i = 1; i < o.parts.size(); ++i) {
    merge_stream_partials(merged, read_stream_partial(o.parts[i]), o.parts.front(), o.parts[i]);
  }
  std::cerr << "merge: " << o.parts.size() << " parts, " << merged.runs.size() << " runs\n";
  OutputBatch outputs;  // every output or none
  if (!o.partial.empty()) {
    write_stream_partial(o.partial, merged);
    std::cout << "wrote " << o.partial << '\n';
  }
  if (!o.out.empty()) {
    std::string robot;
    const Model model = load_part_robot(merged, o.parts.front(), o.robot, o.robot_flags, robot);
    IdentificationResult result = solve_merged_part(model, merged);
    result.choices.emplace_back("merged", std::to_string(o.parts.size()) + " partial results, " +
                                              std::to_string(merged.runs.size()) + " runs");
    for (const auto& [key, value] : result.choices)
      std::cerr << "merge: " << key << ": " << one_line(value) << '\n';
    std::cout << identification_table(model, result);
    const nlohmann::json out =
        identification_to_json(model, result, stream_partial_result_options(merged, robot));
    write_json(o.out, out);
    std::cout << "wrote " << o.out << '\n';
    if (!o.report.empty()) {
      write_html_report(o.report, {{o.out, out}}, {});
      std::cout << "wrote " << o.report << '\n';
    }
  }
  outputs.commit();
}

}  // namespace

void add_merge_command(CLI::App& app) {
  auto o = std::make_shared<MergeCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "merge",
      "Combine partial results of identify --stream --partial exactly (the least-squares sums of "
      "disjoint runs add up) and solve: the same result as one identify --stream over all their "
      "runs");
  cmd->add_option("parts", o->parts, "Partial result files (.dpart), one or more, any order")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--out,-o", o->out, "Result JSON file (as identify writes it)");
  cmd->add_option("--partial", o->partial,
                  "Also write the merged state as one part (a step of a tree reduction)");
  cmd->add_option("--report", o->report, "Also write a self-contained HTML report of the result");
  cmd->add_option("--robot,-r", o->robot,
                  "Built-in robot name or .urdf/.yaml model; default: the one the parts name "
                  "(give it when that path is not valid here); checked against the parts' "
                  "equations");
  add_robot_flags(cmd, o->robot_flags, RobotFlagDefaults::kStoredInParams);
  cmd->callback([o] { run(*o); });
}

}  // namespace dynid::cli
