// On-line identification at control rate (issue 16 item 4): one OnlineIdentification::update —
// torque regressor of one sample, its base columns, n U-D RLS updates with forgetting — for the
// 7-DoF iiwa14 with the full friction layout (Ia, Fv, Fc, Fo per joint) and for puma560.
// Run: ./build/bench/online_bench --benchmark_repetitions=3 --benchmark_report_aggregates_only=true
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/estimation/online_identification.hpp"
#include "dynid/model/robots.hpp"

namespace {

void BM_OnlineUpdate(benchmark::State& st, const std::string& name) {
  const dynid::Model model = dynid::load_robot(name);
  const int n = model.dof();
  const dynid::ParameterLayout layout = dynid::ParameterLayout::full();
  dynid::BaseParameterOptions bo;
  bo.layout = layout;
  const dynid::BaseParameters base = dynid::compute_base_parameters(model, bo);
  dynid::OnlineIdentification online(model, layout, base);
  // 64 random states with their RNEA torques, cycled.
  std::mt19937 rng(1);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const int m = 64;
  Eigen::MatrixXd q(n, m), dq(n, m), ddq(n, m), tau(n, m);
  dynid::Workspace ws(model);
  for (int k = 0; k < m; ++k) {
    for (int j = 0; j < n; ++j) {
      q(j, k) = u(rng);
      dq(j, k) = u(rng);
      ddq(j, k) = u(rng);
    }
    Eigen::VectorXd t(n);
    dynid::rnea(model, ws, q.col(k), dq.col(k), ddq.col(k), t);
    tau.col(k) = t;
  }
  int k = 0;
  for (auto _ : st) {
    online.update(q.col(k), dq.col(k), ddq.col(k), tau.col(k));
    benchmark::DoNotOptimize(online.estimate().data());
    k = (k + 1) % m;
  }
  st.counters["base_parameters"] = static_cast<double>(base.rank);
  st.counters["samples_per_s"] =
      benchmark::Counter(1.0, benchmark::Counter::kIsIterationInvariantRate);
}

}  // namespace

BENCHMARK_CAPTURE(BM_OnlineUpdate, iiwa14, "iiwa14");
BENCHMARK_CAPTURE(BM_OnlineUpdate, puma560, "puma560");

BENCHMARK_MAIN();
