#include "dynid/closed_loop/closed_loop.hpp"

#include <unsupported/Eigen/FFT>

#include <Eigen/Cholesky>
#include <Eigen/SVD>
#include <algorithm>
#include <cmath>
#include <complex>
#include <iomanip>
#include <limits>
#include <map>
#include <sstream>

#include <boost/math/distributions/students_t.hpp>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/signal/differentiation.hpp"
#include "dynid/signal/period_averaging.hpp"
#include "dynid/signal/resampling.hpp"
#include "dynid/signal/sampling_check.hpp"

namespace dynid {

namespace {

// A reference repeats when every channel returns to itself within this fraction of its range
// (a CSV written with 9 significant digits still passes; a drifting reference does not).
constexpr double kPeriodicTolerance = 1e-7;

std::string num(double x) {
  return short_number(x);
}

// The exact period [samples] of qr (m × n), or 0 when it is not periodic with two periods in m.
int exact_period(const Eigen::MatrixXd& qr) {
  const Eigen::Index m = qr.rows();
  Eigen::Index widest = 0;
  double widest_range = 0.0;
  Eigen::VectorXd range(qr.cols());
  for (Eigen::Index j = 0; j < qr.cols(); ++j) {
    range[j] = qr.col(j).maxCoeff() - qr.col(j).minCoeff();
    if (range[j] > widest_range) {
      widest_range = range[j];
      widest = j;
    }
  }
  if (!(widest_range > 0.0) || m < 4) return 0;
  int p = 0;
  try {
    p = detect_period(qr.col(widest));
  } catch (const Error&) {
    return 0;
  }
  if (p < 2 || 2 * p > m) return 0;
  for (Eigen::Index j = 0; j < qr.cols(); ++j) {
    const double d = (qr.col(j).tail(m - p) - qr.col(j).head(m - p)).cwiseAbs().maxCoeff();
    if (d > kPeriodicTolerance * std::max(range[j], 1e-300)) return 0;
  }
  return p;
}

// Derivative (order 1 or 2) of an exactly p-periodic signal x (m × n) sampled at ts, by its
// Fourier series over the first period (exact for a band-limited reference below Nyquist).
Eigen::MatrixXd periodic_derivative(const Eigen::MatrixXd& x, int p, double ts, int order) {
  Eigen::FFT<double> fft;
  Eigen::MatrixXd out(x.rows(), x.cols());
  for (Eigen::Index j = 0; j < x.cols(); ++j) {
    std::vector<double> period(x.col(j).data(), x.col(j).data() + p);
    std::vector<std::complex<double>> f;
    fft.fwd(f, period);
    for (int b = 0; b < p; ++b) {
      const int h = b <= p / 2 ? b : b - p;  // signed harmonic
      if (2 * std::abs(h) == p) {
        f[static_cast<size_t>(b)] = 0.0;  // Nyquist: its derivative is not defined by samples
        continue;
      }
      const std::complex<double> iw(0.0, 2.0 * M_PI * h / (p * ts));
      f[static_cast<size_t>(b)] *= order == 1 ? iw : iw * iw;
    }
    std::vector<double> d;
    fft.inv(d, f);
    for (Eigen::Index k = 0; k < x.rows(); ++k) out(k, j) = d[static_cast<size_t>(k % p)];
  }
  return out;
}

// P·x on harmonics 0…H of whole periods: the least-squares fit of the Fourier basis, evaluated
// (or its derivative). Whole periods make the discrete basis orthogonal for H < period/2.
class LineProjector : public SignalProjector {
 public:
  LineProjector(Eigen::Index len, int period, int harmonics, double ts) : len_(len) {
    basis_.resize(len, 2 * harmonics + 1);
    d1_.resize(len, 2 * harmonics + 1);
    d2_.resize(len, 2 * harmonics + 1);
    basis_.col(0).setOnes();
    d1_.col(0).setZero();
    d2_.col(0).setZero();
    for (int h = 1; h <= harmonics; ++h) {
      const double w = 2.0 * M_PI * h / (period * ts);
      for (Eigen::Index k = 0; k < len; ++k) {
        const double a = 2.0 * M_PI * h * static_cast<double>(k % period) / period;
        const double c = std::cos(a), s = std::sin(a);
        basis_(k, 2 * h - 1) = c;
        basis_(k, 2 * h) = s;
        d1_(k, 2 * h - 1) = -w * s;
        d1_(k, 2 * h) = w * c;
        d2_(k, 2 * h - 1) = -w * w * c;
        d2_(k, 2 * h) = -w * w * s;
      }
    }
    gram_ = (basis_.transpose() * basis_).ldlt();
  }
  Eigen::MatrixXd coefficients(const Eigen::Ref<const Eigen::MatrixXd>& x) const {
    if (x.rows() != len_)
      throw Error("spectral projection: " + std::to_string(x.rows()) +
                  " samples to project, the periods hold " + std::to_string(len_));
    return gram_.solve(basis_.transpose() * x);
  }
  Eigen::MatrixXd project(const Eigen::Ref<const Eigen::MatrixXd>& x) const override {
    return basis_ * coefficients(x);
  }
  Eigen::MatrixXd derivative(const Eigen::Ref<const Eigen::MatrixXd>& x, int order) const {
    return (order == 1 ? d1_ : d2_) * coefficients(x);
  }
  int rank() const override { return static_cast<int>(basis_.cols()); }
  Eigen::Index samples() const override { return len_; }

 private:
  Eigen::Index len_;
  Eigen::MatrixXd basis_, d1_, d2_;
  Eigen::LDLT<Eigen::MatrixXd> gram_;
};

// Energy of the (mean-removed) bins of x's FFT: total, and on harmonics 1…H of `periods` periods.
std::pair<double, double> band_energy(const Eigen::Ref<const Eigen::VectorXd>& x, int periods,
                                      int harmonics, Eigen::FFT<double>& fft,
                                      Eigen::VectorXd* line_amplitude = nullptr) {
  std::vector<double> buf(static_cast<size_t>(x.size()));
  const double mean = x.mean();
  for (Eigen::Index k = 0; k < x.size(); ++k) buf[static_cast<size_t>(k)] = x[k] - mean;
  std::vector<std::complex<double>> f;
  fft.fwd(f, buf);
  const auto len = static_cast<long>(f.size());
  double total = 0.0, kept = 0.0;
  for (long b = 1; b < len; ++b) total += std::norm(f[static_cast<size_t>(b)]);
  for (int h = 1; h <= harmonics; ++h) {
    const long b = static_cast<long>(h) * periods;
    if (b >= len) break;
    const double e = std::norm(f[static_cast<size_t>(b)]) +
                     (len - b != b ? std::norm(f[static_cast<size_t>(len - b)]) : 0.0);
    kept += e;
    if (line_amplitude) (*line_amplitude)[h] = std::sqrt(e);
  }
  return {total, kept};
}

// A reference column that does not move (to 1e-12 of its level): a joint held by its controller.
bool is_constant(const Eigen::Ref<const Eigen::VectorXd>& x) {
  const double mean = x.mean();
  return (x.array() - mean).abs().maxCoeff() <= 1e-12 * std::max(1.0, std::abs(mean));
}

// The reference's exact period [samples]: detected from qr (at least two periods in the run), or
// the whole run when the given dqr is the Fourier derivative of qr taken as one period (one period
// alone cannot show that it repeats; its derivative can). 0 when neither holds.
int reference_period(const ReferenceRecord& reference, double ts) {
  const int p = exact_period(reference.qr);
  const Eigen::Index m = reference.qr.rows();
  if (p > 0 || reference.dqr.size() == 0 || m <= 2) return p;
  const Eigen::MatrixXd d = periodic_derivative(reference.qr, static_cast<int>(m), ts, 1);
  return (d - reference.dqr).cwiseAbs().maxCoeff() <=
                 1e-6 * std::max(reference.dqr.cwiseAbs().maxCoeff(), 1e-300)
             ? static_cast<int>(m)
             : 0;
}

// The lines of a p-periodic reference over the run's last whole periods (seed 2 section 3.4).
struct ReferenceLines {
  Eigen::MatrixXd amplitude;  // (p − 1)/2 + 1 harmonics × joints: each line's amplitude
  std::vector<int> lines;     // harmonics above line_fraction × the same joint's largest
};

ReferenceLines reference_lines(const Eigen::MatrixXd& qr, int p, double line_fraction) {
  if (!(line_fraction > 0.0 && line_fraction < 1.0))
    throw Error("spectral line_fraction must be in (0, 1), got " + num(line_fraction));
  const Eigen::Index m = qr.rows(), n = qr.cols();
  const int periods = static_cast<int>(m / p);
  const Eigen::Index len = static_cast<Eigen::Index>(periods) * p, first = m - len;
  Eigen::FFT<double> fft;
  const int top = (p - 1) / 2;  // highest harmonic below Nyquist
  ReferenceLines out;
  out.amplitude = Eigen::MatrixXd::Zero(top + 1, n);
  for (Eigen::Index j = 0; j < n; ++j) {
    // A held joint has no lines: the round-off of a constant away from 0 would make every
    // harmonic one (relative to its own largest), and the band the whole spectrum.
    if (is_constant(qr.col(j))) continue;
    Eigen::VectorXd a = Eigen::VectorXd::Zero(top + 1);
    band_energy(qr.col(j).segment(first, len), periods, top, fft, &a);
    out.amplitude.col(j) = a;
  }
  for (int h = 1; h <= top; ++h) {
    bool line = false;
    for (Eigen::Index j = 0; j < n; ++j)
      line = line || out.amplitude(h, j) > line_fraction * out.amplitude.col(j).maxCoeff();
    if (line) out.lines.push_back(h);
  }
  return out;
}

// A joint whose reference is constant is held by its controller (seed 2 section 3: one joint
// moves at a time); both preparations take it as still. Only a run where nothing moves is refused.
void check_reference(const JointRecord& run, const ReferenceRecord& reference) {
  const Eigen::Index m = run.t.size(), n = run.q.cols();
  if (reference.qr.size() == 0)
    throw Error("closed-loop identification needs the reference columns qr1..qr" +
                std::to_string(n) +
                " in the run: log the controller's reference (dynid "
                "simulate writes them)");
  auto check = [&](const Eigen::MatrixXd& x, const char* name, bool optional) {
    if (optional && x.size() == 0) return;
    if (x.rows() != m || x.cols() != n)
      throw Error(std::string("closed loop: ") + name + " is " + std::to_string(x.rows()) + "x" +
                  std::to_string(x.cols()) + " but the run is " + std::to_string(m) + "x" +
                  std::to_string(n) + " (samples x joints)");
    if (!x.allFinite()) throw Error(std::string("closed loop: ") + name + " contains NaN or Inf");
  };
  check(reference.qr, "qr", false);
  check(reference.dqr, "dqr", true);
  check(reference.ddqr, "ddqr", true);
  Eigen::Index moving = 0;
  for (Eigen::Index i = 0; i < n; ++i) moving += !is_constant(reference.qr.col(i));
  if (moving == 0)
    throw Error("every reference qr1..qr" + std::to_string(n) +
                " is constant: the run excites nothing; move at least one joint");
}

// The processing choice that names the joints a one-joint run holds (0-based in, 1-based out).
void note_held_joints(const std::vector<int>& held,
                      std::vector<std::pair<std::string, std::string>>& choices) {
  if (held.empty()) return;
  std::string list;
  for (int j : held) list += (list.empty() ? "" : ", ") + std::to_string(j + 1);
  choices.emplace_back(
      "still_joints",
      "joints " + list + " (constant reference): held, velocity and acceleration taken as zero");
}

ClosedLoopRun prepare_projection(const JointRecord& run, const ReferenceRecord& reference,
                                 const ClosedLoopIdOptions& options, double ts,
                                 std::vector<std::pair<std::string, std::string>>& choices) {
  Eigen::MatrixXd dqr = reference.dqr, ddqr = reference.ddqr;
  const int period = reference_period(reference, ts);
  if (dqr.size() == 0 || ddqr.size() == 0) {
    if (period > 0) {
      if (dqr.size() == 0) dqr = periodic_derivative(reference.qr, period, ts, 1);
      if (ddqr.size() == 0) ddqr = periodic_derivative(reference.qr, period, ts, 2);
      choices.emplace_back("reference_derivatives",
                           "from the periodic reference's Fourier series (period " +
                               std::to_string(period) + " samples)");
    } else {
      if (dqr.size() == 0) dqr = central_difference(run.t, reference.qr, 1);
      if (ddqr.size() == 0) ddqr = central_difference(run.t, dqr, 1);
      choices.emplace_back("reference_derivatives",
                           "central differences of the (noise-free) reference: it is not "
                           "periodic; log dqr*, ddqr* for exact ones");
    }
  } else {
    choices.emplace_back("reference_derivatives", "dqr*, ddqr* from the data");
  }
  // A periodic reference with L lines spans 2L + 1 dimensions (cos and sin of each line, and the
  // constant) at every lag: an automatic FIR order that kept fewer would drop lines of the
  // excitation (a 4-harmonic reference at 100 Hz: M = 2 kept 7 of 9).
  ProjectionOptions po = options.projection;
  int dimensions = 0;
  if (period > 0) {
    dimensions =
        2 * static_cast<int>(
                reference_lines(reference.qr, period, options.line_fraction).lines.size()) +
        1;
    if (po.min_rank == 0) po.min_rank = dimensions;
  }
  ProjectionResult p = project_on_reference(run, reference.qr, dqr, ddqr, po);
  ClosedLoopRun out;
  out.processed = std::move(p.processed);
  out.projector = p.projector;
  out.torque_remainder_std = p.torque_remainder_std;
  out.warnings = p.warnings;
  ClosedLoopReport& rep = out.report;
  rep.method = ClosedLoopMethod::kProjection;
  rep.rank = p.projector->rank();
  rep.m1 = p.m1;
  rep.m2 = p.m2;
  rep.correlation = p.correlation;
  rep.max_z = p.tests.back().max_z;
  rep.threshold = p.tests.back().threshold;
  rep.test_passed = p.tests.back().passed;
  rep.reference_dimensions = dimensions;
  rep.held_joints = p.held_joints;
  note_held_joints(p.held_joints, choices);
  std::ostringstream s;
  s << std::setprecision(3) << "projection on the lagged references (Forssell-Ljung; seed 2 "
    << "eqs. 10-12): M1 = " << p.m1 << ", M2 = " << p.m2
    << (options.projection.m1 >= 0 ? " (given)"
                                   : " (smallest passing the test and keeping the reference's "
                                     "dimensions)")
    << "; remainder-reference test max |z| " << rep.max_z << " vs bound " << rep.threshold
    << (rep.test_passed ? " (passed)" : " (FAILED)") << "; the regressor columns projected alike; "
    << p.projector->rank() << " dimensions per channel (interval degrees of freedom)";
  if (dimensions > 0) s << " of the " << dimensions << " the periodic reference spans";
  choices.emplace_back("closed_loop", s.str());
  return out;
}

// The user's period (options.period [s]) in samples, checked against the run: a whole number of
// samples, two periods in the run, and qr repeating with it to options.given_period_tolerance.
int given_period(const Eigen::MatrixXd& qr, const ClosedLoopIdOptions& options, double ts,
                 std::vector<std::pair<std::string, std::string>>& choices) {
  const double samples = options.period / ts;
  const double whole = std::round(samples);
  if (!std::isfinite(samples) || std::abs(samples - whole) > 1e-6 * std::max(whole, 1.0) ||
      whole < 2.0)
    throw Error("--period " + num(options.period) + " s is " + num(samples) +
                " samples at this run's sampling interval " + num(ts) +
                " s; the spectral lines need a whole number of samples per period: check --period/"
                "--f0 or resample the run");
  const Eigen::Index m = qr.rows(), p = static_cast<Eigen::Index>(whole);
  if (2 * p > m)
    throw Error("--period " + num(options.period) + " s (" + std::to_string(p) +
                " samples) leaves fewer than two whole periods in the run's " + std::to_string(m) +
                " samples: check --period/--f0 or record more periods");
  double worst = 0.0;
  for (Eigen::Index j = 0; j < qr.cols(); ++j) {
    const double range = qr.col(j).maxCoeff() - qr.col(j).minCoeff();
    const double d = (qr.col(j).tail(m - p) - qr.col(j).head(m - p)).cwiseAbs().maxCoeff();
    const double rel = d / std::max(range, 1e-300);
    if (rel > options.given_period_tolerance)
      throw Error("qr" + std::to_string(j + 1) + " does not repeat with --period " +
                  num(options.period) + " s: qr(t + T) - qr(t) reaches " + num(rel) +
                  " of its range (at most " + num(options.given_period_tolerance) +
                  "); check --period/--f0 against the reference");
    worst = std::max(worst, rel);
  }
  choices.emplace_back("period", "given: " + num(options.period) + " s = " + std::to_string(p) +
                                     " samples; qr repeats with it to " + num(worst) +
                                     " of its range");
  return static_cast<int>(p);
}

ClosedLoopRun prepare_spectral(const JointRecord& run, const ReferenceRecord& reference,
                               const ClosedLoopIdOptions& options, double ts,
                               std::vector<std::pair<std::string, std::string>>& choices) {
  const Eigen::Index m = run.t.size(), n = run.q.cols();
  const int p = options.period > 0.0 ? given_period(reference.qr, options, ts, choices)
                                     : reference_period(reference, ts);
  if (p == 0)
    throw Error(
        "--closed-loop spectral needs a periodic reference sampled a whole number of times per "
        "period, with at least two periods: qr does not repeat; use --closed-loop projection");
  const int periods = static_cast<int>(m / p);
  const Eigen::Index len = static_cast<Eigen::Index>(periods) * p, first = m - len;
  ExcitationSpectrum sp;
  sp.period_samples = p;
  sp.periods = periods;
  sp.f0_hz = 1.0 / (p * ts);
  sp.lines = reference_lines(reference.qr, p, options.line_fraction).lines;
  Eigen::FFT<double> fft;
  sp.band_harmonic = sp.lines.empty() ? 1 : sp.lines.back();
  sp.reference_energy_above_band.resize(n);
  sp.torque_energy_removed.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    auto [total, kept] =
        band_energy(reference.qr.col(j).segment(first, len), periods, sp.band_harmonic, fft);
    sp.reference_energy_above_band[j] = total > 0.0 ? std::max(0.0, 1.0 - kept / total) : 0.0;
    auto [tt, tk] = band_energy(run.tau.col(j).segment(first, len), periods, sp.band_harmonic, fft);
    sp.torque_energy_removed[j] = tt > 0.0 ? std::max(0.0, 1.0 - tk / tt) : 0.0;
  }
  auto projector = std::make_shared<LineProjector>(len, p, sp.band_harmonic, ts);
  ClosedLoopRun out;
  out.report.method = ClosedLoopMethod::kSpectral;
  out.report.rank = projector->rank();
  JointRecord& r = out.processed.record;
  r.t = run.t.segment(first, len);
  const Eigen::MatrixXd q = run.q.middleRows(first, len);
  r.q = projector->project(q);
  r.dq = projector->derivative(q, 1);
  r.ddq = projector->derivative(q, 2);
  r.tau = projector->project(run.tau.middleRows(first, len));
  // A joint whose reference is constant was held by the controller (one-joint runs, seed 2
  // section 3): its projected motion is tracking error, not excitation, and would make its
  // velocity columns (Ia, friction) look excited; taken as still, as identify's still joints.
  std::vector<int> held;
  for (Eigen::Index j = 0; j < n; ++j) {
    if (!is_constant(reference.qr.col(j))) continue;
    r.dq.col(j).setZero();
    r.ddq.col(j).setZero();
    held.push_back(static_cast<int>(j));
  }
  note_held_joints(held, choices);
  out.report.held_joints = held;
  out.processed.rate_hz = 1.0 / ts;
  out.processed.position_noise_std =
      ((q - r.q).colwise().squaredNorm() / static_cast<double>(len)).cwiseSqrt().transpose();
  out.processed.velocity_noise_std = Eigen::VectorXd::Zero(n);
  const Eigen::MatrixXd remainder = run.tau.middleRows(first, len) - r.tau;
  out.torque_remainder_std =
      (remainder.colwise().squaredNorm() / static_cast<double>(len)).cwiseSqrt().transpose();
  // corr(û_j, ũ_j) as the projection method reports it (seed 2 reports 2.9e-14): the lines and
  // the rest of the spectrum are orthogonal, so this is round-off, a check of the projector.
  out.report.correlation.resize(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    const Eigen::VectorXd uc = r.tau.col(j).array() - r.tau.col(j).mean();
    const double denom = uc.norm() * remainder.col(j).norm();
    out.report.correlation[j] = denom > 0.0 ? uc.dot(remainder.col(j)) / denom : 0.0;
  }
  out.report.spectrum = sp;
  out.projector = projector;
  std::ostringstream s;
  s << std::setprecision(4) << "spectral lines of the periodic reference (seed 2 section 3.4): f0 "
    << sp.f0_hz << " Hz (" << p << " samples), the last " << periods << " whole periods (" << first
    << " leading samples dropped), harmonics 0.." << sp.band_harmonic << " of q and tau "
    << "kept, derivatives analytic on those lines; the regressor columns projected alike; "
    << projector->rank() << " dimensions per channel (interval degrees of freedom)";
  choices.emplace_back("closed_loop", s.str());
  return out;
}

}  // namespace

ClosedLoopRun prepare_closed_loop(const JointRecord& input, const ReferenceRecord& reference,
                                  const ClosedLoopIdOptions& options,
                                  std::vector<std::pair<std::string, std::string>>& choices) {
  if (options.method == ClosedLoopMethod::kNone)
    throw Error("prepare_closed_loop: no closed-loop method chosen");
  check_reference(input, reference);
  const SamplingInfo info =
      require_uniform_sampling(input.t, 1e-6, "closed-loop identification (the reference's lags)");
  const double ts = info.mean_period;
  JointRecord run = input;
  if (options.torque_time_offset != 0.0) {
    if (!std::isfinite(options.torque_time_offset) ||
        std::abs(options.torque_time_offset) > 100.0 * ts)
      throw UsageError("--time-shift " + num(options.torque_time_offset) +
                       " s is not a small finite time (at most 100 samples)");
    const Eigen::Index m = run.t.size();
    const Eigen::VectorXd shifted = run.t.array() + options.torque_time_offset;
    const Eigen::VectorXd query = run.t.cwiseMax(shifted(0)).cwiseMin(shifted(m - 1));
    run.tau = interpolate(shifted, run.tau, query, Interpolation::kLinear);
    choices.emplace_back(
        "torque_time_offset",
        num(options.torque_time_offset) + " s (torques re-interpolated onto the q time stamps)");
  }
  choices.emplace_back("sample_rate_hz", num(info.rate_hz()));
  choices.emplace_back("filter", "none (the closed-loop preparation keeps the reference's band)");
  ClosedLoopRun out = options.method == ClosedLoopMethod::kProjection
                          ? prepare_projection(run, reference, options, ts, choices)
                          : prepare_spectral(run, reference, options, ts, choices);
  out.processed.trim = 0;
  out.processed.decimate = 1;
  return out;
}

EquationBlock project_equations(const EquationBlock& block, const SignalProjector& projector) {
  const auto n = static_cast<Eigen::Index>(block.group_names.size());
  const Eigen::Index len = projector.samples(), p = block.W.cols();
  if (n == 0 || block.y.size() != len * n)
    throw Error("project_equations: the block has " + std::to_string(block.y.size()) +
                " rows, the projection needs every joint's row of its " + std::to_string(len) +
                " samples (no rows removed)");
  for (Eigen::Index i = 0; i < block.y.size(); ++i)
    if (block.sample[i] != i / n || block.group[i] != i % n)
      throw Error("project_equations: row " + std::to_string(i) +
                  " is not sample-major (sample k, joint j at row k*n + j)");
  EquationBlock out = block;
  Eigen::MatrixXd channel(len, p + 1);
  for (Eigen::Index j = 0; j < n; ++j) {
    for (Eigen::Index k = 0; k < len; ++k) {
      channel.row(k).head(p) = block.W.row(k * n + j);
      channel(k, p) = block.y[k * n + j];
    }
    const Eigen::MatrixXd projected = projector.project(channel);
    for (Eigen::Index k = 0; k < len; ++k) {
      out.W.row(k * n + j) = projected.row(k).head(p);
      out.y[k * n + j] = projected(k, p);
    }
  }
  return out;
}

std::string projected_statistics(Estimate& e, const EquationBlock& block,
                                 Eigen::Index effective_rows, bool weighted,
                                 const EstimationOptions& options, const Eigen::VectorXi& channel,
                                 const Eigen::VectorXd& remainder_variance) {
  const Eigen::Index rows = block.W.rows(), p = block.W.cols();
  if (channel.size() != 0 && channel.size() != rows)
    throw Error("projected_statistics: " + std::to_string(channel.size()) + " channel labels for " +
                std::to_string(rows) + " rows");
  if (remainder_variance.size() != 0 && remainder_variance.size() != rows)
    throw Error("projected_statistics: " + std::to_string(remainder_variance.size()) +
                " remainder variances for " + std::to_string(rows) + " rows");
  Eigen::VectorXd w = Eigen::VectorXd::Ones(rows);
  if (weighted && e.group_variance.size()) {
    for (Eigen::Index i = 0; i < rows; ++i) {
      const double v = e.group_variance[block.group[i]];
      if (v > 0.0 && std::isfinite(v)) w[i] = 1.0 / std::sqrt(v);
    }
  }
  const Eigen::MatrixXd Ww = w.asDiagonal() * block.W;
  const Eigen::VectorXd ew = w.asDiagonal() * (block.y - block.W * e.x);
  // Column scaling so that inertia and friction columns of very different sizes invert well.
  Eigen::VectorXd s = Ww.colwise().norm().transpose();
  for (Eigen::Index c = 0; c < p; ++c)
    if (!(s[c] > 0.0)) s[c] = 1.0;
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Ww * s.cwiseInverse().asDiagonal(),
                                              Eigen::ComputeThinV);
  const Eigen::VectorXd sv = svd.singularValues();
  const double cut = std::max(rows, p) * std::numeric_limits<double>::epsilon() * sv[0];
  Eigen::Index rank = 0;
  Eigen::VectorXd inv2 = Eigen::VectorXd::Zero(sv.size());
  for (Eigen::Index k = 0; k < sv.size(); ++k)
    if (sv[k] > cut) {
      inv2[k] = 1.0 / (sv[k] * sv[k]);
      ++rank;
    }
  const Eigen::MatrixXd v_all = svd.matrixV();
  if (effective_rows <= rank) {
    // The estimate exists; the projected residual has no dimension left to measure the noise. The
    // torque remainder u − P·u outside the projected span holds it instead: for noise that is
    // white across the band, each projected dimension carries the remainder's variance σ_j² of its
    // channel, so cov(θ̂) = B·(Σ_i σ_i²·w̃_i·w̃_iᵀ)·B, B = (W̃ᵀW̃)⁻¹ (docs/methods/closed_loop.md,
    // "Intervals without degrees of freedom").
    std::ostringstream m;
    m << "the projected signals span " << effective_rows << " dimensions (all joints and runs) for "
      << rank << " parameters, so no degrees of freedom are left in the projected residual";
    if (remainder_variance.size() != rows || !remainder_variance.allFinite() ||
        !(remainder_variance.maxCoeff() > 0.0))
      throw Error(m.str() +
                  " and no torque remainder to take the noise from; use a reference "
                  "with more harmonics or more runs");
    const Eigen::MatrixXd bread_scaled = v_all * inv2.asDiagonal() * v_all.transpose();
    const Eigen::MatrixXd Ws = Ww * s.cwiseInverse().asDiagonal();
    const Eigen::MatrixXd meat =
        Ws.transpose() * remainder_variance.cwiseProduct(w.cwiseAbs2()).asDiagonal() * Ws;
    const Eigen::MatrixXd cov_scaled = bread_scaled * meat * bread_scaled;
    e.covariance = s.cwiseInverse().asDiagonal() * cov_scaled * s.cwiseInverse().asDiagonal();
    e.residual_variance = remainder_variance.mean();
    // The remainder's variance comes from thousands of samples per channel: normal quantiles.
    e.degrees_of_freedom = std::max<Eigen::Index>(rows - rank, 1000);
    e.covariance_kind = "torque remainder, projected";
    e.std_dev_white.resize(0);
    e.ci_lower_white.resize(0);
    e.ci_upper_white.resize(0);
    e.summary.warnings.push_back(
        m.str() +
        ": the intervals take the noise from the torque remainder outside that span "
        "(white across the band assumed); a reference with more harmonics or more "
        "runs, or --repeat periods (the spread of per-period estimates, Bona & "
        "Curatella's Table 3), measures it on the projected equations themselves");
    fill_parameter_statistics(e, options);
    return "(W~^T W~)^-1 (sum_i s_i^2 w~_i w~_i^T) (W~^T W~)^-1 with s_j^2 the variance of joint "
           "j's torque remainder u - P u: " +
           m.str();
  }
  const double dof = static_cast<double>(effective_rows - rank);
  const double sigma2 = ew.squaredNorm() / dof;
  const Eigen::MatrixXd v = svd.matrixV();
  const Eigen::MatrixXd inv_scaled = v * inv2.asDiagonal() * v.transpose();
  const Eigen::MatrixXd bread =
      s.cwiseInverse().asDiagonal() * inv_scaled * s.cwiseInverse().asDiagonal();
  e.covariance = sigma2 * bread;
  // Channel-clustered sandwich, per parameter the larger of it and the white variance.
  std::ostringstream widened;
  int clusters = 0;
  if (channel.size() == rows) {
    std::map<int, Eigen::VectorXd> score;
    for (Eigen::Index i = 0; i < rows; ++i) {
      auto it = score.try_emplace(channel[i], Eigen::VectorXd::Zero(p)).first;
      it->second += Ww.row(i).transpose() * ew[i];
    }
    clusters = static_cast<int>(score.size());
    if (clusters >= 2) {
      Eigen::MatrixXd meat = Eigen::MatrixXd::Zero(p, p);
      for (const auto& [c, g] : score) meat.selfadjointView<Eigen::Lower>().rankUpdate(g);
      meat = meat.selfadjointView<Eigen::Lower>();
      const double n_eff = static_cast<double>(effective_rows);
      meat *= clusters / (clusters - 1.0) * (n_eff - 1.0) / dof;
      const Eigen::MatrixXd clustered = bread * meat * bread;
      Eigen::VectorXd scale = Eigen::VectorXd::Ones(p);
      widened << std::setprecision(3);
      for (Eigen::Index k = 0; k < p; ++k) {
        const double white = e.covariance(k, k);
        if (!(white > 0.0) || !(clustered(k, k) > white)) continue;
        scale[k] = std::sqrt(clustered(k, k) / white);
        if (scale[k] > 1.2)
          widened << (widened.tellp() > 0 ? ", " : "")
                  << (k < static_cast<Eigen::Index>(options.names.size())
                          ? options.names[static_cast<size_t>(k)]
                          : "#" + std::to_string(k))
                  << " x" << scale[k];
      }
      e.covariance = scale.asDiagonal() * e.covariance * scale.asDiagonal();
    }
  }
  e.residual_variance = sigma2;
  e.degrees_of_freedom = effective_rows - rank;
  e.covariance_kind = clusters >= 2 ? "white or channel-clustered, projected" : "white, projected";
  e.std_dev_white.resize(0);
  e.ci_lower_white.resize(0);
  e.ci_upper_white.resize(0);
  auto& warnings = e.summary.warnings;
  warnings.erase(std::remove_if(warnings.begin(), warnings.end(),
                                [](const std::string& w) {
                                  return w.find("are correlated (lag-1 autocorrelation") !=
                                         std::string::npos;
                                }),
                 warnings.end());
  if (widened.tellp() > 0)
    e.summary.warnings.push_back(
        "the " + std::to_string(clusters) + " projected channels (joints x runs) disagree about " +
        widened.str() +
        " beyond their noise (interval widened by that factor): model error in some joint's "
        "torque (e.g. a joint its controller holds, taken as still while it moves by its "
        "tracking error), which may bias the estimate; the widened interval allows for it");
  fill_parameter_statistics(e, options);
  std::ostringstream c;
  c << std::setprecision(4) << "sigma^2 (W~^T W~)^-1 on the projected equations, sigma^2 = "
    << "|e~|^2/(" << effective_rows << " - " << rank << "): the projected signals span "
    << effective_rows << " dimensions (rank per channel, "
    << "all joints and runs), not one per row (" << rows << "); Student-t intervals with "
    << e.degrees_of_freedom << " degrees of freedom";
  if (clusters >= 2)
    c << "; per parameter the larger of that and the channel-clustered sandwich over the "
      << clusters << " projected channels (joints x runs; Angrist-Pischke max rule)";
  return c.str();
}

void check_closed_loop_request(const IdentifyOptions& options, size_t runs, size_t references) {
  const bool closed = options.closed_loop.method != ClosedLoopMethod::kNone;
  if (!closed) return;
  if (options.model != IdentificationModel::kDifferential)
    throw UsageError("--closed-loop prepares the differential model's signals; drop --model");
  if (references != runs)
    throw Error("closed-loop identification needs the reference of every run: " +
                std::to_string(references) + " references for " + std::to_string(runs) + " runs");
}

RepeatedEstimate repeated_statistics(
    const std::vector<std::pair<std::vector<std::string>, Eigen::VectorXd>>& estimates,
    double confidence_level) {
  if (estimates.size() < 2)
    throw Error("the repeated statistic needs at least 2 estimates, got " +
                std::to_string(estimates.size()) + ": give more periods or runs");
  if (!(confidence_level > 0.0 && confidence_level < 1.0))
    throw Error("confidence level " + num(confidence_level) + " is outside (0, 1)");
  RepeatedEstimate out;
  out.n = static_cast<int>(estimates.size());
  out.confidence_level = confidence_level;
  std::vector<std::vector<double>> values;
  for (size_t c = 0; c < estimates.front().first.size(); ++c) {
    const std::string& name = estimates.front().first[c];
    std::vector<double> v;
    for (const auto& [names, x] : estimates) {
      const auto it = std::find(names.begin(), names.end(), name);
      if (it == names.end()) break;
      v.push_back(x[it - names.begin()]);
    }
    if (static_cast<int>(v.size()) != out.n) continue;
    out.names.push_back(name);
    values.push_back(std::move(v));
  }
  const auto p = static_cast<Eigen::Index>(values.size());
  out.mean.resize(p);
  out.std_dev.resize(p);
  out.ci_half_width.resize(p);
  const double n = out.n;
  const double t = boost::math::quantile(
      boost::math::complement(boost::math::students_t(n - 1.0), (1.0 - confidence_level) / 2.0));
  for (Eigen::Index c = 0; c < p; ++c) {
    const Eigen::Map<const Eigen::VectorXd> v(values[static_cast<size_t>(c)].data(), out.n);
    out.mean[c] = v.mean();
    out.std_dev[c] = std::sqrt((v.array() - out.mean[c]).square().sum() / (n - 1.0));
    out.ci_half_width[c] = t / std::sqrt(n - 1.0) * out.std_dev[c];
  }
  return out;
}

RepeatedPieces repeated_pieces(const std::vector<JointRecord>& runs,
                               const std::vector<ReferenceRecord>& references,
                               const IdentifyOptions& options, RepeatOver over) {
  const bool closed = options.closed_loop.method != ClosedLoopMethod::kNone;
  RepeatedPieces out;
  if (over == RepeatOver::kRuns) {
    if (closed) {
      check_closed_loop_request(options, runs.size(), references.size());
      for (size_t i = 0; i < runs.size(); ++i) check_reference(runs[i], references[i]);
      out.references = references;
    }
    out.runs = runs;
  } else {
    const bool missing = std::any_of(references.begin(), references.end(),
                                     [](const ReferenceRecord& r) { return r.qr.size() == 0; });
    if (references.size() != runs.size() || missing)
      throw Error(
          "--repeat periods finds the period from the reference: the run needs its "
          "qr1..qrn columns");
    for (size_t i = 0; i < runs.size(); ++i) {
      check_reference(runs[i], references[i]);
      const int p = exact_period(references[i].qr);
      if (p == 0)
        throw Error(
            "--repeat periods needs a periodic reference with at least two periods in "
            "the run: qr does not repeat (run " +
            std::to_string(i + 1) + ")");
      // Derivatives of the whole periodic reference: one period alone cannot show it repeats (the
      // preparations check a period against them, reference_period).
      ReferenceRecord ref = references[i];
      const double ts = (runs[i].t[runs[i].t.size() - 1] - runs[i].t[0]) /
                        static_cast<double>(runs[i].t.size() - 1);
      if (ref.dqr.size() == 0) ref.dqr = periodic_derivative(ref.qr, p, ts, 1);
      if (ref.ddqr.size() == 0) ref.ddqr = periodic_derivative(ref.qr, p, ts, 2);
      for (Eigen::Index first = 0; first + p <= runs[i].t.size(); first += p) {
        const JointRecord& r = runs[i];
        auto rows = [&](const Eigen::MatrixXd& x) {
          return x.size() ? Eigen::MatrixXd(x.middleRows(first, p)) : Eigen::MatrixXd();
        };
        out.runs.push_back(
            {r.t.segment(first, p), rows(r.q), rows(r.dq), rows(r.ddq), rows(r.tau)});
        if (closed) out.references.push_back({rows(ref.qr), rows(ref.dqr), rows(ref.ddqr)});
      }
    }
  }
  if (out.runs.size() < 2)
    throw Error("--repeat needs at least 2 " +
                std::string(over == RepeatOver::kRuns ? "runs (give --data several times)"
                                                      : "whole periods in the run") +
                ", got " + std::to_string(out.runs.size()));
  return out;
}

RepeatedEstimate identify_repeated(const Model& model, const RepeatedPieces& pieces,
                                   const IdentifyOptions& options) {
  const bool closed = options.closed_loop.method != ClosedLoopMethod::kNone;
  check_closed_loop_request(options, pieces.runs.size(),
                            closed ? pieces.references.size() : pieces.runs.size());
  std::vector<std::pair<std::vector<std::string>, Eigen::VectorXd>> estimates;
  for (size_t i = 0; i < pieces.runs.size(); ++i) {
    const std::vector<ReferenceRecord> ref =
        closed ? std::vector<ReferenceRecord>{pieces.references[i]}
               : std::vector<ReferenceRecord>{};
    const IdentificationResult r = identify(model, {pieces.runs[i]}, ref, options);
    estimates.emplace_back(r.names, r.estimate.x);
  }
  return repeated_statistics(estimates, options.confidence_level);
}

RepeatedEstimate identify_repeated(const Model& model, const std::vector<JointRecord>& runs,
                                   const std::vector<ReferenceRecord>& references,
                                   const IdentifyOptions& options, RepeatOver over) {
  return identify_repeated(model, repeated_pieces(runs, references, options, over), options);
}

}  // namespace dynid
