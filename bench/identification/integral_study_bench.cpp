// Item 5 of issue 11: how good the integral (energy) model can be on noisy closed-loop data.
// Simulates two closed-loop runs of the puma560 (native RK4 plant with tanh Coulomb friction,
// PID + computed-torque feed-forward, 1 kHz, encoder noise 1e-4 rad, torque noise 0.05 N·m),
// identifies on run A with the differential model (identify() defaults) and with the integral
// model over a grid of signal processing and interval choices, and prints each estimate's
// torque-prediction error on run B (validate_torques with the differential defaults).
// Not a benchmark: a study whose table is in docs/methods/identification.md ("Integral model").
// Run: ./build/bench/integral_study_bench [position-noise-scale [torque-noise-scale]] (1 1 = the
// noise above; 0 0 = noise-free).
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include "../../tests/identification/integral_support.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/integral_equations.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/model/robots.hpp"

namespace {

using namespace dynid;

double g_noise = 1.0, g_torque_noise = 1.0;
// The grid (cut-off < 0: no filter; interval 0: automatic).
const std::vector<double> kCutoffs = {0.0, 2.0, 5.0, 10.0, 20.0, 40.0, 80.0, -1.0};
const std::vector<double> kIntervalsMs = {0.0, 5.0, 10.0, 50.0, 100.0, 200.0, 500.0, 1000.0};

// The closed-loop run of the tests (tests/identification/integral_support.hpp): PID +
// computed-torque feed-forward tracking one multi-sine period twice.
JointRecord run(const Model& model, unsigned seed, double ts) {
  SensorOptions so;
  so.position_noise_std = 1e-4 * g_noise;
  so.torque_noise_std = 0.05 * g_torque_noise;
  so.seed = seed;
  const ClosedLoopResult r = integral_testing::simulate(
      model, integral_testing::multisine(model.dof(), 10.0, ts, seed, 1.0), ts, so, PlantOptions{},
      2);
  return JointRecord{r.t, r.q, {}, {}, r.tau};
}

}  // namespace

int main(int argc, char** argv) {
  if (argc > 1) g_noise = std::atof(argv[1]);
  if (argc > 2) g_torque_noise = std::atof(argv[2]);
  Model model = load_robot("puma560");
  for (int j = 0; j < model.dof(); ++j) {
    model.joints[j].friction = {0.05 * (j + 1), 0.5 + 0.1 * j, 0.3 + 0.1 * j, 0.1 * (j + 1)};
  }
  const double ts = 1e-3;
  const JointRecord a = run(model, 1, ts), b = run(model, 2, ts);
  IdentifyOptions def;
  def.signal.torque_time_offset = 0.5 * ts;  // the logged torque is held for one period
  const IdentificationResult diff = identify(model, a, def);
  const double diff_err =
      validate_torques(model, b, diff.names, diff.estimate.x, def).relative_error_all;
  std::printf("differential model (identify defaults): %.2f %% on run B\n", 100 * diff_err);
  const BaseParameters& base = diff.base;
  const Eigen::VectorXd truth = base.reduce(def.layout.parameters(model));
  std::printf("truth on run B: %.3f %%\n",
              100 * validate_torques(model, b, base.names, truth, def).relative_error_all);
  std::printf(
      "cutoff_hz decimate interval_ms weight(0 none, 1 torque, 2 momentum) power long | "
      "error_B_%%\n");
  for (double cutoff : kCutoffs) {
    for (int decimate : {0, 1}) {
      if (cutoff < 0 && decimate == 0) continue;
      SignalOptions so = def.signal;
      so.filter = cutoff >= 0.0;
      so.cutoff_hz = std::max(cutoff, 0.0);
      so.decimate = decimate;
      std::vector<std::pair<std::string, std::string>> choices;
      ProcessedRecord p;
      try {
        p = preprocess(a, so, choices);
      } catch (const std::exception& e) {
        std::printf("%g %d: %s\n", cutoff, decimate, e.what());
        continue;
      }
      for (double interval_ms : kIntervalsMs) {
        for (int power = 0; power < 2; ++power) {
          // power 0: Simpson on the processed τᵀq̇; 1: the raw held torque's work Σ τ_kᵀΔq_k
          // (zero-order hold on the unfiltered log, no velocity), energy side processed.
          if (power == 1 && decimate != 1) continue;
          for (int weight : {0, 1, 2}) {  // IntegralWeighting: none, torque noise, momentum
            for (bool long_integrals : {false, true}) {
              if (long_integrals && weight) continue;
              IntegralOptions io;
              io.interval = 1e-3 * interval_ms;
              io.weighting = IntegralWeighting::kNone;
              io.long_integrals = long_integrals;
              try {
                EquationBlock blk = integral_equations(model, def.layout, false, p, io);
                if (power == 1) {
                  for (Eigen::Index i = 0; i < blk.y.size(); ++i) {
                    const Eigen::Index e = std::llround(blk.t[i] / ts);
                    const Eigen::Index steps = std::max<Eigen::Index>(
                        1, interval_ms > 0 ? std::llround(interval_ms * 1e-3 / ts) : 2);
                    const Eigen::Index s0 =
                        long_integrals ? std::llround(p.record.t[0] / ts) : e - steps;
                    double y = 0.0;
                    for (Eigen::Index k = s0; k < e; ++k)
                      y += a.tau.row(k).dot(a.q.row(k + 1) - a.q.row(k));
                    blk.y[i] = y;
                  }
                }
                if (weight) {
                  IntegralOptions wo = io;
                  wo.weighting = static_cast<IntegralWeighting>(weight);
                  const EquationBlock w = integral_equations(model, def.layout, false, p, wo);
                  for (Eigen::Index i = 0; i < blk.y.size(); ++i) {
                    const double f = w.W.row(i).norm() / blk.W.row(i).norm();
                    blk.W.row(i) *= f;
                    blk.y[i] *= f;
                  }
                }
                const Estimate e = ordinary_least_squares(base.select(blk.W), blk.y);
                const double err =
                    validate_torques(model, b, base.names, e.x, def).relative_error_all;
                std::printf("%6.1f %2d(%4.0fHz) %6.1f %d %s %d | %7.2f\n",
                            cutoff < 0 ? -1.0 : p.cutoff_hz, decimate, p.rate_hz, interval_ms,
                            weight, power ? "raw-zoh" : "simpson", long_integrals, 100 * err);
              } catch (const std::exception& e) {
                std::printf("%6.1f %2d %6.1f: %s\n", cutoff, decimate, interval_ms, e.what());
              }
            }
          }
        }
      }
    }
  }
  return 0;
}
