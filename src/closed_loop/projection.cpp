#include "dynid/closed_loop/projection.hpp"

#include <unsupported/Eigen/FFT>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <cmath>
#include <complex>
#include <memory>
#include <string>
#include <vector>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/signal/sampling_check.hpp"

namespace dynid {

namespace {

// Rows t = T0 … T1 of the regression; column (i, a), a = k + M1, holds r_i(t − a + M1).
struct Window {
  int m1, m2, w;                                           // orders and width M1 + M2 + 1
  Eigen::Index t0, len;                                    // first row, number of rows
  Eigen::Index start(int a) const { return t0 - a + m1; }  // first sample of column a
};

Window window_for(int m1, int m2, Eigen::Index m) {
  return {m1, m2, m1 + m2 + 1, m2, m - m1 - m2};
}

// Gram of the lagged references and the constant, by the shift recursion
// G(a+1, b+1) = G(a, b) + r_i(t0−1−a+M1)·r_l(t0−1−b+M1) − r_i(t1−a+M1)·r_l(t1−b+M1), so only the
// first row and column of each block are full dot products (O(n²·W·m), not O(n²·W²·m)).
Eigen::MatrixXd lagged_gram(const Eigen::MatrixXd& r, const Window& win) {
  const Eigen::Index n = r.cols(), w = win.w, cols = n * w + 1, len = win.len;
  const Eigen::Index t1 = win.t0 + len - 1;
  Eigen::MatrixXd g(cols, cols);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index l = i; l < n; ++l) {
      auto block = g.block(i * w, l * w, w, w);
      for (int b = 0; b < w; ++b)
        block(0, b) = r.col(i).segment(win.start(0), len).dot(r.col(l).segment(win.start(b), len));
      for (int a = 1; a < w; ++a)
        block(a, 0) = r.col(i).segment(win.start(a), len).dot(r.col(l).segment(win.start(0), len));
      for (int a = 0; a + 1 < w; ++a)
        for (int b = 0; b + 1 < w; ++b)
          block(a + 1, b + 1) = block(a, b) +
                                r(win.t0 - 1 - a + win.m1, i) * r(win.t0 - 1 - b + win.m1, l) -
                                r(t1 - a + win.m1, i) * r(t1 - b + win.m1, l);
      if (l != i) g.block(l * w, i * w, w, w) = block.transpose();
    }
    for (int a = 0; a < w; ++a) {
      g(i * w + a, cols - 1) = g(cols - 1, i * w + a) = r.col(i).segment(win.start(a), len).sum();
    }
  }
  g(cols - 1, cols - 1) = static_cast<double>(len);
  return g;
}

// Φᵀ·y for the outputs y (m × p), rows t0 … t1.
Eigen::MatrixXd lagged_rhs(const Eigen::MatrixXd& r, const Eigen::MatrixXd& y, const Window& win) {
  const Eigen::Index n = r.cols(), w = win.w, cols = n * w + 1;
  Eigen::MatrixXd out(cols, y.cols());
  for (Eigen::Index o = 0; o < y.cols(); ++o) {
    const auto yo = y.col(o).segment(win.t0, win.len);
    for (Eigen::Index i = 0; i < n; ++i)
      for (int a = 0; a < w; ++a)
        out(i * w + a, o) = r.col(i).segment(win.start(a), win.len).dot(yo);
    out(cols - 1, o) = yo.sum();
  }
  return out;
}

// Σ_i Σ_a s(i·W + a)·x_i(t − a + M1) (+ the constant when with_constant), rows t0 … t1.
Eigen::VectorXd apply_fir(const Eigen::MatrixXd& x, const Eigen::Ref<const Eigen::VectorXd>& s,
                          const Window& win, bool with_constant) {
  Eigen::VectorXd out = Eigen::VectorXd::Constant(win.len, with_constant ? s[s.size() - 1] : 0.0);
  for (Eigen::Index i = 0; i < x.cols(); ++i)
    for (int a = 0; a < win.w; ++a)
      out += s[i * win.w + a] * x.col(i).segment(win.start(a), win.len);
  return out;
}

// Least-squares FIR coefficients by the eigen-decomposition of the Jacobi-scaled Gram, dropping
// directions the reference does not span (a few-harmonic reference spans few); factored once, so
// that the regressor columns can be projected with the same operator.
struct FirSolver {
  Eigen::VectorXd d, inv;
  Eigen::MatrixXd v;
  int rank = 0;

  FirSolver(const Eigen::MatrixXd& r, const Window& win, double tolerance) {
    const Eigen::MatrixXd g = lagged_gram(r, win);
    d = g.diagonal().cwiseMax(1e-300).cwiseSqrt().cwiseInverse();
    const Eigen::MatrixXd gs = d.asDiagonal() * g * d.asDiagonal();
    const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(gs);
    const Eigen::VectorXd lambda = eig.eigenvalues();
    const double cut = tolerance * lambda.maxCoeff();
    inv = Eigen::VectorXd::Zero(lambda.size());
    for (Eigen::Index k = 0; k < lambda.size(); ++k)
      if (lambda[k] > cut) {
        inv[k] = 1.0 / lambda[k];
        ++rank;
      }
    v = eig.eigenvectors();
  }

  // Coefficients (cols × p) for the outputs y (m × p, rows t0 … t1 used).
  Eigen::MatrixXd solve(const Eigen::MatrixXd& r, const Eigen::MatrixXd& y,
                        const Window& win) const {
    const Eigen::MatrixXd rhs = d.asDiagonal() * lagged_rhs(r, y, win);
    return d.asDiagonal() * (v * (inv.asDiagonal() * (v.transpose() * rhs)));
  }
};

// P·x on the window: the least-squares fit of x on the lagged references, evaluated.
class FirProjector : public SignalProjector {
 public:
  FirProjector(Eigen::MatrixXd r, const Window& win, double tolerance)
      : r_(std::move(r)), win_(win), solver_(r_, win_, tolerance) {}
  Eigen::MatrixXd project(const Eigen::Ref<const Eigen::MatrixXd>& x) const override {
    if (x.rows() != win_.len)
      throw Error("projection: " + std::to_string(x.rows()) +
                  " samples to project, the window has " + std::to_string(win_.len));
    Eigen::MatrixXd padded = Eigen::MatrixXd::Zero(r_.rows(), x.cols());
    padded.middleRows(win_.t0, win_.len) = x;
    const Eigen::MatrixXd coef = solver_.solve(r_, padded, win_);
    Eigen::MatrixXd out(win_.len, x.cols());
    for (Eigen::Index c = 0; c < x.cols(); ++c) out.col(c) = apply_fir(r_, coef.col(c), win_, true);
    return out;
  }
  int rank() const override { return solver_.rank; }
  Eigen::Index samples() const override { return win_.len; }
  // FIR coefficients of the outputs y (m × p over the whole run).
  Eigen::MatrixXd coefficients(const Eigen::MatrixXd& y) const {
    return solver_.solve(r_, y, win_);
  }

 private:
  Eigen::MatrixXd r_;
  Window win_;
  FirSolver solver_;
};

// Normalised correlations by FFT: out(τ) = Σ_t a(t)·b(t − τ) / (len·σ_a·σ_b), τ = −lags … lags,
// of centred a, b (size len).
Eigen::VectorXd correlation(const std::vector<std::complex<double>>& fa,
                            const std::vector<std::complex<double>>& fb, double norm, int lags,
                            Eigen::FFT<double>& fft) {
  std::vector<std::complex<double>> prod(fa.size());
  for (std::size_t k = 0; k < fa.size(); ++k) prod[k] = fa[k] * std::conj(fb[k]);
  std::vector<double> c;
  fft.inv(c, prod);
  const auto nfft = static_cast<long>(c.size());
  Eigen::VectorXd out(2 * lags + 1);
  for (int tau = -lags; tau <= lags; ++tau) out[tau + lags] = c[(tau + nfft) % nfft] / norm;
  return out;
}

struct Spectrum {
  std::vector<std::complex<double>> f;
  double norm;  // sqrt(Σ (x − mean)²)
};

Spectrum spectrum(const Eigen::Ref<const Eigen::VectorXd>& x, int nfft, Eigen::FFT<double>& fft) {
  std::vector<double> buf(nfft, 0.0);
  const double mean = x.mean();
  double ss = 0.0;
  for (Eigen::Index t = 0; t < x.size(); ++t) {
    buf[t] = x[t] - mean;
    ss += buf[t] * buf[t];
  }
  Spectrum s;
  fft.fwd(s.f, buf);
  s.norm = std::sqrt(ss);
  return s;
}

// Ljung (1999) §16.6 cross-correlation test of the torque remainder against every reference.
ProjectionTest remainder_test(const Eigen::MatrixXd& remainder, const Eigen::MatrixXd& r,
                              const Window& win, int lags, double significance) {
  const Eigen::Index nu = remainder.cols(), nr = r.cols(), len = win.len;
  int nfft = 1;
  while (nfft < 2 * len) nfft *= 2;
  Eigen::FFT<double> fft;
  std::vector<Spectrum> su, sr;
  for (Eigen::Index j = 0; j < nu; ++j) su.push_back(spectrum(remainder.col(j), nfft, fft));
  for (Eigen::Index i = 0; i < nr; ++i)
    sr.push_back(spectrum(r.col(i).segment(win.t0, len), nfft, fft));
  ProjectionTest test;
  test.m1 = win.m1;
  test.m2 = win.m2;
  const double count = static_cast<double>(nu * nr * (2 * lags + 1));
  test.threshold = boost::math::quantile(
      boost::math::complement(boost::math::normal(), significance / (2.0 * count)));
  for (Eigen::Index j = 0; j < nu; ++j) {
    if (!(su[j].norm > 0.0)) continue;  // an exact fit has nothing left to correlate
    const Eigen::VectorXd ru = correlation(su[j].f, su[j].f, su[j].norm * su[j].norm, lags, fft);
    for (Eigen::Index i = 0; i < nr; ++i) {
      const Eigen::VectorXd rr = correlation(sr[i].f, sr[i].f, sr[i].norm * sr[i].norm, lags, fft);
      const double p = std::max(ru.dot(rr), 1.0 / static_cast<double>(len));
      const Eigen::VectorXd cross =
          correlation(su[j].f, sr[i].f, su[j].norm * sr[i].norm, lags, fft);
      const double z = std::sqrt(static_cast<double>(len) / p) * cross.cwiseAbs().maxCoeff();
      test.max_z = std::max(test.max_z, z);
    }
  }
  test.passed = test.max_z <= test.threshold;
  return test;
}

void check_orders(int m1, int m2, Eigen::Index m, Eigen::Index n) {
  const Eigen::Index cols = n * (m1 + m2 + 1) + 1;
  if (m - m1 - m2 < 4 * cols) {
    throw Error("FIR orders M1 = " + std::to_string(m1) + ", M2 = " + std::to_string(m2) +
                " need at least " + std::to_string(4 * cols + m1 + m2) + " samples (" +
                std::to_string(cols) + " coefficients per signal, 4 rows each, plus the " +
                std::to_string(m1 + m2) + " window samples), but the run has " + std::to_string(m) +
                ": use smaller orders or a longer run");
  }
}

}  // namespace

ProjectionResult project_on_reference(const JointRecord& run,
                                      const Eigen::Ref<const Eigen::MatrixXd>& qr,
                                      const Eigen::Ref<const Eigen::MatrixXd>& dqr,
                                      const Eigen::Ref<const Eigen::MatrixXd>& ddqr,
                                      const ProjectionOptions& options) {
  const Eigen::Index m = run.t.size(), n = run.q.cols();
  if (qr.cols() == 0 || qr.rows() == 0)
    throw Error("projection needs the reference columns qr1..qr" + std::to_string(n) +
                " in the run: log the controller's reference (dynid simulate writes them)");
  auto check = [&](const Eigen::Ref<const Eigen::MatrixXd>& x, const std::string& name) {
    if (x.rows() != m || x.cols() != n)
      throw Error("projection: " + name + " is " + std::to_string(x.rows()) + "x" +
                  std::to_string(x.cols()) + " but the run is " + std::to_string(m) + "x" +
                  std::to_string(n) + " (samples x joints)");
    if (!x.allFinite()) throw Error("projection: " + name + " contains NaN or Inf");
  };
  check(run.q, "q");
  check(run.tau, "tau");
  check(qr, "qr");
  check(dqr, "dqr");
  check(ddqr, "ddqr");
  const SamplingInfo info = require_uniform_sampling(run.t, 1e-6, "the projection method");
  // A constant reference (a joint its controller holds: seed 2 section 3 moves one joint at a
  // time) lies in the span of the FIR's constant term at every lag: it adds no dimension, so the
  // FIR is fitted on the moving references alone, and the held joints' derivatives are taken as
  // zero below.
  std::vector<Eigen::Index> moving;
  std::vector<int> held;
  for (Eigen::Index i = 0; i < n; ++i) {
    const double mean = qr.col(i).mean();
    if ((qr.col(i).array() - mean).abs().maxCoeff() <= 1e-12 * std::max(1.0, std::abs(mean)))
      held.push_back(static_cast<int>(i));
    else
      moving.push_back(i);
  }
  if (moving.empty())
    throw Error("every reference qr1..qr" + std::to_string(n) +
                " is constant: the run excites nothing; move at least one joint");
  const auto nm = static_cast<Eigen::Index>(moving.size());
  if ((options.m1 < 0) != (options.m2 < 0) || options.m1 < -1 || options.m2 < -1)
    throw Error("FIR orders must be both given (M1, M2 >= 0) or both chosen (-1), got M1 = " +
                std::to_string(options.m1) + ", M2 = " + std::to_string(options.m2));
  if (!(options.significance > 0.0 && options.significance < 1.0))
    throw Error("projection significance must be in (0, 1), got " +
                short_number(options.significance));
  if (options.min_rank < 0)
    throw Error("projection min_rank must be >= 0, got " + std::to_string(options.min_rank));

  Eigen::MatrixXd r(m, nm), dr(m, nm), ddr(m, nm), u(m, 2 * n);
  for (Eigen::Index c = 0; c < nm; ++c) {
    r.col(c) = qr.col(moving[static_cast<size_t>(c)]);
    dr.col(c) = dqr.col(moving[static_cast<size_t>(c)]);
    ddr.col(c) = ddqr.col(moving[static_cast<size_t>(c)]);
  }
  u << run.tau, run.q;
  ProjectionResult out;
  out.held_joints = held;
  auto lags_for = [&](const Window& win) {
    const int wanted =
        options.test_lags > 0 ? options.test_lags : std::max(100, 3 * std::max(win.m1, win.m2));
    return static_cast<int>(std::max<Eigen::Index>(1, std::min<Eigen::Index>(wanted, win.len / 4)));
  };
  // One FIR order: the projector, the coefficients of every output and the remainder's test.
  auto fit = [&](int m1, int m2, std::shared_ptr<FirProjector>& projector, Eigen::MatrixXd& coef) {
    const Window w = window_for(m1, m2, m);
    projector = std::make_shared<FirProjector>(r, w, options.rank_tolerance);
    coef = projector->coefficients(u);
    Eigen::MatrixXd rem(w.len, n);
    for (Eigen::Index j = 0; j < n; ++j)
      rem.col(j) = u.col(j).segment(w.t0, w.len) - apply_fir(r, coef.col(j), w, true);
    out.tests.push_back(remainder_test(rem, r, w, lags_for(w), options.significance));
    return w;
  };
  Eigen::MatrixXd coef;
  Window win{};
  std::shared_ptr<FirProjector> projector;
  if (options.m1 >= 0) {
    check_orders(options.m1, options.m2, m, nm);
    win = fit(options.m1, options.m2, projector, coef);
  } else {
    if (options.max_order < 2) throw Error("projection max_order must be >= 2");
    // Past max_order only while the reference's dimensions are not all kept (the loop below
    // stops at the run's length).
    std::vector<int> orders = {2, 4, 8, 12, 16, 24, 32, 48, 64, 96, 128};
    for (int k = 192; k <= std::max<Eigen::Index>(options.max_order, m / 2); k = k * 3 / 2)
      orders.push_back(k);
    check_orders(orders.front(), orders.front(), m, nm);
    // The smallest order that keeps every dimension the reference spans (options.min_rank: a
    // shorter FIR drops lines of the excitation, and with them the information they carry) and
    // whose remainder no longer correlates with the reference.
    for (int k : orders) {
      if (m - 2 * k < 4 * (nm * (2 * k + 1) + 1)) break;  // the run is too short for this order
      if (k > options.max_order && (!projector || projector->rank() >= options.min_rank)) break;
      win = fit(k, k, projector, coef);
      if (out.tests.back().passed && projector->rank() >= options.min_rank) break;
    }
    if (projector->rank() < options.min_rank) {
      out.warnings.push_back(
          "the projection's FIR keeps " + std::to_string(projector->rank()) + " of the " +
          std::to_string(options.min_rank) +
          " dimensions the reference spans (M1 = M2 = " + std::to_string(win.m1) +
          ", the largest tried): the dropped lines carry no information into "
          "the estimate; record a longer run or use --closed-loop spectral");
    }
  }
  const ProjectionTest& test = out.tests.back();
  if (!test.passed) {
    out.warnings.push_back(
        "the torque remainder of the projection still correlates with the reference (max |z| " +
        short_number(test.max_z) + " > " + short_number(test.threshold) +
        " at M1 = " + std::to_string(win.m1) + ", M2 = " + std::to_string(win.m2) +
        (options.m1 >= 0 ? ", given" : ", the largest tried") +
        "): the FIR misses part of the loop's response to the reference, and the projected "
        "torques with it; " +
        (options.m1 >= 0 ? "give larger orders with --fir or leave them to the automatic choice"
                         : "record a longer run"));
  }
  // The coefficients in the documented layout: one block of rows per reference, zero for the
  // held ones.
  const Eigen::Index width = win.w;
  Eigen::MatrixXd fir = Eigen::MatrixXd::Zero(n * width + 1, 2 * n);
  for (Eigen::Index c = 0; c < nm; ++c)
    fir.middleRows(moving[static_cast<size_t>(c)] * width, width) =
        coef.middleRows(c * width, width);
  fir.row(n * width) = coef.row(nm * width);
  out.m1 = win.m1;
  out.m2 = win.m2;
  out.fir = std::move(fir);
  out.projector = projector;

  JointRecord& rec = out.processed.record;
  rec.t = run.t.segment(win.t0, win.len);
  rec.tau.resize(win.len, n);
  rec.q.resize(win.len, n);
  rec.dq.resize(win.len, n);
  rec.ddq.resize(win.len, n);
  out.correlation.resize(n);
  out.torque_remainder_std.resize(n);
  out.processed.position_noise_std.resize(n);
  out.processed.velocity_noise_std = Eigen::VectorXd::Zero(n);
  for (Eigen::Index j = 0; j < n; ++j) {
    rec.tau.col(j) = apply_fir(r, coef.col(j), win, true);
    rec.q.col(j) = apply_fir(r, coef.col(n + j), win, true);
    rec.dq.col(j) = apply_fir(dr, coef.col(n + j), win, false);
    rec.ddq.col(j) = apply_fir(ddr, coef.col(n + j), win, false);
    const Eigen::VectorXd ut = u.col(j).segment(win.t0, win.len) - rec.tau.col(j);
    const Eigen::VectorXd qt = u.col(n + j).segment(win.t0, win.len) - rec.q.col(j);
    const Eigen::VectorXd uc = rec.tau.col(j).array() - rec.tau.col(j).mean();
    const double denom = uc.norm() * ut.norm();
    out.correlation[j] = denom > 0.0 ? uc.dot(ut) / denom : 0.0;
    out.torque_remainder_std[j] = std::sqrt(ut.squaredNorm() / static_cast<double>(win.len));
    out.processed.position_noise_std[j] =
        std::sqrt(qt.squaredNorm() / static_cast<double>(win.len));
  }
  // A held joint's projected motion is its tracking error's response to the moving references,
  // not excitation: taken as still (as the spectral preparation and identify's still joints do),
  // so that its armature and friction columns do not look excited.
  for (int j : held) {
    rec.dq.col(j).setZero();
    rec.ddq.col(j).setZero();
  }
  out.processed.rate_hz = info.rate_hz();
  return out;
}

}  // namespace dynid
