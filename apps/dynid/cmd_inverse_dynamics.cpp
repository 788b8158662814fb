#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/io/inverse_dynamics_file.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {
namespace {

struct InverseDynamicsCliOptions {
  std::string robot;  // built-in name or model path
  std::string in;     // states CSV
  std::string out;    // torques CSV
  bool no_friction = false;
  std::string columns;     // --columns from=to,...
  RobotFlags robot_flags;  // --joints, --lock, --strict
};

void run_inverse_dynamics(const InverseDynamicsCliOptions& cli) {
  InverseDynamicsFileOptions options;
  options.joint_terms = !cli.no_friction;
  options.columns = parse_column_mapping(cli.columns);
  const Model model = load_cli_robot(cli.robot, cli.robot_flags,
                                     {"inverse-dynamics", {cli.in}, options.columns, {}, ""});
  const Eigen::Index rows = inverse_dynamics_file(model, cli.in, cli.out, options);
  std::cout << "wrote " << rows << " rows of tau1..tau" << model.dof() << " to " << cli.out << '\n';
}

}  // namespace

void add_inverse_dynamics_command(CLI::App& app) {
  auto options = std::make_shared<InverseDynamicsCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "inverse-dynamics",
      "Joint torques tau = M(q) ddq + c(q, dq) + g(q) [+ Ia ddq + Fv dq + Fc sign(dq) + Fo] for "
      "every row of a states CSV (recursive Newton-Euler)");
  cmd->add_option("--robot,-r", options->robot, "Built-in robot name or a .urdf / .yaml model file")
      ->required();
  add_robot_flags(cmd, options->robot_flags);
  cmd->add_option("--in,-i", options->in,
                  "States CSV with columns q1..qn, dq1..dqn, ddq1..ddqn (or q_<joint name>, ...) "
                  "in any order; t optional (must increase); other columns ignored")
      ->required();
  cmd->add_option("--out,-o", options->out,
                  "Torques CSV to write: t (if the input has it) and tau1..taun, one row per input "
                  "row [N m or N]; written atomically")
      ->required();
  cmd->add_flag("--no-friction", options->no_friction,
                "Leave out the joint terms Ia ddq + Fv dq + Fc sign(dq) + Fo (rigid body only)");
  cmd->add_option("--columns", options->columns,
                  "Rename input columns before lookup: from=to,from=to (e.g. pos1=q1,vel1=dq1)");
  cmd->callback([options] { run_inverse_dynamics(*options); });
}

}  // namespace dynid::cli
