#include "dynid/identification/cutoff_selection.hpp"

#include <algorithm>
#include <cmath>
#include <iomanip>
#include <sstream>

#include <Eigen/QR>

#include "dynid/common/error.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/signal/noise_floor.hpp"
#include "dynid/signal/sampling_check.hpp"
#include "identification/preparation.hpp"

namespace dynid {

namespace {

struct HeldOutError {
  double error = 0.0;  // ‖τ_ref − Ŷθ̂‖/‖τ_ref‖ over the predicted samples
  bool ok = false;     // false when a fold had too few rows for the base parameters
};

// Two-fold cross-validation over alternate blocks of samples (see select_cutoff_held_out): fit on
// the candidate's equations, predict with the reference equations (those at the upper bound).
HeldOutError held_out_error(const CutoffEquations& fit_eq, const CutoffEquations& ref,
                            Eigen::Index samples, int blocks, Eigen::Index guard) {
  const Eigen::Index m = samples, p = fit_eq.W.cols();
  const auto block_of = [&](Eigen::Index k) { return k * blocks / m; };
  double e2 = 0.0, y2 = 0.0;
  for (int fold = 0; fold < 2; ++fold) {
    std::vector<Eigen::Index> fit;
    for (Eigen::Index i = 0; i < fit_eq.y.size(); ++i) {
      if (block_of(fit_eq.sample[i]) % 2 != fold) continue;
      if (!fit_eq.fitted.empty() && !fit_eq.fitted[static_cast<size_t>(i)]) continue;
      fit.push_back(i);
    }
    if (static_cast<Eigen::Index>(fit.size()) <= 2 * p) return {};
    Eigen::MatrixXd A(static_cast<Eigen::Index>(fit.size()), p);
    Eigen::VectorXd b(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i) {
      A.row(i) = fit_eq.W.row(fit[static_cast<size_t>(i)]);
      b[i] = fit_eq.y[fit[static_cast<size_t>(i)]];
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    if (qr.rank() < p) return {};
    const Eigen::VectorXd theta = qr.solve(b);
    for (Eigen::Index i = 0; i < ref.y.size(); ++i) {
      const Eigen::Index k = ref.sample[i];
      const Eigen::Index blk = block_of(k);
      if (blk % 2 == fold) continue;
      // Distance to the nearest boundary of this block: samples near it are not predicted.
      const Eigen::Index first = (blk * m + blocks - 1) / blocks;
      const Eigen::Index next = ((blk + 1) * m + blocks - 1) / blocks;
      if ((blk > 0 && k - first < guard) || (blk + 1 < blocks && next - k <= guard)) continue;
      const double e = ref.y[i] - ref.W.row(i).dot(theta);
      e2 += e * e;
      y2 += ref.y[i] * ref.y[i];
    }
  }
  if (!(y2 > 0.0)) return {};
  return {std::sqrt(e2 / y2), true};
}

// x to 3 significant digits, computed so that the shortest decimal text of the result (the
// stored choices.cutoff_hz) reads back as the same double: validate then filters as identify did.
double three_digits(double x) {
  if (!(x > 0.0) || !std::isfinite(x)) return x;
  const int d = 2 - static_cast<int>(std::floor(std::log10(x)));
  if (d >= 0) {
    const double scale = std::pow(10.0, d);
    return std::round(x * scale) / scale;
  }
  const double scale = std::pow(10.0, -d);
  return std::round(x / scale) * scale;
}

std::string percent(double fraction) {
  std::ostringstream s;
  s << std::setprecision(3) << 100.0 * fraction << " %";
  return s.str();
}

}  // namespace

CutoffSelection select_cutoff_held_out(const JointRecord& record, const SignalOptions& signal,
                                       const CutoffEquationBuilder& build, const std::string& what,
                                       const CutoffSelectionOptions& selection) {
  check_signal_options(signal);  // a NaN cut-off is no request for the automatic one
  CutoffSelection out;
  out.signal = signal;
  if (!signal.filter || signal.cutoff_hz > 0.0) return out;
  if (selection.blocks < 2 || selection.blocks % 2 != 0 || !(selection.grid_ratio > 1.0)) {
    throw Error("select_cutoff: blocks must be even and >= 2 and grid_ratio > 1");
  }
  // The spectral rule on the record as preprocess() sees it: directly on uniform stamps (cheap),
  // through preprocess() when they jitter (it resamples them first).
  double spectral_hz = 0.0, rate = 0.0;
  std::string spectral_reason;
  SamplingInfo info;
  try {
    if (record.t.size() < 10 || !record.q.allFinite()) return out;  // preprocess() reports it
    info = check_sampling(record.t, 0.05);
  } catch (const Error&) {
    return out;  // preprocess_run() reports it
  }
  if (info.uniform) {
    rate = info.rate_hz();
    const CutoffChoice c = choose_cutoff(record.q, rate);
    spectral_hz = c.cutoff_hz;
    spectral_reason = c.reason;
  } else {
    std::vector<std::pair<std::string, std::string>> spectral_choices;
    SignalOptions probe = signal;
    probe.decimate = 1;
    probe.trim = 0;
    const ProcessedRecord spectral = preprocess(record, probe, spectral_choices);
    spectral_hz = spectral.cutoff_hz;
    rate = spectral.rate_hz;
    for (const auto& c : spectral_choices)
      if (c.first == "cutoff") spectral_reason = c.second;
  }
  const CutoffRule rule;
  const double hi = three_digits(std::min(rule.max_hz, rule.max_fraction_of_rate * rate));
  double lowest = spectral_hz;
  if (selection.regressor_degree > 1) {
    // The products of the motion reach degree·f_b: pass them to within 1e-3 of their amplitude.
    const double pass = std::pow(1e-3, 1.0 / (2.0 * std::max(1, signal.order)));
    const double needed = selection.regressor_degree * spectral_hz / rule.margin / pass;
    if (needed > lowest) {
      lowest = std::min(needed, hi);
      std::ostringstream n;
      n << std::setprecision(3) << "; raised to " << lowest << " Hz so that the products of the "
        << "motion in the equations (degree " << selection.regressor_degree << ", up to "
        << selection.regressor_degree * spectral_hz / rule.margin
        << " Hz) pass the filter within 0.1 %";
      spectral_reason += n.str();
    }
  }
  const double f_s = three_digits(lowest);
  out.signal.cutoff_hz = f_s;
  out.selected = true;
  std::ostringstream why;
  why << std::setprecision(3);
  if (f_s >= hi * (1.0 - 1e-12)) {
    out.reason = spectral_reason + "; no higher candidate to compare";
    return out;
  }
  // Candidates: the spectral value (below it, filtering removes motion the position spectrum
  // shows well above its noise) up to the upper bound by grid_ratio; the last step before the
  // bound is dropped when it lies within 10 % of it.
  std::vector<double> grid;
  for (double f = f_s; f < hi / 1.1; f *= selection.grid_ratio) grid.push_back(three_digits(f));
  grid.push_back(hi);

  // One trim (the lowest cut-off's, which has the longest transient) and one decimation (the
  // highest cut-off's) for every candidate, so that all predict the same samples.
  const Eigen::Index m_in = record.t.size();
  SignalOptions common = signal;
  if (common.trim < 0) {
    const auto cap = static_cast<int>(std::max<Eigen::Index>(0, (m_in - 10) / 4));
    common.trim = std::min(cap, static_cast<int>(std::ceil(3.0 * rate / grid.front())));
  }
  if (common.decimate <= 0) {
    common.decimate = std::max(1, static_cast<int>(std::floor(rate / (10.0 * hi))));
  }
  auto equations = [&](double f) {
    SignalOptions s = common;
    s.cutoff_hz = f;
    return build(s);
  };
  try {
    // Every candidate's parameters predict the same held-out samples from the same signals: the
    // record processed at the upper bound (lightly filtered), so a candidate that smooths its own
    // y gains nothing from it, and only the parameters differ.
    const CutoffEquations reference = equations(hi);
    if (reference.y.size() == 0 || reference.sample.size() != reference.y.size())
      throw Error("no equations to compare");
    const Eigen::Index m = reference.sample.maxCoeff() + 1;
    const double kept_rate = rate / common.decimate;
    const auto guard = std::min<Eigen::Index>(
        m / selection.blocks / 4,
        static_cast<Eigen::Index>(std::ceil(selection.guard_periods / grid.front() * kept_rate)));
    double best = INFINITY;
    for (double f : grid) {
      const CutoffEquations e = f == hi ? reference : equations(f);
      if (e.y.size() != reference.y.size() || e.W.cols() != reference.W.cols() ||
          e.sample != reference.sample)
        throw Error("the candidates' equations do not share their rows");
      const HeldOutError h = held_out_error(e, reference, m, selection.blocks, guard);
      if (!h.ok) {
        out.candidates.clear();
        break;
      }
      out.candidates.push_back({f, h.error});
      if (h.error < best) {
        best = h.error;
        out.signal.cutoff_hz = f;
      }
    }
  } catch (const Error& e) {
    out.candidates.clear();
    out.signal.cutoff_hz = f_s;
    out.reason = spectral_reason + "; held-out selection not possible (" + e.what() + ")";
    return out;
  }
  if (out.candidates.empty()) {
    out.signal.cutoff_hz = f_s;
    out.reason = spectral_reason +
                 "; held-out selection not possible (a half of the blocks does not determine the "
                 "parameters)";
    return out;
  }
  why << "auto: " << out.signal.cutoff_hz << " Hz, the lowest " << what
      << " prediction error on held-out samples (fit on alternate " << selection.blocks / 2
      << " of " << selection.blocks << " blocks, predict the others from the signals filtered at "
      << hi << " Hz):";
  for (const CutoffCandidate& c : out.candidates) {
    why << " " << c.cutoff_hz << " Hz " << percent(c.held_out_error) << ";";
  }
  why << " lowest candidate from the spectral rule: " << spectral_reason;
  out.reason = why.str();
  return out;
}

CutoffSelection select_cutoff(const Model& model, const JointRecord& record,
                              const IdentifyOptions& options,
                              const CutoffSelectionOptions& selection) {
  if (record.q.cols() != model.dof()) {  // preprocess_run() reports it
    check_signal_options(options.signal);
    CutoffSelection out;
    out.signal = options.signal;
    return out;
  }
  const bool coupling = options.coupling && !coupled_motors(model).empty();
  BaseParameterOptions bo = options.base;
  bo.layout = options.layout;
  bo.coupling = coupling;
  const BaseParameters base = compute_base_parameters(model, bo);
  const Eigen::VectorXd zero_velocity =
      options.layout.coulomb ? given_zero_velocity(options.signal.zero_velocity, model.dof())
                             : Eigen::VectorXd();
  const auto rank = static_cast<Eigen::Index>(base.base.size());
  // The joint-torque equations on the base columns, sample-major; near-still Coulomb rows (a
  // given zero-velocity threshold) are not fitted, as identify() leaves them out.
  const CutoffEquationBuilder build = [&](const SignalOptions& s) {
    std::vector<std::pair<std::string, std::string>> ignored;
    const ProcessedRecord p = preprocess(record, s, ignored);
    const Eigen::MatrixXd W = processed_regressor(model, options.layout, coupling, p);
    const Eigen::Index m = p.record.t.size(), n = p.record.q.cols();
    CutoffEquations e;
    e.W.resize(m * n, rank);
    e.y.resize(m * n);
    e.sample.resize(m * n);
    e.fitted.assign(static_cast<size_t>(m * n), true);
    for (Eigen::Index k = 0; k < m; ++k) {
      for (Eigen::Index j = 0; j < n; ++j) {
        const Eigen::Index row = k * n + j;
        for (Eigen::Index c = 0; c < rank; ++c)
          e.W(row, c) = W(row, base.base[static_cast<size_t>(c)]);
        e.y[row] = p.record.tau(k, j);
        e.sample[row] = static_cast<int>(k);
        if (zero_velocity.size() && std::abs(p.record.dq(k, j)) < zero_velocity[j])
          e.fitted[static_cast<size_t>(row)] = false;
      }
    }
    return e;
  };
  return select_cutoff_held_out(record, options.signal, build, "torque", selection);
}

void echo_cutoff_selection(const CutoffSelection& selection,
                           std::vector<std::pair<std::string, std::string>>& choices) {
  if (!selection.selected) return;
  for (auto& c : choices) {
    if (c.first == "cutoff") c.second = selection.reason;
  }
}

}  // namespace dynid
