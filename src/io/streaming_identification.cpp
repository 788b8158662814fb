#include "dynid/io/streaming_identification.hpp"

#include "dynid/common/error.hpp"
#include "dynid/estimation/streaming_least_squares.hpp"
#include "dynid/io/csv_chunk_reader.hpp"
#include "dynid/regressor/torque_regressor.hpp"

namespace dynid {

IdentificationResult identify_stream(const Model& model, const std::string& path,
                                     const RunFileOptions& file, const IdentifyOptions& options) {
  if (options.signal.filter) {
    throw UsageError(
        "streaming identification reads the file once and cannot filter it; use "
        "--filter none with dq and ddq columns, or drop --stream");
  }
  if (options.estimator == IdentificationEstimator::kRls) {
    throw UsageError("streaming identification supports --estimator ols or wls");
  }
  const int n = model.dof();
  IdentificationResult result;
  BaseParameterOptions base_options = options.base;
  base_options.layout = options.layout;
  result.base = compute_base_parameters(model, base_options);
  result.names = result.base.names;
  result.expressions = result.base.expressions;
  result.unidentifiable = result.base.unidentifiable_names();
  result.rank = result.base.rank;
  const int rank = result.rank;

  CsvChunkReader reader(path);
  std::vector<std::string> columns = reader.columns();
  for (auto& name : columns) {
    for (const auto& [from, to] : file.columns) {
      if (name == from) name = to;
    }
  }
  std::vector<std::string> joints;
  for (const Joint& j : model.joints) joints.push_back(j.name);
  for (const char* prefix : {"dq", "ddq"}) {
    if (!has_joint_columns(columns, joints, prefix)) {
      throw UsageError("'" + path + "' has no " + prefix +
                       "* columns; streaming identification needs q, dq, ddq and tau on the joint "
                       "side (drop --stream to derive them)");
    }
  }
  const auto cq = resolve_joint_columns(columns, joints, "q", path);
  const auto cdq = resolve_joint_columns(columns, joints, "dq", path);
  const auto cddq = resolve_joint_columns(columns, joints, "ddq", path);
  const auto ctau = resolve_joint_columns(columns, joints, "tau", path);
  Eigen::VectorXd threshold = Eigen::VectorXd::Zero(n);
  const auto& zv = options.signal.zero_velocity;
  if (zv.size() == 1) threshold.setConstant(zv[0]);
  if (static_cast<int>(zv.size()) == n) threshold = Eigen::Map<const Eigen::VectorXd>(zv.data(), n);
  if (!zv.empty() && zv.size() != 1 && static_cast<int>(zv.size()) != n) {
    throw UsageError("--zero-velocity takes 1 or " + std::to_string(n) + " values");
  }
  result.choices.emplace_back("mode",
                              "streaming (constant memory), no filtering, dq and ddq as given");

  StreamingLeastSquares lsq(rank, n);
  Workspace ws(model);
  const int p = options.layout.columns(n);
  Eigen::MatrixXd Y(n, p), block;
  Eigen::VectorXd q(n), dq(n), ddq(n);
  Eigen::MatrixXd Wb;
  Eigen::VectorXd yb;
  Eigen::VectorXi gb;
  Eigen::Index samples = 0, rows = 0;
  while (reader.next(block)) {
    Wb.resize(block.rows() * n, rank);
    yb.resize(block.rows() * n);
    gb.resize(block.rows() * n);
    Eigen::Index r = 0;
    for (Eigen::Index k = 0; k < block.rows(); ++k) {
      for (int j = 0; j < n; ++j) {
        q[j] = block(k, cq[j]);
        dq[j] = block(k, cdq[j]);
        ddq[j] = block(k, cddq[j]);
      }
      torque_regressor(model, ws, options.layout, q, dq, ddq, Y);
      for (int j = 0; j < n; ++j) {
        if (std::abs(dq[j]) < threshold[j]) continue;
        for (int c = 0; c < rank; ++c) Wb(r, c) = Y(j, result.base.base[c]);
        yb[r] = block(k, ctau[j]);
        gb[r] = j;
        ++r;
      }
    }
    lsq.add(Wb.topRows(r), yb.head(r), gb.head(r));
    samples += block.rows();
    rows += r;
  }
  result.samples = samples;
  result.rows = rows;
  if (rows <= rank) {
    throw Error("only " + std::to_string(rows) + " equations in '" + path + "' for " +
                std::to_string(rank) + " base parameters; record a longer run");
  }
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = result.names;
  result.estimate = options.estimator == IdentificationEstimator::kWls ? lsq.solve_weighted(eo)
                                                                       : lsq.solve_ordinary(eo);
  result.residual_rms = result.estimate.group_rms;
  result.joint_relative_error = result.estimate.group_relative_error;
  result.relative_error = result.estimate.relative_error;
  result.condition_number = result.estimate.summary.condition_number;
  result.warnings = result.estimate.summary.warnings;
  return result;
}

}  // namespace dynid
