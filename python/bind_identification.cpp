// identify() and identify_runs() of the Python module (issue 29 item 3): every model, preparation
// and estimator of `dynid identify`, through the library's identify_runs() and
// identify_joint_experiment(), which the command line calls too.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cctype>
#include <string>
#include <vector>

#include "binding.hpp"
#include "dynid/common/error.hpp"
#include "dynid/identification/known_friction.hpp"
#include "dynid/identification/option_text.hpp"
#include "dynid/io/closed_loop_file.hpp"
#include "dynid/workflow/identify_runs.hpp"

namespace dynid::binding {
namespace {

// identify()'s keywords beyond validate()'s, each the command line's flag of the same name.
const char* const kIdentifyOnly[] = {
    "friction_known", "outliers",    "noise", "physical", "equations", "interval",
    "long_integrals", "closed_loop", "fir",   "period",   "f0",        "noise_std",
    "repeat",         "joint",       "params"};

// The flags of the library's messages as identify()'s keywords.
const std::initializer_list<std::pair<const char*, const char*>> kIdentifyFlags = {
    {"--closed-loop", "closed_loop"},
    {"--noise-std", "noise_std"},
    {"--model", "equations"},
    {"--interval", "interval"},
    {"--repeat", "repeat"},
    {"--joint", "joint"},
    {"--estimator", "estimator"},
    {"--fir", "fir"},
    {"--period", "period"},
    {"--f0", "f0"},
    {"--filter", "filter"},
    {"--cutoff", "cutoff_hz"},
    {"--trim", "trim"},
    {"--zero-velocity", "zero_velocity"},
    {"--params", "params"},
    {"--physical", "physical"}};

// An optional m × n array of a run dict, checked against the run's samples.
std::optional<RowMatrix> optional_samples(const py::dict& run, const char* key) {
  if (!run.contains(key) || run[key].is_none()) return std::nullopt;
  return run[key].cast<RowMatrix>();
}

// A run {'t', 'q', 'tau'[, 'dq', 'ddq', 'qr', 'dqr', 'ddqr']} as its record and reference.
std::pair<JointRecord, ReferenceRecord> run_of(const Model& model, const py::handle& item,
                                               size_t index) {
  const std::string where = "runs[" + std::to_string(index) + "]";
  if (!py::isinstance<py::dict>(item))
    throw py::type_error(where + " must be a dict {'t', 'q', 'tau'[, 'dq', 'ddq', 'qr', ...]}");
  const py::dict run = py::reinterpret_borrow<py::dict>(item);
  static const char* const kKeys[] = {"t", "q", "tau", "dq", "ddq", "qr", "dqr", "ddqr"};
  for (const auto& entry : run) {
    const std::string key = py::str(entry.first);
    if (std::find(std::begin(kKeys), std::end(kKeys), key) == std::end(kKeys))
      throw py::value_error(where + ": unknown key '" + key +
                            "'; give t, q, tau and optionally dq, ddq, qr, dqr, ddqr");
  }
  for (const char* key : {"t", "q", "tau"})
    if (!run.contains(key)) throw py::value_error(where + " has no '" + key + "'");
  const JointRecord record = record_of(model, run["t"].cast<Eigen::VectorXd>(),
                                       run["q"].cast<RowMatrix>(), run["tau"].cast<RowMatrix>(),
                                       optional_samples(run, "dq"), optional_samples(run, "ddq"));
  ReferenceRecord reference;
  const auto rows = record.t.size();
  for (const auto& [key, target] : {std::pair<const char*, Eigen::MatrixXd*>{"qr", &reference.qr},
                                    {"dqr", &reference.dqr},
                                    {"ddqr", &reference.ddqr}}) {
    if (const auto x = optional_samples(run, key)) {
      check_samples(model, key, rows, *x);
      *target = *x;
    }
  }
  if (reference.qr.size() == 0 && (reference.dqr.size() || reference.ddqr.size()))
    throw py::value_error(where + ": dqr and ddqr need qr, the reference positions");
  return {record, reference};
}

// The `noise` keyword: an average() result (or the command line's average --json, loaded),
// as identify --noise reads the file: std_averaged when the first run is that result's mean
// period (the same times), else std, the raw per-sample noise.
SensorNoise sensor_noise_of(const Model& model, const std::vector<JointRecord>& runs,
                            const py::handle& noise, nlohmann::json& used) {
  if (!py::isinstance<py::dict>(noise))
    throw py::type_error("noise must be the dict of dynid.average (or of average --json)");
  const py::dict d = py::reinterpret_borrow<py::dict>(noise);
  bool averaged = false;
  if (d.contains("mean") && !runs.empty()) {
    const RowMatrix mean = d["mean"].cast<RowMatrix>();
    const Eigen::VectorXd& t = runs.front().t;
    averaged = mean.cols() > 0 && mean.rows() == t.size() && mean.col(0) == t;
  }
  nlohmann::json j = nlohmann::json::object();
  if (d.contains("channels")) {
    j["channels"] = nlohmann::json::parse(
        py::module_::import("json").attr("dumps")(d["channels"]).cast<std::string>());
  }
  used["noise"] = averaged ? "std_averaged of the mean period" : "std, the raw per-sample noise";
  return sensor_noise_from_json(j, model, averaged, "noise");
}

// identify() of runs as `dynid identify --data R1 --data R2 ...` with the keywords as its flags.
py::object identify_python(const Model& model, const std::vector<JointRecord>& runs,
                           const std::vector<ReferenceRecord>& references, const py::kwargs& kw) {
  nlohmann::json used;
  IdentifyKeywords ik;
  IdentifyOptions options = identify_options(kw, used, &ik);
  std::vector<std::string> warnings;
  nlohmann::json out;
  try {
    if (!ik.noise_std.empty()) options.noise = parse_noise_std(ik.noise_std, model.dof());
    if (kw.contains("noise")) options.noise = sensor_noise_of(model, runs, kw["noise"], used);
    if (kw.contains("friction_known")) {
      if (ik.equations != "differential")
        throw py::value_error("friction_known is for equations='differential'");
      const py::list known = kw["friction_known"].cast<py::list>();
      for (size_t i = 0; i < known.size(); ++i) {
        const std::string name = "friction_known[" + std::to_string(i) + "]";
        const IdentifiedResultFile f = identified_result(model, known[i].cast<py::dict>(), name);
        add_known_friction(options.known_friction, model, f.names, f.values, name);
      }
    }
    if (ik.equations == "gravity" || ik.equations == "friction" || ik.equations == "decoupled") {
      if (options.estimator != IdentificationEstimator::kOls)
        throw py::value_error("equations='" + ik.equations +
                              "' fits by least squares; drop estimator");
      if (options.closed_loop.method != ClosedLoopMethod::kNone || !ik.repeat.empty() ||
          ik.physical)
        throw py::value_error("closed_loop, repeat and physical are for the differential model");
      if (ik.joint == 0)
        throw py::value_error("equations='" + ik.equations + "' needs joint=J (1-based)");
      std::optional<IdentifiedResultFile> params;
      ExperimentCompensation compensation;
      if (kw.contains("params")) {
        if (ik.equations != "friction")
          throw py::value_error("params is the compensation of equations='friction'");
        params = identified_result(model, kw["params"].cast<py::dict>(), "params");
        compensation = {&*params, "params"};
      }
      used["joint"] = ik.joint;
      py::gil_scoped_release release;
      out = identify_joint_experiment(model, runs, joint_experiment_of(ik.equations), ik.joint - 1,
                                      options, used, compensation, warnings);
    } else {
      if (ik.joint != 0 || kw.contains("params"))
        throw py::value_error(
            "joint and params are for equations='gravity', 'friction' or "
            "'decoupled'");
      const bool closed = options.closed_loop.method != ClosedLoopMethod::kNone;
      if ((closed || !ik.repeat.empty()) && ik.equations != "differential")
        throw py::value_error("closed_loop and repeat work on the differential model");
      IdentifyRunsOptions run_options;
      run_options.repeat = ik.repeat;
      run_options.physical = ik.physical;
      run_options.physical_option = "physical=True";
      // References only where the command line reads them: a closed-loop preparation or a
      // repeat over periods.
      const bool with_references = closed || ik.repeat == "periods";
      py::gil_scoped_release release;
      IdentifiedRuns identified =
          identify_runs(model, runs, with_references ? references : std::vector<ReferenceRecord>{},
                        options, run_options);
      identified_runs_to_json(model, runs, options, run_options, used, identified);
      out = std::move(identified.json);
      warnings = std::move(identified.warnings);
    }
  } catch (const UsageError& e) {
    raise_with_keywords(e, kIdentifyFlags);
  }
  warn_all(warnings);
  return to_python(out);
}

}  // namespace

void warn_all(const std::vector<std::string>& warnings) {
  for (const std::string& w : warnings)
    if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
}

void raise_with_keywords(const std::exception& e,
                         std::initializer_list<std::pair<const char*, const char*>> keywords) {
  std::string text = e.what();
  for (const auto& [flag, keyword] : keywords) {
    const std::string from = flag;
    for (size_t at = text.find(from); at != std::string::npos; at = text.find(from, at)) {
      // A longer flag that starts with this one (--f0 in --f0s) is not this flag.
      const size_t end = at + from.size();
      if (end < text.size() &&
          (std::isalnum(static_cast<unsigned char>(text[end])) || text[end] == '-')) {
        at = end;
        continue;
      }
      text.replace(at, from.size(), keyword);
      at += std::string(keyword).size();
    }
  }
  throw Error(text);
}

IdentifyOptions identify_options(const py::kwargs& kw, nlohmann::json& used,
                                 IdentifyKeywords* identify) {
  static const char* const kKeys[] = {
      "armature",   "viscous",    "coulomb",        "offset",        "asymmetric",
      "estimator",  "confidence", "cutoff_hz",      "filter",        "decimate",
      "time_shift", "trim",       "zero_velocity",  "savgol",        "physical",
      "equations",  "interval",   "long_integrals", "closed_loop",   "fir",
      "period",     "f0",         "noise_std",      "repeat",        "joint",
      "params",     "outliers",   "filter_coulomb", "coulomb_width", "friction_known",
      "noise"};
  check_keywords(kw, kKeys);
  if (!identify) {
    for (const char* key : kIdentifyOnly)
      if (kw.contains(key))
        throw py::type_error(std::string(key) + " is an option of identify(), not of validate()");
  }
  auto get = [&](const char* key, auto fallback) {
    using T = decltype(fallback);
    const T value = kw.contains(key) ? kw[key].cast<T>() : fallback;
    used[key] = value;
    return value;
  };
  IdentifyOptions o;
  o.layout = layout_of(get("armature", true), get("viscous", true), get("coulomb", true),
                       get("offset", true), get("asymmetric", false));
  const std::string estimator = get("estimator", std::string("ols"));
  if (identify && estimator == "ml") {
    o.estimator = IdentificationEstimator::kMl;
  } else {
    o.estimator = estimator_of(estimator, IdentificationEstimator::kOls,
                               IdentificationEstimator::kWls, IdentificationEstimator::kRls);
  }
  o.confidence_level = confidence_of(get("confidence", 0.999));
  o.signal.cutoff_hz = get("cutoff_hz", 0.0);
  // filter: a bool (the automatic Butterworth or none), or the command line's --filter text.
  if (kw.contains("filter") && py::isinstance<py::str>(kw["filter"])) {
    const std::string text = kw["filter"].cast<std::string>();
    try {
      apply_filter_text(text, o.signal);
    } catch (const UsageError& e) {
      raise_with_keywords(e, kIdentifyFlags);
    }
    used["filter"] = text;
  } else {
    o.signal.filter = get("filter", true);
  }
  o.signal.decimate = get("decimate", 0);
  // identify's --time-shift, stored under the command line's key so that `dynid validate` and
  // validate() of a stored result shift alike.
  o.signal.torque_time_offset = kw.contains("time_shift") ? kw["time_shift"].cast<double>() : 0.0;
  used["time_shift_s"] = o.signal.torque_time_offset;
  // Stored under the command line's keys, which validate reads back.
  if (kw.contains("trim")) used["trim"] = o.signal.trim = kw["trim"].cast<int>();
  if (kw.contains("zero_velocity"))
    used["zero_velocity"] = o.signal.zero_velocity =
        kw["zero_velocity"].cast<std::vector<double>>();
  if (kw.contains("savgol"))
    used["savitzky_golay"] = o.signal.savitzky_golay = kw["savgol"].cast<bool>();
  if (kw.contains("filter_coulomb"))
    used["filter_coulomb_columns"] = o.signal.filter_coulomb_columns =
        kw["filter_coulomb"].cast<bool>();
  if (kw.contains("coulomb_width"))
    used["coulomb_width"] = o.signal.coulomb_width =
        kw["coulomb_width"].cast<std::vector<double>>();
  if (!identify) return o;

  const std::string outliers = get("outliers", std::string("report"));
  if (outliers != "report" && outliers != "drop")
    throw py::value_error("outliers must be 'report' or 'drop', not '" + outliers + "'");
  o.outliers.policy = outliers == "drop" ? OutlierPolicy::kDrop : OutlierPolicy::kReport;
  if (kw.contains("friction_known")) {
    // Only the rigid body (and armature) is estimated (seed 2 §3.4): the friction columns go.
    for (const char* key : {"viscous", "coulomb", "offset", "asymmetric"})
      if (kw.contains(key) && kw[key].cast<bool>())
        throw py::value_error(std::string("friction_known replaces the friction columns; drop ") +
                              key);
    o.layout = layout_of(o.layout.armature, false, false, false, false);
    for (const char* key : {"viscous", "coulomb", "offset", "asymmetric"}) used[key] = false;
  }

  identify->physical = get("physical", false);
  identify->equations = get("equations", std::string("differential"));
  used["model"] = identify->equations;
  if (identify->equations == "integral") {
    o.model = IdentificationModel::kIntegral;
    o.integral.interval = get("interval", o.integral.interval);
    if (!(o.integral.interval >= 0.0))
      throw py::value_error("interval must be >= 0 s (0 = two samples), e.g. 0.01");
    o.integral.long_integrals = get("long_integrals", false);
  } else if (kw.contains("interval") || kw.contains("long_integrals")) {
    throw py::value_error("interval and long_integrals are options of equations='integral'");
  } else if (identify->equations != "differential" && identify->equations != "gravity" &&
             identify->equations != "friction" && identify->equations != "decoupled") {
    throw py::value_error(
        "equations must be 'differential', 'integral', 'gravity', 'friction' or 'decoupled', not "
        "'" +
        identify->equations + "'");
  }
  const std::string closed = get("closed_loop", std::string("none"));
  if (closed == "projection") {
    o.closed_loop.method = ClosedLoopMethod::kProjection;
  } else if (closed == "spectral") {
    o.closed_loop.method = ClosedLoopMethod::kSpectral;
  } else if (closed != "none") {
    throw py::value_error("closed_loop must be 'none', 'projection' or 'spectral', not '" + closed +
                          "'");
  }
  if (kw.contains("fir")) {
    if (closed != "projection")
      throw py::value_error(
          "fir sets the projection's FIR orders: it needs closed_loop='projection'");
    const auto fir = kw["fir"].cast<std::vector<int>>();
    if (fir.size() != 2) throw py::value_error("fir must be [M1, M2] (future, past lags)");
    apply_fir_text(std::to_string(fir[0]) + "," + std::to_string(fir[1]), o.closed_loop.projection);
    used["fir"] = fir;
  }
  if (kw.contains("period") || kw.contains("f0")) {
    if (closed != "spectral")
      throw py::value_error(
          "period and f0 give the reference's period: they need "
          "closed_loop='spectral'");
    const double period = get("period", 0.0), f0 = get("f0", 0.0);
    if ((period != 0.0) == (f0 != 0.0) || !(period >= 0.0) || !(f0 >= 0.0))
      throw py::value_error("give one of period (s) or f0 (Hz), > 0");
    o.closed_loop.period = period > 0.0 ? period : 1.0 / f0;
  }
  if (kw.contains("noise_std") || kw.contains("noise")) {
    if (o.estimator != IdentificationEstimator::kMl)
      throw py::value_error(
          "noise and noise_std are the noise of estimator='ml'; add it or drop them");
    if (kw.contains("noise_std") && kw.contains("noise"))
      throw py::value_error("give noise (an average() result) or noise_std, not both");
    if (kw.contains("noise_std")) identify->noise_std = get("noise_std", std::string());
  }
  identify->repeat = kw.contains("repeat") ? get("repeat", std::string()) : std::string();
  if (!identify->repeat.empty() && identify->repeat != "periods" && identify->repeat != "runs")
    throw py::value_error("repeat must be 'periods' or 'runs', not '" + identify->repeat + "'");
  identify->joint = kw.contains("joint") ? get("joint", 0) : 0;
  return o;
}

void bind_identification(py::module_& m) {
  m.def(
      "identify",
      [](const Model& model, const Eigen::VectorXd& t, const Samples& q, const Samples& tau,
         const std::optional<RowMatrix>& dq, const std::optional<RowMatrix>& ddq,
         const std::optional<RowMatrix>& qr, const std::optional<RowMatrix>& dqr,
         const std::optional<RowMatrix>& ddqr, const py::kwargs& kw) {
        py::dict run;
        run["t"] = t;
        run["q"] = RowMatrix(q);
        run["tau"] = RowMatrix(tau);
        for (const auto& [key, x] :
             {std::pair<const char*, const std::optional<RowMatrix>*>{"dq", &dq},
              {"ddq", &ddq},
              {"qr", &qr},
              {"dqr", &dqr},
              {"ddqr", &ddqr}})
          if (*x) run[key] = **x;
        auto [record, reference] = run_of(model, run, 0);
        return identify_python(model, {record}, {reference}, kw);
      },
      py::arg("model"), py::arg("t"), py::arg("q"), py::arg("tau"), py::arg("dq") = py::none(),
      py::arg("ddq") = py::none(), py::arg("qr") = py::none(), py::arg("dqr") = py::none(),
      py::arg("ddqr") = py::none(),
      "Identifies base parameters with their uncertainty from one run, as 'dynid identify': t "
      "(m,) [s], q and tau (m x n), optional dq, ddq (derived from q when absent), and for a "
      "closed-loop run the reference qr (optional dqr, ddqr). Options (the command line's flags): "
      "armature, viscous, coulomb, offset, asymmetric (bool: the per-joint columns), estimator "
      "('ols', 'wls', 'rls', or 'ml': maximum likelihood with noisy q and tau, noise_std "
      "'q=S,tau=S', or noise: a dynid.average result, its std_averaged when the run is its mean "
      "period, else its std; default estimated), confidence (0.999), cutoff_hz (0 = automatic), "
      "filter (bool, or "
      "the --filter text: 'none', 'butterworth:4', 'chebyshev:8:0.5'), decimate (0 = automatic), "
      "trim, zero_velocity (list, rad/s), savgol (bool), filter_coulomb (bool), coulomb_width "
      "(list, rad/s), outliers ('report' or 'drop'), friction_known (list of friction or "
      "decoupled experiment results: their friction subtracted, only the rigid body "
      "estimated), time_shift (s: the torque sampled at t "
      "acts at t + time_shift), equations ('differential', 'integral' with interval [s] and "
      "long_integrals, or a one-joint experiment 'gravity', 'friction', 'decoupled' with joint "
      "(1-based) and for friction params, an identify result compensating inertia and gravity), "
      "closed_loop ('projection' with fir [M1, M2], or 'spectral' with period or f0; needs qr), "
      "repeat ('periods' or 'runs': seed 2 Table 3), physical (bool: physically consistent "
      "standard parameters, log-Cholesky fit of C. Rucker, P. M. Wensing, 2022, for "
      "export_urdf). Returns a dict with the keys of the result JSON (parameters, "
      "condition_number, residual_rms, plot, and as selected closed_loop, repeated, "
      "standard_parameters, physical; an experiment's keys for gravity, friction, decoupled). "
      "Warnings of the command line are UserWarnings.");

  m.def(
      "identify_runs",
      [](const Model& model, const py::list& runs, const py::kwargs& kw) {
        if (runs.empty()) throw py::value_error("runs is empty; give at least one run dict");
        std::vector<JointRecord> records;
        std::vector<ReferenceRecord> references;
        for (size_t i = 0; i < runs.size(); ++i) {
          auto [record, reference] = run_of(model, runs[i], i);
          records.push_back(std::move(record));
          references.push_back(std::move(reference));
        }
        return identify_python(model, records, references, kw);
      },
      py::arg("model"), py::arg("runs"),
      "identify() of several runs together, as 'dynid identify --data R1 --data R2 ...': runs is "
      "a list of dicts {'t', 'q', 'tau'[, 'dq', 'ddq', 'qr', 'dqr', 'ddqr']} (arrays as for "
      "identify); each run is processed on its own and their equations are stacked (the "
      "experiments fit all runs of the joint). The keyword options are identify()'s.");
}

}  // namespace dynid::binding
