// Model loading and base parameters of long revolute chains (issue 10: "a 1000-joint chain loads
// and gets its base parameters in under 5 s"; before, 500 joints took minutes at 2 GB). The URDF
// text is generated once per size (tests/support/chain_urdf.hpp) and parsed in the loop.
// Run: ./build/bench/model_bench
#include <string>

#include <benchmark/benchmark.h>

#include "../../tests/support/chain_urdf.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/urdf_loader.hpp"

namespace {

void BM_LoadUrdfChain(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::string xml = dynid::testing::chain_urdf(n, 11);
  for (auto _ : state) benchmark::DoNotOptimize(dynid::parse_urdf(xml, "chain.urdf"));
  state.counters["joints"] = n;
}
BENCHMARK(BM_LoadUrdfChain)->Arg(100)->Arg(1000)->Unit(benchmark::kMillisecond);  // 1000: the limit

void BM_LoadAndBaseParametersChain(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const std::string xml = dynid::testing::chain_urdf(n, 11);
  int rank = 0;
  for (auto _ : state) {
    const dynid::Model model = dynid::parse_urdf(xml, "chain.urdf");
    rank = dynid::compute_base_parameters(model).rank;
  }
  state.counters["joints"] = n;
  state.counters["rank"] = rank;
}
BENCHMARK(BM_LoadAndBaseParametersChain)
    ->Arg(100)
    ->Arg(500)
    ->Arg(1000)  // kMaxJoints: a longer chain is refused by the loader
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// The dense left-to-right sweep it replaces, for comparison at small sizes.
void BM_DenseBaseParametersChain(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const dynid::Model model = dynid::parse_urdf(dynid::testing::chain_urdf(n, 11), "chain.urdf");
  dynid::BaseParameterOptions options;
  options.algorithm = dynid::BaseAlgorithm::kDense;
  for (auto _ : state) benchmark::DoNotOptimize(dynid::compute_base_parameters(model, options));
  state.counters["joints"] = n;
}
BENCHMARK(BM_DenseBaseParametersChain)
    ->Arg(25)
    ->Arg(50)
    ->Arg(100)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
