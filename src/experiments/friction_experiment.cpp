#include "dynid/experiments/friction_experiment.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identification/known_friction.hpp"
#include "experiments/experiment_columns.hpp"

namespace dynid {

FrictionExperimentResult fit_friction_experiment(const Model& model,
                                                 const std::vector<ProcessedRecord>& runs,
                                                 int joint,
                                                 const FrictionExperimentOptions& options) {
  const int n = model.dof();
  if (joint < 0 || joint >= n) {
    throw UsageError("joint " + std::to_string(joint + 1) + " is not a joint of model '" +
                     model.name + "', which has " + std::to_string(n));
  }
  if (!(options.confidence_level > 0.0 && options.confidence_level < 1.0)) {
    throw UsageError("confidence level must be in (0, 1)");
  }
  if (!(options.zero_velocity_fraction >= 0.0 && options.zero_velocity_fraction < 1.0) ||
      !(options.zero_velocity_noise_multiple >= 0.0) || options.curve_points < 2) {
    throw UsageError("friction experiment options: fraction in [0, 1), multiple >= 0, >= 2 points");
  }
  if (runs.empty()) throw UsageError("a friction experiment needs at least one run");
  for (size_t r = 0; r < runs.size(); ++r) {
    if (runs[r].record.q.cols() != n) {
      throw Error("run " + std::to_string(r + 1) + " has " +
                  std::to_string(runs[r].record.q.cols()) + " joints but model '" + model.name +
                  "' has " + std::to_string(n));
    }
  }
  FrictionExperimentResult out;
  out.joint = joint;
  const std::string j = std::to_string(joint + 1);
  out.names = {"Fvp" + j, "Fvn" + j, "Fcp" + j, "Fcn" + j};
  // Compensation with the rigid body and the armature only: the friction is what is sought.
  Model rigid = model;
  for (Joint& jt : rigid.joints) {
    jt.friction.Fv = jt.friction.Fc = jt.friction.Fo = jt.friction.Fva = jt.friction.Fca = 0.0;
  }
  Workspace ws(rigid);
  Eigen::VectorXd tau(n), rest(n);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const bool decoupled = std::isfinite(options.equivalent_inertia);
  if (options.gravity && options.gravity->joint() != joint) {
    throw UsageError("the gravity given is that of joint " +
                     std::to_string(options.gravity->joint() + 1) + ", not of joint " +
                     std::to_string(joint + 1) + "; give the gravity result of this joint");
  }
  double peak = 0.0;
  for (const auto& p : runs) peak = std::max(peak, p.record.dq.col(joint).cwiseAbs().maxCoeff());
  double noise = 0.0;
  for (const auto& p : runs) {
    if (p.velocity_noise_std.size() == n) noise = std::max(noise, p.velocity_noise_std[joint]);
  }
  const double threshold =
      std::max(options.zero_velocity_fraction * peak, options.zero_velocity_noise_multiple * noise);
  out.zero_velocity_threshold = threshold;
  Eigen::Index rows = 0, total = 0;
  for (const auto& p : runs) {
    total += p.record.t.size();
    for (Eigen::Index k = 0; k < p.record.t.size(); ++k)
      rows += std::abs(p.record.dq(k, joint)) >= threshold;
  }
  Eigen::MatrixXd W(rows, 4);
  Eigen::VectorXd y(rows);
  Eigen::VectorXi sample(rows);
  out.sample_run.resize(rows);
  out.sample_t.resize(rows);
  out.sample_dq.resize(rows);
  Eigen::Index i = 0, offset = 0, positive = 0, negative = 0;
  // Samples of each direction (up, down) that accelerate or decelerate by more than a fifth of the
  // peak |q̈_J|: an error of the compensated inertia adds ΔM·q̈ to τ_f, which averages out only
  // when each direction has both phases; with one sign it aliases into the Coulomb level.
  double peak_ddq = 0.0;
  for (const auto& p : runs) {
    for (Eigen::Index k = 0; k < p.record.t.size(); ++k)
      if (std::abs(p.record.dq(k, joint)) >= threshold)
        peak_ddq = std::max(peak_ddq, std::abs(p.record.ddq(k, joint)));
  }
  Eigen::Index speeding[2] = {0, 0}, braking[2] = {0, 0};
  bool expected_sign = true;
  for (size_t r = 0; r < runs.size(); ++r) {
    const ProcessedRecord& p = runs[r];
    const bool filtered = p.moving_positive.size() != 0;
    expected_sign = expected_sign && filtered;
    for (Eigen::Index k = 0; k < p.record.t.size(); ++k) {
      const double v = p.record.dq(k, joint);
      if (std::abs(v) < threshold) continue;
      const Eigen::VectorXd q = p.record.q.row(k).transpose();
      rnea(rigid, ws, q, p.record.dq.row(k).transpose(), p.record.ddq.row(k).transpose(), tau);
      double compensation = tau[joint];
      if (options.gravity || decoupled) {
        // Split the model's torque into its gravity and the rest, replace what is given.
        rnea(rigid, ws, q, zero, zero, rest);
        const double gravity = options.gravity ? options.gravity->torque(q) : rest[joint];
        const double motion = decoupled ? options.equivalent_inertia * p.record.ddq(k, joint)
                                        : tau[joint] - rest[joint];
        compensation = gravity + motion;
      }
      W.row(i) = detail::friction_columns(p, k, joint).transpose();
      y[i] = p.record.tau(k, joint) - compensation;
      positive += v > 0.0;
      negative += v < 0.0;
      const double along = p.record.ddq(k, joint) * (v > 0.0 ? 1.0 : -1.0);
      speeding[v < 0.0] += along > 0.2 * peak_ddq;
      braking[v < 0.0] += along < -0.2 * peak_ddq;
      sample[i] = static_cast<int>(offset + k);
      out.sample_run[i] = static_cast<int>(r);
      out.sample_t[i] = p.record.t[k];
      out.sample_dq[i] = v;
      ++i;
    }
    offset += p.record.t.size() + 1;  // a gap: the HAC lags do not cross runs
  }
  // Each direction needs enough samples for its two parameters and a spread of speeds.
  constexpr Eigen::Index kMinimumPerDirection = 10;
  if (positive < kMinimumPerDirection || negative < kMinimumPerDirection) {
    std::ostringstream m;
    m << "joint " << joint + 1 << " moves " << (positive < kMinimumPerDirection ? "up" : "down")
      << " in only " << std::min(positive, negative)
      << " samples above the zero-velocity threshold " << threshold
      << "; asymmetric friction needs both directions: record back-and-forth moves "
         "(dynid excite --family bang-bang)";
    throw Error(m.str());
  }
  for (int d = 0; d < 2; ++d) {
    if (std::min(speeding[d], braking[d]) >= kMinimumPerDirection) continue;
    std::ostringstream m;
    m << "joint " << joint + 1 << " moving " << (d == 0 ? "up" : "down") << " "
      << (braking[d] < kMinimumPerDirection ? "never decelerates" : "never accelerates") << " ("
      << std::min(speeding[d], braking[d]) << " samples beyond a fifth of the peak |ddq|): a "
      << "friction run must speed up and slow down in each direction, or an error of the "
         "compensated inertia is fitted as Coulomb friction; record the whole bang-bang move "
         "(dynid excite --family bang-bang)";
    throw Error(m.str());
  }
  out.rows = rows;
  out.rows_left_out = total - rows;
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = out.names;
  out.estimate = ordinary_least_squares(W, y, Eigen::VectorXi(), eo);
  if (out.estimate.summary.rank < 4) {
    throw Error("the runs of joint " + std::to_string(joint + 1) +
                " move at a single speed in some direction, so viscous and Coulomb friction "
                "cannot be separated; use bang-bang moves, whose speed sweeps from 0 to the peak");
  }
  const Eigen::VectorXd e = y - W * out.estimate.x;
  const HacSummary h = apply_hac_covariance(out.estimate, W, e, sample, eo);
  out.relative_error = e.norm() / std::max(y.norm(), 1e-300);
  out.residual_rms = e.norm() / std::sqrt(static_cast<double>(rows));
  out.sample_tau = y;
  out.sample_fitted = W * out.estimate.x;
  const Eigen::VectorXd& x = out.estimate.x;
  out.curve_velocity = Eigen::VectorXd::LinSpaced(options.curve_points, -peak, peak);
  out.curve_torque = out.curve_velocity.unaryExpr([&](double v) {
    return v > 0.0 ? x[0] * v + x[2] : v < 0.0 ? x[1] * v - x[3] : 0.0;
  });
  std::ostringstream c;
  c << "rows with |dq" << joint + 1 << "| < " << threshold << " left out (max("
    << options.zero_velocity_fraction << " x max|dq|, " << options.zero_velocity_noise_multiple
    << " x the velocity noise std)): " << out.rows_left_out << " of " << total;
  out.choices.emplace_back("zero_velocity", c.str());
  out.choices.emplace_back(
      "compensation",
      std::string(decoupled ? "the decoupled result's equivalent inertia M_J*ddq_J"
                            : "inertia, Coriolis and centripetal torques of model '" + model.name +
                                  "' (its friction left out)") +
          (options.gravity ? " and the gravity identified by the experiment given (seed 2 §3.2)"
                           : " and its gravity") +
          " subtracted");
  out.choices.emplace_back("coulomb_columns", expected_sign
                                                  ? "filtered expected sign (parallel filtering)"
                                                  : "[dq > 0] and -[dq < 0]");
  out.choices.emplace_back("covariance", "Newey-West (HAC) over samples, Bartlett window of " +
                                             std::to_string(h.bandwidth) + " samples");
  // A friction run's compensated torque is friction plus noise; a residual of a fifth of it is
  // structure the compensation left behind (a wrong model, other joints moving, a torque offset).
  constexpr double kUnexplained = 0.2;
  if (out.relative_error > kUnexplained) {
    std::ostringstream w;
    w << "the compensated torque of joint " << joint + 1 << " is not explained by friction ("
      << std::setprecision(2) << 100.0 * out.relative_error
      << " % residual): check the model given for compensation (--params) and that only this "
         "joint moves; the intervals are about "
      << h.median_ratio << "x the white-noise ones for that reason";
    out.warnings.push_back(w.str());
  }
  for (const std::string& w : out.estimate.summary.warnings) out.warnings.push_back(w);
  return out;
}

}  // namespace dynid
