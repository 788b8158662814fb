#pragma once

#include <random>
#include <vector>

#include <Eigen/Core>

#include "dynid/model/model.hpp"

namespace dynid {

/// Options of the joint sensor models.
struct SensorOptions {
  double counts_per_rev = 0.0;        ///< encoder counts per revolution on revolute joints (step
                                      ///< 2π/counts [rad]); 0 = no quantisation
  double prismatic_resolution = 0.0;  ///< encoder step on prismatic joints [m]; 0 = none
  double position_noise_std = 0.0;    ///< std of white Gaussian noise on positions [rad or m]
  double torque_noise_std = 0.0;      ///< std of white Gaussian noise on torques [N·m or N]
  int position_delay = 0;             ///< delay of the position measurement [samples]; ≥ 0
  int torque_delay = 0;               ///< delay of the torque measurement [samples]; ≥ 0
  unsigned seed = 1;                  ///< seed of the noise generator (std::mt19937_64)
};

/// Joint position and torque sensors: y_k = Q(q_{k−d} + ε_{k−d}), ε ~ N(0, σ_q²), where Q rounds
/// to the nearest encoder count (error uniform in ±step/2); torques m_k = tau_{k−d'} + η_{k−d'},
/// η ~ N(0, σ_τ²). Before d samples have been seen the first sample is repeated (a sensor that
/// holds its initial reading). Call each measure function once per sample.
class Sensors {
 public:
  /// Checks the options (non-negative, finite). Throws dynid::Error naming the field at fault.
  Sensors(const Model& model, const SensorOptions& options);

  /// Clears the delay lines and re-seeds the noise generator with options.seed.
  void reset();

  /// Measured positions y (size n) from the true positions q (size n). No allocation once the
  /// delay line is full.
  void measure_position(const Eigen::Ref<const Eigen::VectorXd>& q, Eigen::Ref<Eigen::VectorXd> y);

  /// Measured torques m (size n) from the applied joint torques tau (size n).
  void measure_torque(const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> m);

  /// Quantisation step per joint (size n, 0 = none) [rad or m].
  const Eigen::VectorXd& resolution() const { return step_; }

 private:
  struct DelayLine {
    std::vector<Eigen::VectorXd> buffer;
    long count = 0;
    void push(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> out);
  };
  SensorOptions options_;
  Eigen::VectorXd step_, scratch_;
  std::mt19937_64 rng_;
  std::normal_distribution<double> normal_;
  DelayLine position_line_, torque_line_;
};

}  // namespace dynid
