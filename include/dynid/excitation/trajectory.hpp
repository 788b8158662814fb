#pragma once

#include <Eigen/Core>

namespace dynid {

/// Common interface of every joint-space trajectory family (Fourier series, polynomial splines,
/// slopes, bang-bang, trapezoidal moves). A trajectory is defined on [0, duration()]; periodic
/// families (Fourier) repeat with period() and may be evaluated at any t.
class Trajectory {
 public:
  virtual ~Trajectory() = default;

  /// Number of joints n.
  virtual int dof() const = 0;

  /// Length of the motion [s]; for a periodic trajectory one period.
  virtual double duration() const = 0;

  /// Period [s] if the trajectory repeats, 0 otherwise.
  virtual double period() const { return 0.0; }

  /// Joint positions, velocities and accelerations at time t [s] (sizes n; rad or m, /s, /s²).
  /// Outside [0, duration()] a non-periodic trajectory holds its end states (zero velocity and
  /// acceleration). No allocation: q, dq, ddq must already have size n.
  virtual void evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> dq,
                        Eigen::Ref<Eigen::VectorXd> ddq) const = 0;
};

}  // namespace dynid
