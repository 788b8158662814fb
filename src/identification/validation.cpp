#include "dynid/identification/validation.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/identification/pipeline.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/signal/plausibility.hpp"
#include "identification/preparation.hpp"

namespace dynid {

namespace {

// A row whose |dq̂| is within 3 velocity-noise stds of zero cannot be told from standing still.
constexpr double kStillNoiseBand = 3.0;

}  // namespace

ValidationResult validate_torques(const Model& model, const JointRecord& record,
                                  const std::vector<std::string>& names,
                                  const Eigen::VectorXd& values, const IdentifyOptions& options,
                                  const std::vector<std::string>& not_excited,
                                  const ParameterCompletion& nominal) {
  const int n = model.dof();
  if (nominal.values.size() != static_cast<Eigen::Index>(nominal.names.size())) {
    throw Error("validate_torques: the nominal completion has " +
                std::to_string(nominal.names.size()) + " names and " +
                std::to_string(nominal.values.size()) + " values");
  }
  ValidationResult out;
  // The time-units diagnosis identify makes (screen_run): a t column in milliseconds is named as
  // such here too, before the filter's cut-off search fails on it for another reason.
  if (record.t.allFinite()) {
    if (auto warning = check_sample_rate(record.t)) out.choices.emplace_back("warning", *warning);
  }
  out.processed = preprocess_run(model, record, options.signal, out.choices);
  // As identify() does: a joint held by its controller did not move (its jitter is noise).
  hold_still_joints(model, out.processed, out.choices);
  const JointRecord& r = out.processed.record;
  // The same equations as identify(): every row for the headline figures, and the rows its
  // zero-velocity rule keeps (near-still rows of a Coulomb model: their sign(dq) is noise).
  const EquationBlock all = differential_equations(
      model, options.layout, options.coupling && !coupled_motors(model).empty(), out.processed,
      Eigen::VectorXd());
  const std::vector<std::string>& columns = all.columns;
  // Each identified parameter selects its leading standard column: W_b·theta_b uses the base
  // columns only (W_2 = W_1·K_d is folded into theta_b).
  const auto column_of = [&columns](const std::string& name) {
    std::string lead = name;
    auto it = std::find(columns.begin(), columns.end(), lead);
    if (it == columns.end() && !lead.empty() && lead.back() == 'R') {
      lead.pop_back();
      it = std::find(columns.begin(), columns.end(), lead);
    }
    if (it == columns.end()) {
      throw Error("parameter '" + name +
                  "' of the result is not a column of this model and friction set; identify and "
                  "validate with the same robot and --friction options");
    }
    return static_cast<int>(it - columns.begin());
  };
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(static_cast<Eigen::Index>(columns.size()));
  std::vector<int> determined;
  for (size_t i = 0; i < names.size(); ++i) {
    determined.push_back(column_of(names[i]));
    theta[determined.back()] = values[static_cast<Eigen::Index>(i)];
  }
  const Eigen::Index m = r.t.size();
  out.samples = m;
  const Eigen::VectorXd threshold =
      zero_velocity_threshold(options.layout, options.signal, out.processed,
                              "left out of the error statistics", out.choices);
  out.zero_velocity_threshold = threshold;
  const EquationBlock moving = moving_rows(all, r.dq, threshold);
  Eigen::VectorXd pred = all.W * theta;
  if (!not_excited.empty() && moving.y.size() > 0) {
    std::vector<int> together = determined;
    for (const std::string& name : not_excited) together.push_back(column_of(name));
    std::sort(determined.begin(), determined.end());
    std::sort(together.begin(), together.end());
    if (data_identifiability(select_columns(moving, together)).rank >
        data_identifiability(select_columns(moving, determined)).rank) {
      std::string list;
      for (const std::string& name : not_excited) list += (list.empty() ? "" : ", ") + name;
      if (nominal.names.empty()) {
        throw Error("the result does not determine " + list +
                    " (not_excited: its identification data did not move them) but this run "
                    "excites them, and no nominal values were given to predict them with; "
                    "validate on a run like the identification run(s), or identify from runs "
                    "that also excite those");
      }
      // The estimates hold D·θ_u (data regrouping); with θ_u at its nominal value the completed
      // vector predicts the identification data as the estimates do, and this run too.
      theta.setZero();
      for (size_t i = 0; i < nominal.names.size(); ++i) {
        theta[column_of(nominal.names[i])] = nominal.values[static_cast<Eigen::Index>(i)];
      }
      const Eigen::VectorXd filled = all.W * theta;
      out.filled_share = (filled - pred).norm() / std::max(filled.norm(), 1e-300);
      pred = filled;
      out.completed = not_excited;
      std::ostringstream share;
      share.precision(3);
      share << 100.0 * out.filled_share;
      out.warnings.push_back(
          "the result does not determine " + list +
          " (not excited by its identification data) but this run excites them: predicted with "
          "their nominal (model) values, which carry " +
          share.str() +
          " % of the predicted torque; identify from runs that also excite those to predict "
          "them from data");
    }
  }
  out.predicted =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          pred.data(), m, n);
  const Eigen::MatrixXd e = r.tau - out.predicted;
  const Eigen::VectorXd e_moving = moving.y - moving.W * theta;
  Eigen::VectorXd e2 = Eigen::VectorXd::Zero(n), y2 = Eigen::VectorXd::Zero(n),
                  cnt = Eigen::VectorXd::Zero(n);
  for (Eigen::Index i = 0; i < moving.y.size(); ++i) {
    const int j = moving.group[i];
    e2[j] += e_moving[i] * e_moving[i];
    y2[j] += moving.y[i] * moving.y[i];
    cnt[j] += 1.0;
  }
  out.rows = static_cast<Eigen::Index>(cnt.sum());
  out.rows_excluded = m * n - out.rows;
  out.joint_rows_excluded = (static_cast<double>(m) - cnt.array()).round().cast<int>();
  out.rms_all_rows = (e.colwise().squaredNorm().transpose() / static_cast<double>(m)).cwiseSqrt();
  out.relative_error_all_rows_joint =
      (e.colwise().squaredNorm().array() / r.tau.colwise().squaredNorm().array().max(1e-300))
          .sqrt()
          .transpose();
  if (out.rows == 0) {
    throw Error(
        "every sample is below the zero-velocity threshold; the run does not move, or "
        "lower --zero-velocity");
  }
  // Still rows (issue 25 item 9): inside the smooth Coulomb law's band or the velocity noise.
  out.still_threshold = Eigen::VectorXd::Zero(n);
  for (int j = 0; j < n; ++j) {
    const double width =
        j < out.processed.coulomb_width.size() ? out.processed.coulomb_width[j] : 0.0;
    const double sigma =
        j < out.processed.velocity_noise_std.size() ? out.processed.velocity_noise_std[j] : 0.0;
    out.still_threshold[j] = std::max(width, kStillNoiseBand * sigma);
  }
  out.joint_rows_still = Eigen::VectorXi::Zero(n);
  double still_e2 = 0.0, still_y2 = 0.0, moving_e2 = 0.0, moving_y2 = 0.0;
  for (Eigen::Index k = 0; k < m; ++k) {
    for (int j = 0; j < n; ++j) {
      const double ee = e(k, j) * e(k, j), yy = r.tau(k, j) * r.tau(k, j);
      if (std::abs(r.dq(k, j)) < out.still_threshold[j]) {
        ++out.joint_rows_still[j];
        still_e2 += ee;
        still_y2 += yy;
      } else {
        moving_e2 += ee;
        moving_y2 += yy;
      }
    }
  }
  out.relative_error_still_rows = still_y2 > 0.0 ? std::sqrt(still_e2 / still_y2) : 0.0;
  out.relative_error_moving_rows = moving_y2 > 0.0 ? std::sqrt(moving_e2 / moving_y2) : 0.0;
  out.rms = (e2.array() / cnt.array().max(1.0)).sqrt();
  out.relative_error = (e2.array() / y2.array().max(1e-300)).sqrt();
  out.relative_error_all = std::sqrt(e2.sum() / std::max(y2.sum(), 1e-300));
  out.relative_error_all_rows = e.norm() / std::max(r.tau.norm(), 1e-300);
  return out;
}

}  // namespace dynid
