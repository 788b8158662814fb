// `dynid simulate`: run a reference trajectory in closed loop on a simulated robot.
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/progress.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/sim/pid_gains.hpp"
#include "dynid/sim/simulate_reference.hpp"

namespace dynid::cli {
namespace {

struct SimulateCliOptions {
  std::string robot, trajectory, out, engine = "mujoco", controller = "pid-feedforward", gains;
  int periods = 25, delay = 0;
  unsigned seed = 1;
  double position_noise = 0.0, torque_noise = 0.0, counts_per_rev = 0.0;
  bool truth = false;
  bool quiet = false;  // --quiet
};

// The gains file written next to the run: run.csv -> run.gains.json (docs/cli.md).
std::string gains_file_for(const std::string& out) {
  const std::string suffix = ".csv";
  const bool csv = out.size() > suffix.size() &&
                   out.compare(out.size() - suffix.size(), suffix.size(), suffix) == 0;
  return (csv ? out.substr(0, out.size() - suffix.size()) : out) + ".gains.json";
}

void run(const SimulateCliOptions& o) {
  if (o.engine != "mujoco" && o.engine != "native") {
    throw UsageError("--engine must be mujoco or native, not '" + o.engine + "'");
  }
  if (o.controller != "pid" && o.controller != "pid-feedforward") {
    throw UsageError("--controller must be pid or pid-feedforward, not '" + o.controller + "'");
  }
  if (o.periods < 1) throw UsageError("--periods must be >= 1");
  const Model model = load_robot(o.robot);
  const JointRecord ref = read_reference(o.trajectory, model);
  SimulateOptions s;
  s.feed_forward = o.controller == "pid" ? FeedForward::kNone : FeedForward::kComputedTorque;
  if (!o.gains.empty()) s.gains = read_pid_gains(o.gains, model);
  s.plant.engine = o.engine == "mujoco" ? PlantEngine::kMujoco : PlantEngine::kNative;
  s.sensors.position_noise_std = o.position_noise;
  s.sensors.torque_noise_std = o.torque_noise;
  s.sensors.counts_per_rev = o.counts_per_rev;
  s.sensors.position_delay = s.sensors.torque_delay = o.delay;
  s.sensors.seed = o.seed;
  s.loop.periods = o.periods;
  s.loop.record_truth = o.truth;
  PidOptions pid;
  ProgressLine progress("simulate", progress_wanted(o.quiet));
  s.loop.progress = progress.callback();
  const ClosedLoopResult r = simulate_reference(model, ref.t, ref.q, ref.dq, ref.ddq, s, &pid);
  progress.finish();
  const Eigen::Index n = model.dof();
  std::vector<std::string> cols = {"t"};
  std::vector<const char*> prefixes = {"qr", "q", "tau"};
  if (o.truth) prefixes.insert(prefixes.end(), {"dq", "ddq"});
  for (const char* p : prefixes)
    for (Eigen::Index j = 0; j < n; ++j) cols.push_back(p + std::to_string(j + 1));
  Eigen::MatrixXd data(r.t.size(), static_cast<Eigen::Index>(cols.size()));
  if (o.truth) {
    data << r.t, r.qr, r.q, r.tau, r.dq_true, r.ddq_true;
  } else {
    data << r.t, r.qr, r.q, r.tau;
  }
  const std::string gains_path = gains_file_for(o.out);
  write_csv(o.out, cols, data);
  write_pid_gains(gains_path, model, pid, o.delay);
  std::cout << "simulated " << r.t.size() << " samples (" << o.periods << " periods) on the "
            << o.engine << " plant with " << o.controller << "; wrote " << o.out << " and "
            << gains_path << '\n';
}

}  // namespace

void add_simulate_command(CLI::App& app) {
  auto o = std::make_shared<SimulateCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "simulate",
      "Run a reference trajectory in closed loop (PID, with or without feed-forward) on a "
      "simulated robot");
  cmd->add_option("--robot,-r", o->robot, "Built-in robot name or .urdf/.yaml model")->required();
  cmd->add_option(
         "--trajectory,-t", o->trajectory,
         "Reference CSV with t and q* (dq*, ddq* optional), one period, e.g. from dynid excite")
      ->required();
  cmd->add_option("--out,-o", o->out, "Run CSV: t, qr*, q*, tau* (and dq*, ddq* with --truth)")
      ->required();
  cmd->add_option("--engine", o->engine, "mujoco or native")->capture_default_str();
  cmd->add_option("--controller", o->controller,
                  "pid (plain joint PID, the closed loop of B. Bona, A. Curatella, Closed-loop "
                  "rigid model identification of an industrial robot, 2005) or pid-feedforward "
                  "(PID plus computed torque from the true model)")
      ->capture_default_str();
  cmd->add_option("--gains", o->gains,
                  "YAML file with kp, ki, kd lists (one value per joint); default: a bandwidth "
                  "rule that accounts for --delay. The gains used are written to <out>.gains.json");
  cmd->add_option("--periods", o->periods, "Periods of the reference to run")
      ->capture_default_str();
  cmd->add_option("--seed", o->seed, "Noise seed")->capture_default_str();
  cmd->add_option("--position-noise", o->position_noise, "Position noise std [rad]");
  cmd->add_option("--torque-noise", o->torque_noise, "Torque noise std [N·m]");
  cmd->add_option("--counts-per-rev", o->counts_per_rev,
                  "Encoder counts per revolution; 0 = exact");
  cmd->add_option("--delay", o->delay, "Measurement delay [samples]");
  cmd->add_flag("--quiet,-q", o->quiet,
                "No progress line on stderr (shown only when stderr is a terminal)");
  cmd->add_flag("--truth", o->truth,
                "Also write the true dq*, ddq* (real robots rarely measure them)");
  cmd->callback([o] { run(*o); });
}

}  // namespace dynid::cli
