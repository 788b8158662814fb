#pragma once

#include <random>
#include <string>

#include <Eigen/Geometry>

#include "dynid/model/model.hpp"

namespace dynid::testing {

/// A random but physical rigid body: mass in [0.5, 5] kg, centre of mass within 0.3 m, principal
/// moments satisfying the triangle inequality, random principal axes.
inline LinkParams random_link(std::mt19937& rng) {
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double m = 0.5 + 4.5 * (0.5 + 0.5 * u(rng));
  const Eigen::Vector3d c(0.3 * u(rng), 0.3 * u(rng), 0.3 * u(rng));
  // Principal moments from a random box: Ixx = m(b²+c²)/12 etc. always meet the triangle
  // inequality.
  const Eigen::Vector3d box =
      (Eigen::Vector3d(u(rng), u(rng), u(rng)).cwiseAbs().array() + 0.05).matrix();
  const Eigen::Vector3d d(m * (box.y() * box.y() + box.z() * box.z()) / 12.0,
                          m * (box.x() * box.x() + box.z() * box.z()) / 12.0,
                          m * (box.x() * box.x() + box.y() * box.y()) / 12.0);
  const Eigen::Matrix3d R =
      Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
  return link_params_from_com(m, c, R * d.asDiagonal() * R.transpose());
}

/// A random tree of n joints: random parents (a chain when `chain`), random origin rotations and
/// offsets, random unit axes, every third joint prismatic when `prismatic`, and random friction.
inline Model random_tree(int n, unsigned seed, bool prismatic, bool chain = false) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Model model;
  model.name = "random_tree_" + std::to_string(seed);
  for (int j = 0; j < n; ++j) {
    Joint joint;
    joint.name = "j" + std::to_string(j + 1);
    joint.link_name = "l" + std::to_string(j + 1);
    joint.parent =
        chain ? j - 1 : (j == 0 ? -1 : std::uniform_int_distribution<int>(-1, j - 1)(rng));
    joint.type = (prismatic && j % 3 == 2) ? JointType::kPrismatic : JointType::kRevolute;
    joint.R_PJ = Eigen::Quaterniond(u(rng), u(rng), u(rng), u(rng)).normalized().toRotationMatrix();
    joint.p_PJ = Eigen::Vector3d(0.5 * u(rng), 0.5 * u(rng), 0.5 * u(rng));
    joint.axis = Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized();
    joint.friction = {0.1 + 0.1 * u(rng), 0.5 + 0.3 * u(rng), 0.3 + 0.2 * u(rng), 0.1 * u(rng)};
    model.joints.push_back(joint);
    model.links.push_back(random_link(rng));
  }
  model.gravity = Eigen::Vector3d(0.3, -0.2, -9.81);
  model.finalize();
  return model;
}

inline Eigen::VectorXd random_vector(int n, std::mt19937& rng, double scale = 1.0) {
  std::uniform_real_distribution<double> u(-scale, scale);
  Eigen::VectorXd v(n);
  for (int i = 0; i < n; ++i) v[i] = u(rng);
  return v;
}

/// Relative difference ‖a − b‖ / max(1, ‖b‖).
inline double rel_diff(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(1.0, b.norm());
}

}  // namespace dynid::testing
