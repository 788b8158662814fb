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
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/io/urdf_export.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/report/identification_report.hpp"
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
IdentifyOptions identify_options(const py::kwargs& kw, nlohmann::json& used) {
  static const char* kKeys[] = {"armature",  "viscous",    "coulomb",   "offset", "asymmetric",
                                "estimator", "confidence", "cutoff_hz", "filter", "decimate"};
  std::string valid;
  for (const char* k : kKeys) valid += (valid.empty() ? "" : ", ") + std::string(k);
  for (const auto& item : kw) {
    const std::string key = py::str(item.first);
    if (std::find_if(std::begin(kKeys), std::end(kKeys), [&](const char* k) { return key == k; }) ==
        std::end(kKeys)) {
      throw py::type_error("unknown option '" + key + "'; valid options are " + valid);
    }
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
  if (estimator == "ols") {
    o.estimator = IdentificationEstimator::kOls;
  } else if (estimator == "wls") {
    o.estimator = IdentificationEstimator::kWls;
  } else if (estimator == "rls") {
    o.estimator = IdentificationEstimator::kRls;
  } else {
    throw py::value_error("estimator must be 'ols', 'wls' or 'rls', not '" + estimator + "'");
  }
  o.confidence_level = get("confidence", 0.999);
  if (!(o.confidence_level > 0.0 && o.confidence_level < 1.0))
    throw py::value_error("confidence must be in (0, 1), e.g. 0.999");
  o.signal.cutoff_hz = get("cutoff_hz", 0.0);
  o.signal.filter = get("filter", true);
  o.signal.decimate = get("decimate", 0);
  return o;
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
