// Load identification on line (issue 12, item 7; seed 1 §VII wished for on-line computation): one
// wrist-sensor sample = the 6×10 load regressor K (seed 1 eq. 28) and six U-D RLS updates of the
// ten load parameters (seed 1 eqs. 36–37). Items per second = wrench samples per second.
#include <cmath>

#include <benchmark/benchmark.h>
#include <Eigen/Core>

#include "dynid/estimation/recursive_least_squares.hpp"
#include "dynid/regressor/load_regressor.hpp"

namespace {

void BM_LoadRlsUpdatePerWrenchSample(benchmark::State& state) {
  dynid::RecursiveLeastSquares rls(10);
  Eigen::Matrix<double, 10, 1> phi;
  phi << 1.91, 0.0573, -0.021, 0.1394, 0.0123, 0.0006, -0.0042, 0.0137, 0.0018, 0.0028;
  double t = 0.0;
  for (auto _ : state) {
    t += 1e-3;
    const Eigen::Vector3d w(std::sin(t), std::cos(2 * t), 0.5),
        dw(std::cos(t), -std::sin(2 * t), 0.1), ddp(0.3, -0.2, std::sin(3 * t)),
        g(0.0, std::sin(t) * 9.81, -std::cos(t) * 9.81);
    const Eigen::Matrix<double, 6, 10> K = dynid::load_regressor(w, dw, ddp, g);
    const Eigen::Matrix<double, 6, 1> y = K * phi;
    for (int r = 0; r < 6; ++r) rls.update(K.row(r).transpose(), y(r));
    benchmark::DoNotOptimize(rls.x().data());
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_LoadRlsUpdatePerWrenchSample);

}  // namespace

BENCHMARK_MAIN();
