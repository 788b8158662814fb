// Python bindings of dynid (issue 15 item 4): one translation unit, so that the module adds one
// compile to the build. Arrays are NumPy float64; a C-contiguous (row-major) m×n array of samples
// is read without a copy. Results are dicts with the keys of the JSON that dynid writes (they go
// through that JSON, so the two cannot drift apart).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <optional>

#include <nlohmann/json.hpp>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/estimation/identification.hpp"
#include "dynid/estimation/load_identification.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/io/urdf_export.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/report/payload_report.hpp"
#include "dynid/version.hpp"

namespace py = pybind11;

namespace dynid {
namespace {

using RowMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
using Samples = Eigen::Ref<const RowMatrix>;

py::object to_python(const nlohmann::json& j) {
  return py::module_::import("json").attr("loads")(j.dump());
}

ParameterLayout layout_of(bool armature, bool viscous, bool coulomb, bool offset, bool asymmetric) {
  ParameterLayout layout;
  layout.armature = armature;
  layout.viscous = viscous || asymmetric;
  layout.coulomb = coulomb || asymmetric;
  layout.offset = offset;
  layout.asymmetric = asymmetric;
  return layout;
}

void check_samples(const Model& model, const char* name, const RowMatrix::Index rows,
                   const Samples& x) {
  if (x.cols() != model.dof() || x.rows() != rows) {
    throw Error(std::string(name) + " must be " + std::to_string(rows) + " x " +
                std::to_string(model.dof()) + " (samples x joints of '" + model.name + "'), not " +
                std::to_string(x.rows()) + " x " + std::to_string(x.cols()));
  }
  if (!x.allFinite()) throw Error(std::string(name) + " holds NaN or Inf");
}

RowMatrix inverse_dynamics(const Model& model, const Samples& q, const Samples& dq,
                           const Samples& ddq, bool joint_terms) {
  check_samples(model, "q", q.rows(), q);
  check_samples(model, "dq", q.rows(), dq);
  check_samples(model, "ddq", q.rows(), ddq);
  Workspace ws(model);
  RowMatrix tau(q.rows(), model.dof());
  Eigen::VectorXd out(model.dof());
  RneaOptions options;
  options.joint_terms = joint_terms;
  for (Eigen::Index k = 0; k < q.rows(); ++k) {
    rnea(model, ws, q.row(k).transpose(), dq.row(k).transpose(), ddq.row(k).transpose(), out,
         options);
    tau.row(k) = out.transpose();
  }
  return tau;
}

JointRecord record_of(const Model& model, const Eigen::VectorXd& t, const Samples& q,
                      const Samples& tau, const std::optional<RowMatrix>& dq,
                      const std::optional<RowMatrix>& ddq) {
  check_samples(model, "q", t.size(), q);
  check_samples(model, "tau", t.size(), tau);
  JointRecord r;
  r.t = t;
  r.q = q;
  r.tau = tau;
  if (dq) {
    check_samples(model, "dq", t.size(), *dq);
    r.dq = *dq;
  }
  if (ddq) {
    check_samples(model, "ddq", t.size(), *ddq);
    r.ddq = *ddq;
  }
  return r;
}

// identify()/validate() options from keyword arguments; an unknown key is an error naming the
// valid ones.
// The `estimator` keyword ('ols', 'wls' or 'rls') as identify's or payload's enum.
template <class Estimator>
Estimator estimator_of(const std::string& name, Estimator ols, Estimator wls, Estimator rls) {
  if (name == "ols") return ols;
  if (name == "wls") return wls;
  if (name == "rls") return rls;
  throw py::value_error("estimator must be 'ols', 'wls' or 'rls', not '" + name + "'");
}

// The `confidence` keyword, checked.
double confidence_of(double level) {
  if (!(level > 0.0 && level < 1.0))
    throw py::value_error("confidence must be in (0, 1), e.g. 0.999");
  return level;
}

// Every keyword is one of `keys`, else a TypeError naming it and the valid ones.
template <size_t N>
void check_keywords(const py::kwargs& kw, const char* const (&keys)[N]) {
  std::string valid;
  for (const char* k : keys) valid += (valid.empty() ? "" : ", ") + std::string(k);
  for (const auto& item : kw) {
    const std::string key = py::str(item.first);
    if (std::find_if(std::begin(keys), std::end(keys), [&](const char* k) { return key == k; }) ==
        std::end(keys)) {
      throw py::type_error("unknown option '" + key + "'; valid options are " + valid);
    }
  }
}

IdentifyOptions identify_options(const py::kwargs& kw, nlohmann::json& used) {
  static const char* const kKeys[] = {"armature",   "viscous",   "coulomb",    "offset",
                                      "asymmetric", "estimator", "confidence", "cutoff_hz",
                                      "filter",     "decimate"};
  check_keywords(kw, kKeys);
  auto get = [&](const char* key, auto fallback) {
    using T = decltype(fallback);
    const T value = kw.contains(key) ? kw[key].cast<T>() : fallback;
    used[key] = value;
    return value;
  };
  IdentifyOptions o;
  o.layout = layout_of(get("armature", true), get("viscous", true), get("coulomb", true),
                       get("offset", true), get("asymmetric", false));
  o.estimator = estimator_of(get("estimator", std::string("ols")), IdentificationEstimator::kOls,
                             IdentificationEstimator::kWls, IdentificationEstimator::kRls);
  o.confidence_level = confidence_of(get("confidence", 0.999));
  o.signal.cutoff_hz = get("cutoff_hz", 0.0);
  o.signal.filter = get("filter", true);
  o.signal.decimate = get("decimate", 0);
  return o;
}

// payload() of a wrist force/torque sensor on the robot, as `dynid payload --robot R
// --sensor-link L`: the same stages and the same JSON (payload_to_json).
nlohmann::json payload(const Model& model, const std::string& sensor_link,
                       const std::optional<Eigen::VectorXd>& t, const Samples& q,
                       const Samples& wrench, const std::optional<RowMatrix>& dq,
                       const std::optional<RowMatrix>& ddq, const py::kwargs& kw) {
  static const char* const kKeys[] = {"sensor_pose", "model",       "interval",
                                      "bias",        "wrench_sign", "estimator",
                                      "confidence",  "cutoff_hz",   "filter"};
  check_keywords(kw, kKeys);
  auto get = [&](const char* key, auto fallback) {
    using T = decltype(fallback);
    return kw.contains(key) ? kw[key].cast<T>() : fallback;
  };
  LoadEquationOptions equations;
  const std::string kind = get("model", std::string("differential"));
  if (kind == "differential") {
    equations.model = LoadModelKind::kDifferential;
  } else if (kind == "integral") {
    equations.model = LoadModelKind::kIntegral;
  } else if (kind == "static") {
    equations.model = LoadModelKind::kStatic;
  } else {
    throw py::value_error("model must be 'differential', 'integral' or 'static', not '" + kind +
                          "'");
  }
  equations.interval = get("interval", 0.2);
  if (!(equations.interval > 0.0)) throw py::value_error("interval must be a positive window [s]");
  equations.bias = get("bias", false);
  equations.wrench_sign = get("wrench_sign", 1.0);
  if (!(equations.wrench_sign == 1.0 || equations.wrench_sign == -1.0)) {
    throw py::value_error(
        "wrench_sign must be 1 (force of the load on the sensor) or -1 (of the sensor on the "
        "load)");
  }
  LoadIdentificationOptions options;
  options.estimator = estimator_of(get("estimator", std::string("ols")), LoadEstimator::kOls,
                                   LoadEstimator::kWls, LoadEstimator::kRls);
  options.confidence_level = confidence_of(get("confidence", 0.999));
  SensorMount mount;
  mount.link = find_link(model, sensor_link);
  if (kw.contains("sensor_pose")) {
    const auto pose = kw["sensor_pose"].cast<std::vector<double>>();
    if (pose.size() != 6) {
      throw py::value_error("sensor_pose must be [x, y, z, roll, pitch, yaw] [m, rad]");
    }
    mount.p_LS = Eigen::Vector3d(pose[0], pose[1], pose[2]);
    mount.R_LS = roll_pitch_yaw(pose[3], pose[4], pose[5]);
  }
  const bool standing = equations.model == LoadModelKind::kStatic;
  if (!standing && !t) throw py::value_error("t is required unless model='static'");
  const RowMatrix::Index rows = q.rows();
  if (t && t->size() != rows) {
    throw Error("t has " + std::to_string(t->size()) + " samples, q " + std::to_string(rows));
  }
  check_samples(model, "q", rows, q);
  if (wrench.rows() != rows || wrench.cols() != 6) {
    throw Error("wrench must be " + std::to_string(rows) +
                " x 6 (fx fy fz mx my mz [N, N m] in the sensor frame), not " +
                std::to_string(wrench.rows()) + " x " + std::to_string(wrench.cols()));
  }
  if (!wrench.allFinite()) throw Error("wrench holds NaN or Inf");
  JointRecord record;
  if (t) record.t = *t;
  record.q = q;
  if (dq) {
    check_samples(model, "dq", rows, *dq);
    record.dq = *dq;
  }
  if (ddq) {
    check_samples(model, "ddq", rows, *ddq);
    record.ddq = *ddq;
  }
  std::vector<std::pair<std::string, std::string>> choices;
  SensorMotion motion;
  Eigen::MatrixXd w = wrench;
  if (standing) {
    record.dq.resize(0, 0);
    record.ddq.resize(0, 0);
    motion = sensor_motion_from_joints(model, record, mount);
  } else {
    SignalOptions signal;
    signal.filter = get("filter", true);
    signal.cutoff_hz = get("cutoff_hz", 0.0);
    PreparedLoadRun run = prepare_load_run(record, w, signal, choices);
    // Filtering correlates neighbouring residuals: intervals from the HAC sandwich.
    options.hac_covariance = signal.filter;
    w = std::move(run.wrench);
    motion = sensor_motion_from_joints(model, run.record, mount);
  }
  const EquationBlock block = load_equations(motion, w, equations);
  LoadIdentificationResult r;
  {
    py::gil_scoped_release release;
    r = identify_load(block, options);
  }
  PayloadJsonContext context;
  context.model = kind;
  context.frame = {{"robot", model.name}, {"sensor_link", model.joints[mount.link].link_name}};
  context.extra = {{"wrench_sign", equations.wrench_sign}};
  if (equations.model == LoadModelKind::kIntegral) context.extra["interval"] = equations.interval;
  context.group_names = block.group_names;
  context.with_inertia = !standing;
  context.choices = choices;
  return payload_to_json(r, context);
}

}  // namespace
}  // namespace dynid

PYBIND11_MODULE(dynid, m) {
  using namespace dynid;
  m.doc() =
      "dynid: identification of robot dynamic parameters (link inertias, actuator inertias, joint "
      "friction). Units SI; parameter names and order as in dynid's DESIGN.md section 3. Arrays "
      "of samples are (samples x joints) float64.";
  m.attr("__version__") = kVersion;
  py::register_exception<Error>(m, "Error", PyExc_ValueError);

  py::class_<Model>(m, "Model", "An immutable robot model (kinematic tree, inertias, friction).")
      .def_readonly("name", &Model::name, "Robot name")
      .def_property_readonly("dof", &Model::dof, "Number of moving joints n")
      .def_property_readonly(
          "joint_names",
          [](const Model& model) {
            std::vector<std::string> names;
            for (const auto& j : model.joints) names.push_back(j.name);
            return names;
          },
          "Joint names in dynid's joint order")
      .def_readonly("gravity", &Model::gravity, "Gravity in the base frame [m/s^2]")
      .def_property_readonly("standard_parameters", &Model::standard_parameters,
                             "Standard parameters theta (10 per link: XX XY XZ YY YZ ZZ MX MY MZ "
                             "M, about the link origin)")
      .def_property_readonly("standard_parameter_names", &Model::standard_parameter_names,
                             "Names of standard_parameters (XX1 ... Mn)")
      .def(
          "summary", [](const Model& model) { return to_python(model_to_json(model)); },
          "The model as a dict with the keys of 'dynid model --json'")
      .def("__repr__", [](const Model& model) {
        return "<dynid.Model '" + model.name + "' with " + std::to_string(model.dof()) + " joints>";
      });

  m.def("load_model", &load_robot, py::arg("path_or_name"),
        "Loads a built-in robot by short name (e.g. 'puma560') or a .urdf / .yaml model file.");

  m.def("inverse_dynamics", &inverse_dynamics, py::arg("model"), py::arg("q"), py::arg("dq"),
        py::arg("ddq"), py::arg("joint_terms") = true,
        "Joint torques tau = M(q) ddq + c(q, dq) + g(q) [+ Ia ddq + Fv dq + Fc sign(dq) + Fo "
        "when joint_terms] by recursive Newton-Euler, one row per sample. q, dq, ddq: (m x n) "
        "[rad, rad/s, rad/s^2 or m, m/s, m/s^2]; returns (m x n) [N m or N].");

  m.def(
      "regressor",
      [](const Model& model, const Samples& q, const Samples& dq, const Samples& ddq, bool armature,
         bool viscous, bool coulomb, bool offset, bool asymmetric) {
        check_samples(model, "q", q.rows(), q);
        check_samples(model, "dq", q.rows(), dq);
        check_samples(model, "ddq", q.rows(), ddq);
        const ParameterLayout layout = layout_of(armature, viscous, coulomb, offset, asymmetric);
        const int n = model.dof();
        Workspace ws(model);
        Eigen::MatrixXd Y(q.rows() * n, layout.columns(n));
        for (Eigen::Index k = 0; k < q.rows(); ++k) {
          torque_regressor(model, ws, layout, q.row(k).transpose(), dq.row(k).transpose(),
                           ddq.row(k).transpose(), Y.middleRows(k * n, n));
        }
        return py::make_tuple(Y, layout.names(n));
      },
      py::arg("model"), py::arg("q"), py::arg("dq"), py::arg("ddq"), py::arg("armature") = true,
      py::arg("viscous") = true, py::arg("coulomb") = true, py::arg("offset") = true,
      py::arg("asymmetric") = false,
      "Joint-torque regressor: returns (Y, names) with tau = Y theta, Y of (m n) x p, "
      "sample-major (rows k n ... k n + n - 1 are sample k), names of the p columns (link "
      "parameters, then Ia Fv Fc Fo per joint as selected).");

  m.def(
      "base_parameters",
      [](const Model& model, bool armature, bool viscous, bool coulomb, bool offset,
         bool asymmetric) {
        BaseParameterOptions options;
        options.layout = layout_of(armature, viscous, coulomb, offset, asymmetric);
        options.coupling = true;
        const BaseParameters base = compute_base_parameters(model, options);
        py::dict out = to_python(base_parameters_to_json(base)).cast<py::dict>();
        out["K_d"] = base.K_d;
        out["base_indices"] = base.base;
        out["dependent_indices"] = base.dependent;
        out["layout_names"] = base.layout_names;
        return out;
      },
      py::arg("model"), py::arg("armature") = true, py::arg("viscous") = true,
      py::arg("coulomb") = true, py::arg("offset") = true, py::arg("asymmetric") = false,
      "Base parameters theta_b = theta_1 + K_d theta_2 (numerical Gautier-Khalil): a dict with "
      "the keys of 'dynid model --base --json' (rank, base_parameters [{name, expression}], "
      "unidentifiable, samples) plus K_d, base_indices, dependent_indices and layout_names.");

  m.def(
      "identify",
      [](const Model& model, const Eigen::VectorXd& t, const Samples& q, const Samples& tau,
         const std::optional<RowMatrix>& dq, const std::optional<RowMatrix>& ddq,
         const py::kwargs& kw) {
        nlohmann::json used;
        const IdentifyOptions options = identify_options(kw, used);
        const JointRecord record = record_of(model, t, q, tau, dq, ddq);
        IdentificationResult result;
        {
          py::gil_scoped_release release;
          result = identify(model, record, options);
        }
        return to_python(identification_to_json(model, result, used));
      },
      py::arg("model"), py::arg("t"), py::arg("q"), py::arg("tau"), py::arg("dq") = py::none(),
      py::arg("ddq") = py::none(),
      "Identifies base parameters with their uncertainty from one run, as 'dynid identify': t "
      "(m,) [s], q and tau (m x n), optional dq, ddq (derived from q when absent). Options: "
      "armature, viscous, coulomb, offset, asymmetric (bool: the per-joint columns), estimator "
      "('ols', 'wls', 'rls'), confidence (0.999), cutoff_hz (0 = automatic), filter (bool), "
      "decimate (0 = automatic). Returns a dict with the keys of the result JSON (parameters, "
      "condition_number, residual_rms, ...).");

  m.def(
      "validate",
      [](const Model& model, const py::dict& result, const Eigen::VectorXd& t, const Samples& q,
         const Samples& tau, const std::optional<RowMatrix>& dq,
         const std::optional<RowMatrix>& ddq, const py::kwargs& kw) {
        nlohmann::json used;
        const IdentifyOptions options = identify_options(kw, used);
        const JointRecord record = record_of(model, t, q, tau, dq, ddq);
        std::vector<std::string> names;
        std::vector<double> values;
        for (const auto& p : result["parameters"].cast<py::list>()) {
          names.push_back(p["name"].cast<std::string>());
          values.push_back(p["value"].cast<double>());
        }
        const ValidationResult v =
            validate_torques(model, record, names,
                             Eigen::Map<const Eigen::VectorXd>(
                                 values.data(), static_cast<Eigen::Index>(values.size())),
                             options);
        return to_python(validation_to_json(model, v));
      },
      py::arg("model"), py::arg("result"), py::arg("t"), py::arg("q"), py::arg("tau"),
      py::arg("dq") = py::none(), py::arg("ddq") = py::none(),
      "Prediction errors of an identify() result on another run, as 'dynid validate': give the "
      "same options as to identify(). Returns a dict with the keys of the validate JSON.");

  m.def(
      "payload",
      [](const Model& model, const std::string& sensor_link,
         const std::optional<Eigen::VectorXd>& t, const Samples& q, const Samples& wrench,
         const std::optional<RowMatrix>& dq, const std::optional<RowMatrix>& ddq,
         const py::kwargs& kw) {
        return to_python(payload(model, sensor_link, t, q, wrench, dq, ddq, kw));
      },
      py::arg("model"), py::arg("sensor_link"), py::arg("t"), py::arg("q"), py::arg("wrench"),
      py::arg("dq") = py::none(), py::arg("ddq") = py::none(),
      "Inertial parameters of a gripped load from a wrist force/torque sensor, as 'dynid payload "
      "--robot R --sensor-link L' (Dutkiewicz, Kozlowski, Wroblewski 1993): sensor_link names "
      "the link (or joint) that carries the sensor; t (m,) [s] (None with model='static'), q "
      "(m x n), wrench (m x 6: fx fy fz mx my mz [N, N m], the force of the load on the sensor, "
      "sensor frame), optional dq, ddq. Options: sensor_pose [x, y, z, roll, pitch, yaw] of the "
      "sensor in the link frame [m, rad], model ('differential', 'integral', 'static'), interval "
      "(integral window [s], 0.2), bias (bool: sensor offsets), wrench_sign (1 or -1), estimator "
      "('ols', 'wls', 'rls'), confidence (0.999), cutoff_hz (0 = automatic), filter (bool). "
      "Returns a dict with the keys of the payload JSON (parameters, mass, com, inertia_com, "
      "physically_consistent, ...).");

  m.def(
      "export_urdf",
      [](const Model& model, const py::dict& result, const std::string& path) {
        if (!result.contains("standard_parameters") || !result.contains("physically_consistent") ||
            !result["physically_consistent"].cast<bool>()) {
          throw Error(
              "the result has no physically consistent standard_parameters; identify with "
              "--physical");
        }
        std::vector<std::string> names;
        std::vector<double> values;
        for (const auto& p : result["standard_parameters"].cast<py::list>()) {
          names.push_back(p["name"].cast<std::string>());
          values.push_back(p["value"].cast<double>());
        }
        const UrdfExport out =
            export_urdf(model, names,
                        Eigen::Map<const Eigen::VectorXd>(values.data(),
                                                          static_cast<Eigen::Index>(values.size())),
                        "python");
        write_text_atomic(path, out.text);
        return out.not_in_urdf;
      },
      py::arg("model"), py::arg("result"), py::arg("path"),
      "Writes the standard_parameters of an 'identify --physical' result as URDF, as 'dynid "
      "export'; returns the identified terms the URDF cannot hold.");
}
