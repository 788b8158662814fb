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
#include "dynid/excitation/bang_bang_trajectory.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/joint_fourier.hpp"
#include "dynid/excitation/polynomial_spline.hpp"
#include "dynid/excitation/slope_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/excitation/trapezoidal_trajectory.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/excitation_report.hpp"
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

Eigen::VectorXd limits(const std::vector<double>& v, int n, const char* flag) {
  if (v.empty()) return {};
  if (v.size() == 1) return Eigen::VectorXd::Constant(n, v[0]);
  if (static_cast<int>(v.size()) != n) {
    throw UsageError(std::string(flag) + " takes 1 or " + std::to_string(n) + " values, got " +
                     std::to_string(v.size()));
  }
  return Eigen::Map<const Eigen::VectorXd>(v.data(), n);
}

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

// The reference of a one-joint experiment: joint o.joint moves, the others stay at --pose; the
// samples are checked against the model's limits narrowed by --limit-fraction (and the given
// --velocity-limit / --acceleration-limit).
TrajectorySamples joint_experiment(const Model& model, const ExciteCliOptions& o) {
  const int n = model.dof();
  if (o.joint < 1 || o.joint > n) {
    throw UsageError("--joint " + std::to_string(o.joint) + " is not a joint of '" + o.robot +
                     "' (1.." + std::to_string(n) + "); --family " + o.family +
                     " moves one joint, give its number");
  }
  const int j = o.joint - 1;
  Eigen::VectorXd pose = Eigen::VectorXd::Zero(n);
  if (!o.pose.empty()) {
    pose = limits(o.pose, n, "--pose");
  } else {
    for (int k = 0; k < n; ++k) {  // 0, or the middle of a range that excludes it
      const JointLimits& l = model.joints[k].limits;
      if (!(l.lower <= 0.0 && 0.0 <= l.upper)) pose[k] = 0.5 * (l.lower + l.upper);
    }
  }
  auto at = [&](double qj) {
    Eigen::VectorXd q = pose;
    q[j] = qj;
    return q;
  };
  auto need = [&](double value, const char* flag, const char* example) {
    if (!(value > 0.0)) {
      throw UsageError("--family " + o.family + " needs " + flag + " > 0 (e.g. " + example + ")");
    }
  };
  const Eigen::VectorXd same = Eigen::VectorXd::Constant(n, 1.0);
  std::unique_ptr<Trajectory> trajectory;
  // What to change when a limit is exceeded, per family.
  const std::string slower = o.family == "fourier"  ? "narrow --range or lower --f0/--harmonics"
                             : o.family == "spline" ? "lengthen --duration"
                                                    : "lower --velocity/--acceleration";
  if (o.family == "fourier") {
    if (o.range.empty()) {
      throw UsageError("--family fourier --joint needs --range FROM:TO of joint " +
                       std::to_string(o.joint) + " (e.g. --range -0.5:0.5)");
    }
    const auto [from, to] = parse_range(o.range);
    JointFourierOptions fo;
    fo.harmonics = o.harmonics;
    fo.f0 = o.f0;
    fo.rest_at_ends = !o.no_rest;
    trajectory =
        std::make_unique<FourierTrajectory>(joint_fourier_reference(pose, j, from, to, fo));
  } else if (o.family == "spline") {
    if (o.via.size() < 2) {
      throw UsageError("--family spline needs --via with at least 2 positions of joint " +
                       std::to_string(o.joint) + " (e.g. --via 0,0.8,-0.4,0)");
    }
    need(o.duration, "--duration [s]", "--duration 4");
    const auto m = static_cast<Eigen::Index>(o.via.size());
    Eigen::MatrixXd points(n, m);
    for (Eigen::Index k = 0; k < m; ++k) points.col(k) = at(o.via[static_cast<size_t>(k)]);
    trajectory =
        std::make_unique<PolynomialSpline>(Eigen::VectorXd::LinSpaced(m, 0.0, o.duration), points);
  } else {
    if (o.range.empty()) {
      throw UsageError("--family " + o.family + " needs --range FROM:TO of joint " +
                       std::to_string(o.joint) + " (e.g. --range -0.5:0.5)");
    }
    if (o.cycles < 1) throw UsageError("--cycles must be >= 1");
    if (!(o.dwell >= 0.0)) throw UsageError("--dwell must be >= 0 s");
    const auto [from, to] = parse_range(o.range);
    need(o.acceleration, "--acceleration [rad/s²]", "--acceleration 2");
    const Eigen::VectorXd a = o.acceleration * same;
    if (o.family == "slope") {
      need(o.velocity, "--velocity [rad/s]", "--velocity 0.3");
      trajectory = std::make_unique<SlopeTrajectory>(at(from), at(to), o.velocity * same, a,
                                                     o.cycles, o.dwell);
    } else {
      Eigen::MatrixXd way(n, 2 * o.cycles + 1);
      for (int k = 0; k <= 2 * o.cycles; ++k) way.col(k) = at(k % 2 ? to : from);
      if (o.family == "trapezoid") {
        need(o.velocity, "--velocity [rad/s]", "--velocity 0.3");
        trajectory = std::make_unique<TrapezoidalTrajectory>(way, o.velocity * same, a, o.dwell);
      } else {
        trajectory = std::make_unique<BangBangTrajectory>(way, a, o.dwell);
      }
    }
  }
  TrajectorySamples samples = sample_trajectory(*trajectory, o.rate, true);
  // Limits with the --limit-fraction margin: positions within the central fraction of the range.
  const Eigen::VectorXd dq_max = limits(o.dq_max, n, "--velocity-limit");
  const Eigen::VectorXd ddq_max = limits(o.ddq_max, n, "--acceleration-limit");
  for (int k = 0; k < n; ++k) {
    const JointLimits& l = model.joints[k].limits;
    const std::string name = "joint " + std::to_string(k + 1) + " (" + model.joints[k].name + ")";
    const double mid = 0.5 * (l.lower + l.upper),
                 half = 0.5 * o.limit_fraction * (l.upper - l.lower);
    const double lo = std::isfinite(half) ? mid - half : l.lower;
    const double hi = std::isfinite(half) ? mid + half : l.upper;
    const double q_lo = samples.q.col(k).minCoeff(), q_hi = samples.q.col(k).maxCoeff();
    if (q_lo < lo || q_hi > hi) {
      throw UsageError(name + " reaches [" + short_number(q_lo) + ", " + short_number(q_hi) +
                       "] outside its allowed range [" + short_number(lo) + ", " +
                       short_number(hi) + "] (model limits x --limit-fraction " +
                       short_number(o.limit_fraction) + "); change --range/--via or --pose");
    }
    double v_lim = o.limit_fraction * l.velocity;
    if (dq_max.size()) v_lim = std::min(v_lim, dq_max[k]);
    const double v = samples.dq.col(k).cwiseAbs().maxCoeff();
    if (v > v_lim) {
      throw UsageError(name + " reaches " + short_number(v) + " rad/s, above its limit " +
                       short_number(v_lim) + "; " + slower);
    }
    if (ddq_max.size()) {
      const double acc = samples.ddq.col(k).cwiseAbs().maxCoeff();
      if (acc > ddq_max[k]) {
        throw UsageError(name + " reaches " + short_number(acc) +
                         " rad/s², above --acceleration-limit " + short_number(ddq_max[k]) + "; " +
                         slower);
      }
    }
  }
  return samples;
}

void run_joint_experiment(const ExciteCliOptions& o) {
  if (!(o.rate > 0.0)) throw UsageError("--rate must be > 0 Hz");
  if (!(o.limit_fraction > 0.0 && o.limit_fraction <= 1.0)) {
    throw UsageError("--limit-fraction must be in (0, 1]");
  }
  const Model model = load_cli_robot(o.robot, o.robot_flags, {"excite", {}, {}, {}, ""});
  TrajectorySamples samples;
  try {
    samples = joint_experiment(model, o);
  } catch (const UsageError&) {
    throw;
  } catch (const Error& e) {  // the trajectory's own checks (too short a range for the speed)
    throw UsageError("--family " + o.family + ": " + e.what());
  }
  write_trajectory_csv(o.out, samples);
  std::cout << o.family << " reference of joint " << o.joint << ": " << samples.t.size()
            << " samples over " << short_number(samples.t[samples.t.size() - 1]) << " s\n"
            << "wrote " << o.out << '\n';
}

// Why an optimised excitation is refused: its tightest constraint (the largest violation relative
// to the limit's own size), what it reaches, and the flag that relaxes it.
std::string violation_text(const ExciteCliOptions& o, const ExcitationResult& r) {
  std::string s = "no excitation of '" + o.robot + "' found meets its constraints (best of " +
                  std::to_string(o.starts) + (o.starts == 1 ? " start, " : " starts, ") +
                  std::to_string(r.evaluations) + " evaluations; condition number " +
                  short_number(r.condition_number) + ")";
  const ConstraintMargin* m = tightest_constraint(r);
  if (m == nullptr) return s;
  const bool lower = m->name.find(" min") != std::string::npos;
  s += ": the tightest, " + m->name + ", reaches " + short_number(m->reached) + " " + m->unit +
       (lower ? " below" : " above") + " its limit " + short_number(m->limit) + " " + m->unit +
       " at t = " + short_number(m->time) + " s; ";
  const std::string fraction =
      o.limit_fraction < 1.0 ? " or --limit-fraction (now " + short_number(o.limit_fraction) + ")"
                             : "";
  const auto starts_with = [&](const char* prefix) { return m->name.rfind(prefix, 0) == 0; };
  if (starts_with("torque")) {
    s += "raise --torque-limit (default: the model's effort)" + fraction;
  } else if (starts_with("velocity")) {
    s += "raise --velocity-limit (default: the model's velocity limit)" + fraction;
  } else if (starts_with("acceleration")) {
    s += "raise --acceleration-limit" + fraction;
  } else if (starts_with("position")) {
    s += o.limit_fraction < 1.0
             ? "raise --limit-fraction (now " + short_number(o.limit_fraction) + ")"
             : "widen the model's position limits or lower --f0/--harmonics";
  } else if (starts_with("workspace z_min")) {
    s += "lower --z-min";
  } else {
    s += "widen the " + m->name;
  }
  return s + ", or search longer (--starts, --max-evaluations, --max-time)";
}

void run_excite(const ExciteCliOptions& o) {
  if (o.family != "fourier") {
    if (o.family != "slope" && o.family != "bang-bang" && o.family != "trapezoid" &&
        o.family != "spline") {
      throw UsageError("--family must be fourier, slope, bang-bang, trapezoid or spline, not '" +
                       o.family + "'");
    }
    if (!o.json.empty()) throw UsageError("--json is written by --family fourier only");
    if (o.allow_violations) {
      throw UsageError("--allow-violations is for the optimised --family fourier; a " + o.family +
                       " reference is checked against its limits and refused when it exceeds one");
    }
    run_joint_experiment(o);
    return;
  }
  if (o.harmonics < 2 && !o.no_rest) {
    throw UsageError("--harmonics " + std::to_string(o.harmonics) +
                     " leaves no free coefficient once the trajectory starts and ends at rest "
                     "(dq = ddq = 0): use --harmonics 2 or more, or --no-rest");
  }
  if (o.harmonics < 1) throw UsageError("--harmonics must be >= 1");
  if (!(o.f0 > 0.0)) throw UsageError("--f0 must be > 0 Hz");
  if (o.rate > 0.0) {  // before the optimisation: its trajectory is one period at --rate
    try {
      check_trajectory_samples(1.0 / o.f0, o.rate,
                               "--f0 " + short_number(o.f0) + " Hz gives a period of");
    } catch (const Error& e) {
      throw UsageError(std::string(e.what()) + " (--f0, --rate)");
    }
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
  if (!(o.rate > 0.0)) throw UsageError("--rate must be > 0 Hz");
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
  options.dq_max = limits(o.dq_max, model.dof(), "--velocity-limit");
  options.ddq_max = limits(o.ddq_max, model.dof(), "--acceleration-limit");
  options.tau_max = limits(o.tau_max, model.dof(), "--torque-limit");
  ProgressLine progress("excite", progress_wanted(o.quiet));
  options.progress = progress.callback();
  const ExcitationResult result = optimize_excitation(model, options);
  progress.finish();
  if (!std::isfinite(result.condition_number)) {
    throw Error("the optimised trajectory of '" + o.robot +
                "' does not excite every base parameter (condition number infinite); use more "
                "--harmonics, a higher --fmax or wider limits");
  }
  if (!result.constraints_satisfied) {
    // A trajectory outside the robot's limits is not an excitation to run: refused, unless asked
    // for (to inspect it, or to relax the limits knowingly).
    if (!o.allow_violations) {
      throw Error(violation_text(o, result) +
                  "; or write it anyway with --allow-violations (nothing was written)");
    }
    std::cerr << "warning: " << one_line(violation_text(o, result))
              << " (written anyway: --allow-violations)\n";
  }
  std::cout << excitation_text(result);
  OutputBatch outputs;  // both files or neither
  if (!o.json.empty()) write_json(o.json, excitation_to_json(result));
  write_trajectory_csv(o.out,
                       sample_trajectory(FourierTrajectory(result.coefficients), o.rate, true));
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
