#include "dynid/workflow/excite.hpp"

#include <algorithm>
#include <cmath>
#include <memory>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/excitation/bang_bang_trajectory.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/joint_fourier.hpp"
#include "dynid/excitation/polynomial_spline.hpp"
#include "dynid/excitation/slope_trajectory.hpp"
#include "dynid/excitation/trapezoidal_trajectory.hpp"
#include "dynid/report/excitation_report.hpp"

namespace dynid {
namespace {

// The Fourier series' own settings, checked before any work: its period sampled at `rate`.
void check_fourier(int harmonics, double f0, bool rest_at_ends, double rate) {
  if (harmonics < 2 && rest_at_ends) {
    throw UsageError("--harmonics " + std::to_string(harmonics) +
                     " leaves no free coefficient once the trajectory starts and ends at rest "
                     "(dq = ddq = 0): use --harmonics 2 or more, or --no-rest");
  }
  if (harmonics < 1) throw UsageError("--harmonics must be >= 1");
  if (!(f0 > 0.0)) throw UsageError("--f0 must be > 0 Hz");
  if (!(rate > 0.0)) throw UsageError("--rate must be > 0 Hz");
  try {
    check_trajectory_samples(1.0 / f0, rate, "--f0 " + short_number(f0) + " Hz gives a period of");
  } catch (const Error& e) {
    throw UsageError(std::string(e.what()) + " (--f0, --rate)");
  }
}

// The reference of a one-joint experiment: joint o.joint moves, the others stay at --pose; the
// samples are checked against the model's limits narrowed by --limit-fraction (and the given
// --velocity-limit / --acceleration-limit).
TrajectorySamples checked_joint_reference(const Model& model, const JointReferenceOptions& o) {
  const int n = model.dof();
  if (o.joint < 0 || o.joint >= n) {
    throw UsageError("--joint " + std::to_string(o.joint + 1) + " is not a joint of '" +
                     model.name + "' (1.." + std::to_string(n) + "); --family " + o.family +
                     " moves one joint, give its number");
  }
  const int j = o.joint;
  Eigen::VectorXd pose = Eigen::VectorXd::Zero(n);
  if (!o.pose.empty()) {
    pose = joint_limits_of(o.pose, n, "--pose");
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
    if (!o.range) {
      throw UsageError("--family fourier --joint needs --range FROM:TO of joint " +
                       std::to_string(o.joint + 1) + " (e.g. --range -0.5:0.5)");
    }
    const auto [from, to] = *o.range;
    JointFourierOptions fo;
    fo.harmonics = o.harmonics;
    fo.f0 = o.f0;
    fo.rest_at_ends = o.rest_at_ends;
    trajectory =
        std::make_unique<FourierTrajectory>(joint_fourier_reference(pose, j, from, to, fo));
  } else if (o.family == "spline") {
    if (o.via.size() < 2) {
      throw UsageError("--family spline needs --via with at least 2 positions of joint " +
                       std::to_string(o.joint + 1) + " (e.g. --via 0,0.8,-0.4,0)");
    }
    need(o.duration, "--duration [s]", "--duration 4");
    const auto m = static_cast<Eigen::Index>(o.via.size());
    Eigen::MatrixXd points(n, m);
    for (Eigen::Index k = 0; k < m; ++k) points.col(k) = at(o.via[static_cast<size_t>(k)]);
    trajectory =
        std::make_unique<PolynomialSpline>(Eigen::VectorXd::LinSpaced(m, 0.0, o.duration), points);
  } else {
    if (!o.range) {
      throw UsageError("--family " + o.family + " needs --range FROM:TO of joint " +
                       std::to_string(o.joint + 1) + " (e.g. --range -0.5:0.5)");
    }
    if (o.cycles < 1) throw UsageError("--cycles must be >= 1");
    if (!(o.dwell >= 0.0)) throw UsageError("--dwell must be >= 0 s");
    const auto [from, to] = *o.range;
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
  const Eigen::VectorXd dq_max = joint_limits_of(o.dq_max, n, "--velocity-limit");
  const Eigen::VectorXd ddq_max = joint_limits_of(o.ddq_max, n, "--acceleration-limit");
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

// Why an optimised excitation is refused: its tightest constraint (the largest violation relative
// to the limit's own size), what it reaches, and the flag that relaxes it.
std::string violation_text(const Model& model, const ExcitationOptions& o,
                           const ExcitationResult& r) {
  std::string s = "no excitation of '" + model.name + "' found meets its constraints (best of " +
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

}  // namespace

Eigen::VectorXd joint_limits_of(const std::vector<double>& v, int n, const char* flag) {
  if (v.empty()) return {};
  if (v.size() == 1) return Eigen::VectorXd::Constant(n, v[0]);
  if (static_cast<int>(v.size()) != n) {
    throw UsageError(std::string(flag) + " takes 1 or " + std::to_string(n) + " values, got " +
                     std::to_string(v.size()));
  }
  return Eigen::Map<const Eigen::VectorXd>(v.data(), n);
}

TrajectorySamples joint_experiment_reference(const Model& model, const JointReferenceOptions& o) {
  static const char* const kFamilies[] = {"fourier", "slope", "bang-bang", "trapezoid", "spline"};
  if (std::find(std::begin(kFamilies), std::end(kFamilies), o.family) == std::end(kFamilies)) {
    throw UsageError("--family must be fourier, slope, bang-bang, trapezoid or spline, not '" +
                     o.family + "'");
  }
  if (o.family == "fourier") check_fourier(o.harmonics, o.f0, o.rest_at_ends, o.rate);
  if (!(o.rate > 0.0)) throw UsageError("--rate must be > 0 Hz");
  if (!(o.limit_fraction > 0.0 && o.limit_fraction <= 1.0)) {
    throw UsageError("--limit-fraction must be in (0, 1]");
  }
  try {
    return checked_joint_reference(model, o);
  } catch (const UsageError&) {
    throw;
  } catch (const Error& e) {  // the trajectory's own checks (too short a range for the speed)
    throw UsageError("--family " + o.family + ": " + e.what());
  }
}

Excitation excite_fourier(const Model& model, const ExcitationOptions& options, double rate,
                          bool allow_violations) {
  check_fourier(options.harmonics, options.f0, options.rest_at_ends, rate);
  Excitation out;
  out.result = optimize_excitation(model, options);
  const ExcitationResult& result = out.result;
  if (!std::isfinite(result.condition_number)) {
    throw Error("the optimised trajectory of '" + model.name +
                "' does not excite every base parameter (condition number infinite); use more "
                "--harmonics, a higher --fmax or wider limits");
  }
  if (!result.constraints_satisfied) {
    // A trajectory outside the robot's limits is not an excitation to run: refused, unless asked
    // for (to inspect it, or to relax the limits knowingly).
    if (!allow_violations) {
      throw Error(violation_text(model, options, result) +
                  "; or write it anyway with --allow-violations (nothing was written)");
    }
    out.warnings.push_back(violation_text(model, options, result) +
                           " (written anyway: --allow-violations)");
  }
  out.json = excitation_to_json(result);
  out.samples = sample_trajectory(FourierTrajectory(result.coefficients), rate, true);
  return out;
}

}  // namespace dynid
