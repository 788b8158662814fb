#include "dynid/report/html_report.hpp"
#include "dynid/identification/validation.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/identification/integral_equations.hpp"
#include "dynid/identification/pipeline.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/markup.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/sim/error_statistics.hpp"
#include "dynid/version.hpp"

namespace dynid {
namespace {

using Json = nlohmann::json;

// Plotted series are capped at this many points whatever the input carries (a friction
// experiment's `fit` holds every cruise sample): the browser, not the data, sets the limit.
constexpr int kMaxSeriesPoints = 2000;
constexpr int kTrajectoryPoints = 400;  // samples of one excitation period
constexpr double kPi = 3.14159265358979323846;

// Numbers rounded to `digits` significant digits print short (nlohmann writes the shortest
// representation that reads back); non-finite ones become null, which the page skips.
Json rounded(double x, int digits) {
  if (!std::isfinite(x)) return nullptr;
  if (x == 0.0) return 0.0;
  const double scale =
      std::pow(10.0, digits - 1 - static_cast<int>(std::floor(std::log10(std::abs(x)))));
  return std::round(x * scale) / scale;
}

// Every k-th index of [0, n) with k the smallest step that keeps at most max_points.
std::vector<Eigen::Index> display_indices(Eigen::Index n, int max_points) {
  const Eigen::Index step =
      std::max<Eigen::Index>(1, (n + max_points - 1) / std::max(1, max_points));
  std::vector<Eigen::Index> out;
  for (Eigen::Index i = 0; i < n; i += step) out.push_back(i);
  return out;
}

double number_or_nan(const Json& j) {
  return j.is_number() ? j.get<double>() : std::numeric_limits<double>::quiet_NaN();
}

// A JSON array of numbers (nulls kept as NaN) or an empty vector.
std::vector<double> numbers_of(const Json& j) {
  std::vector<double> out;
  if (!j.is_array()) return out;
  out.reserve(j.size());
  for (const auto& x : j) out.push_back(number_or_nan(x));
  return out;
}

// A series for the page: y (and x unless the chart has labels), decimated and rounded.
Json series(const std::string& label, const std::vector<double>& x, const std::vector<double>& y,
            const char* kind = "line") {
  Json xs = Json::array(), ys = Json::array();
  const auto n = static_cast<Eigen::Index>(std::min(x.size(), y.size()));
  for (Eigen::Index i : display_indices(n, kMaxSeriesPoints)) {
    xs.push_back(rounded(x[static_cast<size_t>(i)], 6));
    ys.push_back(rounded(y[static_cast<size_t>(i)], 6));
  }
  return {{"label", label}, {"x", xs}, {"y", ys}, {"kind", kind}};
}

Json line_chart(const std::string& title, const std::string& x_label, const std::string& y_label,
                Json list) {
  return {{"title", title},
          {"type", "line"},
          {"x_label", x_label},
          {"y_label", y_label},
          {"series", std::move(list)}};
}

std::string text_of(const Json& j) {
  if (j.is_string()) return j.get<std::string>();
  if (j.is_null()) return "n/a";
  if (j.is_number_float()) {
    std::ostringstream s;
    s.precision(5);
    s << j.get<double>();
    return s.str();
  }
  return j.dump();
}

std::string percent(const Json& j) {
  if (!j.is_number()) return "n/a";
  std::ostringstream s;
  s.precision(4);
  s << 100.0 * j.get<double>() << " %";
  return s.str();
}

std::string joined(const Json& list, const std::string& none = "none") {
  if (!list.is_array() || list.empty()) return none;
  std::string out;
  for (const auto& x : list) out += (out.empty() ? "" : ", ") + text_of(x);
  return out;
}

std::vector<std::string> joint_names_of(const Json& result, size_t n) {
  std::vector<std::string> names;
  if (result.contains("model") && result["model"].is_object() &&
      result["model"].contains("joints") && result["model"]["joints"].is_array()) {
    for (const auto& j : result["model"]["joints"]) names.push_back(text_of(j));
  }
  for (size_t j = names.size(); j < n; ++j) names.push_back("joint " + std::to_string(j + 1));
  return names;
}

// Parameters with their confidence intervals as error bars. Values span orders of magnitude
// (kg·m² beside N·m), so each interval is drawn relative to its estimate (the estimate at ±1);
// the tooltip and the table keep the absolute numbers. Colour: %σ below 5 (green), below 20
// (amber), else or undefined (red).
void add_parameters(const Json& result, Json& section) {
  if (!result.contains("parameters") || !result["parameters"].is_array()) return;
  const Json& params = result["parameters"];
  if (params.empty()) return;
  Json labels = Json::array(), low = Json::array(), high = Json::array(), value = Json::array(),
       colors = Json::array(), tips = Json::array(), rows = Json::array();
  // Every parameter's %σ on a log axis: wide intervals do not saturate it (issue 28 item 4).
  Json all_labels = Json::array(), sigma = Json::array(), sigma_colors = Json::array();
  std::vector<std::string> wide;
  bool nominal = false;
  for (const auto& p : params) {
    if (!p.is_object()) continue;
    const std::string name = text_of(p.value("name", Json("?")));
    const double v = number_or_nan(p.value("value", Json()));
    const double lo = number_or_nan(p.value("ci_low", Json()));
    const double hi = number_or_nan(p.value("ci_high", Json()));
    const double rel = number_or_nan(p.value("relative_std_percent", Json()));
    const double scale = std::abs(v) > 0.0 ? std::abs(v) : 1.0;
    const std::string unit = text_of(p.value("unit", Json("")));
    const char* color = !(rel < 20.0) ? "#d62728" : rel < 5.0 ? "#2ca02c" : "#ff9f1c";
    all_labels.push_back(name);
    sigma.push_back(std::isfinite(rel) && rel > 0.0 ? Json(rounded(rel, 4)) : Json());
    sigma_colors.push_back(color);
    if (rel < 20.0) {
      labels.push_back(name);
      value.push_back(rounded(v / scale, 6));
      low.push_back(rounded(lo / scale, 6));
      high.push_back(rounded(hi / scale, 6));
      colors.push_back(color);
      std::ostringstream tip;
      tip.precision(5);
      tip << name << " = " << v << " " << unit << "  [" << lo << ", " << hi << "]  σ " << rel
          << " %";
      tips.push_back(tip.str());
    } else {
      wide.push_back(name);
    }
    rows.push_back({name, text_of(p.value("value", Json())), unit, text_of(p.value("std", Json())),
                    text_of(p.value("relative_std_percent", Json())),
                    text_of(p.value("ci_low", Json())), text_of(p.value("ci_high", Json()))});
    // The nominal model's value beside the estimate (identify results; n/a where it has none).
    if (p.contains("nominal")) {
      nominal = true;
      rows.back().push_back(text_of(p["nominal"]));
    }
  }
  Json columns = {"name", "value", "unit", "std", "%σ", "ci low", "ci high"};
  if (nominal) {
    columns.push_back("nominal");
    for (auto& row : rows)
      if (row.size() < columns.size()) row.push_back("n/a");
  }
  std::string level = "confidence";
  if (result.contains("confidence_level") && result["confidence_level"].is_number()) {
    level = percent(result["confidence_level"]) + " confidence";
  }
  // What an engineer reads first: the values with units and intervals, open above the charts.
  section["tables"].push_back({{"title", "Parameters (" + level + " intervals)"},
                               {"columns", columns},
                               {"rows", rows},
                               {"open", true}});
  if (std::any_of(sigma.begin(), sigma.end(), [](const Json& x) { return x.is_number(); }))
    section["charts"].push_back({{"title",
                                  "Relative standard deviation %σ of every parameter (log "
                                  "axis; green < 5, amber < 20, red ≥ 20)"},
                                 {"type", "bar"},
                                 {"y_label", "%σ"},
                                 {"log", true},
                                 {"labels", all_labels},
                                 {"colors", sigma_colors},
                                 {"series", {{{"label", "%σ"}, {"y", sigma}, {"kind", "bar"}}}},
                                 {"wide", true}});
  if (!labels.empty()) {
    section["charts"].push_back(
        {{"title", "The " + std::to_string(labels.size()) + " parameters within 20 %σ: " + level +
                       " intervals relative to |estimate|"},
         {"type", "interval"},
         {"x_label", "interval / |estimate|"},
         {"labels", labels},
         {"low", low},
         {"high", high},
         {"value", value},
         {"colors", colors},
         {"tips", tips},
         {"wide", true}});
  }
  if (!wide.empty()) {
    std::string list;
    for (const auto& name : wide) list += (list.empty() ? "" : ", ") + name;
    section["facts"].push_back({"%σ ≥ 20 (not drawn as intervals; values in the table)", list});
  }
}

// Per-joint bar chart of one array of the result (residual RMS, relative error).
void add_joint_bars(const Json& values, const std::vector<std::string>& names,
                    const std::string& title, const std::string& y_label, Json& section) {
  if (!values.is_array() || values.empty()) return;
  // A figure the result does not have (null everywhere, e.g. per-component RMS of a recursive
  // fit) is said so, not drawn as an empty chart.
  if (std::none_of(values.begin(), values.end(), [](const Json& v) { return v.is_number(); })) {
    section["facts"].push_back({title, "not reported in this result"});
    return;
  }
  Json labels = Json::array(), ys = Json::array();
  for (size_t j = 0; j < values.size(); ++j) {
    labels.push_back(j < names.size() ? names[j] : std::to_string(j + 1));
    ys.push_back(rounded(number_or_nan(values[j]), 6));
  }
  section["charts"].push_back({{"title", title},
                               {"type", "bar"},
                               {"y_label", y_label},
                               {"labels", labels},
                               {"series", {{{"label", y_label}, {"y", ys}, {"kind", "bar"}}}}});
}

void add_fact(Json& section, const std::string& key, const std::string& value) {
  section["facts"].push_back({key, value});
}

// The charts of a `plot` section (prediction_plot_json, rls_history_plot_json).
void add_prediction_plots(const Json& plot, const std::vector<std::string>& names, Json& section) {
  if (!plot.is_object()) return;
  const std::vector<double> t = numbers_of(plot.value("t", Json()));
  if (plot.contains("joints") && plot["joints"].is_array()) {
    size_t j = 0;
    for (const auto& joint : plot["joints"]) {
      const std::string name =
          text_of(joint.value("name", Json(names.at(std::min(j, names.size() - 1)))));
      ++j;
      const std::vector<double> m = numbers_of(joint.value("measured", Json()));
      const std::vector<double> p = numbers_of(joint.value("predicted", Json()));
      std::vector<double> r(std::min(m.size(), p.size()));
      for (size_t i = 0; i < r.size(); ++i) r[i] = m[i] - p[i];
      section["charts"].push_back(
          line_chart(name + ": measured and predicted torque", "t [s]", "torque [N·m]",
                     {series("measured", t, m), series("predicted", t, p)}));
      section["charts"].push_back(line_chart(name + ": residual", "t [s]", "τ − τ̂ [N·m]",
                                             Json::array({series("residual", t, r)})));
      const Json& h = joint.value("histogram", Json());
      if (h.is_object() && h.value("centers", Json::array()).empty()) {
        add_fact(section, name + ": residual", "identically zero (no histogram)");
      } else if (h.is_object()) {
        std::ostringstream title;
        title.precision(3);
        title << name << ": residual histogram and fitted Gaussian (mean "
              << number_or_nan(h.value("mean", Json())) << ", σ "
              << number_or_nan(h.value("std", Json())) << ", skewness "
              << number_or_nan(h.value("skewness", Json())) << ", kurtosis "
              << number_or_nan(h.value("kurtosis", Json())) << "; Kolmogorov–Smirnov D "
              << number_or_nan(h.value("ks_statistic", Json())) << ", p "
              << number_or_nan(h.value("ks_p_value", Json())) << ")";
        Json labels = Json::array();
        for (double c : numbers_of(h.value("centers", Json()))) labels.push_back(rounded(c, 3));
        section["charts"].push_back(
            {{"title", title.str()},
             {"type", "bar"},
             {"x_label", "residual [N·m]"},
             {"y_label", "density"},
             {"labels", labels},
             {"series",
              {{{"label", "residual"}, {"y", h.value("density", Json::array())}, {"kind", "bar"}},
               {{"label", "Gaussian"},
                {"y", h.value("gaussian", Json::array())},
                {"kind", "line"}}}}});
      }
    }
  }
  const Json& history = plot.value("history", Json());
  if (history.is_object() && history.contains("parameters")) {
    const std::vector<double> ht = numbers_of(history.value("t", Json()));
    for (const auto& p : history["parameters"]) {
      const std::vector<double> v = numbers_of(p.value("value", Json()));
      const std::vector<double> s = numbers_of(p.value("std", Json()));
      std::vector<double> up(v.size()), down(v.size());
      for (size_t i = 0; i < v.size() && i < s.size(); ++i) {
        up[i] = v[i] + s[i];
        down[i] = v[i] - s[i];
      }
      const std::string name = text_of(p.value("name", Json("?")));
      Json chart = line_chart("RLS history of " + name, "t [s]", name,
                              {series("estimate", ht, v), series("+σ", ht, up, "dashed"),
                               series("−σ", ht, down, "dashed")});
      chart["small"] = true;
      section["charts"].push_back(chart);
    }
  }
  const Json& energy = plot.value("energy", Json());
  if (energy.is_object()) {
    const std::vector<double> et = numbers_of(energy.value("t", Json()));
    section["charts"].push_back(line_chart(
        "Energy over the intervals: measured ∫τᵀq̇ dt and the integral model's prediction", "t [s]",
        "energy [J]",
        {series("measured", et, numbers_of(energy.value("measured", Json()))),
         series("predicted", et, numbers_of(energy.value("predicted", Json())))}));
  }
}

Json new_section(const ReportInput& in, const std::string& kind, const std::string& title) {
  Json s = {{"title", title},         {"source", in.source},       {"kind", kind},
            {"facts", Json::array()}, {"warnings", Json::array()}, {"tables", Json::array()},
            {"charts", Json::array()}};
  if (in.result.contains("warnings") && in.result["warnings"].is_array()) {
    for (const auto& w : in.result["warnings"]) s["warnings"].push_back(text_of(w));
  }
  if (in.result.contains("version")) add_fact(s, "dynid version", text_of(in.result["version"]));
  return s;
}

Json identify_section(const ReportInput& in) {
  const Json& r = in.result;
  const std::string model = r.contains("options") && r["options"].is_object()
                                ? text_of(r["options"].value("model", Json("differential")))
                                : "differential";
  Json s = new_section(in, "identify", "Identification (" + model + " model)");
  if (r.contains("model") && r["model"].is_object()) {
    add_fact(s, "robot", text_of(r["model"].value("name", Json("?"))));
  }
  if (r.contains("locked_joints") && r["locked_joints"].is_array() && !r["locked_joints"].empty()) {
    std::string locked;
    for (const Json& l : r["locked_joints"]) {
      if (!l.is_object()) continue;
      locked += (locked.empty() ? "" : ", ") + text_of(l.value("name", Json("?"))) + " = " +
                text_of(l.value("value", Json()));
    }
    add_fact(s, "locked joints (held, not identified)", locked);
  }
  add_fact(s, "estimator", text_of(r.value("estimator", Json())));
  add_fact(s, "samples / equations",
           text_of(r.value("samples", Json())) + " / " + text_of(r.value("rows", Json())));
  add_fact(s, "rank (model / data)",
           text_of(r.value("rank", Json())) + " / " + text_of(r.value("data_rank", Json())));
  add_fact(s, "condition number", text_of(r.value("condition_number", Json())));
  add_fact(s, "relative torque error", percent(r.value("relative_error", Json())));
  add_fact(s, "not excited by these data", joined(r.value("not_excited", Json())));
  add_fact(s, "unidentifiable (no effect)", joined(r.value("unidentifiable", Json())));
  if (r.contains("physical") && r["physical"].is_object()) {
    add_fact(s, "physically consistent fit: relative torque error",
             percent(r["physical"].value("relative_error", Json())) + " (unconstrained " +
                 percent(r["physical"].value("relative_error_unconstrained", Json())) + ")");
  }
  const auto names = joint_names_of(r, r.value("residual_rms", Json::array()).size());
  add_parameters(r, s);
  add_joint_bars(r.value("residual_rms", Json()), names, "Residual RMS per joint", "RMS [N·m]", s);
  add_joint_bars(r.value("joint_relative_error", Json()), names, "Relative error per joint",
                 "‖e‖/‖τ‖", s);
  add_prediction_plots(r.value("plot", Json()), names, s);
  return s;
}

Json validate_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "validate", "Validation: torque prediction on another run");
  add_fact(s, "relative error (rows compared)", percent(r.value("relative_error", Json())));
  add_fact(s, "relative error (every row)", percent(r.value("relative_error_all_rows", Json())));
  add_fact(s, "samples / rows compared",
           text_of(r.value("samples", Json())) + " / " + text_of(r.value("rows", Json())));
  add_fact(s, "near-still rows left out", text_of(r.value("rows_excluded_zero_velocity", Json())));
  std::vector<std::string> names;
  Json rms = Json::array(), rel = Json::array();
  for (const auto& j : r.value("joints", Json::array())) {
    names.push_back(text_of(j.value("name", Json("?"))));
    rms.push_back(j.value("rms_all_rows", Json()));
    rel.push_back(j.value("relative_error_all_rows", Json()));
  }
  add_joint_bars(rms, names, "Prediction RMS per joint (every row)", "RMS [N·m]", s);
  add_joint_bars(rel, names, "Relative error per joint (every row)", "‖e‖/‖τ‖", s);
  add_prediction_plots(r.value("plot", Json()), names, s);
  return s;
}

Json simulation_validation_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "validate-simulation",
                       "Validation by simulation: identified model under the same reference");
  add_fact(s, "samples", text_of(r.value("samples", Json())));
  std::vector<std::string> names;
  Json q_rms = Json::array(), tau_rms = Json::array(), q_p = Json::array(), tau_p = Json::array();
  for (const auto& j : r.value("joints", Json::array())) {
    names.push_back(text_of(j.value("name", Json("?"))));
    q_rms.push_back(j.value("position", Json::object()).value("rms", Json()));
    tau_rms.push_back(j.value("torque", Json::object()).value("rms", Json()));
    q_p.push_back(j.value("position", Json::object()).value("ks_p_value", Json()));
    tau_p.push_back(j.value("torque", Json::object()).value("ks_p_value", Json()));
  }
  add_joint_bars(q_rms, names, "Position error RMS per joint", "RMS [rad or m]", s);
  add_joint_bars(tau_rms, names, "Torque error RMS per joint", "RMS [N·m]", s);
  add_joint_bars(q_p, names, "Position error: Kolmogorov–Smirnov p against a Gaussian", "p", s);
  add_joint_bars(tau_p, names, "Torque error: Kolmogorov–Smirnov p against a Gaussian", "p", s);
  return s;
}

Json payload_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "payload",
                       "Payload identification (" + text_of(r.value("model", Json())) + " model)");
  add_fact(s, "estimator", text_of(r.value("estimator", Json())));
  add_fact(s, "mass [kg]", text_of(r.value("mass", Json())));
  add_fact(s, "centre of mass [m]", joined(r.value("com", Json()), "n/a"));
  add_fact(s, "physically consistent", text_of(r.value("physically_consistent", Json())));
  add_fact(s, "condition number", text_of(r.value("condition_number", Json())));
  add_fact(s, "relative wrench error", percent(r.value("relative_error", Json())));
  add_fact(s, "not excited by these data", joined(r.value("not_excited", Json())));
  add_parameters(r, s);
  const Json& per = r.value("residual_rms_per_component", Json());
  if (per.is_object() && !per.empty()) {
    std::vector<std::string> names;
    Json values = Json::array();
    for (const auto& [k, v] : per.items()) {
      names.push_back(k);
      values.push_back(v);
    }
    add_joint_bars(values, names, "Residual RMS per wrench component", "RMS [N or N·m]", s);
  }
  return s;
}

Json average_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "average", "Period averaging and noise");
  add_fact(s, "period [s]", text_of(r.value("period", Json())));
  add_fact(s, "periods averaged", text_of(r.value("periods", Json())));
  add_fact(s, "samples per period", text_of(r.value("samples_per_period", Json())));
  std::vector<std::string> names;
  Json std_dev = Json::array(), p = Json::array(), kurt = Json::array();
  for (const auto& c : r.value("channels", Json::array())) {
    names.push_back(text_of(c.value("name", Json("?"))));
    std_dev.push_back(c.value("std", Json()));
    p.push_back(c.value("normality_p", Json()));
    kurt.push_back(c.value("kurtosis", Json()));
  }
  add_joint_bars(std_dev, names, "Noise std per channel (deviation from the mean period)", "std",
                 s);
  add_joint_bars(p, names, "Normality test p per channel", "p", s);
  add_joint_bars(kurt, names, "Kurtosis per channel (3 for a Gaussian)", "kurtosis", s);
  return s;
}

Json excite_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "excite", "Excitation trajectory");
  add_fact(s, "criterion",
           text_of(r.value("criterion", Json())) + " = " + text_of(r.value("value", Json())));
  add_fact(s, "condition number", text_of(r.value("condition_number", Json())));
  add_fact(s, "constraints satisfied", text_of(r.value("constraints_satisfied", Json())));
  add_fact(s, "evaluations", text_of(r.value("evaluations", Json())));
  const Json& c = r.value("coefficients", Json());
  if (c.is_object() && c.contains("a") && c.contains("b")) {
    FourierCoefficients fc;
    fc.f0 = number_or_nan(c.value("f0", Json()));
    for (const auto& a : c["a"]) {
      const auto v = numbers_of(a);
      fc.a.push_back(
          Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
    }
    for (const auto& b : c["b"]) {
      const auto v = numbers_of(b);
      fc.b.push_back(
          Eigen::Map<const Eigen::VectorXd>(v.data(), static_cast<Eigen::Index>(v.size())));
    }
    const auto q0 = numbers_of(c.value("q0", Json()));
    fc.q0 = Eigen::Map<const Eigen::VectorXd>(q0.data(), static_cast<Eigen::Index>(q0.size()));
    const FourierTrajectory trajectory(fc);  // throws, naming the field, on inconsistent sizes
    const int n = fc.dof();
    const double period = 1.0 / fc.f0;
    std::vector<double> t(kTrajectoryPoints);
    std::vector<std::vector<double>> q(static_cast<size_t>(n), t), dq = q;
    Eigen::VectorXd qk(n), dqk(n), ddqk(n);
    for (int k = 0; k < kTrajectoryPoints; ++k) {
      t[static_cast<size_t>(k)] = period * k / (kTrajectoryPoints - 1);
      trajectory.evaluate(t[static_cast<size_t>(k)], qk, dqk, ddqk);
      for (int j = 0; j < n; ++j) {
        q[static_cast<size_t>(j)][static_cast<size_t>(k)] = qk(j);
        dq[static_cast<size_t>(j)][static_cast<size_t>(k)] = dqk(j);
      }
    }
    Json qs = Json::array(), dqs = Json::array();
    for (int j = 0; j < n; ++j) {
      qs.push_back(series("q" + std::to_string(j + 1), t, q[static_cast<size_t>(j)]));
      dqs.push_back(series("dq" + std::to_string(j + 1), t, dq[static_cast<size_t>(j)]));
    }
    s["charts"].push_back(
        line_chart("Joint positions over one period", "t [s]", "q [rad or m]", qs));
    s["charts"].push_back(
        line_chart("Joint velocities over one period", "t [s]", "dq [rad/s or m/s]", dqs));
    // Line spectrum of the positions: harmonic k of joint i has amplitude √(a²+b²)/(ω_f k)
    // (seed 2 eq. 17).
    Json labels = Json::array(), spectra = Json::array();
    for (int k = 1; k <= fc.max_harmonics(); ++k) labels.push_back(rounded(k * fc.f0, 4));
    for (int j = 0; j < n; ++j) {
      Json amp = Json::array();
      const auto& a = fc.a[static_cast<size_t>(j)];
      const auto& b = fc.b[static_cast<size_t>(j)];
      for (int k = 1; k <= fc.max_harmonics(); ++k) {
        amp.push_back(k <= a.size()
                          ? rounded(std::hypot(a(k - 1), b(k - 1)) / (2.0 * kPi * fc.f0 * k), 6)
                          : Json(0.0));
      }
      spectra.push_back({{"label", "q" + std::to_string(j + 1)}, {"y", amp}, {"kind", "bar"}});
    }
    s["charts"].push_back({{"title", "Position spectrum (amplitude per harmonic)"},
                           {"type", "bar"},
                           {"x_label", "frequency [Hz]"},
                           {"y_label", "amplitude [rad or m]"},
                           {"labels", labels},
                           {"series", spectra}});
  }
  // Only limits that bound something: an unbounded limit's margin is infinite (null in the JSON)
  // and would only flatten the others.
  std::vector<std::string> names;
  Json margins = Json::array();
  for (const auto& m : r.value("margins", Json::array())) {
    const double margin = number_or_nan(m.value("margin", Json()));
    if (!std::isfinite(margin)) continue;
    names.push_back(text_of(m.value("name", Json("?"))));
    margins.push_back(rounded(margin, 6));
  }
  add_joint_bars(margins, names, "Constraint margins of the finite limits (negative: violated)",
                 "margin", s);
  return s;
}

// `dynid compare-control` (seed 2 §3.6, Fig. 9): per joint, each controller's tracking error
// after the first period — RMS, peak, peak near a velocity reversal — side by side.
Json control_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "compare-control",
                       "Controller comparison: tracking errors under the same reference");
  add_fact(s, "samples (after the first period)", text_of(r.value("samples", Json())));
  add_fact(s, "reversal window [s]", text_of(r.value("reversal_window", Json())));
  const Json& controllers = r.value("controllers", Json::array());
  Json labels = Json::array();
  if (!controllers.empty()) {
    for (const auto& j : controllers[0].value("joints", Json::array()))
      labels.push_back(text_of(j.value("name", Json("?"))));
  }
  const std::pair<const char*, const char*> metrics[] = {
      {"rms", "Tracking error RMS per joint"},
      {"max", "Largest tracking error per joint"},
      {"max_at_reversal", "Largest tracking error near a velocity reversal per joint"}};
  for (const auto& [key, title] : metrics) {
    Json list = Json::array();
    for (const auto& c : controllers) {
      Json ys = Json::array();
      for (const auto& j : c.value("joints", Json::array()))
        ys.push_back(rounded(number_or_nan(j.value(key, Json())), 6));
      list.push_back({{"label", text_of(c.value("name", Json("?")))}, {"y", ys}, {"kind", "bar"}});
    }
    if (list.empty() || labels.empty()) continue;
    s["charts"].push_back({{"title", title},
                           {"type", "bar"},
                           {"y_label", "|qr − q| [rad or m]"},
                           {"labels", labels},
                           {"series", list}});
  }
  if (controllers.size() >= 2) {
    // The ratio the comparison is about: how much of the PID's error the model removes.
    Json rows = Json::array();
    const Json& first = controllers[0].value("joints", Json::array());
    const Json& second = controllers[1].value("joints", Json::array());
    for (size_t j = 0; j < first.size() && j < second.size(); ++j) {
      const double a = number_or_nan(first[j].value("max", Json()));
      const double b = number_or_nan(second[j].value("max", Json()));
      rows.push_back({text_of(first[j].value("name", Json("?"))), text_of(rounded(a, 4)),
                      text_of(rounded(b, 4)), a > 0.0 ? text_of(rounded(b / a, 3)) : "n/a"});
    }
    s["tables"].push_back({{"title", "Peak tracking error"},
                           {"columns",
                            {"joint", text_of(controllers[0].value("name", Json("?"))),
                             text_of(controllers[1].value("name", Json("?"))), "ratio"}},
                           {"rows", rows}});
  }
  return s;
}

Json experiment_section(const ReportInput& in, const std::string& model) {
  const Json& r = in.result;
  Json s = new_section(in, "experiment", "Dedicated experiment: " + model);
  add_fact(s, "relative error", percent(r.value("relative_error", Json())));
  add_fact(s, "residual RMS", text_of(r.value("residual_rms", Json())));
  add_parameters(r, s);
  const Json& fit = r.value("fit", Json());
  if (fit.is_object()) {
    const bool gravity = fit.contains("q");
    const std::vector<double> x = numbers_of(fit.value(gravity ? "q" : "dq", Json()));
    const std::string x_label = gravity ? "q [rad]" : "dq [rad/s]";
    Json list = {series("measured", x, numbers_of(fit.value("tau", Json())), "points"),
                 series("fitted", x, numbers_of(fit.value("fitted", Json())), "points")};
    if (r.contains("curve")) {
      list.push_back(series("friction law", numbers_of(r["curve"].value("velocity", Json())),
                            numbers_of(r["curve"].value("torque", Json()))));
    }
    s["charts"].push_back(line_chart(gravity ? "Torque against position on the cruise samples"
                                             : "Friction torque against velocity",
                                     x_label, "torque [N·m]", list));
  }
  return s;
}

// `dynid compare` (issue 31 item 3): the flagged changes first (friction and payload named), the
// z-scores of the last result against the baseline with the first step's critical value, and
// with more than two results each flagged (or friction / payload) parameter's trend with ±2σ.
Json compare_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "compare", "Drift: parameter changes against the baseline");
  const Json& results = r.value("results", Json::array());
  add_fact(s, "baseline", results.empty() ? "?" : text_of(results[0].value("file", Json("?"))));
  add_fact(s, "results compared", text_of(Json(results.size())));
  add_fact(s, "tests (parameter × later result)", text_of(r.value("tests", Json())));
  add_fact(s, "family-wise false-alarm rate (Holm)", text_of(r.value("alpha", Json())));
  add_fact(s, "first-step critical |z|",
           text_of(rounded(number_or_nan(r.value("first_critical_z", Json())), 4)));
  add_fact(s, "friction changes", joined(r.value("flagged_friction", Json::array())));
  add_fact(s, "payload changes", joined(r.value("flagged_payload", Json::array())));
  for (const auto& res : results) {
    const std::string cov = text_of(res.value("covariance", Json("")));
    if (cov.rfind("white", 0) == 0) {
      s["warnings"].push_back(text_of(res.value("file", Json("?"))) +
                              ": white-noise σ (streamed or merged result), too narrow if its "
                              "residuals are correlated");
    }
  }
  Json rows = Json::array();
  for (const auto& f : r.value("flagged", Json::array())) {
    rows.push_back({text_of(f.value("file", Json("?"))), text_of(f.value("name", Json("?"))),
                    text_of(f.value("role", Json("?"))),
                    text_of(rounded(number_or_nan(f.value("change", Json())), 5)),
                    text_of(rounded(number_or_nan(f.value("std", Json())), 4)),
                    text_of(rounded(number_or_nan(f.value("z", Json())), 4)),
                    text_of(rounded(number_or_nan(f.value("p_adjusted", Json())), 3))});
  }
  if (rows.empty()) add_fact(s, "verdict", "no significant change");
  s["tables"].push_back(
      {{"title", "Significant changes"},
       {"columns", {"result", "parameter", "role", "change", "std", "z", "adjusted p"}},
       {"rows", rows}});
  const Json& params = r.value("parameters", Json::array());
  Json labels = Json::array(), zs = Json::array();
  for (const auto& p : params) {
    const Json& comparisons = p.value("comparisons", Json::array());
    if (comparisons.empty()) continue;
    labels.push_back(text_of(p.value("name", Json("?"))));
    zs.push_back(rounded(number_or_nan(comparisons.back().value("z", Json())), 4));
  }
  if (!labels.empty()) {
    s["charts"].push_back(
        {{"title", "z-score of each parameter's change, last result against the baseline"},
         {"type", "bar"},
         {"y_label", "z"},
         {"labels", labels},
         {"wide", true},
         {"series", {{{"label", "z"}, {"y", zs}, {"kind", "bar"}}}}});
  }
  if (results.size() <= 2) return s;
  for (const auto& p : params) {
    const std::string role = text_of(p.value("role", Json("")));
    bool flagged = false;
    for (const auto& c : p.value("comparisons", Json::array()))
      flagged |= c.value("flagged", false);
    if (!flagged && role != "friction" && role != "payload") continue;
    const std::vector<double> v = numbers_of(p.value("values", Json()));
    const std::vector<double> sd = numbers_of(p.value("std", Json()));
    std::vector<double> x(v.size()), up(v.size()), down(v.size());
    for (size_t i = 0; i < v.size(); ++i) {
      x[i] = static_cast<double>(i);
      const double si = i < sd.size() ? sd[i] : std::numeric_limits<double>::quiet_NaN();
      up[i] = v[i] + 2 * si;
      down[i] = v[i] - 2 * si;
    }
    const std::string name = text_of(p.value("name", Json("?")));
    Json chart = line_chart("Trend of " + name + (flagged ? " (flagged)" : ""),
                            "result (0 = baseline)", name,
                            {series("estimate", x, v, "points"), series("+2σ", x, up, "dashed"),
                             series("−2σ", x, down, "dashed")});
    chart["small"] = true;
    s["charts"].push_back(chart);
  }
  return s;
}

Json generic_section(const ReportInput& in) {
  const Json& r = in.result;
  Json s = new_section(in, "generic", "Result");
  for (const auto& [k, v] : r.items()) {
    if (v.is_primitive() && k != "version") add_fact(s, k, text_of(v));
  }
  add_parameters(r, s);
  if (r.contains("plot")) add_prediction_plots(r["plot"], joint_names_of(r, 64), s);
  return s;
}

// "</" inside a <script> element would end it early: JSON and JavaScript both read "<\/" as "</".
std::string script_safe(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (size_t i = 0; i < text.size(); ++i) {
    out += text[i];
    if (text[i] == '<' && i + 1 < text.size() && text[i + 1] == '/') out += '\\';
  }
  return out;
}

// The data block is JSON in a <script> element: every '<' written as \u003c (the same string to
// JSON.parse), so no name or warning can end the element ("</script"), open a comment that hides
// the page's own end tag ("<!--<script>", the HTML script-data escape states), or start a tag.
std::string json_script_safe(const std::string& json) {
  std::string out;
  out.reserve(json.size());
  for (char c : json) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

constexpr const char* kStyle = R"CSS(
body{font-family:system-ui,sans-serif;margin:1.5em;color:#222;max-width:1400px}
h1{font-size:1.5em}h2{font-size:1.2em;margin-top:2em;border-bottom:1px solid #ccc}
.source{color:#666;font-size:.85em}
table{border-collapse:collapse;font-size:.85em;margin:.5em 0}
td,th{border:1px solid #ddd;padding:2px 8px;text-align:left}
.warnings{color:#a33}
.grid{display:grid;grid-template-columns:repeat(auto-fill,minmax(520px,1fr));gap:12px}
.chart{height:280px;position:relative}.chart.small{height:200px}.chart.wide{grid-column:1/-1}
details{margin:.5em 0}
)CSS";

// Renders the embedded page description with Chart.js: facts, warnings, tables, charts. Every
// chart counts its points; the counts and any script error go to <body data-*> for the tests.
constexpr const char* kRenderer = R"JS(
(function () {
  var charts = 0, points = 0, empty = 0, errors = 0;
  function status() {
    var d = document.body.dataset;
    d.charts = charts; d.points = points; d.emptyCharts = empty; d.errors = errors;
    d.reportStatus = (errors === 0 && empty === 0) ? 'ok' : 'failed';
  }
  window.addEventListener('error', function () { errors++; status(); });
  var palette = ['#1f77b4', '#ff7f0e', '#2ca02c', '#d62728', '#9467bd', '#8c564b', '#e377c2',
                 '#7f7f7f', '#bcbd22', '#17becf'];
  function el(tag, cls, text) {
    var e = document.createElement(tag);
    if (cls) e.className = cls;
    if (text !== undefined) e.textContent = text;
    return e;
  }
  function axis(label) { return label ? {display: true, text: label} : {display: false}; }
  function count(values) { var n = 0; values.forEach(function (v) { if (v !== null) n++; }); return n; }
  function config(c) {
    var n = 0, datasets = [];
    var scales = {x: {title: axis(c.x_label)}, y: {title: axis(c.y_label)}};
    var options = {animation: false, responsive: true, maintainAspectRatio: false,
                   plugins: {title: {display: true, text: c.title}, legend: {display: true}},
                   scales: scales};
    if (c.type === 'line') {
      c.series.forEach(function (s, i) {
        var data = [];
        for (var k = 0; k < s.x.length; k++)
          if (s.x[k] !== null && s.y[k] !== null) data.push({x: s.x[k], y: s.y[k]});
        n += data.length;
        var col = palette[i % palette.length];
        datasets.push({label: s.label, data: data, showLine: s.kind !== 'points',
                       pointRadius: s.kind === 'points' ? 1.5 : 0, borderWidth: 1,
                       borderDash: s.kind === 'dashed' ? [4, 3] : [],
                       borderColor: col, backgroundColor: col});
      });
      scales.x.type = 'linear';
      options.parsing = false;
      options.normalized = true;
      return {n: n, cfg: {type: 'scatter', data: {datasets: datasets}, options: options}};
    }
    if (c.type === 'bar') {
      c.series.forEach(function (s, i) {
        n += count(s.y);
        var col = palette[i % palette.length];
        datasets.push(s.kind === 'line'
          ? {type: 'line', label: s.label, data: s.y, pointRadius: 0, borderColor: '#d62728',
             borderWidth: 2, backgroundColor: '#d62728'}
          : {type: 'bar', label: s.label, data: s.y,
             backgroundColor: c.colors ? c.colors : col + 'b0'});
      });
      if (c.log) { scales.y.type = 'logarithmic'; scales.x.ticks = {autoSkip: false, font: {size: 9}}; }
      return {n: n, cfg: {type: 'bar', data: {labels: c.labels, datasets: datasets}, options: options}};
    }
    if (c.type === 'interval') {
      var bars = c.low.map(function (l, k) { return (l === null || c.high[k] === null) ? null : [l, c.high[k]]; });
      n = count(bars) + count(c.value);
      options.indexAxis = 'y';
      // Intervals wider than the estimate itself run off a [-3, 5] axis (red, with their numbers
      // in the tooltip) so that the well-determined ones stay readable.
      var lo = Math.min.apply(null, c.low.filter(function (v) { return v !== null; }).concat([-1]));
      var hi = Math.max.apply(null, c.high.filter(function (v) { return v !== null; }).concat([1]));
      options.scales = {x: {title: axis(c.x_label), min: Math.max(-3, lo - 0.1), max: Math.min(5, hi + 0.1)},
                        y: {ticks: {autoSkip: false, font: {size: 10}}}};
      options.plugins.tooltip = {callbacks: {label: function (ctx) { return c.tips[ctx.dataIndex]; }}};
      datasets.push({type: 'bar', label: 'confidence interval', data: bars,
                     backgroundColor: c.colors, barPercentage: 0.9, categoryPercentage: 0.9});
      datasets.push({type: 'line', label: 'estimate (±1)', data: c.value, showLine: false,
                     pointRadius: 2, borderColor: '#000', backgroundColor: '#000'});
      return {n: n, cfg: {type: 'bar', data: {labels: c.labels, datasets: datasets}, options: options}};
    }
    throw new Error('unknown chart type ' + c.type);
  }
  function render(page) {
    document.body.appendChild(el('h1', '', page.title));
    document.body.appendChild(el('div', 'source', page.generated));
    page.sections.forEach(function (sec) {
      var root = el('section');
      root.dataset.kind = sec.kind;
      var own = 0, ownEmpty = 0;
      document.body.appendChild(root);
      root.appendChild(el('h2', '', sec.title));
      root.appendChild(el('div', 'source', sec.source));
      if (sec.facts.length) {
        var t = el('table');
        sec.facts.forEach(function (f) {
          var r = el('tr'); r.appendChild(el('th', '', f[0])); r.appendChild(el('td', '', f[1]));
          t.appendChild(r);
        });
        root.appendChild(t);
      }
      if (sec.warnings.length) {
        var ul = el('ul', 'warnings');
        sec.warnings.forEach(function (w) { ul.appendChild(el('li', '', w)); });
        root.appendChild(ul);
      }
      function table(tab) {
        var d = el('details'); d.appendChild(el('summary', '', tab.title));
        if (tab.open) d.open = true;
        var t = el('table'), h = el('tr');
        tab.columns.forEach(function (c) { h.appendChild(el('th', '', c)); });
        t.appendChild(h);
        tab.rows.forEach(function (row) {
          var r = el('tr'); row.forEach(function (v) { r.appendChild(el('td', '', v)); }); t.appendChild(r);
        });
        d.appendChild(t); root.appendChild(d);
      }
      sec.tables.forEach(function (tab) { if (tab.open) table(tab); });
      var grid = el('div', 'grid');
      root.appendChild(grid);
      sec.charts.forEach(function (c) {
        var box = el('div', 'chart' + (c.small ? ' small' : '') + (c.wide ? ' wide' : ''));
        if (c.type === 'interval') box.style.height = Math.max(200, 40 + 14 * c.labels.length) + 'px';
        var canvas = el('canvas');
        box.appendChild(canvas);
        grid.appendChild(box);
        try {
          var made = config(c);
          charts++; own++; points += made.n;
          if (made.n === 0) { empty++; ownEmpty++; }
          new Chart(canvas, made.cfg);
        } catch (e) { errors++; console.error(e); }
      });
      sec.tables.forEach(function (tab) { if (!tab.open) table(tab); });
      root.dataset.charts = own; root.dataset.emptyCharts = ownEmpty;
    });
  }
  try {
    render(JSON.parse(document.getElementById('dynid-data').textContent));
  } catch (e) { errors++; console.error(e); }
  status();
})();
)JS";

std::string read_text(const std::string& path, const std::string& what) {
  return read_regular_file(path, kMaxResultFileBytes, what);
}

}  // namespace

std::string result_kind(const nlohmann::json& r) {
  if (!r.is_object()) return "generic";
  if (r.value("command", Json()) == "payload") return "payload";
  if (r.value("command", Json()) == "compare") return "compare";
  if (r.contains("criterion") && r.contains("coefficients")) return "excite";
  if (r.contains("channels") && r.contains("periods")) return "average";
  if (r.contains("controllers") && r["controllers"].is_array()) return "compare-control";
  if (r.contains("joints") && r["joints"].is_array() && !r["joints"].empty() &&
      r["joints"][0].is_object()) {
    if (r["joints"][0].contains("position")) return "validate-simulation";
    if (r.contains("relative_error_all_rows")) return "validate";
  }
  const Json model = r.contains("options") && r["options"].is_object()
                         ? r["options"].value("model", Json())
                         : Json();
  if (model == "gravity" || model == "friction" || model == "decoupled") return "experiment";
  if (r.contains("parameters") && r.contains("rank") && r.contains("condition_number")) {
    return "identify";
  }
  return "generic";
}

ReportInput read_report_input(const std::string& path) {
  ReportInput in;
  in.source = path;
  const std::string text = read_text(path, "result file");
  try {
    in.result = Json::parse(text);
  } catch (const Json::exception& e) {
    throw Error("'" + path + "' is not valid JSON (" + std::string(e.what()) +
                "); give a result file written by dynid");
  }
  if (!in.result.is_object()) {
    throw Error("'" + path + "' is JSON but not an object; give a result file written by dynid");
  }
  return in;
}

std::string html_report(const std::vector<ReportInput>& inputs, const HtmlReportOptions& options) {
  const std::string chart_js =
      read_text(options.chart_js, "Chart.js bundle (install the Debian package libjs-chart.js)");
  Json page = {{"title", options.title},
               {"generated", std::string("written by dynid ") + kVersion},
               {"sections", Json::array()}};
  for (const ReportInput& in : inputs) {
    const std::string kind = result_kind(in.result);
    Json section;
    try {
      if (kind == "identify")
        section = identify_section(in);
      else if (kind == "validate")
        section = validate_section(in);
      else if (kind == "validate-simulation")
        section = simulation_validation_section(in);
      else if (kind == "payload")
        section = payload_section(in);
      else if (kind == "average")
        section = average_section(in);
      else if (kind == "excite")
        section = excite_section(in);
      else if (kind == "compare-control")
        section = control_section(in);
      else if (kind == "compare")
        section = compare_section(in);
      else if (kind == "experiment")
        section = experiment_section(in, in.result["options"]["model"]);
      else
        section = generic_section(in);
    } catch (const Json::exception& e) {
      throw Error("'" + in.source + "' looks like a " + kind + " result but a field has the " +
                  "wrong type (" + e.what() + "); give the file dynid wrote, unedited");
    }
    page["sections"].push_back(std::move(section));
  }
  std::string out;
  out.reserve(chart_js.size() + (1 << 16));
  out += "<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\"><title>";
  out += markup_escaped(options.title);
  out += "</title><style>";
  out += kStyle;
  out += "</style><script>";
  out += script_safe(chart_js);
  out += "</script></head><body data-report-status=\"loading\">\n";
  out += "<script type=\"application/json\" id=\"dynid-data\">";
  out += json_script_safe(page.dump(-1, ' ', false, Json::error_handler_t::replace));
  out += "</script>\n<script>";
  out += kRenderer;
  out += "</script></body></html>\n";
  return out;
}

void write_html_report(const std::string& path, const std::vector<ReportInput>& inputs,
                       const HtmlReportOptions& options) {
  write_text_atomic(path, html_report(inputs, options));
}

nlohmann::json prediction_plot_json(const Eigen::VectorXd& t, const Eigen::MatrixXd& measured,
                                    const Eigen::MatrixXd& predicted,
                                    const std::vector<std::string>& joint_names,
                                    const PredictionPlotOptions& options) {
  if (measured.rows() != t.size() || predicted.rows() != t.size() ||
      measured.cols() != predicted.cols()) {
    throw Error("prediction_plot_json: t, measured and predicted have inconsistent sizes");
  }
  const int digits = options.significant_digits;
  const auto keep = display_indices(t.size(), options.max_points);
  Json ts = Json::array();
  for (Eigen::Index i : keep) ts.push_back(rounded(t(i), 8));
  Json joints = Json::array();
  for (Eigen::Index j = 0; j < measured.cols(); ++j) {
    Json m = Json::array(), p = Json::array();
    for (Eigen::Index i : keep) {
      m.push_back(rounded(measured(i, j), digits));
      p.push_back(rounded(predicted(i, j), digits));
    }
    Json joint = {{"name", j < static_cast<Eigen::Index>(joint_names.size())
                               ? joint_names[static_cast<size_t>(j)]
                               : "joint " + std::to_string(j + 1)},
                  {"measured", m},
                  {"predicted", p}};
    const Eigen::VectorXd e = measured.col(j) - predicted.col(j);
    if (e.size() >= 2 && e.allFinite()) {
      const ErrorStatistics st = error_statistics(e);
      const int bins = std::max(3, options.histogram_bins);
      Json centers = Json::array(), density = Json::array(), gaussian = Json::array();
      if (st.std > 0.0 && std::isfinite(st.std) && std::isfinite(st.mean)) {
        // mean ± 4σ: a Gaussian's mass outside is 6e-5; heavier tails pile into the end bins.
        const double lo = st.mean - 4.0 * st.std, width = 8.0 * st.std / bins;
        std::vector<double> counts(static_cast<size_t>(bins), 0.0);
        for (Eigen::Index i = 0; i < e.size(); ++i) {
          // Clamped as a double: a residual far outside (a huge torque sample) must not
          // overflow the int conversion; one that is not a number is not counted.
          const double x = std::floor((e(i) - lo) / width);
          if (std::isnan(x)) continue;
          counts[static_cast<size_t>(std::clamp(x, 0.0, bins - 1.0))] += 1.0;
        }
        for (int b = 0; b < bins; ++b) {
          const double c = lo + (b + 0.5) * width;
          const double z = (c - st.mean) / st.std;
          centers.push_back(rounded(c, digits));
          density.push_back(rounded(counts[static_cast<size_t>(b)] / (e.size() * width), digits));
          gaussian.push_back(
              rounded(std::exp(-0.5 * z * z) / (st.std * std::sqrt(2.0 * kPi)), digits));
        }
      }
      joint["histogram"] = {{"centers", centers},
                            {"density", density},
                            {"gaussian", gaussian},
                            {"mean", rounded(st.mean, digits)},
                            {"std", rounded(st.std, digits)},
                            {"skewness", rounded(st.skewness, digits)},
                            {"kurtosis", rounded(st.kurtosis, digits)},
                            {"ks_statistic", rounded(st.ks_statistic, digits)},
                            {"ks_p_value", rounded(st.ks_p_value, digits)},
                            {"samples", st.samples}};
    }
    joints.push_back(std::move(joint));
  }
  return {
      {"t", ts}, {"joints", joints}, {"decimated_every", keep.size() > 1 ? keep[1] - keep[0] : 1}};
}

nlohmann::json prediction_plot_json(const ValidationResult& v,
                                    const std::vector<std::string>& joint_names,
                                    const PredictionPlotOptions& options) {
  return prediction_plot_json(v.processed.record.t, v.processed.record.tau, v.predicted,
                              joint_names, options);
}

nlohmann::json rls_history_plot_json(const IdentificationResult& r,
                                     const PredictionPlotOptions& options) {
  const Eigen::Index rows = r.history_x.rows(), p = r.history_x.cols();
  if (rows == 0 || static_cast<Eigen::Index>(r.names.size()) != p) return nullptr;
  Eigen::Index first = 0;  // σ needs more equations than parameters (as write_rls_history)
  while (first < rows && !r.history_std.row(first).allFinite()) ++first;
  if (first == rows) return nullptr;
  auto keep = display_indices(rows - first, options.history_points);
  for (auto& i : keep) i += first;
  if (keep.back() != rows - 1) keep.push_back(rows - 1);  // the final estimate
  const int digits = options.significant_digits;
  Json ts = Json::array();
  for (Eigen::Index i : keep) ts.push_back(rounded(r.history_t(i), 8));
  Json params = Json::array();
  for (Eigen::Index c = 0; c < p; ++c) {
    Json value = Json::array(), std_dev = Json::array();
    for (Eigen::Index i : keep) {
      value.push_back(rounded(r.history_x(i, c), digits));
      std_dev.push_back(rounded(r.history_std(i, c), digits));
    }
    params.push_back(
        {{"name", r.names[static_cast<size_t>(c)]}, {"value", value}, {"std", std_dev}});
  }
  return {{"t", ts}, {"parameters", params}};
}

nlohmann::json energy_plot_json(const Model& model, const IdentificationResult& result,
                                const IdentifyOptions& options,
                                const PredictionPlotOptions& plot_options) {
  if (!result.estimate.x.allFinite()) return nullptr;
  IntegralOptions integral = options.integral;
  // Joules on both sides: the row weights only balance the estimator.
  integral.weighting = IntegralWeighting::kNone;
  const bool coupling =
      static_cast<int>(result.base.layout_names.size()) > options.layout.columns(model.dof());
  // The estimate lives on result.names: the base columns the data determine. With parameters
  // not excited (result.not_excited) those are fewer than the base set, and on these data the
  // kept estimates already hold the not-excited ones' share (data_regrouping), so W_kept·θ̂
  // predicts the measured work.
  if (result.estimate.x.size() != static_cast<Eigen::Index>(result.names.size())) {
    throw Error("energy_plot_json: the estimate has " + std::to_string(result.estimate.x.size()) +
                " values for " + std::to_string(result.names.size()) + " parameter names");
  }
  const EquationBlock block = select_named_columns(
      select_base_columns(
          integral_equations(model, options.layout, coupling, result.processed, integral),
          result.base),
      result.names);
  const Eigen::VectorXd predicted = block.W * result.estimate.x;
  const auto keep = display_indices(block.y.size(), plot_options.max_points);
  const int digits = plot_options.significant_digits;
  Json ts = Json::array(), measured = Json::array(), pred = Json::array();
  for (Eigen::Index i : keep) {
    ts.push_back(rounded(block.t(i), 8));
    measured.push_back(rounded(block.y(i), digits));
    pred.push_back(rounded(predicted(i), digits));
  }
  return {{"t", ts},
          {"measured", measured},
          {"predicted", pred},
          {"decimated_every", keep.size() > 1 ? keep[1] - keep[0] : 1}};
}

}  // namespace dynid
