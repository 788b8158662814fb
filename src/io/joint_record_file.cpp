#include "dynid/io/joint_record_file.hpp"

#include "dynid/common/error.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/signal/differentiation.hpp"

namespace dynid {

JointRecord read_joint_record(const std::string& path, const Model& model,
                              const RunFileOptions& options) {
  CsvTable table = read_csv(path);
  apply_column_mapping(table, options.columns);
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  auto has = [&](const char* prefix) { return has_joint_columns(table.columns, names, prefix); };
  JointRecord r;
  if (const auto t = checked_time_column(table)) {
    r.t = table.data.col(*t);
  } else if (options.rate_hz > 0.0) {
    r.t = Eigen::VectorXd::LinSpaced(table.rows(), 0.0, (table.rows() - 1) / options.rate_hz);
  } else {
    throw UsageError("'" + path +
                     "' has no time column 't'; add one or give the sample rate with --rate HZ");
  }
  const bool joint_q = has("q"), motor_q = has("qm");
  if (joint_q && motor_q) {
    throw Error("'" + path +
                "' has both q* and qm* columns; keep one side or rename with --columns");
  }
  if (!joint_q && !motor_q) {
    // Let the resolver produce its precise message about the missing joint columns.
    joint_signal(table, names, "q");
  }
  r.q = joint_q ? joint_signal(table, names, "q")
                : joint_positions_from_motor(model, joint_signal(table, names, "qm"));
  const bool joint_tau = has("tau"), motor_tau = has("taum");
  if (joint_tau && motor_tau) {
    throw Error("'" + path +
                "' has both tau* and taum* columns; keep one side or rename with --columns");
  }
  r.tau = motor_tau ? joint_torques_from_motor(model, joint_signal(table, names, "taum"))
                    : joint_signal(table, names, "tau");
  if (has("dq")) r.dq = joint_signal(table, names, "dq");
  if (has("ddq")) r.ddq = joint_signal(table, names, "ddq");
  return r;
}

JointRecord read_reference(const std::string& path, const Model& model,
                           const RunFileOptions& options) {
  CsvTable table = read_csv(path);
  apply_column_mapping(table, options.columns);
  const auto t = checked_time_column(table);
  if (!t)
    throw Error("'" + path + "' has no time column 't'; write the reference with dynid excite");
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  JointRecord r;
  r.t = table.data.col(*t);
  r.q = joint_signal(table, names, "q");
  r.dq = has_joint_columns(table.columns, names, "dq") ? joint_signal(table, names, "dq")
                                                       : central_difference(r.t, r.q, 1);
  r.ddq = has_joint_columns(table.columns, names, "ddq") ? joint_signal(table, names, "ddq")
                                                         : central_difference(r.t, r.dq, 1);
  return r;
}

}  // namespace dynid
