// `dynid simulate`: run a reference trajectory in closed loop on a simulated robot.
#include <iostream>
#include <memory>
#include <optional>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/progress.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/sim/load_sensor.hpp"
#include "dynid/sim/pid_gains.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "dynid/workflow/simulate_run.hpp"
#include "flag_checks.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {
namespace {

struct SimulateCliOptions {
  std::string robot, trajectory, out, engine = "mujoco", controller = "pid-feedforward", gains;
  std::string params;      // --params: identified model of computed-torque
  RobotFlags robot_flags;  // --joints, --lock, --strict
  int periods = 25, delay = 0;
  unsigned seed = 1;
  double position_noise = 0.0, torque_noise = 0.0, counts_per_rev = 0.0;
  bool truth = false;
  // A load behind a wrist force/torque sensor (issue 12 item 4).
  std::string payload, payload_link, sensor_pose;
  std::vector<double> wrench_noise;
  bool quiet = false;  // --quiet
};

// The load of --payload on --payload-link at --sensor-pose, or none; usage errors name the flag.
std::optional<MountedLoad> payload_options(const SimulateCliOptions& o, const Model& model) {
  if (o.payload.empty()) {
    if (!o.payload_link.empty() || !o.sensor_pose.empty() || !o.wrench_noise.empty()) {
      throw UsageError("--payload-link, --sensor-pose and --wrench-noise need --payload load.yaml");
    }
    return std::nullopt;
  }
  if (o.payload_link.empty()) {
    throw UsageError("--payload needs --payload-link LINK: the link that carries the sensor");
  }
  MountedLoad load;
  load.mount.link = find_link(model, o.payload_link);
  if (!o.sensor_pose.empty()) {
    const std::vector<double> pose =
        flag_numbers(o.sensor_pose, 6, "--sensor-pose",
                     "\"x y z roll pitch yaw\" [m, rad] of the sensor in the link frame");
    load.mount.p_LS = Eigen::Vector3d(pose[0], pose[1], pose[2]);
    load.mount.R_LS = roll_pitch_yaw(pose[3], pose[4], pose[5]);
  }
  load.phi = read_load_file(o.payload);
  return load;
}

void run(const SimulateCliOptions& o) {
  if (o.engine != "mujoco" && o.engine != "native") {
    throw UsageError("--engine must be mujoco or native, not '" + o.engine + "'");
  }
  if (o.controller != "pid" && o.controller != "pid-feedforward" &&
      o.controller != "computed-torque") {
    throw UsageError("--controller must be pid, pid-feedforward or computed-torque, not '" +
                     o.controller + "'");
  }
  if ((o.controller == "computed-torque") != !o.params.empty()) {
    throw UsageError(o.params.empty() ? "--controller computed-torque needs --params result.json "
                                        "(the identified model it is computed from)"
                                      : "--params is for --controller computed-torque; drop it "
                                        "or add --controller computed-torque");
  }
  if (o.periods < 1) throw UsageError("--periods must be >= 1");
  const Model model =
      load_cli_robot(o.robot, o.robot_flags,
                     {"simulate", {o.trajectory}, {}, selection_stored_in(o.params), o.params});
  const std::optional<MountedLoad> load = payload_options(o, model);
  const JointRecord ref = read_reference(o.trajectory, model);
  SimulateRunOptions options;
  options.load = load;
  options.wrench_noise = o.wrench_noise;
  options.truth = o.truth;
  SimulateOptions& s = options.simulate;
  s.feed_forward = o.controller == "pid"               ? FeedForward::kNone
                   : o.controller == "computed-torque" ? FeedForward::kInverseDynamics
                                                       : FeedForward::kComputedTorque;
  if (!o.params.empty())
    s.controller_model = completed_model_from_result(model, o.params, "simulate").model;
  if (!o.gains.empty()) s.gains = read_pid_gains(o.gains, model);
  s.plant.engine = o.engine == "mujoco" ? PlantEngine::kMujoco : PlantEngine::kNative;
  s.sensors.position_noise_std = o.position_noise;
  s.sensors.torque_noise_std = o.torque_noise;
  s.sensors.counts_per_rev = o.counts_per_rev;
  s.sensors.position_delay = s.sensors.torque_delay = o.delay;
  s.sensors.seed = o.seed;
  s.loop.periods = o.periods;
  ProgressLine progress("simulate", progress_wanted(o.quiet));
  s.loop.progress = progress.callback();
  const SimulatedRun r = simulate_run(model, ref.t, ref.q, ref.dq, ref.ddq, options);
  progress.finish();
  const std::string gains_path = gains_file_for_run(o.out);
  write_csv(o.out, r.columns, r.data);
  write_pid_gains(gains_path, model, r.pid, o.delay);
  std::cout << "simulated " << r.data.rows() << " samples (" << o.periods << " periods) on the "
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
  add_robot_flags(cmd, o->robot_flags, RobotFlagDefaults::kStoredInParams);
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
                  "(PID plus computed torque from the true model) or computed-torque (the "
                  "computed-torque law with the model identified in --params: mass matrix, "
                  "Coriolis, gravity and friction, the PID correcting the acceleration)")
      ->capture_default_str();
  cmd->add_option(
      "--params,-p", o->params,
      "With --controller computed-torque: result.json of dynid identify; parameters its "
      "data did not determine take the --robot model's values (a warning names them)");
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
  cmd->add_option("--payload", o->payload,
                  "Load file (YAML: mass, com, inertia_com in the sensor frame, docs/cli.md) of a "
                  "rigid load behind a wrist force/torque sensor; adds fx fy fz mx my mz, what "
                  "the sensor reads (force and moment of the load on it, sensor frame), to --out");
  cmd->add_option("--payload-link", o->payload_link,
                  "With --payload: link (or joint) name that carries the sensor");
  cmd->add_option("--sensor-pose", o->sensor_pose,
                  "With --payload: \"x y z roll pitch yaw\" of the sensor frame in the link "
                  "frame [m, rad], URDF roll-pitch-yaw convention; default: the link frame");
  cmd->add_option("--wrench-noise", o->wrench_noise,
                  "With --payload: Gaussian noise std on the wrench, FORCE[,MOMENT] [N, N m] "
                  "(one value: the same on all six); seeded by --seed")
      ->delimiter(',');
  cmd->add_flag("--quiet,-q", o->quiet,
                "No progress line on stderr (shown only when stderr is a terminal)");
  cmd->add_flag("--truth", o->truth,
                "Also write the true dq*, ddq* (real robots rarely measure them)");
  cmd->callback([o] { run(*o); });
}

}  // namespace dynid::cli
