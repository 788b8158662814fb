// `dynid compare-control`: the same reference on the same simulated robot under the plain PID and
// under the computed-torque law of an identified model; tracking errors as a table and JSON.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/control_report.hpp"
#include "dynid/report/stored_result.hpp"
#include "dynid/sim/control_comparison.hpp"
#include "dynid/sim/pid_gains.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {
namespace {

struct CompareControlCliOptions {
  std::string robot, params, trajectory, engine = "mujoco", gains, json;
  RobotFlags robot_flags;  // --joints, --lock, --strict
  int periods = 3;
  double reversal_window = 0.05;
};

void run(const CompareControlCliOptions& o) {
  if (o.engine != "mujoco" && o.engine != "native") {
    throw UsageError("--engine must be mujoco or native, not '" + o.engine + "'");
  }
  if (o.periods < 2) {
    throw UsageError("--periods must be >= 2 (the first period is the start-up, left out)");
  }
  if (!(o.reversal_window >= 0.0)) throw UsageError("--reversal-window must be >= 0 [s]");
  const Model model = load_cli_robot(
      o.robot, o.robot_flags,
      {"compare-control", {o.trajectory}, {}, selection_stored_in(o.params), o.params});
  const CompletedModel identified = completed_model_from_result(model, o.params, "compare-control");
  const JointRecord ref = read_reference(o.trajectory, model);
  ControlComparisonOptions c;
  c.simulate.plant.engine = o.engine == "mujoco" ? PlantEngine::kMujoco : PlantEngine::kNative;
  c.simulate.loop.periods = o.periods;
  if (!o.gains.empty()) c.simulate.gains = read_pid_gains(o.gains, model);
  c.reversal_window = o.reversal_window;
  const ControlComparison result =
      compare_control(model, identified.model, ref.t, ref.q, ref.dq, ref.ddq, c);
  std::cout << control_comparison_table(model, result);
  if (!o.json.empty()) {
    nlohmann::json out = control_comparison_to_json(model, result, o.reversal_window);
    out["parameter_sources"] = parameter_sources_json(identified);
    write_json(o.json, out);
    std::cout << "wrote " << o.json << '\n';
  }
}

}  // namespace

void add_compare_control_command(CLI::App& app) {
  auto o = std::make_shared<CompareControlCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "compare-control",
      "Track one reference on the simulated robot with the plain PID and with the computed-torque "
      "law of an identified model (B. Bona, A. Curatella, Closed-loop rigid model identification "
      "of an industrial robot, 2005, Fig. 9); per joint RMS, maximum and maximum around velocity "
      "reversals of the tracking error");
  cmd->add_option("--robot,-r", o->robot, "Built-in robot name or .urdf/.yaml model (the plant)")
      ->required();
  add_robot_flags(cmd, o->robot_flags, RobotFlagDefaults::kStoredInParams);
  cmd->add_option("--params,-p", o->params,
                  "result.json of dynid identify: the model of the computed-torque controller; "
                  "parameters its data did not determine take the --robot model's values "
                  "(parameter_sources in --json)")
      ->required();
  cmd->add_option("--trajectory,-t", o->trajectory,
                  "Reference CSV with t and q* (dq*, ddq* optional), one period")
      ->required();
  cmd->add_option("--engine", o->engine, "mujoco or native")->capture_default_str();
  cmd->add_option("--gains", o->gains,
                  "YAML file with kp, ki, kd lists, used by both controllers; default: the "
                  "bandwidth rule of simulate --controller pid");
  cmd->add_option("--periods", o->periods, "Periods to run; the first is left out")
      ->capture_default_str();
  cmd->add_option("--reversal-window", o->reversal_window,
                  "Half-width [s] of the window around each sign change of the reference "
                  "velocity")
      ->capture_default_str();
  cmd->add_option("--json", o->json, "Write the errors as JSON (controllers, joints)");
  cmd->callback([o] { run(*o); });
}

}  // namespace dynid::cli
