#pragma once

#include <vector>

#include <Eigen/Core>

#include "dynid/excitation/trajectory.hpp"

namespace dynid {

/// Coefficients of a finite Fourier series trajectory (seed 2 eqs. 17–19), per joint i:
///   q_i(t)   = Σ_k a_ik/(ω_f k)·sin(ω_f k t) − b_ik/(ω_f k)·cos(ω_f k t) + q_i0,
///   dq_i(t)  = Σ_k a_ik·cos(ω_f k t) + b_ik·sin(ω_f k t),
///   ddq_i(t) = Σ_k −a_ik ω_f k·sin(ω_f k t) + b_ik ω_f k·cos(ω_f k t),
/// with ω_f = 2π f0 and k = 1..N_i. Note that q_i0 is the constant term of the series, not q_i(0).
struct FourierCoefficients {
  double f0 = 0.1;                 ///< fundamental frequency f0 [Hz]; the period is 1/f0
  std::vector<Eigen::VectorXd> a;  ///< a[i]: N_i sine-of-position coefficients [rad/s or m/s]
  std::vector<Eigen::VectorXd> b;  ///< b[i]: N_i cosine-of-position coefficients (same size)
  Eigen::VectorXd q0;              ///< n constant terms q_i0 [rad or m]

  int dof() const { return static_cast<int>(a.size()); }
  /// Largest number of harmonics over the joints, max_i N_i.
  int max_harmonics() const;
  /// Highest frequency in the trajectory, max_i N_i · f0 [Hz] (the bandwidth, seed 2 §3.3).
  double bandwidth() const { return max_harmonics() * f0; }

  /// Zero coefficients: n joints, harmonics[i] harmonics each, fundamental f0.
  static FourierCoefficients zeros(const std::vector<int>& harmonics, double f0);

  /// Checks sizes (a[i], b[i] same length ≥ 1, q0 of size n) and f0 finite and > 0; throws
  /// dynid::Error naming the field at fault.
  void validate() const;
};

/// Makes the trajectory start and end at rest: dq(0) = dq(T) = 0 and ddq(0) = ddq(T) = 0
/// (T = 1/f0; the series is T-periodic so the end conditions equal the start ones). By eqs. 18–19
/// at t = 0 these are the linear constraints Σ_k a_ik = 0 and Σ_k k·b_ik = 0, one pair per joint;
/// the coefficients are replaced by their Euclidean orthogonal projection onto that subspace:
///   a_i ← a_i − (1ᵀa_i / N_i)·1,   b_i ← b_i − (kᵀb_i / kᵀk)·k,   k = (1, …, N_i)ᵀ.
/// Positions are left free (q(0) = q(T) automatically). With N_i = 1 joint i becomes constant.
/// Throws dynid::Error for inconsistent sizes (see FourierCoefficients::validate).
void project_rest_at_ends(FourierCoefficients& coefficients);

/// Finite Fourier series trajectory (seed 2 eqs. 17–19; Swevers et al. 1997). Periodic with
/// period 1/f0; evaluate() accepts any t. Velocities and accelerations are analytic.
class FourierTrajectory final : public Trajectory {
 public:
  /// Throws dynid::Error if the coefficients are inconsistent or f0 is not > 0 (validate()).
  explicit FourierTrajectory(FourierCoefficients coefficients);

  int dof() const override { return coefficients_.dof(); }
  double duration() const override { return 1.0 / coefficients_.f0; }
  double period() const override { return 1.0 / coefficients_.f0; }
  void evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> dq,
                Eigen::Ref<Eigen::VectorXd> ddq) const override;

  const FourierCoefficients& coefficients() const { return coefficients_; }

 private:
  FourierCoefficients coefficients_;
};

}  // namespace dynid
