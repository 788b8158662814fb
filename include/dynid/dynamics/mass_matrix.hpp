#pragma once

#include <Eigen/Core>

#include "dynid/dynamics/articulated_body.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"

namespace dynid {

/// Joint-space mass matrix M(q) (n×n, symmetric positive definite) by the composite-rigid-body
/// algorithm (Featherstone 2008, §6.2), including the actuator inertias Ia on the diagonal.
/// Identity: M·ddq + rnea(q, dq, 0) = rnea(q, dq, ddq).
void mass_matrix(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                 Eigen::Ref<Eigen::MatrixXd> M);

/// Forward dynamics by RNEA + CRBA + tree-sparse LᵀDL (Featherstone 2008, Tables 6.3–6.4):
/// ddq = M⁻¹(tau − rnea(q, dq, 0, options)), M from mass_matrix: Ia always belongs to the inertia,
/// options.joint_terms switches the friction torques only (friction uses sign(dq), Coulomb
/// discontinuous at dq = 0; simulators smooth it themselves).
/// O(n + Σ depth²): the faster for short chains and shallow trees. Sizes n; no allocation.
void crba_forward_dynamics(const Model& model, Workspace& ws,
                           const Eigen::Ref<const Eigen::VectorXd>& q,
                           const Eigen::Ref<const Eigen::VectorXd>& dq,
                           const Eigen::Ref<const Eigen::VectorXd>& tau,
                           Eigen::Ref<Eigen::VectorXd> ddq, const RneaOptions& options = {});

/// Chains of at least this many joints go to the articulated-body algorithm in forward_dynamics:
/// the crossover measured by bench/dynamics/chain_kernels_bench.cpp (docs/performance.md).
inline constexpr int kArticulatedBodyMinChain = 13;

/// Whether forward_dynamics takes the articulated-body algorithm for this workspace's model: when
/// the mean joint depth Σ depth / n reaches that of a kArticulatedBodyMinChain-joint chain,
/// (k + 1)/2. The CRBA path costs O(Σ depth²) against the ABA's O(n), so the mean depth, not n,
/// decides; a chain of n joints takes the ABA exactly when n ≥ kArticulatedBodyMinChain.
bool prefers_articulated_body(const Workspace& ws);

/// Forward dynamics: ddq = M⁻¹(tau − rnea(q, dq, 0, options)) with M = mass_matrix (Ia included
/// whatever options.joint_terms), so rnea(q, dq, ddq) = tau with the default options, by whichever
/// of crba_forward_dynamics and articulated_body_forward_dynamics is faster for the model
/// (prefers_articulated_body); both give the same result to round-off. Sizes n (rad, m, N·m, N); no
/// allocation.
void forward_dynamics(const Model& model, Workspace& ws, const Eigen::Ref<const Eigen::VectorXd>& q,
                      const Eigen::Ref<const Eigen::VectorXd>& dq,
                      const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> ddq,
                      const RneaOptions& options = {});

}  // namespace dynid
