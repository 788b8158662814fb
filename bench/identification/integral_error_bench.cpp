// Item 5 of issue 11, second study: where the integral model's error on noisy closed-loop data
// comes from, and what removes it. Same runs as integral_study_bench (puma560, native RK4 plant,
// PID + computed-torque feed-forward at 1 kHz, encoder noise 1e-4 rad, torque noise 0.05 N·m).
// The equations of run A are built twice on the same intervals: from the processed (filtered)
// record and from the true states with the held torque's exact work. Swapping one side at a
// time (y, the energy columns, the friction columns) between the two attributes the error; the
// printed figure is each estimate's torque-prediction error on run B (validate_torques). Then the
// treatments for correlated rows and errors in the regressor on the processed equations: AR(1)
// prewhitening, MA(1) GLS (the shared end points of adjacent intervals), instrumental variables.
// Not a benchmark: its table is in docs/methods/identification.md ("Integral model").
// Run: ./build/bench/integral_error_bench [position-noise-scale [torque-noise-scale [after]]]
// (after = 1: encoder noise added to the log of a run with exact feedback, no jitter);
// ./build/bench/integral_error_bench window [after]: endpoint-velocity window study;
// ./build/bench/integral_error_bench tx40 [source-dir]: the same on the real TX40 run;
// ./build/bench/integral_error_bench eiv [Tf-ms [after [noise-seed]]]: runs made with the PID's
// derivative filtered with time constant Tf (default 1 ms), defaults, best settings and the
// errors-in-variables treatments of the kinetic-energy columns;
// ./build/bench/integral_error_bench eiv-tx40 [source-dir]: those treatments on the TX40 run.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>
#include <Eigen/SVD>

#include "../../tests/identification/integral_support.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/integral_equations.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/energy_regressor.hpp"

namespace {

using namespace dynid;

double g_noise = 1.0, g_torque_noise = 1.0;
// 1: the encoder noise is added to the log after a run with exact position feedback, so the true
// motion carries no jitter from the controller's reaction to the noise.
bool g_after = false;

// PID derivative filter time constant Tf [s] of the simulated runs (PidOptions), and an offset
// to the sensor-noise seed (the reference stays the same).
double g_derivative_filter = 1e-3;
unsigned g_noise_seed = 0;

ClosedLoopResult run(const Model& model, unsigned seed, double ts) {
  SensorOptions so;
  so.position_noise_std = g_after ? 0.0 : 1e-4 * g_noise;
  so.torque_noise_std = 0.05 * g_torque_noise;
  so.seed = seed + g_noise_seed;
  ClosedLoopResult r = integral_testing::simulate(
      model, integral_testing::multisine(model.dof(), 10.0, ts, seed, 1.0), ts, so, PlantOptions{},
      2, g_derivative_filter);
  if (g_after) {
    std::mt19937 rng(seed + 100 + g_noise_seed);
    std::normal_distribution<double> normal(0.0, 1e-4 * g_noise);
    for (Eigen::Index k = 0; k < r.q.size(); ++k) r.q.data()[k] += normal(rng);
  }
  return r;
}

// The puma560 of the studies, with friction Ia, Fv, Fc, Fo on every joint.
Model puma_with_friction() {
  Model model = load_robot("puma560");
  for (int j = 0; j < model.dof(); ++j) {
    model.joints[j].friction = {0.05 * (j + 1), 0.5 + 0.1 * j, 0.3 + 0.1 * j, 0.1 * (j + 1)};
  }
  return model;
}

// The record processed as integral_signal_options() does, at another cut-off [Hz].
ProcessedRecord processed_at(const JointRecord& record, double cutoff) {
  SignalOptions so = integral_signal_options();
  so.cutoff_hz = cutoff;
  std::vector<std::pair<std::string, std::string>> choices;
  return preprocess(record, so, choices);
}

// Of the TX40's 12 joint friction values (Fv_j, Fc_j) in the estimate x of `base`, how many are
// within 10 % of the published ones, and the largest relative error.
std::pair<int, double> tx40_friction_score(const integral_testing::Tx40Run& run,
                                           const BaseParameters& base, const Eigen::VectorXd& x) {
  int within = 0;
  double worst = 0.0;
  for (int j = 0; j < 6; ++j) {
    for (const char* kind : {"v", "c"}) {
      const std::string name = std::string("F") + kind + std::to_string(j + 1);
      const double truth = run.published[kind[0] == 'v' ? "fv" : "fs"][j].as<double>();
      const Eigen::Index i =
          std::find(base.names.begin(), base.names.end(), name) - base.names.begin();
      const double err = std::abs(x[i] - truth) / truth;
      within += err <= 0.1;
      worst = std::max(worst, err);
    }
  }
  return {within, worst};
}

// Rows [first, first + m) of the true run as a processed record.
ProcessedRecord truth_rows(const ClosedLoopResult& r, Eigen::Index first, Eigen::Index m,
                           double ts) {
  ProcessedRecord p;
  p.record.t = r.t.segment(first, m);
  p.record.q = r.q_true.middleRows(first, m);
  p.record.dq = r.dq_true.middleRows(first, m);
  p.record.tau = r.tau_true.middleRows(first, m);
  p.rate_hz = 1.0 / ts;
  return p;
}

// Run A identified with the differential model (identify's defaults, the logged torque held for
// one step) and the torque-prediction error [%] on run B of any base-parameter estimate (−1 for
// none or a non-finite one); the constructor prints the differential model's and the truth's.
class PredictionOnB {
 public:
  PredictionOnB(const Model& model, const ClosedLoopResult& ra, const ClosedLoopResult& rb,
                double ts)
      : model_(model), a_{ra.t, ra.q, {}, {}, ra.tau}, b_{rb.t, rb.q, {}, {}, rb.tau} {
    def_.signal.torque_time_offset = 0.5 * ts;
    diff_ = identify(model, a_, def_);
    std::printf("differential %.2f %%, truth %.3f %%\n", (*this)(diff_.estimate.x),
                (*this)(base().reduce(def_.layout.parameters(model))));
  }
  double operator()(const Eigen::VectorXd& x) const {
    if (x.size() == 0 || !x.allFinite()) return -1.0;
    return 100 * validate_torques(model_, b_, base().names, x, def_).relative_error_all;
  }
  const IdentifyOptions& options() const { return def_; }
  const BaseParameters& base() const { return diff_.base; }
  const JointRecord& a() const { return a_; }

 private:
  const Model& model_;
  JointRecord a_, b_;
  IdentifyOptions def_;
  IdentificationResult diff_;
};

// Third study: the velocity of the kinetic-energy columns at the interval ends from a local
// quadratic fit of the processed positions (IntegralOptions::endpoint_window), over cut-offs and
// intervals; torque-prediction error on run B.
int endpoint_window_study(const Model& model, const ClosedLoopResult& ra,
                          const ClosedLoopResult& rb, double ts) {
  const PredictionOnB err_b(model, ra, rb, ts);
  const IdentifyOptions& def = err_b.options();
  const BaseParameters& base = err_b.base();
  const JointRecord& a = err_b.a();
  std::printf("cutoff interval | endpoint window [ms]: 0 5 10 25 50 100\n");
  for (double cutoff : {5.0, 10.0, 20.0, 40.0}) {
    SignalOptions so = def.signal;
    so.cutoff_hz = cutoff;
    so.decimate = 1;
    std::vector<std::pair<std::string, std::string>> choices;
    const ProcessedRecord p = preprocess(a, so, choices);
    for (double interval_ms : {10.0, 50.0, 100.0}) {
      std::printf("%5.0f %5.0f |", cutoff, interval_ms);
      for (double window_ms : {0.0, 5.0, 10.0, 25.0, 50.0, 100.0}) {
        IntegralOptions io;
        io.interval = 1e-3 * interval_ms;
        io.endpoint_window = 1e-3 * window_ms;
        const EquationBlock f = integral_equations(model, def.layout, false, p, io);
        std::printf(" %7.2f", err_b(ordinary_least_squares(base.select(f.W), f.y).x));
      }
      std::printf("\n");
    }
  }
  return 0;
}

// The errors-in-variables treatments on the TX40 run (below).
int eiv_tx40(const integral_testing::Tx40Run& run, const BaseParameters& base);

// The same grid on the real TX40 run: joint friction values within 10 % of the published ones
// (of 12), the largest friction error, the torque validation on the run and the energy
// equations' relative error; for the defaults, every friction value with its 99.9 % interval.
// With `eiv`, the errors-in-variables treatments instead (eiv_tx40).
int tx40_study(const std::string& source_dir, bool eiv) {
  const integral_testing::Tx40Run run = integral_testing::load_tx40(source_dir);
  if (!run.found) {
    std::printf("TX40 data set not found\n");
    return 1;
  }
  const Model& model = run.model;
  IdentifyOptions def;
  const BaseParameters base = integral_testing::base_of(model, def.layout, true);
  if (eiv) return eiv_tx40(run, base);
  const IdentificationResult diff = identify(model, run.record);
  std::printf(
      "differential: torque %.2f %%\n",
      100 *
          validate_torques(model, run.record, diff.names, diff.estimate.x, def).relative_error_all);
  auto index = [&](const std::string& name) {
    return std::find(base.names.begin(), base.names.end(), name) - base.names.begin();
  };
  {
    // Control: the integral model on torques that a rigid model explains exactly — the
    // differential estimate's prediction on the integral processing's own states (filtered
    // Coulomb columns included). What it recovers is the differential estimate, less the part
    // of the error that comes from the energy equations themselves.
    std::vector<std::pair<std::string, std::string>> choices;
    Eigen::VectorXd x_diff(base.names.size());
    for (size_t i = 0; i < base.names.size(); ++i) {
      const auto it = std::find(diff.names.begin(), diff.names.end(), base.names[i]);
      x_diff[i] = it == diff.names.end() ? 0.0 : diff.estimate.x[it - diff.names.begin()];
    }
    const ProcessedRecord p = integral_testing::with_model_torques(
        model, def.layout, true, base, x_diff,
        preprocess(run.record, integral_signal_options(), choices));
    const Estimate e = integral_testing::estimate_with_intervals(
        integral_equations(model, def.layout, true, p, IntegralOptions{}), base);
    std::printf("integral model on the differential model's torques (energy error %.3f %%):\n",
                100 * e.relative_error);
    for (int j = 0; j < 6; ++j) {
      for (const char* kind : {"Fv", "Fc"}) {
        const std::string name = kind + std::to_string(j + 1);
        const Eigen::Index i = index(name);
        std::printf("    %s %.3f (differential %.3f)\n", name.c_str(), e.x[i], x_diff[i]);
      }
    }
  }
  std::printf("cutoff interval window | within10 maxerr%% torque%% energy%%\n");
  for (double cutoff : {10.0, 20.0, 40.0}) {
    const ProcessedRecord p = processed_at(run.record, cutoff);
    for (double interval_ms : {10.0, 50.0}) {
      for (double window_ms : {0.0, 10.0, 25.0, 50.0, 100.0}) {
        IntegralOptions io;
        io.interval = 1e-3 * interval_ms;
        io.endpoint_window = 1e-3 * window_ms;
        const Estimate e = integral_testing::estimate_with_intervals(
            integral_equations(model, def.layout, true, p, io), base);
        const auto [within, worst] = tx40_friction_score(run, base, e.x);
        const bool detail = cutoff == 10.0 && interval_ms == 10.0;
        for (int j = 0; j < 6 && detail; ++j) {
          for (const char* kind : {"v", "c"}) {
            const std::string name = std::string("F") + kind + std::to_string(j + 1);
            const double truth = run.published[kind[0] == 'v' ? "fv" : "fs"][j].as<double>();
            const Eigen::Index i = index(name);
            std::printf("    %s %.3f [%.3f, %.3f] published %.3f%s\n", name.c_str(), e.x[i],
                        e.ci_lower[i], e.ci_upper[i], truth,
                        truth >= e.ci_lower[i] && truth <= e.ci_upper[i] ? "" : "  OUTSIDE");
          }
        }
        const double torque =
            validate_torques(model, run.record, base.names, e.x, def).relative_error_all;
        std::printf("%5.0f %5.0f %5.0f | %2d %7.1f %7.2f %7.2f\n", cutoff, interval_ms, window_ms,
                    within, 100 * worst, 100 * torque, 100 * e.relative_error);
      }
    }
  }
  return 0;
}

// ---- Errors-in-variables study (issue 11 item 5): the kinetic-energy columns carry the
// processed velocity's noise at the interval ends, e_a and e_b: a row's error there is
// δw = J_bᵀe_b − J_aᵀe_a, J = ∂h/∂q̇ (n × columns), so E[WᵀW] = W₀ᵀW₀ + Σ_r E[δw_r δw_rᵀ] and OLS
// is biased (attenuated) in the directions the noise covers.

std::string format_row(const Eigen::MatrixXd& v) {
  std::string out;
  char buf[32];
  for (Eigen::Index i = 0; i < v.size(); ++i) {
    std::snprintf(buf, sizeof buf, " %.3g", v.data()[i]);
    out += buf;
  }
  return out;
}

// ∂h/∂q̇ (n × cols, zero beyond the energy row's columns) of the energy row at (q, v); h is
// quadratic in q̇, so central differences are exact up to round-off.
Eigen::MatrixXd velocity_jacobian(const Model& model, Workspace& ws, const ParameterLayout& layout,
                                  Eigen::Index cols, const Eigen::VectorXd& q,
                                  const Eigen::VectorXd& v) {
  const int n = model.dof(), p = layout.columns(n);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(n, cols);
  Eigen::VectorXd hp(p), hm(p), w = v;
  for (int j = 0; j < n; ++j) {
    const double d = 1e-3 * (1.0 + std::abs(v[j]));
    w[j] = v[j] + d;
    energy_regressor(model, ws, layout, q, w, hp);
    w[j] = v[j] - d;
    energy_regressor(model, ws, layout, q, w, hm);
    w[j] = v[j];
    J.row(j).head(p) = (hp - hm).transpose() / (2 * d);
  }
  return J;
}

// Per joint, the variance of the processed velocity's noise and its correlation at every lag up
// to max_lag, from white position noise of the record's measured std passed through the same
// processing (preprocess is linear in q; its trim is kept).
struct VelocityNoise {
  Eigen::VectorXd variance;     // n
  Eigen::MatrixXd correlation;  // (max_lag + 1) × n
};

VelocityNoise velocity_noise(const JointRecord& raw, const SignalOptions& so,
                             const ProcessedRecord& p, Eigen::Index max_lag) {
  const Eigen::Index m = raw.t.size();
  const int n = static_cast<int>(raw.q.cols());
  std::mt19937 rng(77);
  std::normal_distribution<double> normal;
  JointRecord noise{raw.t, Eigen::MatrixXd(m, n), {}, {}, Eigen::MatrixXd::Zero(m, n)};
  for (int j = 0; j < n; ++j) {
    const double s = p.position_noise_std.size() == n ? p.position_noise_std[j] : 0.0;
    for (Eigen::Index k = 0; k < m; ++k) noise.q(k, j) = s * normal(rng);
  }
  SignalOptions o = so;
  o.trim = p.trim;
  std::vector<std::pair<std::string, std::string>> choices;
  const Eigen::MatrixXd e = preprocess(noise, o, choices).record.dq;
  VelocityNoise out;
  out.variance = e.colwise().squaredNorm().transpose() / static_cast<double>(e.rows());
  out.correlation.setZero(max_lag + 1, n);
  for (int j = 0; j < n; ++j) {
    const double v = e.col(j).squaredNorm();
    for (Eigen::Index l = 0; l <= max_lag && v > 0.0; ++l)
      out.correlation(l, j) = e.col(j).tail(e.rows() - l).dot(e.col(j).head(e.rows() - l)) / v;
  }
  return out;
}

// Ratio of the endpoint-momentum-weighted row to the unweighted one (the default weights), and
// the unweighted block.
Eigen::VectorXd default_row_weights(const Model& model, const ParameterLayout& layout,
                                    bool coupling, const ProcessedRecord& p, IntegralOptions io,
                                    EquationBlock& unweighted) {
  io.weighting = IntegralWeighting::kNone;
  unweighted = integral_equations(model, layout, coupling, p, io);
  io.weighting = IntegralWeighting::kEndpointMomentum;
  const EquationBlock w = integral_equations(model, layout, coupling, p, io);
  Eigen::VectorXd weight(w.y.size());
  for (Eigen::Index i = 0; i < weight.size(); ++i) {
    const double d = unweighted.W.row(i).norm();
    weight[i] = d > 0.0 ? w.W.row(i).norm() / d : 1.0;
  }
  return weight;
}

// Solves A x = b for the normal-type matrix A of base columns scaled to unit diagonal.
Eigen::VectorXd scaled_solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b,
                             const Eigen::VectorXd& scale) {
  const Eigen::MatrixXd As = scale.asDiagonal() * A * scale.asDiagonal();
  return scale.asDiagonal() * As.colPivHouseholderQr().solve(scale.asDiagonal() * b);
}

struct EivEstimates {
  Eigen::VectorXd ols, bcls, iv_lag, iv_ref;
  double rho_interval = 0.0;  // velocity-noise correlation at one interval (largest joint)
  double rho_lag = 0.0;       // at the instruments' lag
  Eigen::Index lag_rows = 0;
  double attenuation = 0.0;   // largest eigenvalue of (WᵀW)⁻¹·B, scaled: the bias' size
  Eigen::VectorXd noise_std;  // per joint, the modelled processed-velocity noise std
};

// OLS, bias-compensated LS (B = Σ_r E[δw_r δw_rᵀ] from the velocity noise model), IV with the
// energy columns of the intervals `lag_rows` later (earlier at the end; the lag is the first at
// which every joint's velocity-noise correlation is below 0.05), and IV with the energy columns
// from the reference (`reference`, when not null: the same intervals, q = qr, q̇ = q̇r), on the
// endpoint-momentum-weighted block.
EivEstimates eiv_estimates(const Model& model, const ParameterLayout& layout, bool coupling,
                           const BaseParameters& base, const JointRecord& raw,
                           const SignalOptions& so, const ProcessedRecord& p,
                           const IntegralOptions& io, const ProcessedRecord* reference,
                           const Eigen::MatrixXd* true_dq = nullptr) {
  const int n = model.dof();
  const JointRecord& r = p.record;
  const Eigen::Index m = r.t.size();
  const double step = (r.t[m - 1] - r.t[0]) / static_cast<double>(m - 1);
  const Eigen::Index steps = std::max<Eigen::Index>(1, std::llround(io.interval / step));
  EquationBlock f;
  const Eigen::VectorXd weight = default_row_weights(model, layout, coupling, p, io, f);
  const Eigen::Index rows = f.y.size(), cols = f.W.cols();
  const Eigen::Index friction_begin = kLinkParams * n;
  const Eigen::MatrixXd Wb = base.select(weight.asDiagonal() * f.W);
  const Eigen::VectorXd yb = weight.cwiseProduct(f.y);
  const Eigen::VectorXd scale = Wb.colwise().norm().cwiseInverse().transpose();
  EivEstimates out;
  out.ols = ordinary_least_squares(Wb, yb).x;

  const VelocityNoise noise = velocity_noise(raw, so, p, std::min<Eigen::Index>(m / 4, 2000));
  out.rho_interval =
      noise.correlation.row(std::min(steps, noise.correlation.rows() - 1)).maxCoeff();
  out.noise_std = noise.variance.cwiseSqrt();
  // Bias-compensated LS: per joint e_a = s·z₁, e_b = s·(ρz₁ + √(1−ρ²)z₂), so δw has the two
  // independent parts s(ρJ_b − J_a)ᵀz₁ and s√(1−ρ²)J_bᵀz₂.
  Workspace ws(model);
  Eigen::MatrixXd B = Eigen::MatrixXd::Zero(cols, cols), B_actual = B;
  Eigen::MatrixXd Ja =
      velocity_jacobian(model, ws, layout, cols, r.q.row(0).transpose(), r.dq.row(0).transpose());
  for (Eigen::Index i = 0; i < rows; ++i) {
    const Eigen::Index b = (i + 1) * steps;
    const Eigen::MatrixXd Jb =
        velocity_jacobian(model, ws, layout, cols, r.q.row(b).transpose(), r.dq.row(b).transpose());
    for (int j = 0; j < n; ++j) {
      const double s = std::sqrt(noise.variance[j]) * weight[i];
      const double rho = noise.correlation(std::min(steps, noise.correlation.rows() - 1), j);
      const Eigen::RowVectorXd d1 = s * (rho * Jb.row(j) - Ja.row(j));
      const Eigen::RowVectorXd d2 = s * std::sqrt(std::max(0.0, 1 - rho * rho)) * Jb.row(j);
      B.noalias() += d1.transpose() * d1 + d2.transpose() * d2;
    }
    if (true_dq != nullptr) {
      // The same second moment from the record's actual velocity error at the two ends.
      const Eigen::Index a = i * steps;
      const Eigen::RowVectorXd d =
          weight[i] * ((r.dq.row(b) - true_dq->row(b)) * Jb - (r.dq.row(a) - true_dq->row(a)) * Ja);
      B_actual.noalias() += d.transpose() * d;
    }
    Ja = Jb;
  }
  const Eigen::MatrixXd Bb = base.select(base.select(B).transpose());
  const Eigen::MatrixXd N = Wb.transpose() * Wb;
  out.bcls = scaled_solve(N - Bb, Wb.transpose() * yb, scale);
  {
    const Eigen::MatrixXd Ns = scale.asDiagonal() * N * scale.asDiagonal();
    const Eigen::MatrixXd Bs = scale.asDiagonal() * Bb * scale.asDiagonal();
    Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> es(Bs, Ns);
    out.attenuation = es.eigenvalues().maxCoeff();
    if (true_dq != nullptr) {
      const Eigen::MatrixXd Ba =
          scale.asDiagonal() * base.select(base.select(B_actual).transpose()) * scale.asDiagonal();
      Eigen::GeneralizedSelfAdjointEigenSolver<Eigen::MatrixXd> ea(Ba, Ns);
      const Eigen::VectorXd v = es.eigenvectors().col(es.eigenvalues().size() - 1);
      std::printf(
          "  actual endpoint error: largest eigenvalue %.3g; along the modelled top "
          "direction %.3g (modelled %.3g); trace ratio actual/modelled %.3g\n",
          ea.eigenvalues().maxCoeff(), v.dot(Ba * v) / v.dot(Ns * v), v.dot(Bs * v) / v.dot(Ns * v),
          Ba.trace() / Bs.trace());
    }
    // The classical attenuation per column (B/N on the diagonal): about 1e-5 on the puma560 runs.
  }
  // Lagged instruments.
  Eigen::Index lag = 1;
  while (lag < noise.correlation.rows() && noise.correlation.row(lag).cwiseAbs().maxCoeff() >= 0.05)
    ++lag;
  out.rho_lag = noise.correlation.row(std::min(lag, noise.correlation.rows() - 1)).maxCoeff();
  out.lag_rows = (lag + steps - 1) / steps;
  if (out.lag_rows < rows) {
    Eigen::MatrixXd Z = f.W;
    for (Eigen::Index i = 0; i < rows; ++i) {
      const Eigen::Index src = i + out.lag_rows < rows ? i + out.lag_rows : i - out.lag_rows;
      Z.row(i).head(friction_begin) = f.W.row(src).head(friction_begin);
    }
    const Eigen::MatrixXd Zb = base.select(weight.asDiagonal() * Z);
    out.iv_lag = scaled_solve(Zb.transpose() * Wb, Zb.transpose() * yb, scale);
  }
  if (reference != nullptr) {
    IntegralOptions ro = io;
    ro.weighting = IntegralWeighting::kNone;
    const EquationBlock z = integral_equations(model, layout, coupling, *reference, ro);
    Eigen::MatrixXd Z = f.W;
    Z.leftCols(friction_begin) = z.W.leftCols(friction_begin);
    const Eigen::MatrixXd Zb = base.select(weight.asDiagonal() * Z);
    out.iv_ref = scaled_solve(Zb.transpose() * Wb, Zb.transpose() * yb, scale);
  }
  return out;
}

// Runs with the PID's derivative filtered at Tf: the torque noise the controller adds, the
// differential model, the integral model at its defaults and over a grid, and the
// errors-in-variables treatments; torque-prediction error on run B.
int eiv_study(double tf) {
  g_derivative_filter = tf;
  const Model model = puma_with_friction();
  const double ts = 1e-3;
  const int n = model.dof();
  const ClosedLoopResult ra = run(model, 1, ts), rb = run(model, 2, ts);
  {
    // The torque the controller adds in reaction to the noise: the same run without noise.
    SensorOptions quiet;
    quiet.seed = 1 + g_noise_seed;
    const ClosedLoopResult r0 = integral_testing::simulate(
        model, integral_testing::multisine(n, 10.0, ts, 1, 1.0), ts, quiet, PlantOptions{}, 2, tf);
    const Eigen::MatrixXd d = ra.tau_true - r0.tau_true;
    const Eigen::MatrixXd dv = ra.dq_true - r0.dq_true;
    std::printf(
        "Tf %.1f ms%s: torque from the noise %.3f N·m rms (per joint max %.3f), "
        "velocity jitter %.4f rad/s rms\n",
        1e3 * tf, g_after ? " (noise added after the run)" : "",
        std::sqrt(d.squaredNorm() / d.size()),
        (d.colwise().squaredNorm() / d.rows()).cwiseSqrt().maxCoeff(),
        std::sqrt(dv.squaredNorm() / dv.size()));
  }
  const PredictionOnB err_b(model, ra, rb, ts);
  const IdentifyOptions& def = err_b.options();
  const BaseParameters& base = err_b.base();
  const JointRecord& a = err_b.a();
  const Reference ref = integral_testing::multisine(n, 10.0, ts, 1, 1.0);
  std::printf(
      "cutoff interval | OLS  window25  | BCLS  IV(lagged)  IV(reference) | rho(interval) "
      "lag[rows] rho(lag) attenuation\n");
  for (double cutoff : {5.0, 10.0, 20.0, 40.0}) {
    SignalOptions so = integral_signal_options();
    so.cutoff_hz = cutoff;
    so.torque_time_offset = 0.5 * ts;
    std::vector<std::pair<std::string, std::string>> choices;
    const ProcessedRecord p = preprocess(a, so, choices);
    const Eigen::Index first = std::llround((p.record.t[0] - ra.t[0]) / ts);
    ProcessedRecord rp;
    rp.record.t = p.record.t;
    rp.record.q = ra.qr.middleRows(first, p.record.t.size());
    rp.record.dq.resize(p.record.t.size(), n);
    for (Eigen::Index k = 0; k < p.record.t.size(); ++k)
      rp.record.dq.row(k) = ref.dq.row((first + k) % ref.dq.rows());
    rp.record.tau.setZero(p.record.t.size(), n);
    rp.rate_hz = p.rate_hz;
    for (double interval_ms : {10.0, 50.0}) {
      IntegralOptions io;
      io.interval = 1e-3 * interval_ms;
      const Eigen::MatrixXd true_dq = ra.dq_true.middleRows(first, p.record.t.size());
      const EivEstimates e =
          eiv_estimates(model, def.layout, false, base, a, so, p, io, &rp, &true_dq);
      {
        // The model of the velocity noise against the processed record's actual error.
        const Eigen::MatrixXd err = p.record.dq - ra.dq_true.middleRows(first, p.record.t.size());
        const Eigen::Index steps = std::llround(io.interval / ts);
        std::printf(
            "  noise std: modelled %s\n  identify's %s\n  actual %s\n  actual rho %s\n",
            format_row(e.noise_std).c_str(), format_row(p.velocity_noise_std).c_str(),
            format_row((err.colwise().squaredNorm() / err.rows()).cwiseSqrt()).c_str(),
            format_row(
                (err.bottomRows(err.rows() - steps).cwiseProduct(err.topRows(err.rows() - steps)))
                    .colwise()
                    .sum()
                    .cwiseQuotient(err.colwise().squaredNorm()))
                .c_str());
      }
      IntegralOptions wo = io;
      wo.endpoint_window = 0.025;
      const EquationBlock w = integral_equations(model, def.layout, false, p, wo);
      std::printf("%5.0f %5.0f | %7.2f %7.2f | %7.2f %7.2f %7.2f | %.3f %3ld %.3f %.3g\n", cutoff,
                  interval_ms, err_b(e.ols), err_b(ordinary_least_squares(base.select(w.W), w.y).x),
                  err_b(e.bcls), err_b(e.iv_lag), err_b(e.iv_ref), e.rho_interval,
                  static_cast<long>(e.lag_rows), e.rho_lag, e.attenuation);
      std::fflush(stdout);
    }
  }
  return 0;
}

// The same treatments on the TX40 run (no reference: OLS, BCLS, lagged IV): friction values
// within 10 % of the published 12, the largest error, the torque validation.
int eiv_tx40(const integral_testing::Tx40Run& run, const BaseParameters& base) {
  const Model& model = run.model;
  const IdentifyOptions def;
  auto score = [&](const Eigen::VectorXd& x) {
    if (x.size() == 0 || !x.allFinite()) {
      std::printf("  —              ");
      return;
    }
    const auto [within, worst] = tx40_friction_score(run, base, x);
    std::printf("  %2d %6.1f %6.2f", within, 100 * worst,
                100 * validate_torques(model, run.record, base.names, x, def).relative_error_all);
  };
  std::printf(
      "cutoff interval | OLS | BCLS | IV(lagged): within10 maxerr%% torque%% | rho(interval)"
      " lag[rows] attenuation\n");
  for (double cutoff : {10.0, 20.0, 40.0}) {
    SignalOptions so = integral_signal_options();
    so.cutoff_hz = cutoff;
    const ProcessedRecord p = processed_at(run.record, cutoff);
    for (double interval_ms : {10.0, 50.0}) {
      IntegralOptions io;
      io.interval = 1e-3 * interval_ms;
      const EivEstimates e =
          eiv_estimates(model, def.layout, true, base, run.record, so, p, io, nullptr);
      std::printf("%5.0f %5.0f |", cutoff, interval_ms);
      score(e.ols);
      score(e.bcls);
      score(e.iv_lag);
      std::printf(" | %.3f %ld %.3g\n", e.rho_interval, static_cast<long>(e.lag_rows),
                  e.attenuation);
      std::fflush(stdout);
    }
  }
  return 0;
}
}  // namespace

int main(int argc, char** argv) {
  if (argc > 1 && std::string(argv[1]) == "tx40")
    return tx40_study(argc > 2 ? argv[2] : ".", false);
  if (argc > 1 && std::string(argv[1]) == "eiv-tx40")
    return tx40_study(argc > 2 ? argv[2] : ".", true);
  if (argc > 1 && std::string(argv[1]) == "eiv") {
    g_after = argc > 3 && std::atoi(argv[3]) != 0;
    if (argc > 4) g_noise_seed = static_cast<unsigned>(std::atoi(argv[4]));
    return eiv_study(argc > 2 ? 1e-3 * std::atof(argv[2]) : 1e-3);
  }
  if (argc > 1 && std::string(argv[1]) == "window") {
    g_after = argc > 2 && std::atoi(argv[2]) != 0;
    const Model model = puma_with_friction();
    return endpoint_window_study(model, run(model, 1, 1e-3), run(model, 2, 1e-3), 1e-3);
  }
  if (argc > 1) g_noise = std::atof(argv[1]);
  if (argc > 2) g_torque_noise = std::atof(argv[2]);
  if (argc > 3) g_after = std::atoi(argv[3]) != 0;
  const Model model = puma_with_friction();
  const double ts = 1e-3;
  const ClosedLoopResult ra = run(model, 1, ts), rb = run(model, 2, ts);
  const JointRecord a{ra.t, ra.q, {}, {}, ra.tau}, b{rb.t, rb.q, {}, {}, rb.tau};
  IdentifyOptions def;
  def.signal.torque_time_offset = 0.5 * ts;
  const IdentificationResult diff = identify(model, a, def);
  const BaseParameters& base = diff.base;
  auto err_b = [&](const Eigen::VectorXd& x) {
    return 100 * validate_torques(model, b, base.names, x, def).relative_error_all;
  };
  std::printf("differential %.2f %% (cond %.3g), truth %.3f %%\n", err_b(diff.estimate.x),
              diff.condition_number, err_b(base.reduce(def.layout.parameters(model))));
  const int n = model.dof(), friction_begin = kLinkParams * n;
  const std::vector<double> cutoffs = {5.0, 10.0, 20.0, 40.0};
  const std::vector<double> intervals_ms = {2.0, 10.0, 50.0, 100.0, 200.0};
  std::printf(
      "cutoff interval | filtered: all  y  energy  friction  y+energy  y+friction  "
      "energy+friction  none\n");
  for (double cutoff : cutoffs) {
    SignalOptions so = def.signal;
    so.cutoff_hz = cutoff;
    so.decimate = 1;
    std::vector<std::pair<std::string, std::string>> choices;
    const ProcessedRecord p = preprocess(a, so, choices);
    const Eigen::Index first = std::llround(p.record.t[0] / ts);
    const ProcessedRecord truth = truth_rows(ra, first, p.record.t.size(), ts);
    for (double interval_ms : intervals_ms) {
      IntegralOptions io;
      io.interval = 1e-3 * interval_ms;
      io.weighting = IntegralWeighting::kNone;
      const EquationBlock f = integral_equations(model, def.layout, false, p, io);
      IntegralOptions to = io;
      to.rule = IntegrationRule::kZeroOrderHold;
      const EquationBlock t = integral_equations(model, def.layout, false, truth, to);
      // Row weights of the default (endpoint momentum) on the processed record, for every mix.
      IntegralOptions wo = io;
      wo.weighting = IntegralWeighting::kEndpointMomentum;
      const EquationBlock fw = integral_equations(model, def.layout, false, p, wo);
      Eigen::VectorXd weight(f.y.size());
      for (Eigen::Index i = 0; i < weight.size(); ++i)
        weight[i] = fw.W.row(i).norm() / f.W.row(i).norm();
      auto solve = [&](bool true_y, bool true_energy, bool true_friction) {
        Eigen::MatrixXd W = f.W;
        Eigen::VectorXd y = true_y ? t.y : f.y;
        if (true_energy) {
          W.leftCols(friction_begin) = t.W.leftCols(friction_begin);
        }
        if (true_friction) {
          W.rightCols(W.cols() - friction_begin) = t.W.rightCols(W.cols() - friction_begin);
        }
        W = weight.asDiagonal() * W;
        y = weight.cwiseProduct(y);
        return err_b(ordinary_least_squares(base.select(W), y).x);
      };
      {
        // Conditioning of the column-scaled base regressor (the differential model's: below).
        Eigen::MatrixXd Wb = base.select(weight.asDiagonal() * f.W);
        // Evaluated first: scaling Wb in place by its own lazily evaluated norms aliases.
        const Eigen::VectorXd inverse_norms = Wb.colwise().norm().cwiseInverse().transpose();
        Wb = Wb * inverse_norms.asDiagonal();
        Eigen::JacobiSVD<Eigen::MatrixXd> svd(Wb);
        const Eigen::VectorXd sv = svd.singularValues();
        double dv = 0.0;
        for (Eigen::Index i = 0; i < p.record.dq.rows(); ++i) {
          dv += (p.record.dq.row(i) - truth.record.dq.row(i)).squaredNorm();
        }
        std::printf("  cond %.3g, velocity error rms %.3g rad/s\n", sv[0] / sv[sv.size() - 1],
                    std::sqrt(dv / p.record.dq.size()));
      }
      // Columns: which parts come from the filtered record (the rest from the truth).
      std::printf("%5.0f %5.0f | %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f %7.2f\n", cutoff,
                  interval_ms, solve(false, false, false), solve(false, true, true),
                  solve(true, false, true), solve(true, true, false), solve(false, false, true),
                  solve(false, true, false), solve(true, false, false), solve(true, true, true));
      // Treatments on the filtered equations (momentum-weighted rows): OLS; AR(1) prewhitening
      // with ρ from the OLS residuals (Cochrane–Orcutt, 1 and 3 passes); instrumental variables
      // with the energy columns rebuilt from a 2 Hz-filtered record as instruments.
      const Eigen::MatrixXd Wf = base.select(weight.asDiagonal() * f.W);
      const Eigen::VectorXd yf = weight.cwiseProduct(f.y);
      Eigen::VectorXd x = ordinary_least_squares(Wf, yf).x;
      const double e_ols = err_b(x);
      double rho = 0.0, e_ar[3] = {0, 0, 0};
      for (int pass = 0; pass < 3; ++pass) {
        const Eigen::VectorXd r = yf - Wf * x;
        rho = r.tail(r.size() - 1).dot(r.head(r.size() - 1)) / r.squaredNorm();
        const Eigen::Index rows = Wf.rows() - 1;
        const Eigen::MatrixXd Wd = Wf.bottomRows(rows) - rho * Wf.topRows(rows);
        const Eigen::VectorXd yd = yf.tail(rows) - rho * yf.head(rows);
        x = ordinary_least_squares(Wd, yd).x;
        e_ar[pass] = err_b(x);
      }
      // MA(1) GLS: rows' errors with lag-1 correlation ρ1 (from the OLS residuals, clamped to
      // ±0.45), whitened by the Cholesky factor of the tridiagonal covariance (the shared end
      // points of adjacent intervals give ρ1 = −0.5 when the end-point noise is white).
      double e_ma = 0.0, rho1 = 0.0;
      {
        Eigen::VectorXd xo = ordinary_least_squares(Wf, yf).x;
        const Eigen::VectorXd r = yf - Wf * xo;
        rho1 = r.tail(r.size() - 1).dot(r.head(r.size() - 1)) / r.squaredNorm();
        const double c = std::clamp(rho1, -0.45, 0.45);
        Eigen::MatrixXd Ww = Wf;
        Eigen::VectorXd yw = yf;
        double l_prev = 1.0;  // L(i, i); L(i, i−1) = c / L(i−1, i−1)
        for (Eigen::Index i = 0; i < Ww.rows(); ++i) {
          if (i == 0) continue;
          const double off = c / l_prev;
          const double diag = std::sqrt(1.0 - off * off);
          Ww.row(i) = (Ww.row(i) - off * Ww.row(i - 1)) / diag;
          yw[i] = (yw[i] - off * yw[i - 1]) / diag;
          l_prev = diag;
        }
        e_ma = err_b(ordinary_least_squares(Ww, yw).x);
      }
      {
        // The Coulomb work of the filtered velocity, ∫|q̇_j|, instead of parallel filtering.
        ProcessedRecord serial = p;
        serial.moving_positive.resize(0, 0);
        serial.moving_negative.resize(0, 0);
        const EquationBlock sb = integral_equations(model, def.layout, false, serial, wo);
        std::printf("  Coulomb columns ∫|dq| (no parallel filtering): %.2f\n",
                    err_b(ordinary_least_squares(base.select(sb.W), sb.y).x));
      }
      std::printf("  MA(1) GLS rho1 %.3f: %.2f\n", rho1, e_ma);
      SignalOptions so2 = so;
      so2.cutoff_hz = 2.0;
      so2.trim = p.trim;
      const ProcessedRecord p2 = preprocess(a, so2, choices);
      const EquationBlock z = integral_equations(model, def.layout, false, p2, io);
      const Eigen::MatrixXd Z = base.select(weight.asDiagonal() * z.W);
      {
        // Link energy columns from the same run filtered at half the cut-off (less endpoint
        // velocity noise), power and per-joint columns at the cut-off.
        SignalOptions half = so;
        half.cutoff_hz = 0.5 * so.cutoff_hz;
        half.trim = p.trim;
        const EquationBlock hb =
            integral_equations(model, def.layout, false, preprocess(a, half, choices), io);
        Eigen::MatrixXd W = f.W;
        W.leftCols(friction_begin) = hb.W.leftCols(friction_begin);
        W = weight.asDiagonal() * W;
        std::printf("  energy columns at half the cut-off: %.2f\n",
                    err_b(ordinary_least_squares(base.select(W), weight.cwiseProduct(f.y)).x));
      }
      const Eigen::VectorXd x_iv = (Z.transpose() * Wf).fullPivLu().solve(Z.transpose() * yf);
      std::printf("  treatments: OLS %.2f, AR(1) rho %.3f: %.2f / %.2f (3 passes), IV(2 Hz) %.2f\n",
                  e_ols, rho, e_ar[0], e_ar[2], err_b(x_iv));
    }
  }
  return 0;
}
