#include "dynid/experiments/decoupled_model.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "experiments/experiment_columns.hpp"

namespace dynid {

DecoupledJointResult fit_decoupled_joint(const std::vector<ProcessedRecord>& runs, int joint,
                                         const DecoupledModelOptions& options) {
  if (!(options.confidence_level > 0.0 && options.confidence_level < 1.0)) {
    throw UsageError("confidence level must be in (0, 1)");
  }
  if (runs.empty()) throw UsageError("a decoupled model needs at least one run");
  const Eigen::Index n = runs.front().record.q.cols();
  for (size_t r = 0; r < runs.size(); ++r) {
    if (runs[r].record.q.cols() != n) {
      throw Error("run " + std::to_string(r + 1) + " has " +
                  std::to_string(runs[r].record.q.cols()) + " joints, run 1 has " +
                  std::to_string(n));
    }
  }
  if (joint < 0 || joint >= n) {
    throw UsageError("joint " + std::to_string(joint + 1) +
                     " is not a joint of the runs, which have " + std::to_string(n));
  }
  DecoupledJointResult out;
  out.joint = joint;
  const std::string j = std::to_string(joint + 1);
  out.names = {"M" + j, "a" + j, "b" + j, "Fvp" + j, "Fvn" + j, "Fcp" + j, "Fcn" + j};
  // Where the premise fails: held joints that moved, and coupling torque on them. A joint moved
  // when its position spans more than max(held_motion, 10 σ_q): a held joint jitters by its
  // encoder noise and by the deflection its controller allows.
  out.held_span = Eigen::VectorXd::Zero(n);
  out.coupling_ratio = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd var = Eigen::VectorXd::Zero(n), position_noise = Eigen::VectorXd::Zero(n);
  double count = 0.0;
  for (const ProcessedRecord& p : runs) {
    const Eigen::VectorXd span =
        (p.record.q.colwise().maxCoeff() - p.record.q.colwise().minCoeff()).transpose();
    out.held_span = out.held_span.cwiseMax(span);
    const Eigen::MatrixXd centred = p.record.tau.rowwise() - p.record.tau.colwise().mean();
    var += centred.colwise().squaredNorm().transpose();
    count += static_cast<double>(p.record.t.size());
    if (p.position_noise_std.size() == n) {
      position_noise = position_noise.cwiseMax(p.position_noise_std);
    }
  }
  const auto still = [&](Eigen::Index i) {
    return out.held_span[i] <= std::max(options.held_motion, 10.0 * position_noise[i]);
  };
  if (still(joint)) {
    std::ostringstream m;
    m << "joint " << j << " does not move in these runs (its position spans "
      << out.held_span[joint] << "); record a run of that joint (dynid excite --joint " << j << ")";
    throw Error(m.str());
  }
  double peak = 0.0, noise = 0.0;
  for (const auto& p : runs) {
    peak = std::max(peak, p.record.dq.col(joint).cwiseAbs().maxCoeff());
    if (p.velocity_noise_std.size() == n) noise = std::max(noise, p.velocity_noise_std[joint]);
  }
  const double threshold =
      std::max(options.zero_velocity_fraction * peak, options.zero_velocity_noise_multiple * noise);
  if (!(peak > threshold) || !(peak > 0.0)) {
    throw Error("joint " + j +
                " does not move above its velocity noise in these runs; record a "
                "run of that joint (dynid excite --joint " +
                j + ")");
  }
  Eigen::Index rows = 0;
  for (const auto& p : runs) rows += (p.record.dq.col(joint).array().abs() >= threshold).count();
  Eigen::MatrixXd W(rows, 7);
  Eigen::VectorXd y(rows);
  Eigen::VectorXi sample(rows);
  Eigen::Index i = 0, offset = 0;
  for (const ProcessedRecord& p : runs) {
    for (Eigen::Index k = 0; k < p.record.t.size(); ++k) {
      if (std::abs(p.record.dq(k, joint)) < threshold) continue;
      const double q = p.record.q(k, joint);
      W(i, 0) = p.record.ddq(k, joint);
      W(i, 1) = std::sin(q);
      W(i, 2) = std::cos(q);
      W.block<1, 4>(i, 3) = detail::friction_columns(p, k, joint).transpose();
      y[i] = p.record.tau(k, joint);
      sample[i] = static_cast<int>(offset + k);
      ++i;
    }
    offset += p.record.t.size() + 1;  // the HAC lags do not cross runs
  }
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = out.names;
  out.estimate = ordinary_least_squares(W, y, Eigen::VectorXi(), eo);
  if (out.estimate.summary.rank < W.cols()) {
    std::string missing;
    for (Eigen::Index c : out.estimate.unidentifiable) missing += " " + out.names[c];
    throw Error("the runs of joint " + j + " do not determine" + missing +
                ": the joint must move both ways, at varying speed and over a range of positions "
                "(a Fourier or bang-bang run of that joint)");
  }
  const Eigen::VectorXd e = y - W * out.estimate.x;
  const HacSummary h = apply_hac_covariance(out.estimate, W, e, sample, eo);
  out.rows = rows;
  out.relative_error = e.norm() / std::max(y.norm(), 1e-300);
  const detail::Sinusoid g = detail::sinusoid_from_linear(
      out.estimate.x[1], out.estimate.x[2], out.estimate.covariance.block<2, 2>(1, 1));
  out.k = g.k;
  out.q_off = g.q_off;
  out.k_std = g.k_std;
  out.q_off_std = g.q_off_std;

  const Eigen::VectorXd rms = (var / count).cwiseSqrt();
  for (Eigen::Index i2 = 0; i2 < n; ++i2) {
    if (i2 == joint) continue;
    out.coupling_ratio[i2] = rms[i2] / std::max(rms[joint], 1e-300);
    std::ostringstream w;
    w << std::setprecision(2);
    if (!still(i2)) {
      w << "joint " << i2 + 1 << " moved by " << out.held_span[i2] << " while joint " << joint + 1
        << " was identified: the decoupled model assumes it held; hold it or identify both "
           "together (dynid identify)";
      out.warnings.push_back(w.str());
    } else if (out.coupling_ratio[i2] > options.coupling_warning) {
      w << "held joint " << i2 + 1 << " carries torque variations " << out.coupling_ratio[i2]
        << "x those of joint " << joint + 1
        << ": the joints are dynamically coupled, so the decoupled model holds in this pose "
           "only and will mispredict motions of several joints";
      out.warnings.push_back(w.str());
    }
  }
  std::ostringstream c;
  c << "rows with |dq" << joint + 1 << "| < " << threshold << " left out (max("
    << options.zero_velocity_fraction << " x max|dq|, " << options.zero_velocity_noise_multiple
    << " x the velocity noise std))";
  out.choices.emplace_back("zero_velocity", c.str());
  out.choices.emplace_back("covariance", "Newey-West (HAC) over samples, Bartlett window of " +
                                             std::to_string(h.bandwidth) + " samples");
  for (const std::string& w : out.estimate.summary.warnings) out.warnings.push_back(w);
  return out;
}

}  // namespace dynid
