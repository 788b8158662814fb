// Forward dynamics (CRBA + LᵀDL against the articulated-body algorithm) and the RNEA derivatives
// (analytic against central differences of the RNEA) on random chains of 6…30 joints and on the
// built-in puma560 and iiwa14 (issue 30 items 2–4). The crossover of the two forward dynamics
// sets kArticulatedBodyMinChain. Run:
// ./build/bench/chain_kernels_bench --benchmark_repetitions=3
// --benchmark_report_aggregates_only=true --benchmark_min_time=0.2
#include <map>
#include <random>
#include <string>

#include <benchmark/benchmark.h>

#include "dynid/dynamics/articulated_body.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/rnea_derivatives.hpp"
#include "dynid/model/robots.hpp"
#include "support/random_models.hpp"

namespace {

using dynid::Model;

// A tree of `branches` random chains of `length` revolute joints on one root joint.
Model branching(int branches, int length) {
  Model m = dynid::testing::random_tree(1 + branches * length, 30, false, true);
  for (int j = 1; j < m.dof(); ++j) m.joints[j].parent = (j - 1) % length == 0 ? 0 : j - 1;
  m.finalize();
  return m;
}

// A random chain of n revolute joints (tests/support/random_models.hpp), or for n < 6: a built-in
// robot (0: puma560, 1: iiwa14) or a tree of 31 joints (2: five branches of 6 on a root, mean
// depth 4.4; 3: two branches of 15, mean depth 8.7).
const Model& model_for(int n) {
  static std::map<int, Model> cache;
  auto it = cache.find(n);
  if (it == cache.end()) {
    Model m = n == 0   ? dynid::load_robot("puma560")
              : n == 1 ? dynid::load_robot("iiwa14")
              : n == 2 ? branching(5, 6)
              : n == 3 ? branching(2, 15)
                       : dynid::testing::random_tree(n, 30, false, true);
    it = cache.emplace(n, std::move(m)).first;
  }
  return it->second;
}

struct State {
  Eigen::VectorXd q, dq, ddq;
  explicit State(int n) {
    std::mt19937 rng(1);
    q = dynid::testing::random_vector(n, rng);
    dq = dynid::testing::random_vector(n, rng);
    ddq = dynid::testing::random_vector(n, rng);
  }
};

template <void (*Fd)(const Model&, dynid::Workspace&, const Eigen::Ref<const Eigen::VectorXd>&,
                     const Eigen::Ref<const Eigen::VectorXd>&,
                     const Eigen::Ref<const Eigen::VectorXd>&, Eigen::Ref<Eigen::VectorXd>,
                     const dynid::RneaOptions&)>
void BM_Fd(benchmark::State& st) {
  const Model& model = model_for(static_cast<int>(st.range(0)));
  dynid::Workspace ws(model);
  const State s(model.dof());
  Eigen::VectorXd ddq(model.dof());
  for (auto _ : st) {
    Fd(model, ws, s.q, s.dq, s.ddq, ddq, {});  // s.ddq serves as the torque
    benchmark::DoNotOptimize(ddq.data());
  }
  st.counters["dof"] = model.dof();
}

void BM_CrbaForwardDynamics(benchmark::State& st) {
  BM_Fd<dynid::crba_forward_dynamics>(st);
}
void BM_ArticulatedBody(benchmark::State& st) {
  BM_Fd<dynid::articulated_body_forward_dynamics>(st);
}
void BM_ForwardDynamics(benchmark::State& st) {
  BM_Fd<dynid::forward_dynamics>(st);
}

void BM_RneaDerivatives(benchmark::State& st) {
  const Model& model = model_for(static_cast<int>(st.range(0)));
  const int n = model.dof();
  dynid::Workspace ws(model);
  const State s(n);
  Eigen::MatrixXd d_q(n, n), d_dq(n, n), M(n, n);
  for (auto _ : st) {
    dynid::rnea_derivatives(model, ws, s.q, s.dq, s.ddq, d_q, d_dq, M);
    benchmark::DoNotOptimize(d_q.data());
    benchmark::DoNotOptimize(d_dq.data());
    benchmark::DoNotOptimize(M.data());
  }
  st.counters["dof"] = n;
}

// The same three matrices by central differences of the RNEA: 6n calls.
void BM_RneaCentralDifferences(benchmark::State& st) {
  const Model& model = model_for(static_cast<int>(st.range(0)));
  const int n = model.dof();
  dynid::Workspace ws(model);
  const State s(n);
  Eigen::VectorXd x[3] = {s.q, s.dq, s.ddq};
  Eigen::MatrixXd d[3] = {Eigen::MatrixXd(n, n), Eigen::MatrixXd(n, n), Eigen::MatrixXd(n, n)};
  Eigen::VectorXd plus(n), minus(n);
  for (auto _ : st) {
    for (int c = 0; c < 3; ++c) {
      const double h = c == 0 ? 1e-5 : 1e-2;
      for (int k = 0; k < n; ++k) {
        const double x0 = x[c][k];
        x[c][k] = x0 + h;
        dynid::rnea(model, ws, x[0], x[1], x[2], plus);
        x[c][k] = x0 - h;
        dynid::rnea(model, ws, x[0], x[1], x[2], minus);
        x[c][k] = x0;
        d[c].col(k) = (plus - minus) / (2.0 * h);
      }
    }
    benchmark::DoNotOptimize(d[0].data());
  }
  st.counters["dof"] = n;
}

void sizes(benchmark::internal::Benchmark* b) {
  for (int n : {0, 1, 6, 7, 12, 18, 24, 30}) b->Arg(n);  // 0: puma560, 1: iiwa14
}

// The forward dynamics also around the crossover and on two trees.
void fd_sizes(benchmark::internal::Benchmark* b) {
  for (int n : {0, 1, 2, 3, 6, 7, 10, 12, 14, 16, 18, 24, 30}) b->Arg(n);
}

}  // namespace

BENCHMARK(BM_CrbaForwardDynamics)->Apply(fd_sizes);
BENCHMARK(BM_ArticulatedBody)->Apply(fd_sizes);
BENCHMARK(BM_ForwardDynamics)->Apply(fd_sizes);
BENCHMARK(BM_RneaDerivatives)->Apply(sizes);
BENCHMARK(BM_RneaCentralDifferences)->Apply(sizes);

BENCHMARK_MAIN();
