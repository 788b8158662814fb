#include "dynid/report/excitation_report.hpp"

#include <sstream>

#include "dynid/io/csv_writer.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/version.hpp"

namespace dynid {

namespace {

const char* criterion_name(ExcitationCriterion c) {
  return c == ExcitationCriterion::kConditionNumber ? "cond" : "logdet";
}

// The one condition number reported (`value` is the same number when the criterion is cond).
constexpr const char* kConditionNumberDefinition =
    "sigma_max / sigma_min of the base regressor W_b (one row per joint and sample, unscaled "
    "columns), stacked over one period on the fine check grid";

std::vector<double> to_std(const Eigen::VectorXd& v) {
  return {v.data(), v.data() + v.size()};
}

}  // namespace

nlohmann::json excitation_to_json(const ExcitationResult& r) {
  nlohmann::json margins = nlohmann::json::array();
  for (const auto& m : r.margins) {
    margins.push_back({{"name", m.name},
                       {"margin", json_number(m.margin)},
                       {"time", m.time},
                       {"limit", json_number(m.limit)},
                       {"reached", json_number(m.reached)},
                       {"unit", m.unit},
                       {"relative", json_number(m.relative)}});
  }
  nlohmann::json a = nlohmann::json::array(), b = nlohmann::json::array();
  for (int i = 0; i < r.coefficients.dof(); ++i) {
    a.push_back(to_std(r.coefficients.a[i]));
    b.push_back(to_std(r.coefficients.b[i]));
  }
  return {{"criterion", criterion_name(r.criterion)},
          // One condition number: for cond the criterion is that number (the optimiser's own
          // value differs from the check grid's in the last digits).
          {"value",
           json_number(r.criterion == ExcitationCriterion::kConditionNumber ? r.condition_number
                                                                            : r.value)},
          {"condition_number", json_number(r.condition_number)},
          {"condition_number_definition", kConditionNumberDefinition},
          {"log_det", json_number(r.log_det)},
          {"constraints_satisfied", r.constraints_satisfied},
          {"margins", margins},
          {"coefficients",
           {{"f0", r.coefficients.f0}, {"a", a}, {"b", b}, {"q0", to_std(r.coefficients.q0)}}},
          {"base_parameters", r.base_names},
          {"evaluations", r.evaluations},
          {"seconds", r.seconds},
          {"version", kVersion}};
}

void write_trajectory_csv(const std::string& path, const TrajectorySamples& s) {
  const Eigen::Index n = s.q.cols();
  std::vector<std::string> columns = {"t"};
  for (const char* prefix : {"q", "dq", "ddq"}) {
    for (Eigen::Index j = 0; j < n; ++j) columns.push_back(prefix + std::to_string(j + 1));
  }
  Eigen::MatrixXd data(s.t.size(), 1 + 3 * n);
  data << s.t, s.q, s.dq, s.ddq;
  write_csv(path, columns, data);
}

std::string excitation_text(const ExcitationResult& r) {
  std::ostringstream s;
  if (r.criterion == ExcitationCriterion::kConditionNumber) {
    s << "condition number " << r.condition_number;
  } else {
    s << "log det(W_b^T W_b) " << r.log_det << ", condition number " << r.condition_number;
  }
  s << " (sigma_max/sigma_min of the base regressor over one period), " << r.evaluations
    << " evaluations in " << r.seconds << " s\n"
    << "constraints " << (r.constraints_satisfied ? "satisfied" : "VIOLATED")
    << " at every sample of the check grid; worst margins:\n";
  for (const auto& m : r.margins)
    s << "  " << m.name << ": " << m.margin << " at t = " << m.time << " s\n";
  return s.str();
}

}  // namespace dynid
