#include "dynid/estimation/identification.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/SVD>

#include "dynid/common/error.hpp"
#include "dynid/estimation/closed_loop.hpp"
#include "dynid/estimation/cutoff_selection.hpp"
#include "dynid/estimation/integral_equations.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/maximum_likelihood.hpp"
#include "dynid/estimation/outliers.hpp"
#include "dynid/estimation/pipeline.hpp"
#include "dynid/estimation/recursive_least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/signal/differentiation.hpp"
#include "dynid/signal/noise_floor.hpp"
#include "dynid/signal/resampling.hpp"
#include "dynid/signal/sampling_check.hpp"
#include "dynid/signal/zero_phase_filter.hpp"

namespace dynid {

namespace {

std::string fmt(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

void check_record(const JointRecord& r, int n) {
  const Eigen::Index m = r.t.size();
  auto check = [&](const Eigen::MatrixXd& x, const char* what, bool optional) {
    if (optional && x.size() == 0) return;
    if (x.rows() != m || x.cols() != n) {
      throw Error(std::string(what) + " has " + std::to_string(x.rows()) + "×" +
                  std::to_string(x.cols()) + " values; expected " + std::to_string(m) + "×" +
                  std::to_string(n) + " (samples × joints)");
    }
    if (!x.allFinite()) throw Error(std::string(what) + " contains NaN or Inf; clean the data");
  };
  check(r.q, "q", false);
  check(r.dq, "dq", true);
  check(r.ddq, "ddq", true);
  check(r.tau, "tau", false);
}

Eigen::MatrixXd take_rows(const Eigen::MatrixXd& x, Eigen::Index first, Eigen::Index last,
                          int step) {
  if (x.size() == 0) return x;
  const Eigen::Index count = (last - first + step - 1) / step;
  Eigen::MatrixXd out(count, x.cols());
  for (Eigen::Index k = 0; k < count; ++k) out.row(k) = x.row(first + k * step);
  return out;
}

}  // namespace

std::vector<std::string> stacked_regressor_names(const Model& model, const ParameterLayout& layout,
                                                 bool coupling) {
  std::vector<std::string> names = layout.names(model.dof());
  if (coupling) {
    for (const auto& name : coupling_column_names(model)) names.push_back(name);
  }
  return names;
}

Eigen::MatrixXd stacked_regressor(const Model& model, const ParameterLayout& layout, bool coupling,
                                  const JointRecord& record) {
  const int n = model.dof();
  const Eigen::Index m = record.q.rows();
  const int p = layout.columns(n);
  const std::vector<int> motors = coupling ? coupled_motors(model) : std::vector<int>{};
  const int extra = 3 * static_cast<int>(motors.size());
  Eigen::MatrixXd W(m * n, p + extra);
  Workspace ws(model);
  for (Eigen::Index k = 0; k < m; ++k) {
    const auto q = record.q.row(k).transpose();
    const auto dq = record.dq.row(k).transpose();
    const auto ddq = record.ddq.row(k).transpose();
    torque_regressor(model, ws, layout, q, dq, ddq, W.block(k * n, 0, n, p));
    if (extra) coupling_regressor(model, motors, dq, ddq, W.block(k * n, p, n, extra));
  }
  return W;
}

ProcessedRecord preprocess(const JointRecord& input, const SignalOptions& options,
                           std::vector<std::pair<std::string, std::string>>& choices) {
  const int n = static_cast<int>(input.q.cols());
  check_record(input, n);
  if (input.t.size() < 10) {
    throw Error("the run has " + std::to_string(input.t.size()) +
                " samples; identification needs at least 10 (more than the parameters)");
  }
  SamplingInfo info = check_sampling(input.t, 0.05);
  JointRecord r = input;
  if (options.filter && !info.uniform) {
    // Zero-phase filtering assumes uniform steps: resample first at the mean rate.
    const double rate = info.rate_hz();
    Eigen::VectorXd t_new;
    auto resample = [&](Eigen::MatrixXd& x) {
      if (x.size() == 0) return;
      ResampleOptions ro;
      ro.anti_alias.enabled = false;  // same rate: interpolation only
      UniformRecord u = resample_uniform(input.t, x, rate, ro);
      x = std::move(u.x);
      t_new = std::move(u.t);
    };
    resample(r.q);
    resample(r.dq);
    resample(r.ddq);
    resample(r.tau);
    r.t = t_new;
    info = check_sampling(r.t, 0.05);
    choices.emplace_back("resampled",
                         "uniform at " + fmt(rate) + " Hz (time stamps were not uniform)");
  }
  const double rate = info.rate_hz();
  choices.emplace_back("sample_rate_hz", fmt(rate));
  if (options.torque_time_offset != 0.0) {
    if (!std::isfinite(options.torque_time_offset) ||
        std::abs(options.torque_time_offset) * rate > 100.0) {
      throw UsageError("--torque-offset " + fmt(options.torque_time_offset) +
                       " s is not a small finite time (at most 100 samples); give e.g. " +
                       fmt(0.5 / rate) + " for a command held over one period");
    }
    // Sample k of tau sits at t_k + offset; evaluate that signal at the t_k (ends held).
    const Eigen::Index m = r.t.size();
    const Eigen::VectorXd shifted = r.t.array() + options.torque_time_offset;
    const Eigen::VectorXd query = r.t.cwiseMax(shifted(0)).cwiseMin(shifted(m - 1));
    r.tau = interpolate(shifted, r.tau, query, Interpolation::kLinear);
    choices.emplace_back("torque_time_offset", fmt(options.torque_time_offset) +
                                                   " s (torques re-interpolated onto the q time "
                                                   "stamps)");
  }
  double cutoff = options.cutoff_hz;
  int trim = options.trim;
  int decimate = options.decimate;
  double out_noise_gain = 0.0;
  SosFilter filter;
  NoiseFloor floor;
  if (options.filter) {
    if (cutoff <= 0.0) {
      CutoffChoice c = choose_cutoff(r.q, rate);
      cutoff = c.cutoff_hz;
      floor = std::move(c.floor);
      choices.emplace_back("cutoff", c.reason);
      choices.emplace_back("cutoff_hz", fmt(cutoff));
    } else {
      choices.emplace_back("cutoff", fmt(cutoff) + " Hz (given)");
      choices.emplace_back("cutoff_hz", fmt(cutoff));
    }
    LowpassOptions lp;
    lp.family = options.family;
    lp.order = options.order;
    lp.cutoff_hz = cutoff;
    lp.sample_rate_hz = rate;
    lp.ripple_db = options.ripple_db;
    filter = design_lowpass_unit_dc(lp);
    // Noise of the velocity as processed: from the position's noise floor through filter and
    // central differences, or from the given velocity's floor through the filter.
    const bool given_dq = r.dq.size() != 0;
    if (given_dq) floor = position_noise_floor(r.dq, rate);
    if (floor.noise_std.size() == 0) floor = position_noise_floor(r.q, rate);
    out_noise_gain = white_noise_gain(&filter, given_dq ? 0 : 1, rate);
    r.q = filtfilt(filter, r.q);
    r.tau = filtfilt(filter, r.tau);
    if (r.dq.size()) r.dq = filtfilt(filter, r.dq);
    if (r.ddq.size()) r.ddq = filtfilt(filter, r.ddq);
    choices.emplace_back(
        "filter",
        std::string(options.family == LowpassFamily::kButterworth ? "butterworth" : "chebyshev1") +
            " order " + std::to_string(options.order) + ", cut-off " + fmt(cutoff) +
            " Hz, zero phase, on q, dq, ddq and tau");
    if (trim < 0) {
      // A low automatic cut-off must not consume a short run: keep at least half of it.
      const auto cap = static_cast<int>(std::max<Eigen::Index>(0, (r.t.size() - 10) / 4));
      trim = std::min(cap, static_cast<int>(std::ceil(3.0 * rate / cutoff)));
    }
    if (decimate <= 0) decimate = std::max(1, static_cast<int>(std::floor(rate / (10.0 * cutoff))));
  } else {
    const bool given_dq = r.dq.size() != 0;
    floor = position_noise_floor(given_dq ? r.dq : r.q, rate);
    out_noise_gain = white_noise_gain(nullptr, given_dq ? 0 : 1, rate);
    choices.emplace_back("filter", "none");
    if (trim < 0) trim = 0;
    if (decimate <= 0) decimate = 1;
  }
  auto differentiate = [&](const Eigen::MatrixXd& x) {
    if (options.savitzky_golay) {
      SavitzkyGolayOptions sg;
      return savitzky_golay(r.t, x, sg);
    }
    return central_difference(r.t, x, 1);
  };
  const char* method =
      options.savitzky_golay ? "Savitzky-Golay (window 11, order 3)" : "central differences";
  if (r.dq.size() == 0) {
    r.dq = differentiate(r.q);
    choices.emplace_back("dq", std::string("derived from q by ") + method);
  } else {
    choices.emplace_back("dq", "from the data");
  }
  if (r.ddq.size() == 0) {
    r.ddq = differentiate(r.dq);
    choices.emplace_back("ddq", std::string("derived from dq by ") + method);
  } else {
    choices.emplace_back("ddq", "from the data");
  }
  const Eigen::Index m = r.t.size();
  if (2 * static_cast<Eigen::Index>(trim) + 10 > m) {
    throw Error("the run has " + std::to_string(m) + " samples but " + std::to_string(2 * trim) +
                " are trimmed as filter edges; record a longer run or set --trim / --cutoff");
  }
  choices.emplace_back("trim", std::to_string(trim) + " samples at each end");
  choices.emplace_back("decimate", std::to_string(decimate));
  ProcessedRecord out;
  const Eigen::Index first = trim, last = m - trim;
  out.record.t = take_rows(r.t, first, last, decimate);
  out.record.q = take_rows(r.q, first, last, decimate);
  out.record.dq = take_rows(r.dq, first, last, decimate);
  out.record.ddq = take_rows(r.ddq, first, last, decimate);
  out.record.tau = take_rows(r.tau, first, last, decimate);
  out.rate_hz = rate / decimate;
  out.cutoff_hz = options.filter ? cutoff : 0.0;
  out.trim = trim;
  out.decimate = decimate;
  out.position_noise_std =
      floor.noise_std.unaryExpr([](double v) { return std::isfinite(v) ? v : 0.0; });
  out.velocity_noise_std = out_noise_gain * out.position_noise_std;
  if (options.filter && (options.filter_coulomb_columns || options.zero_velocity.empty())) {
    // Expected sign of the true velocity given the noisy one (Gaussian noise σ_dq, flat prior):
    // E[sign(dq)] = erf(dq̂/(√2σ)); its halves are the moving-positive/-negative indicators.
    Eigen::MatrixXd pos(r.dq.rows(), r.dq.cols()), neg(r.dq.rows(), r.dq.cols());
    for (Eigen::Index j = 0; j < r.dq.cols(); ++j) {
      const double sigma = out.velocity_noise_std[j];
      for (Eigen::Index k = 0; k < r.dq.rows(); ++k) {
        const double v = r.dq(k, j);
        const double s = sigma > 0.0 ? std::erf(v / (std::sqrt(2.0) * sigma))
                                     : static_cast<double>((v > 0.0) - (v < 0.0));
        pos(k, j) = sigma > 0.0 ? 0.5 * (1.0 + s) : static_cast<double>(v > 0.0);
        neg(k, j) = sigma > 0.0 ? 0.5 * (1.0 - s) : static_cast<double>(v < 0.0);
      }
    }
    out.moving_positive = take_rows(filtfilt(filter, pos), first, last, decimate);
    out.moving_negative = take_rows(filtfilt(filter, neg), first, last, decimate);
    choices.emplace_back("coulomb_columns",
                         "expected sign erf(dq/(sqrt(2) sigma_dq)) of the velocity, filtered like "
                         "tau at the full rate (parallel filtering)");
  }
  return out;
}

Eigen::MatrixXd processed_regressor(const Model& model, const ParameterLayout& layout,
                                    bool coupling, const ProcessedRecord& processed) {
  Eigen::MatrixXd W = stacked_regressor(model, layout, coupling, processed.record);
  if (processed.moving_positive.size() == 0 || !layout.coulomb) return W;
  const int n = model.dof();
  // Column of the first Coulomb term of joint j: after its armature and viscous terms
  // (joint_columns order, regressor/joint_columns.hpp).
  const int repeat = layout.asymmetric ? 2 : 1;
  const int within = (layout.armature ? 1 : 0) + (layout.viscous ? repeat : 0);
  for (Eigen::Index k = 0; k < processed.record.t.size(); ++k) {
    for (int j = 0; j < n; ++j) {
      const Eigen::Index row = k * n + j;
      const Eigen::Index col = kLinkParams * n + layout.joint_columns() * j + within;
      const double pos = processed.moving_positive(k, j), neg = processed.moving_negative(k, j);
      if (layout.asymmetric) {
        W(row, col) = pos;
        W(row, col + 1) = -neg;
      } else {
        W(row, col) = pos - neg;
      }
    }
  }
  return W;
}

Eigen::VectorXd given_zero_velocity(const std::vector<double>& zero_velocity, int n) {
  if (zero_velocity.empty()) return Eigen::VectorXd();
  if (zero_velocity.size() == 1) return Eigen::VectorXd::Constant(n, zero_velocity[0]);
  if (static_cast<int>(zero_velocity.size()) == n) {
    return Eigen::Map<const Eigen::VectorXd>(zero_velocity.data(), n);
  }
  throw UsageError("--zero-velocity takes 1 or " + std::to_string(n) + " values, got " +
                   std::to_string(zero_velocity.size()));
}

namespace {

// preprocess() of a run of `model`, after checking that it has one column per joint.
ProcessedRecord preprocess_run(const Model& model, const JointRecord& record,
                               const SignalOptions& options,
                               std::vector<std::pair<std::string, std::string>>& choices) {
  if (record.q.cols() != model.dof()) {
    throw Error("the run has " + std::to_string(record.q.cols()) + " joints but model '" +
                model.name + "' has " + std::to_string(model.dof()) +
                "; pass the run of this robot or the model it was recorded on");
  }
  return preprocess(record, options, choices);
}

// Rows of joint j where |dq_j| is below threshold_j, too small for sign(dq_j) to be meaningful, are
// left out when the layout has Coulomb friction: given values (1 or n), or by default
// max(zero_velocity_fraction × max|dq_j|, zero_velocity_noise_multiple × the processed velocity's
// noise std): the band where real friction leaves the Coulomb law, or where the sign of dq is not
// known from the data. Zero without Coulomb friction. The choice is appended to `choices`.
Eigen::VectorXd zero_velocity_threshold(const IdentifyOptions& options,
                                        const ProcessedRecord& processed, const char* verb,
                                        std::vector<std::pair<std::string, std::string>>& choices) {
  const auto n = processed.record.dq.cols();
  Eigen::VectorXd threshold = Eigen::VectorXd::Zero(n);
  if (!options.layout.coulomb) return threshold;
  threshold = given_zero_velocity(options.signal.zero_velocity, static_cast<int>(n));
  std::ostringstream s;
  s << std::setprecision(3);
  if (threshold.size() == 0) {
    const double k = options.signal.zero_velocity_noise_multiple;
    if (!(k >= 0.0) || !std::isfinite(k)) {
      throw UsageError("zero_velocity_noise_multiple " + fmt(k) + " is not >= 0; use e.g. 3");
    }
    const double f = options.signal.zero_velocity_fraction;
    if (!(f >= 0.0 && f < 1.0)) {
      throw UsageError("zero_velocity_fraction " + fmt(f) + " is not in [0, 1); use e.g. 0.01");
    }
    const Eigen::VectorXd band =
        f * processed.record.dq.cwiseAbs().colwise().maxCoeff().transpose();
    threshold = band.cwiseMax(k * processed.velocity_noise_std);
    s << "auto: rows with |dq_j| < [" << threshold.transpose() << "] " << verb << " = max(" << f
      << " x max|dq_j| (real friction leaves the Coulomb law there), " << k
      << " x the velocity noise std [" << processed.velocity_noise_std.transpose()
      << "] (the sign of dq is unknown there)); Coulomb columns: the filtered expected sign, "
         "which keeps Fv and Fc unbiased when the cut-off smears the Coulomb step";
  } else {
    s << "rows with |dq_j| < [" << threshold.transpose() << "] " << verb << " (given)";
  }
  choices.emplace_back("zero_velocity", s.str());
  return threshold;
}

// The joint a layout column belongs to: link parameters of link j and joint columns of joint j;
// −1 for coupled-motor columns.
int column_joint(const Model& model, const ParameterLayout& layout, int column) {
  const int n = model.dof();
  if (column < kLinkParams * n) return column / kLinkParams;
  const int jc = layout.joint_columns();
  if (jc > 0 && column < kLinkParams * n + jc * n) return (column - kLinkParams * n) / jc;
  return -1;
}

// A joint whose processed velocity never leaves its noise band did not move: the controller held
// it and the encoder noise made it jitter. Its velocity, acceleration and Coulomb indicators are
// set to zero so that no velocity-driven column (Ia, Fv, Fc, coupled motors) looks excited by
// noise; its position (gravity) is kept. |dq| of pure Gaussian noise passes 6 σ_dq with
// probability 2e-9 per sample, so a run of 10⁶ samples still classifies a still joint as still.
constexpr double kStillNoiseMultiple = 6.0;

void hold_still_joints(const Model& model, ProcessedRecord& p,
                       std::vector<std::pair<std::string, std::string>>& choices) {
  JointRecord& r = p.record;
  std::string still;
  for (Eigen::Index j = 0; j < r.dq.cols(); ++j) {
    const double sigma = j < p.velocity_noise_std.size() ? p.velocity_noise_std[j] : 0.0;
    const double peak = r.dq.col(j).cwiseAbs().maxCoeff();
    // A quantised encoder that never left its count has no measurable noise (sigma = 0), and the
    // filtered velocity of its constant position is round-off, not motion.
    const double range = r.q.col(j).maxCoeff() - r.q.col(j).minCoeff();
    const bool constant = range <= 1e-12 * std::max(1.0, r.q.col(j).cwiseAbs().maxCoeff());
    if (!constant && (!(sigma > 0.0) || peak >= kStillNoiseMultiple * sigma)) continue;
    // The integral model's friction integrals read the steps Δq: round-off steps are no motion.
    if (constant) r.q.col(j).setConstant(r.q.col(j).mean());
    r.dq.col(j).setZero();
    r.ddq.col(j).setZero();
    if (p.moving_positive.size()) {
      p.moving_positive.col(j).setZero();
      p.moving_negative.col(j).setZero();
    }
    std::ostringstream w;
    w << std::setprecision(3) << model.joints[static_cast<size_t>(j)].name;
    if (constant) {
      w << " (position constant)";
    } else {
      w << " (max|dq| " << peak << " < " << kStillNoiseMultiple << " x noise std " << sigma << ")";
    }
    still += (still.empty() ? "" : ", ") + w.str();
  }
  if (!still.empty()) {
    choices.emplace_back("still_joints",
                         still +
                             ": held still, their motion is encoder noise; velocity and "
                             "acceleration taken as zero");
  }
}

// One warning per base parameter the data leave undetermined: why, and which motion would excite
// it where that is cheap to say (its own joint, or the parameters it cannot be told from).
void not_excited_warnings(const Model& model, const ParameterLayout& layout,
                          const BaseParameters& base, const EquationBlock& based,
                          const DataIdentifiability& data, std::vector<std::string>& warnings) {
  std::ostringstream head;
  head << "the data excite " << data.rank << " of the model's " << base.rank
       << " base parameters (data rank; column-scaled singular values below " << data.tolerance
       << " x the largest count as zero): the others are not estimated (not_excited)";
  warnings.push_back(head.str());
  for (int c : data.not_excited) {
    const std::string& name = base.names[static_cast<size_t>(c)];
    const int joint = column_joint(model, layout, base.base[static_cast<size_t>(c)]);
    std::ostringstream w;
    w << name << " is not excited: ";
    if (based.W.col(c).squaredNorm() == 0.0) {
      w << "its column is zero on every equation used";
    } else {
      std::string with;
      for (size_t i = 0; i < data.kept.size(); ++i) {
        for (const auto& [col, coef] : data.absorbs[i]) {
          if (col == c)
            with += (with.empty() ? "" : ", ") + base.names[static_cast<size_t>(data.kept[i])];
        }
      }
      w << "the data cannot tell it from " << (with.empty() ? "the other parameters" : with)
        << " (those estimates include its effect on these runs)";
    }
    if (joint >= 0) {
      w << "; a run in which " << model.joints[static_cast<size_t>(joint)].name
        << " moves (above its encoder noise, with both velocity signs and varied "
           "configurations of the joints before it) would excite it";
    }
    warnings.push_back(w.str());
  }
}

}  // namespace

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
  Eigen::Index projected_dimensions = 0;  // Σ over runs and joints of the projector's rank
  std::vector<ProcessedRecord> prepared;  // every run's (maximum likelihood needs them all)
  ProjectedRun projected;                 // the first run's projection (maximum likelihood)
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
  result.zero_velocity_threshold = Eigen::VectorXd::Zero(n);
  for (size_t i = 0; i < runs.size(); ++i) {
    std::vector<std::pair<std::string, std::string>> choices;
    screened.push_back(screen_run(model, runs[i], options.outliers));  // outliers.hpp
    ProcessedRecord processed;
    Eigen::VectorXd threshold = Eigen::VectorXd::Zero(n);
    if (closed) {
      ClosedLoopIdOptions co = options.closed_loop;
      co.torque_time_offset = options.signal.torque_time_offset;
      ClosedLoopRun cl = prepare_closed_loop(screened.back().record, references[i], co, choices);
      processed = std::move(cl.processed);
      // Known friction (seed 2 section 3.4) leaves the torque before the projection, so that
      // both sides of the regression are projected alike.
      EquationBlock raw =
          differential_equations(model, options.layout, coupling, processed, Eigen::VectorXd());
      subtract_known_friction(model, options.known_friction, processed, raw);
      blocks.push_back(project_equations(raw, *cl.projector));
      projected_dimensions += static_cast<Eigen::Index>(n) * cl.report.rank;
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
      threshold = zero_velocity_threshold(options, processed, "removed", choices);
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
    const std::string prefix = runs.size() > 1 ? "run " + std::to_string(i + 1) + " " : "";
    for (auto& [key, value] : choices) result.choices.emplace_back(prefix + key, value);
    if (ml) prepared.push_back(processed);
    if (i == 0) result.processed = std::move(processed);
    result.warnings.insert(result.warnings.end(), screened.back().warnings.begin(),
                           screened.back().warnings.end());
  }
  // stack + structural base columns (Gautier–Khalil, from the model).
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
  result.data_regrouping =
      Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(data.kept.size()),
                            static_cast<Eigen::Index>(data.not_excited.size()));
  for (size_t i = 0; i < data.kept.size(); ++i) {
    for (const auto& [col, coef] : data.absorbs[i]) {
      const auto at = std::find(data.not_excited.begin(), data.not_excited.end(), col);
      result.data_regrouping(static_cast<Eigen::Index>(i), at - data.not_excited.begin()) = coef;
      std::ostringstream term;
      term << std::setprecision(6) << (coef < 0 ? " - " : " + ") << std::abs(coef) << '*'
           << result.base.names[static_cast<size_t>(col)] << " (on these data)";
      result.expressions[i] += term.str();
    }
  }
  if (deficient)
    not_excited_warnings(model, options.layout, result.base, based, data, result.warnings);
  // estimate
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
    Eigen::Index at = 0;
    for (size_t b = 0; b < blocks.size(); ++b) {
      const Eigen::Index rows = blocks[b].y.size();
      channel.segment(at, rows) = W.group.segment(at, rows).array() + static_cast<int>(b) * n;
      at += rows;
    }
    fit.covariance_choice =
        projected_statistics(fit.estimate, W, projected_dimensions,
                             options.estimator == IdentificationEstimator::kWls, so, channel);
  }
  if (ml) {
    projected.dimensions = projected_dimensions;
    std::vector<int> columns;
    for (int c : data.kept) columns.push_back(result.base.base[static_cast<size_t>(c)]);
    maximum_likelihood_stage(model, options, coupling, blocks, prepared, screened.front().record,
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
  return result;
}

ValidationResult validate_torques(const Model& model, const JointRecord& record,
                                  const std::vector<std::string>& names,
                                  const Eigen::VectorXd& values, const IdentifyOptions& options,
                                  const std::vector<std::string>& not_excited) {
  const int n = model.dof();
  ValidationResult out;
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
  const Eigen::VectorXd pred = all.W * theta;
  const Eigen::Index m = r.t.size();
  out.samples = m;
  out.predicted =
      Eigen::Map<const Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>>(
          pred.data(), m, n);
  const Eigen::VectorXd threshold = zero_velocity_threshold(
      options, out.processed, "left out of the error statistics", out.choices);
  out.zero_velocity_threshold = threshold;
  const Eigen::MatrixXd e = r.tau - out.predicted;
  const EquationBlock moving = moving_rows(all, r.dq, threshold);
  if (!not_excited.empty() && moving.y.size() > 0) {
    std::vector<int> together = determined;
    for (const std::string& name : not_excited) together.push_back(column_of(name));
    std::sort(determined.begin(), determined.end());
    std::sort(together.begin(), together.end());
    if (data_identifiability(select_columns(moving, together)).rank >
        data_identifiability(select_columns(moving, determined)).rank) {
      std::string list;
      for (const std::string& name : not_excited) list += (list.empty() ? "" : ", ") + name;
      throw Error("the result does not determine " + list +
                  " (not_excited: its identification data did not move them) but this run "
                  "excites them, so its torques cannot be predicted; validate on a run like the "
                  "identification run(s), or identify from runs that also excite those");
    }
  }
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
  out.rms = (e2.array() / cnt.array().max(1.0)).sqrt();
  out.relative_error = (e2.array() / y2.array().max(1e-300)).sqrt();
  out.relative_error_all = std::sqrt(e2.sum() / std::max(y2.sum(), 1e-300));
  out.relative_error_all_rows = e.norm() / std::max(r.tau.norm(), 1e-300);
  return out;
}

Model identified_model(const Model& nominal, const std::vector<std::string>& names,
                       const Eigen::VectorXd& values, const IdentifyOptions& options) {
  BaseParameterOptions bo = options.base;
  bo.layout = options.layout;
  bo.coupling = options.coupling && !coupled_motors(nominal).empty();
  const BaseParameters base = compute_base_parameters(nominal, bo);
  const int n = nominal.dof();
  const int p = options.layout.columns(n);
  Eigen::VectorXd theta =
      Eigen::VectorXd::Zero(static_cast<Eigen::Index>(base.layout_names.size()));
  theta.head(p) = options.layout.parameters(nominal);
  Eigen::VectorXd theta_b = base.reduce(theta);
  for (size_t i = 0; i < names.size(); ++i) {
    const auto it = std::find(base.names.begin(), base.names.end(), names[i]);
    if (it == base.names.end()) {
      throw Error("parameter '" + names[i] + "' is not a base parameter of model '" + nominal.name +
                  "' with this friction set; validate with the options used to identify");
    }
    theta_b[it - base.names.begin()] = values[static_cast<Eigen::Index>(i)];
  }
  // theta_1 = theta_b − K_d·theta_2 with theta_2 at its nominal values.
  for (int i = 0; i < base.rank; ++i) {
    double regrouped = 0.0;
    for (size_t j = 0; j < base.dependent.size(); ++j)
      regrouped += base.K_d(i, j) * theta[base.dependent[j]];
    theta[base.base[i]] = theta_b[i] - regrouped;
  }
  Model out = nominal;
  for (int j = 0; j < n; ++j) out.links[j] = theta.segment<kLinkParams>(kLinkParams * j);
  const int jc = options.layout.joint_columns();
  for (int j = 0; j < n; ++j) {
    const double* c = theta.data() + kLinkParams * n + jc * j;
    JointFriction& f = out.joints[j].friction;
    int k = 0;
    if (options.layout.armature) f.Ia = c[k++];
    const int repeat = options.layout.asymmetric ? 2 : 1;
    // Asymmetric pairs (positive, negative) become mean and asymmetry, which joint_torque()
    // turns back into the sign-dependent law of seed 2 eq. 2.
    if (options.layout.viscous) {
      f.Fv = repeat == 2 ? 0.5 * (c[k] + c[k + 1]) : c[k];
      f.Fva = repeat == 2 ? 0.5 * (c[k] - c[k + 1]) : 0.0;
      k += repeat;
    }
    if (options.layout.coulomb) {
      f.Fc = repeat == 2 ? 0.5 * (c[k] + c[k + 1]) : c[k];
      f.Fca = repeat == 2 ? 0.5 * (c[k] - c[k + 1]) : 0.0;
      k += repeat;
    }
    if (options.layout.offset) f.Fo = c[k++];
  }
  return out;
}

}  // namespace dynid
