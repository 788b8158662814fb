#pragma once

// Orocos KDL behind an Eigen-free interface (URDF text, std::string, double*), for the oracle
// tests and bench/dynamics_bench. KDL's API passes Eigen objects (JntArray::data, ...) and
// Debian's KDL is built for plain x86-64, while the `native` preset builds dynid with
// -march=native, where Eigen aligns its heap blocks differently: no Eigen object may cross that
// boundary (docs/design.md section 1). This header includes neither Eigen nor KDL; its
// implementation is a shared library compiled without -march=native and with hidden symbols, so its
// Eigen code is never merged with the native build's (cmake/DynidKdlBridge.cmake).

#include <memory>
#include <string>
#include <vector>

#define DYNID_KDL_BRIDGE_API __attribute__((visibility("default")))

namespace dynid::kdl {

/// Where a URDF comes from: the text itself, or a file path (kdl_parser's treeFromString or
/// treeFromFile).
enum class UrdfSource { kText, kFile };

/// A KDL tree (TreeIdSolver_RNE), with its joints reordered to a caller-given order.
class DYNID_KDL_BRIDGE_API Tree {
 public:
  /// Parses `urdf` with kdl_parser; `joint_names` gives the caller's joint order (every
  /// non-fixed KDL joint matched by name); `gravity` is the base-frame vector (m/s², 3 values).
  /// Throws std::runtime_error if the URDF does not parse or a name is not a KDL joint.
  Tree(const std::string& urdf, UrdfSource source, const std::vector<std::string>& joint_names,
       const double* gravity);
  ~Tree();
  Tree(const Tree&) = delete;
  Tree& operator=(const Tree&) = delete;

  /// Number of non-fixed joints KDL sees in the tree.
  int joint_count() const;
  /// tau = ID(q, dq, ddq) by TreeIdSolver_RNE without external wrenches; all arrays of
  /// joint_names.size() values in the caller's order (rad or m, /s, /s², N·m or N). Returns
  /// KDL's error code (< 0 on failure).
  int inverse_dynamics(const double* q, const double* dq, const double* ddq, double* tau);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// A KDL chain between two links (ChainIdSolver_RNE, ChainDynParam, ChainFdSolver_RNE); joint
/// order is the chain's, base to tip.
class DYNID_KDL_BRIDGE_API Chain {
 public:
  /// Parses `urdf` and takes the chain from `base_link` (the tree's root if empty) to
  /// `tip_link`; `gravity` is the base-frame vector (m/s², 3 values). Throws std::runtime_error
  /// if the URDF does not parse or the chain does not exist.
  Chain(const std::string& urdf, UrdfSource source, const std::string& base_link,
        const std::string& tip_link, const double* gravity);
  ~Chain();
  Chain(const Chain&) = delete;
  Chain& operator=(const Chain&) = delete;

  /// Number of joints in the chain (n).
  int joint_count() const;
  /// tau = ID(q, dq, ddq) by ChainIdSolver_RNE, no external wrenches; n values each. Returns
  /// KDL's error code (< 0 on failure).
  int inverse_dynamics(const double* q, const double* dq, const double* ddq, double* tau);
  /// M(q) by ChainDynParam::JntToMass into `mass` (n×n, column-major, kg·m² / kg). Returns KDL's
  /// error code.
  int mass_matrix(const double* q, double* mass);
  /// ddq = M⁻¹(tau − c(q, dq)) by ChainFdSolver_RNE, no external wrenches. Returns KDL's error
  /// code.
  int forward_dynamics(const double* q, const double* dq, const double* tau, double* ddq);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dynid::kdl
