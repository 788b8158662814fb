#include "dynid/io/closed_loop_file.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/joint_columns.hpp"
#include "dynid/io/json_writer.hpp"

namespace dynid {

ReferenceRecord read_reference_columns(const std::string& path, const Model& model,
                                       const RunFileOptions& options, const JointRecord& run) {
  const bool positional = columns_by_position(options.columns);
  CsvTable table = positional ? read_csv_without_header(path) : read_csv(path);
  apply_column_mapping(table, options.columns);
  std::vector<std::string> names;
  for (const Joint& j : model.joints) names.push_back(j.name);
  ReferenceRecord out;
  if (!has_joint_columns(table.columns, names, "qr")) return out;
  // The run's first sample in the file: by its time stamp (t column), else by --rate's grid.
  Eigen::Index first = 0;
  const auto tc = checked_time_column(table);
  const Eigen::Index m = run.t.size();
  if (tc) {
    const Eigen::VectorXd t = table.data.col(*tc);
    while (first < t.size() && t[first] != run.t[0]) ++first;
  } else if (options.rate_hz > 0.0) {
    first = static_cast<Eigen::Index>(std::llround(run.t[0] * options.rate_hz));
  }
  if (first + m > table.rows())
    throw Error("'" + path + "': the reference columns do not cover the run's samples");
  auto take = [&](const char* prefix) {
    return Eigen::MatrixXd(joint_signal(table, names, prefix).middleRows(first, m));
  };
  out.qr = take("qr");
  if (has_joint_columns(table.columns, names, "dqr")) out.dqr = take("dqr");
  if (has_joint_columns(table.columns, names, "ddqr")) out.ddqr = take("ddqr");
  return out;
}

SensorNoise sensor_noise_from_json(const nlohmann::json& j, const Model& model, bool averaged,
                                   const std::string& name) {
  if (!j.is_object() || !j.contains("channels") || !j["channels"].is_array())
    throw Error(name + " has no channels list; give the file of dynid average --json");
  const std::string field = averaged ? "std_averaged" : "std";
  const int n = model.dof();
  SensorNoise out;
  out.q.resize(n);
  out.tau.resize(n);
  auto find = [&](const std::string& prefix, int joint) {
    const std::string a = prefix + std::to_string(joint + 1);
    const std::string b = prefix + "_" + model.joints[static_cast<size_t>(joint)].name;
    for (const auto& c : j["channels"]) {
      if (!c.is_object() || !c.contains("name") || !c["name"].is_string()) continue;
      const std::string channel = c["name"].get<std::string>();
      if (channel != a && channel != b) continue;
      if (!c.contains(field) || !c[field].is_number() || !std::isfinite(c[field].get<double>()) ||
          c[field].get<double>() < 0.0)
        throw Error(
            name + ": channel " + channel + " has no finite " + field +
            " >= 0; give the file of dynid average --json" +
            (averaged ? " (a file written before std_averaged existed: average again)" : ""));
      return c[field].get<double>();
    }
    throw Error(name + " has no channel " + a +
                ": average the run with its q and tau columns (dynid average)");
  };
  for (int k = 0; k < n; ++k) {
    out.q[k] = find("q", k);
    out.tau[k] = find("tau", k);
  }
  return out;
}

SensorNoise read_sensor_noise(const std::string& path, const Model& model, const std::string& data,
                              std::string* which) {
  require_regular_file(path, "--noise");
  std::ifstream in(path);
  if (!in) throw Error("--noise '" + path + "' cannot be opened; check the path");
  nlohmann::json j;
  try {
    in >> j;
  } catch (const nlohmann::json::exception&) {
    throw Error("--noise '" + path + "' is not JSON; give the file of dynid average --json");
  }
  const std::string name = "--noise '" + path + "'";
  if (!j.is_object()) return sensor_noise_from_json(j, model, false, name);
  // The mean period's noise is the raw one over √(periods·decimate): fitting the mean with the
  // raw std misstates the variance factor by that ratio (docs/methods/closed_loop.md).
  auto same_file = [](const nlohmann::json& file, const std::string& other) {
    std::error_code ec;
    return !other.empty() && file.is_string() &&
           std::filesystem::equivalent(file.get<std::string>(), other, ec) && !ec;
  };
  const bool averaged = same_file(j.value("out", nlohmann::json()), data);
  if (which) {
    if (averaged)
      *which = path + ": std_averaged, the noise of the mean period " + data + " (" +
               j.value("periods", nlohmann::json()).dump() + " periods averaged)";
    else if (!data.empty() && !same_file(j.value("data", nlohmann::json()), data))
      *which = path + ": std, the raw per-sample noise of " +
               j.value("data", nlohmann::json("?")).dump() + "; " + data +
               " is neither that run nor its mean period (out), so it is taken as raw";
    else
      *which = path + ": std, the raw per-sample noise of the run " + data;
  }
  return sensor_noise_from_json(j, model, averaged, name);
}

SensorNoise parse_noise_std(const std::string& text, int joints) {
  SensorNoise out;
  std::stringstream s(text);
  std::string item;
  const std::string usage =
      "--noise-std '" + text + "' is not q=S,tau=S (raw sensor noise std per joint, rad and N m)";
  while (std::getline(s, item, ',')) {
    const auto eq = item.find('=');
    if (eq == std::string::npos) throw UsageError(usage);
    const std::string key = item.substr(0, eq), value = item.substr(eq + 1);
    double v = 0.0;
    try {
      size_t used = 0;
      v = std::stod(value, &used);
      if (used != value.size()) throw UsageError(usage);
    } catch (const std::exception&) {
      throw UsageError(usage);
    }
    if (!std::isfinite(v) || v < 0.0)
      throw UsageError("--noise-std " + key + "=" + value + " is not a finite std >= 0");
    if (key == "q")
      out.q = Eigen::VectorXd::Constant(joints, v);
    else if (key == "tau")
      out.tau = Eigen::VectorXd::Constant(joints, v);
    else
      throw UsageError(usage);
  }
  return out;
}

namespace {

nlohmann::json vector_json(const Eigen::VectorXd& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(json_number(v[i]));
  return out;
}

nlohmann::json one_run(const ClosedLoopReport& r) {
  nlohmann::json j;
  j["dimensions_per_channel"] = r.rank;
  nlohmann::json held = nlohmann::json::array();  // 1-based, as the joints are numbered in qr<J>
  for (int h : r.held_joints) held.push_back(h + 1);
  j["held_joints"] = held;
  if (r.method == ClosedLoopMethod::kProjection) {
    if (r.reference_dimensions > 0) j["reference_dimensions"] = r.reference_dimensions;
    j["method"] = "projection";
    j["M1"] = r.m1;
    j["M2"] = r.m2;
    j["correlation"] = vector_json(r.correlation);
    j["remainder_test"] = {{"max_z", json_number(r.max_z)},
                           {"threshold", json_number(r.threshold)},
                           {"passed", r.test_passed}};
  } else {
    const ExcitationSpectrum& s = r.spectrum;
    j["method"] = "spectral";
    j["M1"] = 0;
    j["M2"] = 0;
    j["correlation"] = vector_json(r.correlation);
    j["spectrum"] = {{"f0_hz", json_number(s.f0_hz)},
                     {"period_samples", s.period_samples},
                     {"periods", s.periods},
                     {"band_harmonic", s.band_harmonic},
                     {"lines", s.lines},
                     {"reference_energy_above_band", vector_json(s.reference_energy_above_band)},
                     {"torque_energy_removed", vector_json(s.torque_energy_removed)}};
  }
  return j;
}

}  // namespace

nlohmann::json closed_loop_to_json(const std::vector<ClosedLoopReport>& reports) {
  if (reports.empty()) return nullptr;
  nlohmann::json j = one_run(reports.front());
  if (reports.size() > 1) {
    j["runs"] = nlohmann::json::array();
    for (const auto& r : reports) j["runs"].push_back(one_run(r));
  }
  return j;
}

nlohmann::json repeated_to_json(const RepeatedEstimate& r, const std::string& over) {
  nlohmann::json j;
  j["over"] = over;
  j["n"] = r.n;
  j["confidence_level"] = r.confidence_level;
  j["parameters"] = nlohmann::json::array();
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    j["parameters"].push_back({{"name", r.names[i]},
                               {"mean", json_number(r.mean[k])},
                               {"std", json_number(r.std_dev[k])},
                               {"ci_half_width", json_number(r.ci_half_width[k])}});
  }
  return j;
}

}  // namespace dynid
