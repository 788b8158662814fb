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

// Two-fold cross-validation over alternate blocks of samples (see select_cutoff): fit on the
// candidate's processing (W_fit, p), predict with the reference processing (W_ref, tau_ref).
HeldOutError held_out_error(const Eigen::MatrixXd& W_fit, const ProcessedRecord& p,
                            const Eigen::MatrixXd& W_ref, const Eigen::MatrixXd& tau_ref,
                            const std::vector<int>& base, const Eigen::VectorXd& zero_velocity,
                            int blocks, Eigen::Index guard) {
  const Eigen::Index m = p.record.t.size(), n = p.record.q.cols();
  const auto rank = static_cast<Eigen::Index>(base.size());
  const auto block_of = [&](Eigen::Index k) { return k * blocks / m; };
  double e2 = 0.0, y2 = 0.0;
  for (int fold = 0; fold < 2; ++fold) {
    std::vector<Eigen::Index> fit;
    for (Eigen::Index k = 0; k < m; ++k) {
      if (block_of(k) % 2 != fold) continue;
      for (Eigen::Index j = 0; j < n; ++j) {
        if (zero_velocity.size() && std::abs(p.record.dq(k, j)) < zero_velocity[j]) continue;
        fit.push_back(k * n + j);
      }
    }
    if (static_cast<Eigen::Index>(fit.size()) <= 2 * rank) return {};
    Eigen::MatrixXd A(static_cast<Eigen::Index>(fit.size()), rank);
    Eigen::VectorXd b(A.rows());
    for (Eigen::Index i = 0; i < A.rows(); ++i) {
      for (Eigen::Index c = 0; c < rank; ++c) A(i, c) = W_fit(fit[i], base[c]);
      b[i] = p.record.tau(fit[i] / n, fit[i] % n);
    }
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(A);
    if (qr.rank() < rank) return {};
    const Eigen::VectorXd theta = qr.solve(b);
    for (Eigen::Index k = 0; k < m; ++k) {
      const Eigen::Index blk = block_of(k);
      if (blk % 2 == fold) continue;
      // Distance to the nearest boundary of this block: samples near it are not predicted.
      const Eigen::Index first = (blk * m + blocks - 1) / blocks;
      const Eigen::Index next = ((blk + 1) * m + blocks - 1) / blocks;
      if ((blk > 0 && k - first < guard) || (blk + 1 < blocks && next - k <= guard)) continue;
      for (Eigen::Index j = 0; j < n; ++j) {
        double pred = 0.0;
        for (Eigen::Index c = 0; c < rank; ++c) pred += W_ref(k * n + j, base[c]) * theta[c];
        const double e = tau_ref(k, j) - pred;
        e2 += e * e;
        y2 += tau_ref(k, j) * tau_ref(k, j);
      }
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

CutoffSelection select_cutoff(const Model& model, const JointRecord& record,
                              const IdentifyOptions& options,
                              const CutoffSelectionOptions& selection) {
  check_signal_options(options.signal);  // a NaN cut-off is no request for the automatic one
  CutoffSelection out;
  out.signal = options.signal;
  if (!options.signal.filter || options.signal.cutoff_hz > 0.0) return out;
  if (record.q.cols() != model.dof()) return out;  // preprocess_run() reports it
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
    SignalOptions probe = options.signal;
    probe.decimate = 1;
    probe.trim = 0;
    const ProcessedRecord spectral = preprocess(record, probe, spectral_choices);
    spectral_hz = spectral.cutoff_hz;
    rate = spectral.rate_hz;
    for (const auto& c : spectral_choices)
      if (c.first == "cutoff") spectral_reason = c.second;
  }
  const double f_s = three_digits(spectral_hz);
  out.signal.cutoff_hz = f_s;
  out.selected = true;
  const CutoffRule rule;
  const double hi = three_digits(std::min(rule.max_hz, rule.max_fraction_of_rate * rate));
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
  SignalOptions common = options.signal;
  if (common.trim < 0) {
    const auto cap = static_cast<int>(std::max<Eigen::Index>(0, (m_in - 10) / 4));
    common.trim = std::min(cap, static_cast<int>(std::ceil(3.0 * rate / grid.front())));
  }
  if (common.decimate <= 0) {
    common.decimate = std::max(1, static_cast<int>(std::floor(rate / (10.0 * hi))));
  }
  const bool coupling = options.coupling && !coupled_motors(model).empty();
  BaseParameterOptions bo = options.base;
  bo.layout = options.layout;
  bo.coupling = coupling;
  const BaseParameters base = compute_base_parameters(model, bo);
  const Eigen::VectorXd zero_velocity =
      options.layout.coulomb ? given_zero_velocity(options.signal.zero_velocity, model.dof())
                             : Eigen::VectorXd();

  auto process = [&](double f) {
    std::vector<std::pair<std::string, std::string>> ignored;
    SignalOptions s = common;
    s.cutoff_hz = f;
    return preprocess(record, s, ignored);
  };
  try {
    // Every candidate's parameters predict the same held-out samples from the same signals: the
    // record processed at the upper bound (lightly filtered), so a candidate that smooths its own
    // torque gains nothing from it, and only the parameters differ.
    const ProcessedRecord reference = process(hi);
    const Eigen::MatrixXd W_ref = processed_regressor(model, options.layout, coupling, reference);
    const Eigen::Index m = reference.record.t.size();
    const auto guard = std::min<Eigen::Index>(
        m / selection.blocks / 4, static_cast<Eigen::Index>(std::ceil(
                                      selection.guard_periods / grid.front() * reference.rate_hz)));
    double best = INFINITY;
    for (double f : grid) {
      const bool is_ref = f == hi;
      const ProcessedRecord p = is_ref ? reference : process(f);
      const Eigen::MatrixXd W =
          is_ref ? W_ref : processed_regressor(model, options.layout, coupling, p);
      const HeldOutError h = held_out_error(W, p, W_ref, reference.record.tau, base.base,
                                            zero_velocity, selection.blocks, guard);
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
                 "base parameters)";
    return out;
  }
  why << "auto: " << out.signal.cutoff_hz
      << " Hz, the lowest torque prediction error on held-out samples (fit on alternate "
      << selection.blocks / 2 << " of " << selection.blocks
      << " blocks, predict the others from q and tau filtered at " << hi << " Hz):";
  for (const CutoffCandidate& c : out.candidates) {
    why << " " << c.cutoff_hz << " Hz " << percent(c.held_out_error) << ";";
  }
  why << " lowest candidate from the spectral rule: " << spectral_reason;
  out.reason = why.str();
  return out;
}

void echo_cutoff_selection(const CutoffSelection& selection,
                           std::vector<std::pair<std::string, std::string>>& choices) {
  if (!selection.selected) return;
  for (auto& c : choices) {
    if (c.first == "cutoff") c.second = selection.reason;
  }
}

}  // namespace dynid
