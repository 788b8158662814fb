#include "dynid/io/inverse_dynamics_file.hpp"

#include <algorithm>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/csv_writer.hpp"

namespace dynid {

CsvTable inverse_dynamics_table(const Model& model, const CsvTable& states,
                                const InverseDynamicsFileOptions& options) {
  std::vector<std::string> names;
  names.reserve(model.joints.size());
  for (const auto& j : model.joints) names.push_back(j.name);
  const auto time = checked_time_column(states);
  const Eigen::MatrixXd q = joint_signal(states, names, "q");
  const Eigen::MatrixXd dq = joint_signal(states, names, "dq");
  const Eigen::MatrixXd ddq = joint_signal(states, names, "ddq");

  const Eigen::Index n = model.dof();
  const Eigen::Index offset = time ? 1 : 0;
  CsvTable out;
  out.source = states.source;
  if (time) out.columns.push_back("t");
  for (Eigen::Index j = 0; j < n; ++j) out.columns.push_back("tau" + std::to_string(j + 1));
  out.data.resize(states.rows(), n + offset);
  if (time) out.data.col(0) = states.data.col(*time);

  RneaOptions rnea_options;
  rnea_options.joint_terms = options.joint_terms;
  Workspace ws(model);
  Eigen::VectorXd qi(n), dqi(n), ddqi(n), tau(n);
  for (Eigen::Index i = 0; i < states.rows(); ++i) {
    qi = q.row(i).transpose();
    dqi = dq.row(i).transpose();
    ddqi = ddq.row(i).transpose();
    rnea(model, ws, qi, dqi, ddqi, tau, rnea_options);
    if (!tau.allFinite()) {
      // Finite but huge states (dq = 1e155: dq² overflows) give Inf or NaN torques.
      const std::string largest = short_number(std::max(
          {qi.cwiseAbs().maxCoeff(), dqi.cwiseAbs().maxCoeff(), ddqi.cwiseAbs().maxCoeff()}));
      throw Error(states.source + " line " + std::to_string(states.line_of(i)) +
                  ": the torques overflow for these q, dq, ddq (largest |value| " + largest +
                  "); check the row and the units (rad, rad/s, rad/s²)");
    }
    out.data.row(i).segment(offset, n) = tau.transpose();
  }
  return out;
}

Eigen::Index inverse_dynamics_file(const Model& model, const std::string& in_path,
                                   const std::string& out_path,
                                   const InverseDynamicsFileOptions& options) {
  CsvTable states = read_csv(in_path);
  apply_column_mapping(states, options.columns);
  const CsvTable torques = inverse_dynamics_table(model, states, options);
  write_csv(out_path, torques.columns, torques.data);
  return torques.rows();
}

}  // namespace dynid
