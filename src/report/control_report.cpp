#include "dynid/report/control_report.hpp"

#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <vector>

#include "dynid/io/csv_writer.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/version.hpp"

namespace dynid {

nlohmann::json control_comparison_to_json(const Model& model, const ControlComparison& c,
                                          double reversal_window) {
  nlohmann::json controllers = nlohmann::json::array();
  for (const TrackingErrors& e : c.controllers) {
    nlohmann::json joints = nlohmann::json::array();
    for (int j = 0; j < model.dof(); ++j) {
      joints.push_back({{"name", model.joints[j].name},
                        {"rms", json_number(e.rms[j])},
                        {"max", json_number(e.max[j])},
                        {"max_at_reversal", json_number(e.max_at_reversal[j])},
                        {"reversals", e.reversals[j]}});
    }
    controllers.push_back({{"name", e.controller}, {"joints", joints}});
  }
  auto list = [](const Eigen::VectorXd& v) {
    return std::vector<double>(v.data(), v.data() + v.size());
  };
  return {{"controllers", controllers},
          {"gains", {{"kp", list(c.gains.kp)}, {"ki", list(c.gains.ki)}, {"kd", list(c.gains.kd)}}},
          {"samples", c.samples},
          {"reversal_window", reversal_window},
          {"version", kVersion}};
}

std::string control_comparison_table(const Model& model, const ControlComparison& c) {
  std::ostringstream s;
  s << "tracking error after the first period (" << c.samples
    << " samples), deg (revolute) or mm (prismatic)\n";
  char line[256];
  std::snprintf(line, sizeof line, "%-12s", "joint");
  s << line;
  for (const TrackingErrors& e : c.controllers) {
    std::snprintf(line, sizeof line, " | %15.15s %9s %9s", (e.controller + " rms").c_str(), "max",
                  "reversal");
    s << line;
  }
  s << '\n';
  for (int j = 0; j < model.dof(); ++j) {
    const double unit = model.joints[j].type == JointType::kRevolute ? 180.0 / M_PI : 1000.0;
    std::snprintf(line, sizeof line, "%-12.12s", model.joints[j].name.c_str());
    s << line;
    for (const TrackingErrors& e : c.controllers) {
      std::snprintf(line, sizeof line, " | %15.4g %9.4g %9.4g", unit * e.rms[j], unit * e.max[j],
                    unit * e.max_at_reversal[j]);
      s << line;
    }
    s << '\n';
  }
  return s.str();
}

void write_error_histograms(const std::string& path, const Model& model,
                            const SimulationValidation& v, int bins) {
  const int n = model.dof();
  std::vector<std::string> columns;
  Eigen::MatrixXd data(bins, 6 * n);
  for (int j = 0; j < n; ++j) {
    const std::string s = std::to_string(j + 1);
    columns.insert(columns.end(), {"q_err" + s, "q_pdf" + s, "q_gauss" + s, "tau_err" + s,
                                   "tau_pdf" + s, "tau_gauss" + s});
    const Eigen::Index used = v.position[static_cast<size_t>(j)].samples;
    const ErrorHistogram q = error_histogram(v.position_error.col(j).tail(used), bins);
    const ErrorHistogram tau = error_histogram(v.torque_error.col(j).tail(used), bins);
    data.middleCols(6 * j, 6) << q.center, q.density, q.gaussian, tau.center, tau.density,
        tau.gaussian;
  }
  write_csv(path, columns, data);
}

}  // namespace dynid
