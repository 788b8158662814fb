// The hot paths do not allocate: every heap allocation in this test binary is counted, and the
// count must not change across calls of rnea, its derivatives, mass_matrix, the forward dynamics
// (both algorithms) and the regressors with a reused Workspace.
#include <atomic>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/rnea_derivatives.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/energy_regressor.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "support/asan.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

// AddressSanitizer replaces operator new itself, so the count is only taken without it.
#if DYNID_UNDER_ASAN
#define DYNID_COUNT_ALLOCATIONS 0
#else
#define DYNID_COUNT_ALLOCATIONS 1
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept {
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept {
  std::free(p);
}
#endif

namespace dynid {
namespace {

TEST(Allocation, HotPathsDoNotAllocate) {
  if (!DYNID_COUNT_ALLOCATIONS) GTEST_SKIP() << "AddressSanitizer owns operator new in this build";
  for (const char* name : {"puma560", "iiwa14"}) {
    const Model model = load_robot(name);
    const int n = model.dof();
    Workspace ws(model);
    const ParameterLayout layout = ParameterLayout::full();
    Eigen::VectorXd q = Eigen::VectorXd::Constant(n, 0.3), dq = Eigen::VectorXd::Constant(n, 0.5),
                    ddq = Eigen::VectorXd::Constant(n, -0.2), tau(n), h(layout.columns(n));
    Eigen::MatrixXd M(n, n), Y(n, layout.columns(n)), d_q(n, n), d_dq(n, n);
    const long before = g_allocations.load();
    for (int k = 0; k < 10; ++k) {
      rnea(model, ws, q, dq, ddq, tau);
      mass_matrix(model, ws, q, M);
      forward_dynamics(model, ws, q, dq, tau, ddq);
      crba_forward_dynamics(model, ws, q, dq, tau, ddq);
      articulated_body_forward_dynamics(model, ws, q, dq, tau, ddq);
      rnea_derivatives(model, ws, q, dq, ddq, d_q, d_dq, M);
      torque_regressor(model, ws, layout, q, dq, ddq, Y);
      energy_regressor(model, ws, layout, q, dq, h);
    }
    EXPECT_EQ(g_allocations.load() - before, 0) << name;
  }
}

}  // namespace
}  // namespace dynid
