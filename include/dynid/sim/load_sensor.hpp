#pragma once

#include <string>

#include <Eigen/Core>

#include "dynid/load/load_identification.hpp"
#include "dynid/model/model.hpp"

namespace dynid {

/// A rigid load behind a wrist force/torque sensor (issue 12 item 4): the sensor frame S is fixed
/// on a link (SensorMount) and the load is rigidly attached to S.
struct MountedLoad {
  SensorMount mount;  ///< carrying link and the sensor's pose on it
  /// The load's ten parameters m mcx mcy mcz Ixx Ixy Ixz Iyy Iyz Izz about S's origin in S
  /// [kg, kg·m, kg·m²] (docs/design.md §3, the order of `dynid payload`).
  Eigen::VectorXd phi = Eigen::VectorXd::Zero(10);
};

/// Reads a load file (docs/cli.md "Load file"): YAML with `mass` [kg], `com` [x, y, z] [m] and
/// `inertia_com` [Ixx, Ixy, Ixz, Iyy, Iyz, Izz] [kg·m²] about the centre of mass, both in the
/// sensor frame; returns phi about the sensor origin (seed 1 eq. 24). Throws dynid::Error naming
/// the file and the key: unreadable or malformed YAML, unknown or missing key, a list of the wrong
/// length, a non-finite number, a mass that is not > 0, an inertia about the centre of mass that
/// is not positive definite or violates a triangle inequality (not a rigid body).
Eigen::VectorXd read_load_file(const std::string& path);

/// The robot with the load merged into the carrying link: the link's standard parameters plus
/// transform_link_params(load, R_LS, p_LS) (the same merge as a URDF fixed joint), so that any
/// plant (native or MuJoCo) moves the robot carrying the load. Throws dynid::Error for a link
/// index out of range or a phi that is not 10 finite values.
Model model_with_load(const Model& robot, const MountedLoad& load);

/// What the sensor reads, per sample, while the robot moves along (q, dq, ddq) (m×n each, joint
/// order, [rad, rad/s, rad/s²]): fx fy fz mx my mz (m×6, [N, N·m], sensor frame), the force and
/// the moment about S's origin that the load exerts on the sensor (drivers' convention; seed 1's
/// F, N of eq. 28 are their negatives). Computed by recursive Newton–Euler on the robot with the
/// load as one more link whose joint frame is S, held still: the force and moment its parent
/// exerts on that link, negated (not from the load regressor K). Throws dynid::Error for sizes or
/// a link out of range.
Eigen::MatrixXd load_sensor_wrench(const Model& robot, const MountedLoad& load,
                                   const Eigen::Ref<const Eigen::MatrixXd>& q,
                                   const Eigen::Ref<const Eigen::MatrixXd>& dq,
                                   const Eigen::Ref<const Eigen::MatrixXd>& ddq);

/// Adds zero-mean Gaussian noise of std force_std [N] to fx fy fz and moment_std [N·m] to mx my mz
/// of an m×6 wrench, from a generator seeded with `seed` (reproducible). Throws dynid::Error for a
/// negative or non-finite std or a wrench that is not m×6.
void add_wrench_noise(Eigen::MatrixXd& wrench, double force_std, double moment_std, unsigned seed);

}  // namespace dynid
