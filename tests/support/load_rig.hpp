#pragma once

// A robot carrying a known load behind a wrist force/torque sensor, for the load identification
// tests: the wrench comes from the recursive Newton-Euler algorithm of the robot with the load as
// an extra link (not from the load regressor K), the motion from analytic joint sines.

#include <cmath>
#include <functional>
#include <random>

#include <Eigen/Core>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/load/load_identification.hpp"
#include "support/random_models.hpp"

namespace dynid::load_rig {

constexpr int kJoints = 6;

// The truth: seed 1 Table I's mass and first moments (1.910 kg steel cuboid) with the inertia of
// a 50×50×97 mm steel cuboid about its centre of mass. Table I's own computed inertias are not
// physically consistent (principal moments about the centre of mass 4.0e-5, 3.27e-3, 4.49e-3
// kg m²: the triangle inequality fails), so they cannot be a rigid body's.
inline Eigen::VectorXd table_one_load() {
  const double m = 1.910;
  const Eigen::Vector3d c = Eigen::Vector3d(0.0573, -0.0210, 0.1394) / m;
  const double a = 0.05, b = 0.05, h = 0.097;
  const Eigen::Vector3d d(m * (b * b + h * h) / 12.0, m * (a * a + h * h) / 12.0,
                          m * (a * a + b * b) / 12.0);
  const Eigen::Matrix3d R = roll_pitch_yaw(0.2, 0.1, -0.3);
  const LinkParams p = link_params_from_com(m, c, R * d.asDiagonal() * R.transpose());
  Eigen::VectorXd phi(10);
  phi << p(9), p(6), p(7), p(8), p(0), p(1), p(2), p(3), p(4), p(5);
  return phi;
}

inline LinkParams to_link_order(const Eigen::VectorXd& phi) {
  LinkParams p;
  p << phi(4), phi(5), phi(6), phi(7), phi(8), phi(9), phi(1), phi(2), phi(3), phi(0);
  return p;
}

// A 6-joint chain with the sensor at `mount` on its last link, and the same chain with the load as
// a seventh link whose joint frame is the sensor frame (held still): RNEA's force and moment on
// that link are the wrench the sensor exerts on the load (seed 1's F, N), independently of K.
struct Rig {
  Model robot;
  Model loaded;
  SensorMount mount;
};

inline Rig make_rig(const Model& robot, const Eigen::VectorXd& phi, const SensorMount& mount) {
  Rig rig;
  rig.robot = robot;
  rig.mount = mount;
  rig.loaded = rig.robot;
  Joint holder;
  holder.name = "sensor";
  holder.link_name = "load";
  holder.parent = mount.link;
  holder.R_PJ = rig.mount.R_LS;
  holder.p_PJ = rig.mount.p_LS;
  rig.loaded.joints.push_back(holder);
  rig.loaded.links.push_back(to_link_order(phi));
  rig.loaded.transmission = Transmission{};
  rig.loaded.finalize();
  return rig;
}

// A random 6-joint chain with the sensor at a fixed offset pose on its last link.
inline Rig random_rig(const Eigen::VectorXd& phi, unsigned seed) {
  SensorMount mount;
  mount.link = kJoints - 1;
  mount.R_LS = roll_pitch_yaw(0.3, -0.2, 0.5);
  mount.p_LS = Eigen::Vector3d(0.02, -0.01, 0.08);
  return make_rig(testing::random_tree(kJoints, seed, false, true), phi, mount);
}

// Joint motion: a sum of two sines per joint with exact derivatives.
inline void trajectory(double t, Eigen::VectorXd& q, Eigen::VectorXd& dq, Eigen::VectorXd& ddq) {
  q.resize(kJoints);
  dq.resize(kJoints);
  ddq.resize(kJoints);
  for (int j = 0; j < kJoints; ++j) {
    const double a1 = 0.6 + 0.1 * j, w1 = 1.1 + 0.37 * j, a2 = 0.3, w2 = 2.3 + 0.21 * j;
    q(j) = a1 * std::sin(w1 * t + j) + a2 * std::sin(w2 * t);
    dq(j) = a1 * w1 * std::cos(w1 * t + j) + a2 * w2 * std::cos(w2 * t);
    ddq(j) = -a1 * w1 * w1 * std::sin(w1 * t + j) - a2 * w2 * w2 * std::sin(w2 * t);
  }
}

struct LoadRun {
  JointRecord record;
  Eigen::MatrixXd reading;  // m×6: what the sensor reports (force of the load on the sensor)
};

// Joint motion at time t: q, dq, ddq (sized by the callee to the robot's joint count).
using Motion = std::function<void(double, Eigen::VectorXd&, Eigen::VectorXd&, Eigen::VectorXd&)>;

// The run from t0 to t0 + duration along `motion`; record.tau holds the joint torques of the
// loaded robot (rigid body only: the loaded model's joint terms are left out).
inline LoadRun simulate(const Rig& rig, double duration, double rate, double t0 = 0.0,
                        const Motion& motion = trajectory) {
  const int n = rig.robot.dof();
  const auto m = static_cast<Eigen::Index>(std::lround(duration * rate)) + 1;
  LoadRun run;
  run.record.t.resize(m);
  run.record.q.resize(m, n);
  run.record.dq.resize(m, n);
  run.record.ddq.resize(m, n);
  run.reading.resize(m, 6);
  run.record.tau.resize(m, n);
  Workspace ws(rig.loaded);
  Eigen::VectorXd q, dq, ddq, tau(n + 1);
  // The load's joint is held at zero: its frame is the sensor frame.
  Eigen::VectorXd q_all = Eigen::VectorXd::Zero(n + 1), dq_all = q_all, ddq_all = q_all;
  RneaOptions options;
  options.joint_terms = false;
  for (Eigen::Index k = 0; k < m; ++k) {
    const double t = t0 + static_cast<double>(k) / rate;
    motion(t, q, dq, ddq);
    run.record.t(k) = t;
    run.record.q.row(k) = q.transpose();
    run.record.dq.row(k) = dq.transpose();
    run.record.ddq.row(k) = ddq.transpose();
    q_all.head(n) = q;
    dq_all.head(n) = dq;
    ddq_all.head(n) = ddq;
    rnea(rig.loaded, ws, q_all, dq_all, ddq_all, tau, options);
    run.record.tau.row(k) = tau.head(n).transpose();
    run.reading.row(k).head<3>() = -ws.links[n].f.transpose();
    run.reading.row(k).tail<3>() = -ws.links[n].n.transpose();
  }
  return run;
}

inline void add_noise(Eigen::MatrixXd& reading, unsigned seed, double force_std,
                      double moment_std) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> f(0.0, force_std), n(0.0, moment_std);
  for (Eigen::Index k = 0; k < reading.rows(); ++k) {
    for (int c = 0; c < 3; ++c) reading(k, c) += f(rng);
    for (int c = 3; c < 6; ++c) reading(k, c) += n(rng);
  }
}

}  // namespace dynid::load_rig
