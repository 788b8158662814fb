#include "dynid/model/transmission.hpp"

#include <Eigen/LU>

#include "dynid/common/error.hpp"

namespace dynid {

namespace {

void check_columns(const Model& model, Eigen::Index cols, const char* what) {
  if (cols != model.dof()) {
    throw Error(std::string(what) + " have " + std::to_string(cols) + " columns but model '" +
                model.name + "' has " + std::to_string(model.dof()) + " joints");
  }
}

double sign(double x) {
  return static_cast<double>((x > 0.0) - (x < 0.0));
}

}  // namespace

Eigen::MatrixXd joint_positions_from_motor(const Model& model,
                                           const Eigen::Ref<const Eigen::MatrixXd>& qm) {
  check_columns(model, qm.cols(), "motor positions");
  const Eigen::MatrixXd N_inv = model.transmission.N.inverse();
  Eigen::MatrixXd q = qm * N_inv.transpose();
  q.rowwise() += model.transmission.q_offset.transpose();
  return q;
}

Eigen::MatrixXd joint_torques_from_motor(const Model& model,
                                         const Eigen::Ref<const Eigen::MatrixXd>& taum) {
  check_columns(model, taum.cols(), "motor torques");
  return taum * model.transmission.N;  // row form of tau = Nᵀ·tau_m
}

std::vector<int> coupled_motors(const Model& model) {
  std::vector<int> out;
  const Eigen::MatrixXd& N = model.transmission.N;
  for (Eigen::Index k = 0; k < N.rows(); ++k) {
    if ((N.row(k).array() != 0.0).count() > 1) out.push_back(static_cast<int>(k));
  }
  return out;
}

int coupling_columns(const Model& model) {
  return 3 * static_cast<int>(coupled_motors(model).size());
}

std::vector<std::string> coupling_column_names(const Model& model) {
  std::vector<std::string> names;
  for (int k : coupled_motors(model)) {
    const std::string s = std::to_string(k + 1);
    names.insert(names.end(), {"Iam" + s, "Fvm" + s, "Fcm" + s});
  }
  return names;
}

void coupling_regressor(const Model& model, const std::vector<int>& motors,
                        const Eigen::Ref<const Eigen::VectorXd>& dq,
                        const Eigen::Ref<const Eigen::VectorXd>& ddq,
                        Eigen::Ref<Eigen::MatrixXd> out) {
  const Eigen::MatrixXd& N = model.transmission.N;
  out.setZero();
  for (size_t c = 0; c < motors.size(); ++c) {
    const Eigen::RowVectorXd n_k = N.row(motors[c]) / N.row(motors[c]).cwiseAbs().maxCoeff();
    const double coulomb = sign(n_k.dot(dq));
    for (int j = 0; j < model.dof(); ++j) {
      if (n_k[j] == 0.0) continue;
      out(j, 3 * c) = n_k[j] * (n_k.dot(ddq) - n_k[j] * ddq[j]);
      out(j, 3 * c + 1) = n_k[j] * (n_k.dot(dq) - n_k[j] * dq[j]);
      out(j, 3 * c + 2) = n_k[j] * coulomb;
    }
  }
}

}  // namespace dynid
