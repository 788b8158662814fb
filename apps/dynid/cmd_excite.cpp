// `dynid excite`: optimise a Fourier excitation and write the reference trajectory.
#include <cmath>
#include <iostream>
#include <memory>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/excitation_report.hpp"

namespace dynid::cli {
namespace {

struct ExciteCliOptions {
  std::string robot, out, json, criterion = "cond";
  int harmonics = 5, starts = 4, max_evaluations = 3000;
  double f0 = 0.1, f_max = 0.0, rate = 100.0, max_time = 10.0, z_min = -1e300;
  double limit_fraction = 1.0;
  std::vector<double> dq_max, ddq_max, tau_max;
  unsigned seed = 20261123;
  bool no_rest = false;
};

Eigen::VectorXd limits(const std::vector<double>& v, int n, const char* flag) {
  if (v.empty()) return {};
  if (v.size() == 1) return Eigen::VectorXd::Constant(n, v[0]);
  if (static_cast<int>(v.size()) != n) {
    throw UsageError(std::string(flag) + " takes 1 or " + std::to_string(n) + " values, got " +
                     std::to_string(v.size()));
  }
  return Eigen::Map<const Eigen::VectorXd>(v.data(), n);
}

void run_excite(const ExciteCliOptions& o) {
  if (o.criterion != "cond" && o.criterion != "logdet") {
    throw UsageError("--criterion must be cond or logdet, not '" + o.criterion + "'");
  }
  if (!(o.rate > 0.0)) throw UsageError("--rate must be > 0 Hz");
  const Model model = load_robot(o.robot);
  ExcitationOptions options;
  options.criterion = o.criterion == "cond" ? ExcitationCriterion::kConditionNumber
                                            : ExcitationCriterion::kDOptimality;
  options.harmonics = o.harmonics;
  options.f0 = o.f0;
  options.f_max = o.f_max;
  options.rest_at_ends = !o.no_rest;
  options.starts = o.starts;
  options.seed = o.seed;
  options.max_evaluations = o.max_evaluations;
  options.max_time = o.max_time;
  options.limit_fraction = o.limit_fraction;
  if (o.z_min > -1e299) options.z_min = o.z_min;
  options.dq_max = limits(o.dq_max, model.dof(), "--velocity-limit");
  options.ddq_max = limits(o.ddq_max, model.dof(), "--acceleration-limit");
  options.tau_max = limits(o.tau_max, model.dof(), "--torque-limit");
  if (o.harmonics < 2 && !o.no_rest) {
    throw UsageError("--harmonics " + std::to_string(o.harmonics) +
                     " leaves no free coefficient once the trajectory starts and ends at rest "
                     "(dq = ddq = 0): use --harmonics 2 or more, or --no-rest");
  }
  const ExcitationResult result = optimize_excitation(model, options);
  if (!std::isfinite(result.condition_number)) {
    throw Error("the optimised trajectory of '" + o.robot +
                "' does not excite every base parameter (condition number infinite); use more "
                "--harmonics, a higher --fmax or wider limits");
  }
  std::cout << excitation_text(result);
  if (!o.json.empty()) write_json(o.json, excitation_to_json(result));
  write_trajectory_csv(o.out,
                       sample_trajectory(FourierTrajectory(result.coefficients), o.rate, true));
  std::cout << "wrote " << o.out << (o.json.empty() ? "" : " and " + o.json) << '\n';
}

}  // namespace

void add_excite_command(CLI::App& app) {
  auto o = std::make_shared<ExciteCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "excite", "Optimise a finite-Fourier-series excitation (condition number or D-optimality)");
  cmd->add_option("--robot,-r", o->robot, "Built-in robot name or .urdf/.yaml model")->required();
  cmd->add_option("--out,-o", o->out, "Trajectory CSV: t, q1..qn, dq1..dqn, ddq1..ddqn")
      ->required();
  cmd->add_option("--json", o->json,
                  "Result JSON: criterion, value, constraints_satisfied, coefficients");
  cmd->add_option("--harmonics", o->harmonics,
                  "Harmonics per joint (5 in B. Bona, A. Curatella, Closed-loop rigid model "
                  "identification of an industrial robot, 2005)")
      ->capture_default_str();
  cmd->add_option("--f0", o->f0, "Fundamental frequency [Hz]; period 1/f0")->capture_default_str();
  cmd->add_option("--fmax", o->f_max,
                  "Bandwidth limit [Hz]: harmonics·f0 must not exceed it; 0 = none");
  cmd->add_option("--criterion", o->criterion, "cond (condition number) or logdet (D-optimality)")
      ->capture_default_str();
  cmd->add_option("--rate", o->rate, "Sample rate of the written trajectory [Hz]")
      ->capture_default_str();
  cmd->add_option("--velocity-limit", o->dq_max,
                  "|dq| limits [rad/s], 1 or n values; default model")
      ->delimiter(',');
  cmd->add_option("--acceleration-limit", o->ddq_max, "|ddq| limits [rad/s²], 1 or n values")
      ->delimiter(',');
  cmd->add_option("--torque-limit", o->tau_max,
                  "|tau| limits [N·m], 1 or n values; default model effort")
      ->delimiter(',');
  cmd->add_option("--limit-fraction", o->limit_fraction, "Use this fraction of every limit (0, 1]");
  cmd->add_option("--z-min", o->z_min, "Every link origin must stay above this height [m]");
  cmd->add_option("--starts", o->starts, "Multi-start initial points")->capture_default_str();
  cmd->add_option("--seed", o->seed, "Seed of the initial points")->capture_default_str();
  cmd->add_option("--max-evaluations", o->max_evaluations, "Evaluations per start")
      ->capture_default_str();
  cmd->add_option("--max-time", o->max_time, "Wall-clock budget [s]; 0 = none (reproducible)")
      ->capture_default_str();
  cmd->add_flag("--no-rest", o->no_rest,
                "Do not force zero velocity/acceleration at start and end");
  cmd->callback([o] { run_excite(*o); });
}

}  // namespace dynid::cli
