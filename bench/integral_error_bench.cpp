// Item 5 of issue 11, second study: where the integral model's error on noisy closed-loop data
// comes from, and what removes it. Same runs as integral_study_bench (puma560, native RK4 plant,
// PID + computed-torque feed-forward at 1 kHz, encoder noise 1e-4 rad, torque noise 0.05 N·m).
// The equations of run A are built twice on the same intervals: from the processed (filtered)
// record and from the true states with the held torque's exact work. Swapping one side at a
// time (y, the energy columns, the friction columns) between the two attributes the error; the
// printed figure is each estimate's torque-prediction error on run B (validate_torques). Then the
// treatments for correlated rows and errors in the regressor on the processed equations: AR(1)
// prewhitening, MA(1) GLS (the shared end points of adjacent intervals), instrumental variables.
// Not a benchmark: its table is in docs/methods/estimation.md ("Integral model").
// Run: ./build/bench/integral_error_bench [position-noise-scale [torque-noise-scale [after]]]
// (after = 1: encoder noise added to the log of a run with exact feedback, no jitter).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include <Eigen/SVD>

#include "../tests/estimation/integral_support.hpp"
#include "dynid/estimation/identification.hpp"
#include "dynid/estimation/integral_equations.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/model/robots.hpp"

namespace {

using namespace dynid;

double g_noise = 1.0, g_torque_noise = 1.0;
// 1: the encoder noise is added to the log after a run with exact position feedback, so the true
// motion carries no jitter from the controller's reaction to the noise.
bool g_after = false;

ClosedLoopResult run(const Model& model, unsigned seed, double ts) {
  SensorOptions so;
  so.position_noise_std = g_after ? 0.0 : 1e-4 * g_noise;
  so.torque_noise_std = 0.05 * g_torque_noise;
  so.seed = seed;
  ClosedLoopResult r = integral_testing::simulate(
      model, integral_testing::multisine(model.dof(), 10.0, ts, seed, 1.0), ts, so, PlantOptions{},
      2);
  if (g_after) {
    std::mt19937 rng(seed + 100);
    std::normal_distribution<double> normal(0.0, 1e-4 * g_noise);
    for (Eigen::Index k = 0; k < r.q.size(); ++k) r.q.data()[k] += normal(rng);
  }
  return r;
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

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1) g_noise = std::atof(argv[1]);
  if (argc > 2) g_torque_noise = std::atof(argv[2]);
  if (argc > 3) g_after = std::atoi(argv[3]) != 0;
  Model model = load_robot("puma560");
  for (int j = 0; j < model.dof(); ++j) {
    model.joints[j].friction = {0.05 * (j + 1), 0.5 + 0.1 * j, 0.3 + 0.1 * j, 0.1 * (j + 1)};
  }
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
        Wb = Wb * Wb.colwise().norm().cwiseInverse().asDiagonal();
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
