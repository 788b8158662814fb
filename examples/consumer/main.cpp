// A few lines against the installed library: load a built-in robot (found in the install prefix's
// share/dynid/robots), compute the inverse dynamics at a state by the recursive Newton-Euler
// algorithm and by the joint-torque regressor times the standard parameters (tau = Y·theta), and
// check that the two agree.
//
// Usage: consumer [ROBOT]   (a built-in name or a .urdf / .yaml file; default puma560)
// Exit: 0 when the two torques agree, 1 otherwise or with one `error:` line on a bad robot.

#include <cmath>
#include <iostream>
#include <string>

#include <Eigen/Core>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/version.hpp"

int main(int argc, char** argv) {
  const std::string robot = argc > 1 ? argv[1] : "puma560";
  try {
    const dynid::Model model = dynid::load_robot(robot);
    const int n = model.dof();
    const Eigen::VectorXd q = Eigen::VectorXd::LinSpaced(n, 0.1, 0.7);
    const Eigen::VectorXd dq = Eigen::VectorXd::LinSpaced(n, -0.5, 0.5);
    const Eigen::VectorXd ddq = Eigen::VectorXd::LinSpaced(n, 1.0, -1.0);

    const Eigen::VectorXd tau = dynid::rnea(model, q, dq, ddq);

    const dynid::ParameterLayout layout = dynid::ParameterLayout::full();
    dynid::Workspace ws(model);
    Eigen::MatrixXd Y(n, layout.columns(n));
    dynid::torque_regressor(model, ws, layout, q, dq, ddq, Y);
    const Eigen::VectorXd tau_regressor = Y * layout.parameters(model);

    const double difference = (tau - tau_regressor).cwiseAbs().maxCoeff();
    std::cout << "dynid " << dynid::kVersion << ", robot " << model.name << " (" << n
              << " joints)\ntau = " << tau.transpose() << " N.m\n|tau - Y.theta| = " << difference
              << '\n';
    return difference <= 1e-9 * (1.0 + tau.cwiseAbs().maxCoeff()) ? 0 : 1;
  } catch (const dynid::Error& e) {
    std::cerr << "error: " << e.what() << '\n';
    return 1;
  }
}
