#include "dynid/identification/identify.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/SVD>

#include "dynid/closed_loop/closed_loop.hpp"
#include "dynid/closed_loop/maximum_likelihood.hpp"
#include "dynid/common/error.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/recursive_least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identification/cutoff_selection.hpp"
#include "dynid/identification/integral_equations.hpp"
#include "dynid/identification/outliers.hpp"
#include "dynid/identification/pipeline.hpp"
#include "dynid/model/transmission.hpp"
#include "identification/preparation.hpp"

namespace dynid {

namespace {

// Shares of identify()'s progress line: the runs' preparation, then the stacked estimate; maximum
// likelihood (when asked) fills the rest.
constexpr double kPreparedShare = 0.7;
constexpr double kEstimateShare = 0.1;

// The joint a layout column belongs to: link parameters of link j and joint columns of joint j;
// −1 for coupled-motor columns.
int column_joint(const Model& model, const ParameterLayout& layout, int column) {
  const int n = model.dof();
  if (column < kLinkParams * n) return column / kLinkParams;
  const int jc = layout.joint_columns();
  if (jc > 0 && column < kLinkParams * n + jc * n) return (column - kLinkParams * n) / jc;
  return -1;
}

// it where that is cheap to say (its own joint, or the parameters it cannot be told from).
void not_excited_warnings(const Model& model, const ParameterLayout& layout,
                          const BaseParameters& base, const EquationBlock& based,
                          const DataIdentifiability& data,
                          const std::vector<std::string>& expressions,
                          const std::vector<LockstepJoints>& lockstep,
                          std::vector<std::string>& warnings) {
  std::ostringstream head;
  head << std::setprecision(3) << "the data excite " << data.rank << " of the model's " << base.rank
       << " base parameters (data rank): the others are not estimated (not_excited)";
  if (data.plausible_magnitude > 0.0) {
    head << "; a combination counts as determined when its standard deviation (the residual "
            "noise "
         << data.noise_std << " per equation over its singular value) is below its plausible "
         << "magnitude (the whole torque, norm " << data.plausible_magnitude
         << "): here column-scaled singular values below " << data.tolerance << " x the largest";
  } else {
    head << "; column-scaled singular values below " << data.tolerance
         << " x the largest are round-off";
  }
  warnings.push_back(head.str());
  for (int c : data.not_excited) {
    const std::string& name = base.names[static_cast<size_t>(c)];
    const int joint = column_joint(model, layout, base.base[static_cast<size_t>(c)]);
    std::ostringstream w;
    const bool regrouped =
        std::find(data.regrouped.begin(), data.regrouped.end(), c) != data.regrouped.end();
    if (regrouped) {
      // Exactly dependent: one parameter with those that absorb it, not a question of noise.
      std::string into;
      for (size_t i = 0; i < data.kept.size(); ++i) {
        for (const auto& [col, coef] : data.absorbs[i]) {
          if (col == c) into += (into.empty() ? "" : "; ") + expressions[i];
        }
      }
      w << name << " is regrouped on these data: its column is a combination of the estimated "
        << "ones to round-off, so it is estimated only with them (" << into << ")";
    } else if (based.W.col(c).squaredNorm() == 0.0) {
      w << name << " is not excited: its column is zero on every equation used";
    } else {
      std::string with;
      for (size_t i = 0; i < data.kept.size(); ++i) {
        for (const auto& [col, coef] : data.absorbs[i]) {
          if (col == c)
            with += (with.empty() ? "" : ", ") + base.names[static_cast<size_t>(data.kept[i])];
        }
      }
      w << name << " is not excited: the data cannot tell it from "
        << (with.empty() ? "the other parameters" : with)
        << " (those estimates include its effect on these runs)";
    }
    const auto pair = std::find_if(lockstep.begin(), lockstep.end(), [&](const auto& p) {
      return p.first == joint || p.second == joint;
    });
    if (pair != lockstep.end()) {
      // The joint moved; "a run in which it moves" would be wrong advice (issue 26 item 5).
      w << "; " << lockstep_text(model, *pair);
    } else if (joint >= 0) {
      w << "; a run in which " << model.joints[static_cast<size_t>(joint)].name
        << " moves (above its encoder noise, with both velocity signs and varied "
           "configurations of the joints before it) would "
        << (regrouped ? "separate it" : "excite it");
    }
    warnings.push_back(w.str());
  }
}

}  // namespace

Eigen::VectorXd estimated_base_values(const IdentificationResult& result,
                                      const Eigen::VectorXd& base_values) {
  const std::vector<std::string>& all = result.base.names;
  const auto kept = static_cast<Eigen::Index>(result.names.size());
  const auto unexcited = static_cast<Eigen::Index>(result.not_excited.size());
  if (base_values.size() != static_cast<Eigen::Index>(all.size())) {
    throw Error("estimated_base_values: " + std::to_string(base_values.size()) +
                " values for the " + std::to_string(all.size()) + " base parameters");
  }
  if (unexcited > 0 &&
      (result.data_regrouping.rows() != kept || result.data_regrouping.cols() != unexcited)) {
    throw Error("estimated_base_values: data_regrouping is " +
                std::to_string(result.data_regrouping.rows()) + " x " +
                std::to_string(result.data_regrouping.cols()) + " for " + std::to_string(kept) +
                " estimates and " + std::to_string(unexcited) + " parameters not excited");
  }
  const auto at = [&](const std::string& name) {
    const auto it = std::find(all.begin(), all.end(), name);
    if (it == all.end()) {
      throw Error("estimated_base_values: '" + name + "' is not a base parameter of the result");
    }
    return base_values[it - all.begin()];
  };
  Eigen::VectorXd out(kept);
  for (Eigen::Index i = 0; i < kept; ++i) {
    out[i] = at(result.names[static_cast<size_t>(i)]);
    for (Eigen::Index j = 0; j < unexcited; ++j)
      out[i] += result.data_regrouping(i, j) * at(result.not_excited[static_cast<size_t>(j)]);
  }
  return out;
}

IdentificationResult identify(const Model& model, const JointRecord& record,
                              const IdentifyOptions& options) {
  return identify(model, std::vector<JointRecord>{record}, options);
}

IdentificationResult identify(const Model& model, const std::vector<JointRecord>& runs,
                              const IdentifyOptions& options) {
  return identify(model, runs, {}, options);
}

IdentificationResult identify(const Model& model, const std::vector<JointRecord>& runs,
                              const std::vector<ReferenceRecord>& references,
                              const IdentifyOptions& options) {
  if (runs.empty()) throw Error("identify: no run given; pass at least one recorded run");
  const int n = model.dof();
  IdentificationResult result;
  const bool coupling = options.coupling && !coupled_motors(model).empty();
  const bool integral = options.model == IdentificationModel::kIntegral;
  if (integral && !options.known_friction.empty())
    throw UsageError("known friction is subtracted from joint torques: use the differential model");
  const bool closed = options.closed_loop.method != ClosedLoopMethod::kNone;
  const bool ml = options.estimator == IdentificationEstimator::kMl;
  check_closed_loop_request(options, runs.size(), references.size());
  Eigen::Index projected_dimensions = 0;       // Σ over runs and joints of the projector's rank
  std::vector<ProcessedRecord> prepared;       // every run's (maximum likelihood needs them all)
  ProjectedRun projected;                      // the first run's projection (maximum likelihood)
  std::vector<Eigen::VectorXd> remainder_std;  // per closed-loop run, per joint [N·m or N]
  if (integral) {
    std::ostringstream m;
    m << "integral (energy) model, "
      << (options.integral.long_integrals ? "long integrals from the first sample in steps of "
                                          : "short intervals of ")
      << options.integral.interval << " s";
    result.choices.emplace_back("model", m.str());
  } else {
    result.choices.emplace_back("model", "differential (joint torques)");
  }
  // prepare + equations, one run at a time (each its own rate, filter edges, derivatives).
  std::vector<EquationBlock> blocks;
  std::vector<ScreenedRun> screened;
  std::vector<Eigen::MatrixXd> velocities;  // per run, as processed (lockstep diagnosis)
  result.zero_velocity_threshold = Eigen::VectorXd::Zero(n);
  // The progress line advances through the real stages (it sat at 0 % for 17 s): each run's
  // preparation (the cut-off selection is most of it) takes kPreparedShare, the stacked estimate
  // the next share, maximum likelihood the rest.
  const auto stage = [&](double fraction, const std::string& what) {
    if (options.progress) options.progress(fraction, what);
  };
  const double runs_count = static_cast<double>(runs.size());
  for (size_t i = 0; i < runs.size(); ++i) {
    stage(kPreparedShare * static_cast<double>(i) / runs_count,
          "run " + std::to_string(i + 1) + "/" + std::to_string(runs.size()) +
              ": screening, cut-off, filtering");
    std::vector<std::pair<std::string, std::string>> choices;
    screened.push_back(screen_run(model, runs[i], options.outliers));  // outliers.hpp
    ProcessedRecord processed;
    Eigen::VectorXd threshold = Eigen::VectorXd::Zero(n);
    if (closed) {
      ClosedLoopIdOptions co = options.closed_loop;
      co.torque_time_offset = options.signal.torque_time_offset;
      ClosedLoopRun cl = prepare_closed_loop(screened.back().record, references[i], co, choices);
      const std::string run_name = runs.size() > 1 ? "run " + std::to_string(i + 1) + ": " : "";
      for (const std::string& w : cl.warnings) result.warnings.push_back(run_name + w);
      processed = std::move(cl.processed);
      // Known friction (seed 2 section 3.4) leaves the torque before the projection, so that
      // both sides of the regression are projected alike.
      EquationBlock raw =
          differential_equations(model, options.layout, coupling, processed, Eigen::VectorXd());
      subtract_known_friction(model, options.known_friction, processed, raw);
      blocks.push_back(project_equations(raw, *cl.projector));
      projected_dimensions += static_cast<Eigen::Index>(n) * cl.report.rank;
      remainder_std.push_back(cl.torque_remainder_std);
      if (i == 0) {
        projected.projector = cl.projector;
        projected.torque_remainder_std = cl.torque_remainder_std;
      }
      result.closed_loop.push_back(std::move(cl.report));
    } else if (integral) {
      // The held-out cut-off selection fits the differential model; the integral model has its
      // own fixed defaults (integral_signal_options()).
      SignalOptions signal = options.signal;
      if (signal.cutoff_hz <= 0.0) signal.cutoff_hz = integral_signal_options().cutoff_hz;
      if (signal.decimate <= 0) signal.decimate = 1;
      // The friction work ∫|q̇| dt is continuous through rest: no pre-sliding band is modelled.
      if (signal.coulomb_width.empty()) signal.coulomb_width_fraction = 0.0;
      processed = preprocess_run(model, screened.back().record, signal, choices);
      hold_still_joints(model, processed, choices);
      blocks.push_back(
          integral_equations(model, options.layout, coupling, processed, options.integral));
    } else {
      // The cut-off of each run from its own data (held-out prediction, cutoff_selection.hpp).
      const CutoffSelection cutoff = select_cutoff(model, screened.back().record, options);
      processed = preprocess_run(model, screened.back().record, cutoff.signal, choices);
      echo_cutoff_selection(cutoff, choices);
      hold_still_joints(model, processed, choices);
      threshold =
          zero_velocity_threshold(options.layout, options.signal, processed, "removed", choices);
      blocks.push_back(
          differential_equations(model, options.layout, coupling, processed, threshold));
      subtract_known_friction(model, options.known_friction, processed, blocks.back());
    }
    RunSummary run;
    run.samples = processed.record.t.size();
    run.rows = blocks.back().y.size();
    run.zero_velocity_threshold = threshold;
    result.runs.push_back(run);
    result.samples += run.samples;
    // Validation leaves out the rows below the largest threshold any run used.
    result.zero_velocity_threshold = result.zero_velocity_threshold.cwiseMax(threshold);
    if (processed.coulomb_width.size() == n) {
      result.coulomb_width = result.coulomb_width.size() == n
                                 ? result.coulomb_width.cwiseMax(processed.coulomb_width)
                                 : processed.coulomb_width;
    }
    const std::string prefix = runs.size() > 1 ? "run " + std::to_string(i + 1) + " " : "";
    for (auto& [key, value] : choices) result.choices.emplace_back(prefix + key, value);
    if (ml) prepared.push_back(processed);
    velocities.push_back(processed.record.dq);
    if (i == 0) result.processed = std::move(processed);
    result.warnings.insert(result.warnings.end(), screened.back().warnings.begin(),
                           screened.back().warnings.end());
  }
  // stack + structural base columns (Gautier–Khalil, from the model).
  stage(kPreparedShare, "base parameters and what the data determine");
  BaseParameterOptions base_options = options.base;
  base_options.layout = options.layout;
  base_options.coupling = coupling;
  result.base = compute_base_parameters(model, base_options);
  result.unidentifiable = result.base.unidentifiable_names();
  result.rank = result.base.rank;
  EquationBlock based = select_base_columns(stack_equations(blocks), result.base);
  result.rows = based.y.size();
  // Data-identifiable columns: what these data determine of the base set.
  const DataIdentifiability data = data_identifiability(based);
  result.data_rank = data.rank;
  if (result.rows <= data.rank) {
    throw Error("only " + std::to_string(result.rows) + " equations remain for " +
                std::to_string(data.rank) +
                " base parameters; record a longer or faster run, or lower --zero-velocity");
  }
  if (data.rank == 0) {
    throw Error(
        "the data excite no parameter (no joint moves above its noise); record a run "
        "in which the joints move");
  }
  const bool deficient = !data.not_excited.empty();
  const EquationBlock W = deficient ? select_columns(based, data.kept) : based;
  for (int c : data.kept) {
    result.names.push_back(result.base.names[static_cast<size_t>(c)]);
    result.expressions.push_back(result.base.expressions[static_cast<size_t>(c)]);
  }
  for (int c : data.not_excited) {
    result.not_excited.push_back(result.base.names[static_cast<size_t>(c)]);
  }
  for (int c : data.regrouped)
    result.data_regrouped.push_back(result.base.names[static_cast<size_t>(c)]);
  result.labels = result.names;
  result.data_regrouping =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(data.kept.size()),
                            static_cast<Eigen::Index>(data.not_excited.size()));
  for (size_t i = 0; i < data.kept.size(); ++i) {
    // A parameter these data regroup exactly is named as the base set names a regrouping: the
    // leading name with an R (issue 28 item 7: Fc2R = Fc2 + Fcm3 on an IRp-6 joint-2 run).
    std::string& label = result.labels[i];
    for (const auto& [col, coef] : data.absorbs[i]) {
      const bool exact =
          std::find(data.regrouped.begin(), data.regrouped.end(), col) != data.regrouped.end();
      if (exact && label.back() != 'R') {
        result.expressions[i] = label + "R" + result.expressions[i].substr(label.size());
        label += 'R';
      }
    }
    for (const auto& [col, coef] : data.absorbs[i]) {
      const auto at = std::find(data.not_excited.begin(), data.not_excited.end(), col);
      result.data_regrouping(static_cast<Eigen::Index>(i), at - data.not_excited.begin()) = coef;
      std::ostringstream term;
      term << std::setprecision(6) << (coef < 0 ? " - " : " + ") << std::abs(coef) << '*'
           << result.base.names[static_cast<size_t>(col)] << " (on these data)";
      result.expressions[i] += term.str();
    }
  }
  // Joints in lockstep, and the not excited parameters of theirs that this explains.
  result.lockstep = find_lockstep_joints(velocities);
  for (LockstepJoints& pair : result.lockstep) {
    for (int c : data.not_excited) {
      const int joint =
          column_joint(model, options.layout, result.base.base[static_cast<size_t>(c)]);
      if (joint == pair.first || joint == pair.second)
        pair.undetermined.push_back(result.base.names[static_cast<size_t>(c)]);
    }
  }
  if (deficient)
    not_excited_warnings(model, options.layout, result.base, based, data, result.expressions,
                         result.lockstep, result.warnings);
  {
    const std::vector<std::optional<double>> nominal =
        nominal_base_values(model, result.base, options.layout);
    for (int c : data.kept) result.nominal.push_back(nominal[static_cast<size_t>(c)]);
  }
  // estimate
  stage(kPreparedShare + 0.5 * kEstimateShare, "estimating " + std::to_string(W.W.cols()) +
                                                   " parameters from " +
                                                   std::to_string(W.y.size()) + " equations");
  BlockEstimationOptions eo;
  eo.estimator = options.estimator;
  eo.confidence_level = options.confidence_level;
  eo.hac_bandwidth = options.hac_bandwidth;
  eo.record_history = options.record_history;
  BlockEstimate fit = estimate_block(W, eo);
  if (blocks.size() > 1 && fit.hac.bandwidth > 0 && !closed) {
    // Restack with runs a window apart and that window fixed, so that the HAC sums never pair two
    // runs' errors (the estimate itself does not depend on the spacing).
    eo.hac_bandwidth = fit.hac.bandwidth;
    EquationBlock spaced = based;
    spaced.sample =
        select_base_columns(stack_equations(blocks, fit.hac.bandwidth + 1), result.base).sample;
    if (deficient) spaced = select_columns(spaced, data.kept);
    fit = estimate_block(spaced, eo);
    fit.covariance_choice += "; runs stacked a window apart (no window spans two runs)";
  }
  if (closed) {
    EstimationOptions so;
    so.confidence_level = options.confidence_level;
    so.names = W.columns;
    // Channel of each row: run × joint, the projected series the clustered sandwich sums over.
    Eigen::VectorXi channel(W.y.size());
    Eigen::VectorXd remainder_variance(W.y.size());
    Eigen::Index at = 0;
    for (size_t b = 0; b < blocks.size(); ++b) {
      const Eigen::Index rows = blocks[b].y.size();
      channel.segment(at, rows) = W.group.segment(at, rows).array() + static_cast<int>(b) * n;
      for (Eigen::Index i = at; i < at + rows; ++i) {
        const Eigen::VectorXd& r = remainder_std[b];
        remainder_variance[i] = r.size() == n ? r[W.group[i]] * r[W.group[i]] : NAN;
      }
      at += rows;
    }
    fit.covariance_choice = projected_statistics(fit.estimate, W, projected_dimensions,
                                                 options.estimator == IdentificationEstimator::kWls,
                                                 so, channel, remainder_variance);
    result.interval_source = fit.estimate.covariance_kind == "torque remainder, projected"
                                 ? "torque_remainder"
                                 : "projected_residual";
  }
  if (ml) {
    projected.dimensions = projected_dimensions;
    std::vector<int> columns;
    for (int c : data.kept) columns.push_back(result.base.base[static_cast<size_t>(c)]);
    IdentifyOptions ml_options = options;
    if (options.progress) {
      ml_options.progress = [&options](double fraction, const std::string& what) {
        options.progress(
            kPreparedShare + kEstimateShare + (1.0 - kPreparedShare - kEstimateShare) * fraction,
            what);
      };
    }
    maximum_likelihood_stage(model, ml_options, coupling, blocks, prepared, screened.front().record,
                             columns, W, projected, fit, result.choices);
  }
  check_finite_estimate(fit.estimate, screened.front());
  result.estimate = std::move(fit.estimate);
  result.residual_rms = fit.group_rms;
  result.joint_relative_error = fit.group_relative_error;
  result.relative_error = fit.relative_error;
  result.residual_autocorrelation = fit.group_autocorrelation;
  result.choices.emplace_back("covariance", fit.covariance_choice);
  result.history_t = std::move(fit.history_t);
  result.history_x = std::move(fit.history_x);
  result.history_std = std::move(fit.history_std);
  if (options.estimator == IdentificationEstimator::kRls) {
    result.excitation = persistent_excitation(W, options.excitation_window);
    result.has_excitation = true;
  }
  // Per run: the relative error of its own rows.
  Eigen::Index at = 0;
  for (auto& run : result.runs) {
    const auto e = fit.residual.segment(at, run.rows);
    const auto y = W.y.segment(at, run.rows);
    run.relative_error = e.norm() / std::max(y.norm(), 1e-300);
    at += run.rows;
  }
  result.condition_number = result.estimate.summary.condition_number;
  if (!(result.condition_number > 0.0)) {
    const Eigen::VectorXd s = Eigen::BDCSVD<Eigen::MatrixXd>(W.W).singularValues();
    result.condition_number = s[s.size() - 1] > 0.0 ? s[0] / s[s.size() - 1] : INFINITY;
  }
  result.warnings.insert(result.warnings.end(), result.estimate.summary.warnings.begin(),
                         result.estimate.summary.warnings.end());
  // A pair whose parameters were all estimated: name those the estimate leaves at more than
  // 100 % relative std (not even the order of magnitude determined).
  for (LockstepJoints& pair : result.lockstep) {
    if (pair.undetermined.empty()) {
      for (size_t i = 0; i < data.kept.size(); ++i) {
        const int c = data.kept[i];
        const int joint =
            column_joint(model, options.layout, result.base.base[static_cast<size_t>(c)]);
        if ((joint == pair.first || joint == pair.second) &&
            !(result.estimate.relative_std_percent[static_cast<Eigen::Index>(i)] <= 100.0))
          pair.undetermined.push_back(result.names[i]);
      }
    }
    result.warnings.push_back(lockstep_text(model, pair));
  }
  return result;
}

}  // namespace dynid
