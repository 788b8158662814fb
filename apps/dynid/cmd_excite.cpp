// `dynid excite`: optimise a Fourier excitation, or build a one-joint experiment reference (slope,
// bang-bang, trapezoid, spline), and write the reference trajectory.
#include <cmath>
#include <iostream>
#include <memory>
#include <stdexcept>
#include <string>
#include <utility>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/common/progress.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/excitation_report.hpp"
#include "dynid/workflow/excite.hpp"
#include "robot_flags.hpp"

namespace dynid::cli {
namespace {

struct ExciteCliOptions {
  std::string robot, out, json, criterion = "cond";
  RobotFlags robot_flags;  // --joints, --lock, --strict
  int harmonics = 5, starts = 4, max_evaluations = 3000;
  double f0 = 0.1, f_max = 0.0, rate = 100.0, max_time = 10.0, z_min = -1e300;
  double limit_fraction = 1.0;
  bool quiet = false;             // --quiet
  bool allow_violations = false;  // --allow-violations
  std::vector<double> dq_max, ddq_max, tau_max;
  unsigned seed = 20261123;
  bool no_rest = false;
  // One-joint experiment references (--family other than fourier).
  std::string family = "fourier", range;
  int joint = 0, cycles = 1;
  double velocity = 0.0, acceleration = 0.0, dwell = 0.0, duration = 0.0;
  std::vector<double> pose, via;
};

// "A:B" of --range as two numbers.
std::pair<double, double> parse_range(const std::string& text) {
  const auto colon = text.find(':');
  try {
    if (colon == std::string::npos) throw std::invalid_argument("no colon");
    size_t used_a = 0, used_b = 0;
    const double a = std::stod(text.substr(0, colon), &used_a);
    const double b = std::stod(text.substr(colon + 1), &used_b);
    if (used_a != colon || used_b != text.size() - colon - 1 || !std::isfinite(a) ||
        !std::isfinite(b) || a == b) {
      throw std::invalid_argument("bad");
    }
    return {a, b};
  } catch (const std::exception&) {
    throw UsageError("--range '" + text +
                     "' is not FROM:TO with two different finite positions [rad or m], e.g. "
                     "-0.5:0.5");
  }
}

void run_joint_experiment(const ExciteCliOptions& o) {
  JointReferenceOptions r;
  r.family = o.family;
  r.joint = o.joint - 1;
  r.pose = o.pose;
  if (!o.range.empty()) r.range = parse_range(o.range);
  r.velocity = o.velocity;
  r.acceleration = o.acceleration;
  r.cycles = o.cycles;
  r.dwell = o.dwell;
  r.via = o.via;
  r.duration = o.duration;
  r.harmonics = o.harmonics;
  r.f0 = o.f0;
  r.rest_at_ends = !o.no_rest;
  r.rate = o.rate;
  r.limit_fraction = o.limit_fraction;
  r.dq_max = o.dq_max;
  r.ddq_max = o.ddq_max;
  const Model model = load_cli_robot(o.robot, o.robot_flags, {"excite", {}, {}, {}, ""});
  const TrajectorySamples samples = joint_experiment_reference(model, r);
  write_trajectory_csv(o.out, samples);
  std::cout << o.family << " reference of joint " << o.joint << ": " << samples.t.size()
            << " samples over " << short_number(samples.t[samples.t.size() - 1]) << " s\n"
            << "wrote " << o.out << '\n';
}

void run_excite(const ExciteCliOptions& o) {
  if (o.family != "fourier") {
    if (!o.json.empty()) throw UsageError("--json is written by --family fourier only");
    if (o.allow_violations) {
      throw UsageError("--allow-violations is for the optimised --family fourier; a " + o.family +
                       " reference is checked against its limits and refused when it exceeds one");
    }
    run_joint_experiment(o);
    return;
  }
  if (o.joint != 0) {  // one joint, Schroeder phases scaled to --range (joint_fourier_reference)
    if (!o.json.empty())
      throw UsageError(
          "--json is written by the optimised --family fourier only (without --joint)");
    if (o.allow_violations) {
      throw UsageError(
          "--allow-violations is for the optimised --family fourier (without --joint); a "
          "one-joint reference is checked against its limits and refused when it exceeds one");
    }
    run_joint_experiment(o);
    return;
  }
  if (o.criterion != "cond" && o.criterion != "logdet") {
    throw UsageError("--criterion must be cond or logdet, not '" + o.criterion + "'");
  }
  const Model model = load_cli_robot(o.robot, o.robot_flags, {"excite", {}, {}, {}, ""});
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
  options.dq_max = joint_limits_of(o.dq_max, model.dof(), "--velocity-limit");
  options.ddq_max = joint_limits_of(o.ddq_max, model.dof(), "--acceleration-limit");
  options.tau_max = joint_limits_of(o.tau_max, model.dof(), "--torque-limit");
  ProgressLine progress("excite", progress_wanted(o.quiet));
  options.progress = progress.callback();
  const Excitation excitation = excite_fourier(model, options, o.rate, o.allow_violations);
  progress.finish();
  for (const std::string& w : excitation.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  std::cout << excitation_text(excitation.result);
  OutputBatch outputs;  // both files or neither
  if (!o.json.empty()) write_json(o.json, excitation.json);
  write_trajectory_csv(o.out, excitation.samples);
  outputs.commit();
  std::cout << "wrote " << o.out << (o.json.empty() ? "" : " and " + o.json) << '\n';
}

}  // namespace

void add_excite_command(CLI::App& app) {
  auto o = std::make_shared<ExciteCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "excite",
      "Optimise a finite-Fourier-series excitation (condition number or D-optimality), or write "
      "a one-joint experiment reference (--family ... --joint J)");
  cmd->add_option("--robot,-r", o->robot, "Built-in robot name or .urdf/.yaml model")->required();
  add_robot_flags(cmd, o->robot_flags);
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
  cmd->add_flag("--quiet,-q", o->quiet,
                "No progress line on stderr (shown only when stderr is a terminal)");
  cmd->add_flag("--allow-violations", o->allow_violations,
                "Write the optimised trajectory even when it violates a limit (a warning names "
                "the tightest); without it that is an error and nothing is written");
  cmd->add_flag("--no-rest", o->no_rest,
                "Do not force zero velocity/acceleration at start and end");
  cmd->add_option("--family", o->family,
                  "fourier (optimised, every joint; with --joint: joint J alone, Schroeder phases, "
                  "amplitudes 1/k, scaled to --range), or a one-joint experiment reference: slope "
                  "(constant-velocity slopes, gravity), bang-bang (friction), trapezoid, spline")
      ->capture_default_str();
  cmd->add_option("--joint", o->joint, "The joint that moves (1..n); the others stay at --pose");
  cmd->add_option("--pose", o->pose,
                  "Positions of the other joints [rad or m], n values; default 0 (or the middle "
                  "of a range that excludes 0)")
      ->delimiter(',');
  cmd->add_option("--range", o->range,
                  "fourier --joint, slope, bang-bang, trapezoid: FROM:TO of the joint");
  cmd->add_option("--velocity", o->velocity, "slope, trapezoid: cruise speed [rad/s]");
  cmd->add_option("--acceleration", o->acceleration,
                  "slope, bang-bang, trapezoid: acceleration [rad/s²]");
  cmd->add_option("--cycles", o->cycles, "slope, bang-bang, trapezoid: FROM-TO-FROM cycles")
      ->capture_default_str();
  cmd->add_option("--dwell", o->dwell, "Rest between moves [s]")->capture_default_str();
  cmd->add_option("--via", o->via,
                  "spline: positions of the joint, equally spaced in time, at rest at both ends")
      ->delimiter(',');
  cmd->add_option("--duration", o->duration, "spline: duration [s]");
  cmd->callback([o] { run_excite(*o); });
}

}  // namespace dynid::cli
