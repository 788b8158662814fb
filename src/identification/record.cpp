#include "dynid/identification/record.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>
#include <tuple>
#include <utility>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/signal/differentiation.hpp"
#include "dynid/signal/noise_floor.hpp"
#include "dynid/signal/plausibility.hpp"
#include "dynid/signal/resampling.hpp"
#include "dynid/signal/sampling_check.hpp"
#include "dynid/signal/zero_phase_filter.hpp"
#include "identification/preparation.hpp"

namespace dynid {

namespace {

std::string fmt(double x) {
  std::ostringstream s;
  s << x;
  return s.str();
}

}  // namespace

void check_signal_options(const SignalOptions& options) {
  // A NaN cut-off failed every "> 0" test and silently became the automatic one; a negative
  // decimation or trim the automatic ones too (the CLI refuses both as flags).
  if (!(options.cutoff_hz >= 0.0) || !std::isfinite(options.cutoff_hz)) {
    throw UsageError("the cut-off (--cutoff, cutoff_hz) " + fmt(options.cutoff_hz) +
                     " is not a finite frequency >= 0 Hz; give e.g. 10, or 0 for automatic");
  }
  if (options.decimate < 0) {
    throw UsageError("the decimation (--decimate, decimate) " + std::to_string(options.decimate) +
                     " is negative; give 1 or more, or 0 for automatic");
  }
  if (options.trim < -1) {
    throw UsageError("the trim (--trim) " + std::to_string(options.trim) +
                     " is below -1; give the samples to drop at each end, or -1 for automatic");
  }
}

void check_corrupt_samples(const JointRecord& r, const std::string& fix) {
  // Floors of the spread [rad, rad/s, rad/s², N·m]: a column held constant in most samples still
  // moves by up to 1e4 of them (1e5 rad/s² in a ddq column) before a sample counts as corrupt.
  const std::pair<const Eigen::MatrixXd*, std::pair<const char*, double>> columns[] = {
      {&r.q, {"q", 1.0}}, {&r.dq, {"dq", 1.0}}, {&r.ddq, {"ddq", 10.0}}, {&r.tau, {"tau", 1.0}}};
  for (const auto& [x, what] : columns) {
    if (x->size() == 0 || x->rows() != r.t.size()) continue;
    const std::optional<CorruptSample> c = find_corrupt_sample(*x, what.second);
    if (!c) continue;
    throw Error(std::string(what.first) + std::to_string(c->column + 1) + " at sample " +
                std::to_string(c->sample + 1) + " (t = " + short_number(r.t[c->sample]) +
                " s) = " + short_number(c->value) + " is a corrupt sample: it lies more than " +
                short_number(c->limit) + " from the median " + short_number(c->median) +
                " of its column and would make the estimate not finite; " + fix);
  }
}

namespace {

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
  if (!r.t.allFinite()) throw Error("t contains NaN or Inf; clean the data");
  check(r.q, "q", false);
  check(r.dq, "dq", true);
  check(r.ddq, "ddq", true);
  check(r.tau, "tau", false);
  check_corrupt_samples(r, "remove or repair that row of the log");
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
                           std::vector<std::pair<std::string, std::string>>& choices,
                           const Eigen::MatrixXd& coupled_rows) {
  const int n = static_cast<int>(input.q.cols());
  check_signal_options(options);
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
      throw UsageError("--time-shift " + fmt(options.torque_time_offset) +
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
      choices.emplace_back("cutoff", fmt(cutoff) + " Hz (" + options.cutoff_source + ")");
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
  if (options.filter && (options.filter_coulomb_columns || options.zero_velocity.empty() ||
                         !options.coulomb_width.empty())) {
    // Expected value of the smooth Coulomb law erf(dq/(√2 v_c)) given the noisy velocity dq̂
    // (Gaussian noise σ_dq, flat prior): erf(dq̂/(√2·√(v_c² + σ²))); with v_c = 0 the expected
    // sign of seed 1's Fc·sign(dq) term. Its halves are the moving-positive/-negative indicators.
    Eigen::VectorXd width = given_coulomb_width(options.coulomb_width, n);
    const bool automatic = width.size() == 0;
    if (automatic) {
      const double f = options.coulomb_width_fraction;
      if (!(f >= 0.0 && f < 1.0)) {
        throw UsageError("coulomb_width_fraction " + fmt(f) + " is not in [0, 1); use e.g. 0.005");
      }
      width = f * r.dq.middleRows(first, last - first).cwiseAbs().colwise().maxCoeff().transpose();
    }
    // The smooth law's expected value erf(v/(√2·√(v_c² + σ²))) and its halves, filtered like tau.
    const auto indicators = [&](const Eigen::MatrixXd& v, const Eigen::VectorXd& scale) {
      Eigen::MatrixXd pos(v.rows(), v.cols()), neg(v.rows(), v.cols());
      for (Eigen::Index j = 0; j < v.cols(); ++j) {
        for (Eigen::Index k = 0; k < v.rows(); ++k) {
          const double x = v(k, j);
          const double s = std::erf(x / (std::sqrt(2.0) * scale[j]));
          pos(k, j) = scale[j] > 0.0 ? 0.5 * (1.0 + s) : static_cast<double>(x > 0.0);
          neg(k, j) = scale[j] > 0.0 ? 0.5 * (1.0 - s) : static_cast<double>(x < 0.0);
        }
      }
      return std::make_pair(take_rows(filtfilt(filter, pos), first, last, decimate),
                            take_rows(filtfilt(filter, neg), first, last, decimate));
    };
    const Eigen::VectorXd scale =
        (out.velocity_noise_std.array().square() + width.array().square()).sqrt();
    std::tie(out.moving_positive, out.moving_negative) = indicators(r.dq, scale);
    // With v_c = 0 the motors keep the hard sign of coupling_regressor (the former law).
    if (width.maxCoeff() > 0.0 && coupled_rows.rows() > 0 && coupled_rows.cols() == n) {
      const Eigen::VectorXd motor_scale =
          (coupled_rows.array().square().matrix() * scale.array().square().matrix()).cwiseSqrt();
      const auto motor = indicators(r.dq * coupled_rows.transpose(), motor_scale);
      out.coupled_sign = motor.first - motor.second;
    }
    out.coulomb_width = width;
    if (width.maxCoeff() > 0.0) {
      std::ostringstream w;
      w << std::setprecision(3) << width.transpose();
      choices.emplace_back("coulomb_columns",
                           "expected smooth sign erf(dq/(sqrt(2) sqrt(v_c^2 + sigma_dq^2))) of the "
                           "velocity, v_c = [" +
                               w.str() + "] (" +
                               (automatic ? fmt(options.coulomb_width_fraction) + " x max|dq_j|"
                                          : options.coulomb_width_source) +
                               "), filtered like tau at the full rate (parallel filtering)");
    } else {
      choices.emplace_back(
          "coulomb_columns",
          "expected sign erf(dq/(sqrt(2) sigma_dq)) of the velocity, filtered like "
          "tau at the full rate (parallel filtering)");
    }
  }
  return out;
}

Eigen::MatrixXd coupled_motor_rows(const Model& model) {
  const std::vector<int> motors = coupled_motors(model);
  Eigen::MatrixXd rows(static_cast<Eigen::Index>(motors.size()), model.dof());
  for (size_t c = 0; c < motors.size(); ++c) {
    const Eigen::RowVectorXd n_k = model.transmission.N.row(motors[c]);
    rows.row(static_cast<Eigen::Index>(c)) = n_k / n_k.cwiseAbs().maxCoeff();
  }
  return rows;
}

Eigen::MatrixXd processed_regressor(const Model& model, const ParameterLayout& layout,
                                    bool coupling, const ProcessedRecord& processed) {
  Eigen::MatrixXd W = stacked_regressor(model, layout, coupling, processed.record);
  const int n = model.dof();
  if (coupling && processed.coupled_sign.size() != 0) {
    // The motors' Fcm columns n_kj·sign(n_k·dq) (coupling_regressor) with the same smooth law.
    const Eigen::MatrixXd rows = coupled_motor_rows(model);
    const Eigen::Index p = layout.columns(n);
    for (Eigen::Index k = 0; k < processed.record.t.size(); ++k) {
      for (Eigen::Index c = 0; c < rows.rows(); ++c) {
        for (int j = 0; j < n; ++j) {
          if (rows(c, j) != 0.0)
            W(k * n + j, p + 3 * c + 2) = rows(c, j) * processed.coupled_sign(k, c);
        }
      }
    }
  }
  if (processed.moving_positive.size() == 0 || !layout.coulomb) return W;
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

namespace {

// One value for all n joints or n values of the option `flag`; empty stays empty.
Eigen::VectorXd per_joint_values(const std::vector<double>& values, int n, const char* flag) {
  if (values.empty()) return Eigen::VectorXd();
  if (values.size() == 1) return Eigen::VectorXd::Constant(n, values[0]);
  if (static_cast<int>(values.size()) == n) {
    return Eigen::Map<const Eigen::VectorXd>(values.data(), n);
  }
  throw UsageError(std::string(flag) + " takes 1 or " + std::to_string(n) + " values, got " +
                   std::to_string(values.size()));
}

}  // namespace

Eigen::VectorXd given_zero_velocity(const std::vector<double>& zero_velocity, int n) {
  return per_joint_values(zero_velocity, n, "--zero-velocity");
}

Eigen::VectorXd given_coulomb_width(const std::vector<double>& width, int n) {
  for (const double v : width) {
    if (!(v >= 0.0) || !std::isfinite(v)) {
      throw UsageError("--coulomb-width values must be finite and >= 0 [rad/s], not " + fmt(v));
    }
  }
  return per_joint_values(width, n, "--coulomb-width");
}

// preprocess() of a run of `model`, after checking that it has one column per joint.
ProcessedRecord preprocess_run(const Model& model, const JointRecord& record,
                               const SignalOptions& options,
                               std::vector<std::pair<std::string, std::string>>& choices) {
  if (record.q.cols() != model.dof()) {
    throw Error("the run has " + std::to_string(record.q.cols()) + " joints but model '" +
                model.name + "' has " + std::to_string(model.dof()) +
                "; pass the run of this robot or the model it was recorded on");
  }
  return preprocess(record, options, choices, coupled_motor_rows(model));
}

// Rows of joint j where |dq_j| is below threshold_j, too small for sign(dq_j) to be meaningful, are
// left out when the layout has Coulomb friction: given values (1 or n), or by default
// max(zero_velocity_fraction × max|dq_j|, zero_velocity_noise_multiple × the processed velocity's
// noise std): the band where real friction leaves the Coulomb law, or where the sign of dq is not
// known from the data. Zero without Coulomb friction. The choice is appended to `choices`.
Eigen::VectorXd zero_velocity_threshold(const ParameterLayout& layout, const SignalOptions& signal,
                                        const ProcessedRecord& processed, const char* verb,
                                        std::vector<std::pair<std::string, std::string>>& choices) {
  const auto n = processed.record.dq.cols();
  Eigen::VectorXd threshold = Eigen::VectorXd::Zero(n);
  if (!layout.coulomb) return threshold;
  threshold = given_zero_velocity(signal.zero_velocity, static_cast<int>(n));
  std::ostringstream s;
  s << std::setprecision(3);
  if (threshold.size() == 0) {
    const double k = signal.zero_velocity_noise_multiple;
    if (!(k >= 0.0) || !std::isfinite(k)) {
      throw UsageError("zero_velocity_noise_multiple " + fmt(k) + " is not >= 0; use e.g. 3");
    }
    const double f = signal.zero_velocity_fraction;
    if (!(f >= 0.0 && f < 1.0)) {
      throw UsageError("zero_velocity_fraction " + fmt(f) + " is not in [0, 1); use e.g. 0.01");
    }
    const Eigen::VectorXd band =
        f * processed.record.dq.cwiseAbs().colwise().maxCoeff().transpose();
    threshold = band.cwiseMax(k * processed.velocity_noise_std);
    if (threshold.maxCoeff() > 0.0) {
      s << "auto: rows with |dq_j| < [" << threshold.transpose() << "] " << verb << " = max(" << f
        << " x max|dq_j| (real friction leaves the Coulomb law there), " << k
        << " x the velocity noise std [" << processed.velocity_noise_std.transpose()
        << "] (the sign of dq is unknown there)); Coulomb columns: the filtered expected sign, "
           "which keeps Fv and Fc unbiased when the cut-off smears the Coulomb step";
    } else {
      // Removing rows by the size of a filtered, noisy velocity selects on the regressor; the
      // smooth expected-sign columns model the unknown sign and the pre-sliding band instead
      // (docs/methods/identification.md §3).
      s << "none: every row is kept; the Coulomb columns are the filtered expected smooth sign, "
           "which models the unknown sign of dq at rest and the pre-sliding band";
    }
  } else {
    s << "rows with |dq_j| < [" << threshold.transpose() << "] " << verb << " ("
      << signal.zero_velocity_source << ")";
  }
  choices.emplace_back("zero_velocity", s.str());
  return threshold;
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
  std::vector<bool> held(static_cast<size_t>(r.dq.cols()), false);
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
    held[j] = true;
    std::ostringstream w;
    w << std::setprecision(3) << model.joints[static_cast<size_t>(j)].name;
    if (constant) {
      w << " (position constant)";
    } else {
      w << " (max|dq| " << peak << " < " << kStillNoiseMultiple << " x noise std " << sigma << ")";
    }
    still += (still.empty() ? "" : ", ") + w.str();
  }
  // A coupled motor all of whose joints are held does not turn: its Coulomb column is noise too.
  if (p.coupled_sign.size()) {
    const Eigen::MatrixXd rows = coupled_motor_rows(model);
    for (Eigen::Index c = 0; c < rows.rows() && c < p.coupled_sign.cols(); ++c) {
      bool turns = false;
      for (Eigen::Index j = 0; j < rows.cols(); ++j)
        turns = turns || (rows(c, j) != 0.0 && !held[j]);
      if (!turns) p.coupled_sign.col(c).setZero();
    }
  }
  if (!still.empty()) {
    choices.emplace_back("still_joints",
                         still +
                             ": held still, their motion is encoder noise; velocity and "
                             "acceleration taken as zero");
  }
}

// One warning per base parameter the data leave undetermined: why, and which motion would excite

}  // namespace dynid
