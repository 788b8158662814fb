// RNEA, mass matrix, forward dynamics, torque and energy regressors of dynid against KDL's
// ChainIdSolver_RNE, ChainDynParam::JntToMass and ChainFdSolver_RNE on the same robot (the KDL
// chain is parsed from dynid's URDF export of the built-in model). Run:
// ./build/bench/dynamics_bench --benchmark_repetitions=5
// --benchmark_report_aggregates_only=true
#include <map>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>

#include <benchmark/benchmark.h>

#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/urdf_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/energy_regressor.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "oracle/kdl_bridge.hpp"

namespace {

using dynid::Model;

struct State {
  Eigen::VectorXd q, dq, ddq;
  explicit State(int n) {
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    q = Eigen::VectorXd::NullaryExpr(n, [&] { return u(rng); });
    dq = Eigen::VectorXd::NullaryExpr(n, [&] { return u(rng); });
    ddq = Eigen::VectorXd::NullaryExpr(n, [&] { return u(rng); });
  }
};

const Model& robot(const std::string& name) {
  static std::map<std::string, Model> cache;
  auto it = cache.find(name);
  if (it == cache.end()) it = cache.emplace(name, dynid::load_robot(name)).first;
  return it->second;
}

void BM_Rnea(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  dynid::Workspace ws(model);
  const State s(model.dof());
  Eigen::VectorXd tau(model.dof());
  for (auto _ : st) {
    dynid::rnea(model, ws, s.q, s.dq, s.ddq, tau);
    benchmark::DoNotOptimize(tau.data());
  }
}

void BM_RneaRigid(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  dynid::Workspace ws(model);
  const State s(model.dof());
  Eigen::VectorXd tau(model.dof());
  for (auto _ : st) {
    dynid::rnea(model, ws, s.q, s.dq, s.ddq, tau, dynid::RneaOptions{true, false});
    benchmark::DoNotOptimize(tau.data());
  }
}

void BM_MassMatrix(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  dynid::Workspace ws(model);
  const State s(model.dof());
  Eigen::MatrixXd M(model.dof(), model.dof());
  for (auto _ : st) {
    dynid::mass_matrix(model, ws, s.q, M);
    benchmark::DoNotOptimize(M.data());
  }
}

void BM_ForwardDynamics(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  dynid::Workspace ws(model);
  const State s(model.dof());
  Eigen::VectorXd ddq(model.dof());
  for (auto _ : st) {
    dynid::forward_dynamics(model, ws, s.q, s.dq, s.ddq, ddq);  // s.ddq serves as the torque
    benchmark::DoNotOptimize(ddq.data());
  }
}

void BM_TorqueRegressor(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  dynid::Workspace ws(model);
  const State s(model.dof());
  const auto layout = dynid::ParameterLayout::full();
  Eigen::MatrixXd Y(model.dof(), layout.columns(model.dof()));
  for (auto _ : st) {
    dynid::torque_regressor(model, ws, layout, s.q, s.dq, s.ddq, Y);
    benchmark::DoNotOptimize(Y.data());
  }
}

void BM_TorqueRegressorRigid(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  dynid::Workspace ws(model);
  const State s(model.dof());
  const auto layout = dynid::ParameterLayout::rigid();
  Eigen::MatrixXd Y(model.dof(), layout.columns(model.dof()));
  for (auto _ : st) {
    dynid::torque_regressor(model, ws, layout, s.q, s.dq, s.ddq, Y);
    benchmark::DoNotOptimize(Y.data());
  }
}

void BM_EnergyRegressor(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  dynid::Workspace ws(model);
  const State s(model.dof());
  const auto layout = dynid::ParameterLayout::full();
  Eigen::VectorXd h(layout.columns(model.dof()));
  for (auto _ : st) {
    dynid::energy_regressor(model, ws, layout, s.q, s.dq, h);
    benchmark::DoNotOptimize(h.data());
  }
}

// The KDL chain of a built-in robot, parsed from dynid's URDF export, behind the Eigen-free
// bridge (tests/oracle/kdl_bridge.hpp, for the native preset): each call copies n doubles in and
// out of KDL's JntArrays, a few ns against KDL's µs. Null if parsing failed.
std::unique_ptr<dynid::kdl::Chain> kdl_chain(const Model& model) {
  try {
    return std::make_unique<dynid::kdl::Chain>(dynid::to_urdf(model), dynid::kdl::UrdfSource::kText,
                                               "base_link", model.joints.back().link_name,
                                               model.gravity.data());
  } catch (const std::exception&) {
    return nullptr;
  }
}

void BM_KdlMass(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  const auto chain = kdl_chain(model);
  if (!chain) {
    st.SkipWithError("kdl_parser failed");
    return;
  }
  const int n = model.dof();
  const State s(n);
  Eigen::MatrixXd H(n, n);
  for (auto _ : st) {
    chain->mass_matrix(s.q.data(), H.data());
    benchmark::DoNotOptimize(H.data());
  }
}

void BM_KdlForwardDynamics(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  const auto chain = kdl_chain(model);
  if (!chain) {
    st.SkipWithError("kdl_parser failed");
    return;
  }
  const State s(model.dof());
  Eigen::VectorXd ddq(model.dof());
  for (auto _ : st) {
    chain->forward_dynamics(s.q.data(), s.dq.data(), s.ddq.data(), ddq.data());
    benchmark::DoNotOptimize(ddq.data());
  }
}

void BM_KdlRne(benchmark::State& st, const std::string& name) {
  const Model& model = robot(name);
  const auto chain = kdl_chain(model);
  if (!chain) {
    st.SkipWithError("kdl_parser failed");
    return;
  }
  const State s(model.dof());
  Eigen::VectorXd tau(model.dof());
  for (auto _ : st) {
    chain->inverse_dynamics(s.q.data(), s.dq.data(), s.ddq.data(), tau.data());
    benchmark::DoNotOptimize(tau.data());
  }
}

}  // namespace

#define DYNID_ROBOT_BENCH(robot_name)                                  \
  BENCHMARK_CAPTURE(BM_KdlRne, robot_name, #robot_name);               \
  BENCHMARK_CAPTURE(BM_Rnea, robot_name, #robot_name);                 \
  BENCHMARK_CAPTURE(BM_RneaRigid, robot_name, #robot_name);            \
  BENCHMARK_CAPTURE(BM_TorqueRegressor, robot_name, #robot_name);      \
  BENCHMARK_CAPTURE(BM_TorqueRegressorRigid, robot_name, #robot_name); \
  BENCHMARK_CAPTURE(BM_EnergyRegressor, robot_name, #robot_name);      \
  BENCHMARK_CAPTURE(BM_MassMatrix, robot_name, #robot_name);           \
  BENCHMARK_CAPTURE(BM_KdlMass, robot_name, #robot_name);              \
  BENCHMARK_CAPTURE(BM_ForwardDynamics, robot_name, #robot_name);      \
  BENCHMARK_CAPTURE(BM_KdlForwardDynamics, robot_name, #robot_name);

DYNID_ROBOT_BENCH(puma560)
DYNID_ROBOT_BENCH(iiwa14)

BENCHMARK_MAIN();
