// Python bindings of dynid (issue 15 item 4): one translation unit, so that the module adds one
// compile to the build. Arrays are NumPy float64; a C-contiguous (row-major) m×n array of samples
// is read without a copy. Results are dicts with the keys of the JSON that dynid writes (they go
// through that JSON, so the two cannot drift apart).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>
#include <tuple>

#include <nlohmann/json.hpp>

#include "binding.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/estimation/parameter_drift.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/streaming_partial.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/load/load_identification.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/physical/physical_parameters.hpp"
#include "dynid/physical/urdf_export.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/report/drift_report.hpp"
#include "dynid/report/experiment_report.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/report/payload_report.hpp"
#include "dynid/report/stored_result.hpp"
#include "dynid/version.hpp"

namespace py = pybind11;

namespace dynid::binding {

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

double confidence_of(double level) {
  if (!(level > 0.0 && level < 1.0))
    throw py::value_error("confidence must be in (0, 1), e.g. 0.999");
  return level;
}

IdentifiedResultFile identified_result(const Model& model, const py::dict& result,
                                       const std::string& what) {
  // allow_nan=False: a NaN or Inf value is refused here by name, as the command line refuses it,
  // instead of reaching the JSON parser as the non-JSON token NaN.
  std::string text;
  try {
    text = py::module_::import("json")
               .attr("dumps")(result, py::arg("allow_nan") = false)
               .cast<std::string>();
  } catch (const py::error_already_set& e) {
    throw Error("the " + what + " holds a value a result cannot have (" + one_line(e.what()) +
                "); give finite numbers, as dynid.identify returns them");
  }
  const nlohmann::json j = nlohmann::json::parse(text);
  IdentifiedResultFile identified = identification_result_from_json(j, what);
  if (!identified.robot.empty() && identified.robot != model.name) {
    throw Error("the " + what + " is of robot '" + identified.robot + "', not '" + model.name +
                "'; give a result of this robot");
  }
  return identified;
}

}  // namespace dynid::binding

namespace dynid {
namespace {

using namespace binding;

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

// The load equations and estimator shared by the sensor modes of payload (`dynid payload`'s
// --model, --static, --interval, --components, --bias, --wrench-sign, --estimator, --confidence).
struct LoadKeywords {
  LoadEquationOptions equations;
  LoadIdentificationOptions options;
  std::string model;  // the JSON's `model`
};

template <class Get>
LoadKeywords load_keywords(const Get& get) {
  LoadKeywords k;
  k.model = get("equations", std::string("differential"));
  if (k.model == "differential") {
    k.equations.model = LoadModelKind::kDifferential;
  } else if (k.model == "integral") {
    k.equations.model = LoadModelKind::kIntegral;
  } else if (k.model == "static") {
    k.equations.model = LoadModelKind::kStatic;
  } else {
    throw py::value_error("equations must be 'differential', 'integral' or 'static', not '" +
                          k.model + "'");
  }
  k.equations.interval = get("interval", 0.2);
  if (!(k.equations.interval > 0.0))
    throw py::value_error("interval must be a positive window [s]");
  k.equations.bias = get("bias", false);
  const std::string components = get("components", std::string());
  if (!components.empty()) {
    k.equations.components = load_components_from_text(components, "components");
  }
  k.equations.wrench_sign = get("wrench_sign", 1.0);
  if (!(k.equations.wrench_sign == 1.0 || k.equations.wrench_sign == -1.0)) {
    throw py::value_error(
        "wrench_sign must be 1 (force of the load on the sensor) or -1 (of the sensor on the "
        "load)");
  }
  k.options.estimator = estimator_of(get("estimator", std::string("ols")), LoadEstimator::kOls,
                                     LoadEstimator::kWls, LoadEstimator::kRls);
  k.options.confidence_level = confidence_of(get("confidence", 0.999));
  return k;
}

// A pose keyword [x, y, z, roll, pitch, yaw] [m, rad] as (R, p), URDF roll-pitch-yaw.
std::pair<Eigen::Matrix3d, Eigen::Vector3d> pose_of(const py::kwargs& kw, const char* key,
                                                    const char* of) {
  const auto pose = kw[key].cast<std::vector<double>>();
  if (pose.size() != 6 ||
      !std::all_of(pose.begin(), pose.end(), [](double x) { return std::isfinite(x); })) {
    throw py::value_error(std::string(key) + " must be [x, y, z, roll, pitch, yaw] of " + of +
                          " [m, rad], finite");
  }
  return {roll_pitch_yaw(pose[3], pose[4], pose[5]), Eigen::Vector3d(pose[0], pose[1], pose[2])};
}

void check_wrench(RowMatrix::Index rows, const Samples& wrench) {
  if (wrench.rows() != rows || wrench.cols() != 6) {
    throw Error("wrench must be " + std::to_string(rows) +
                " x 6 (fx fy fz mx my mz [N, N m] in the sensor frame), not " +
                std::to_string(wrench.rows()) + " x " + std::to_string(wrench.cols()));
  }
  if (!wrench.allFinite()) throw Error("wrench holds NaN or Inf");
}

// An optional m×k block of the sensor log (w, dw, a), checked; empty when absent.
Eigen::MatrixXd log_columns(const std::optional<RowMatrix>& x, const char* name,
                            RowMatrix::Index rows, RowMatrix::Index cols) {
  if (!x) return {};
  if (x->rows() != rows || x->cols() != cols) {
    throw Error(std::string(name) + " must be " + std::to_string(rows) + " x " +
                std::to_string(cols) + ", not " + std::to_string(x->rows()) + " x " +
                std::to_string(x->cols()));
  }
  if (!x->allFinite()) throw Error(std::string(name) + " holds NaN or Inf");
  return *x;
}

// The load's equations, estimate and JSON, as `dynid payload` ends every sensor mode.
nlohmann::json solve_load(const SensorMotion& motion, const Eigen::MatrixXd& wrench,
                          const LoadKeywords& k, const nlohmann::json& frame,
                          const std::vector<std::pair<std::string, std::string>>& choices) {
  const EquationBlock block = load_equations(motion, wrench, k.equations);
  LoadIdentificationResult r;
  {
    py::gil_scoped_release release;
    r = identify_load(block, k.options);
  }
  PayloadJsonContext context;
  context.model = k.model;
  context.frame = frame;
  context.extra = {{"wrench_sign", k.equations.wrench_sign}};
  if (k.equations.model == LoadModelKind::kIntegral)
    context.extra["interval"] = k.equations.interval;
  context.extra["components"] = block.group_names;
  context.group_names = block.group_names;
  context.with_inertia = k.equations.model != LoadModelKind::kStatic;
  context.choices = choices;
  return payload_to_json(r, context);
}

// payload() of a wrist force/torque sensor on the robot, as `dynid payload --robot R
// --sensor-link L`: the same stages and the same JSON (payload_to_json).
nlohmann::json payload(const Model& model, const std::string& sensor_link,
                       const std::optional<Eigen::VectorXd>& t, const Samples& q,
                       const Samples& wrench, const std::optional<RowMatrix>& dq,
                       const std::optional<RowMatrix>& ddq, const py::kwargs& kw) {
  static const char* const kKeys[] = {"sensor_pose", "equations",   "interval",  "bias",
                                      "components",  "wrench_sign", "estimator", "confidence",
                                      "cutoff_hz",   "filter"};
  check_keywords(kw, kKeys);
  const auto get = keyword_getter(kw);
  LoadKeywords k = load_keywords(get);
  SensorMount mount;
  mount.link = find_link(model, sensor_link);
  if (kw.contains("sensor_pose")) {
    std::tie(mount.R_LS, mount.p_LS) = pose_of(kw, "sensor_pose", "the sensor in the link frame");
  }
  const bool standing = k.equations.model == LoadModelKind::kStatic;
  if (!standing && !t) throw py::value_error("t is required unless equations='static'");
  const RowMatrix::Index rows = q.rows();
  if (t && t->size() != rows) {
    throw Error("t has " + std::to_string(t->size()) + " samples, q " + std::to_string(rows));
  }
  check_samples(model, "q", rows, q);
  check_wrench(rows, wrench);
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
    PreparedLoadRun run = prepare_sensor_run(model, mount, record, w, signal, k.equations, choices);
    // Filtering correlates neighbouring residuals: intervals from the HAC sandwich.
    k.options.hac_covariance = signal.filter;
    w = std::move(run.wrench);
    motion = sensor_motion_from_joints(model, run.record, mount);
  }
  return solve_load(motion, w, k,
                    {{"robot", model.name}, {"sensor_link", model.joints[mount.link].link_name}},
                    choices);
}

// payload_from_orientation(): a sensor without a robot model, as `dynid payload` with the columns
// qx qy qz qw [wx wy wz dwx dwy dwz ax ay az].
nlohmann::json payload_from_orientation(const std::optional<Eigen::VectorXd>& t,
                                        const Samples& quaternion, const Samples& wrench,
                                        const std::optional<RowMatrix>& w,
                                        const std::optional<RowMatrix>& dw,
                                        const std::optional<RowMatrix>& a, const py::kwargs& kw) {
  static const char* const kKeys[] = {"equations",   "interval",  "components", "bias",
                                      "wrench_sign", "estimator", "confidence", "gravity"};
  check_keywords(kw, kKeys);
  const auto get = keyword_getter(kw);
  const LoadKeywords k = load_keywords(get);
  const auto g = get("gravity", std::vector<double>{0.0, 0.0, -9.81});
  if (g.size() != 3)
    throw py::value_error("gravity must be [gx, gy, gz] in the base frame [m/s^2]");
  const bool standing = k.equations.model == LoadModelKind::kStatic;
  if (!standing && !t) throw py::value_error("t is required unless equations='static'");
  const RowMatrix::Index rows = quaternion.rows();
  if (quaternion.cols() != 4) {
    throw Error("quaternion must be " + std::to_string(rows) +
                " x 4 (qx qy qz qw: the sensor frame in the base frame), not " +
                std::to_string(rows) + " x " + std::to_string(quaternion.cols()));
  }
  if (!quaternion.allFinite()) throw Error("quaternion holds NaN or Inf");
  check_wrench(rows, wrench);
  OrientationLog log;
  log.quaternion = quaternion;
  if (!standing) {  // standing poses: only the orientation is used, as on the command line
    if (t->size() != rows) {
      throw Error("t has " + std::to_string(t->size()) + " samples, quaternion " +
                  std::to_string(rows));
    }
    log.t = *t;
    log.w = log_columns(w, "w", rows, 3);
    log.dw = log_columns(dw, "dw", rows, 3);
    log.a = log_columns(a, "a", rows, 3);
  }
  std::vector<std::pair<std::string, std::string>> choices;
  const SensorMotion motion =
      sensor_motion_from_orientation(log, Eigen::Vector3d(g[0], g[1], g[2]), choices);
  return solve_load(motion, wrench, k, {{"orientation", "qx qy qz qw from the data"}}, choices);
}

// The identify options that rebuild a result's regressor and filtering, as `dynid validate` and
// `dynid payload --reference result.json` read the file (options_of_stored_result).
IdentifyOptions options_of_result(const Model& model, const IdentifiedResultFile& identified) {
  return options_of_stored_result(identified, "result", model.dof()).options;
}

// payload_from_torques(): a load without a sensor, as `dynid payload --robot R --link L
// --reference unloaded.csv|result.json`.
nlohmann::json payload_from_torques(const Model& model, const std::string& link_name,
                                    const Eigen::VectorXd& t, const Samples& q, const Samples& tau,
                                    const py::dict& reference, const std::optional<RowMatrix>& dq,
                                    const std::optional<RowMatrix>& ddq, const py::kwargs& kw) {
  static const char* const kKeys[] = {"frame", "estimator", "confidence", "cutoff_hz", "filter"};
  check_keywords(kw, kKeys);
  const auto get = keyword_getter(kw);
  LoadIdentificationOptions options;
  options.estimator = estimator_of(get("estimator", std::string("ols")), LoadEstimator::kOls,
                                   LoadEstimator::kWls, LoadEstimator::kRls);
  options.confidence_level = confidence_of(get("confidence", 0.999));
  LoadFrame frame;
  std::string frame_text = "link frame";
  if (kw.contains("frame")) {
    std::tie(frame.R_LF, frame.p_LF) = pose_of(kw, "frame", "the load's frame in the link frame");
    std::ostringstream text;
    const auto pose = kw["frame"].cast<std::vector<double>>();
    for (size_t i = 0; i < pose.size(); ++i) text << (i ? " " : "") << pose[i];
    frame_text = text.str();
  }
  const int link = find_link(model, link_name);
  const JointRecord loaded_raw = record_of(model, t, q, tau, dq, ddq);
  LoadIdentificationResult r;
  std::vector<std::pair<std::string, std::string>> choices;
  std::string reference_text;
  // With a result reference: what its prediction took from the nominal model.
  nlohmann::json filled = nlohmann::json::object();
  if (reference.contains("parameters")) {  // an identify() result of the unloaded robot
    if (kw.contains("cutoff_hz") || kw.contains("filter")) {
      throw py::value_error(
          "cutoff_hz and filter come from the reference result (the loaded run is filtered as "
          "identify filtered the unloaded one); drop them");
    }
    const IdentifiedResultFile identified = identified_result(model, reference, "reference");
    const IdentifyOptions identify = options_of_result(model, identified);
    // Filtering correlates neighbouring residuals: intervals from the HAC sandwich.
    options.hac_covariance = identify.signal.filter;
    {
      py::gil_scoped_release release;
      const ValidationResult predicted = validate_torques(
          model, loaded_raw, identified.names, identified.values, identify, identified.not_excited,
          nominal_completion_of_result(model, identified, "reference"));
      r = identify_load_from_unexplained_torques(model, link, frame, predicted.processed.record,
                                                 predicted.predicted,
                                                 predicted.zero_velocity_threshold, options);
      choices = predicted.choices;
      filled = {{"completed", predicted.completed}, {"filled_share", predicted.filled_share}};
    }
    if (identified.options.contains("torque_scale") &&
        !identified.options["torque_scale"].empty()) {
      choices.emplace_back("torque_scale",
                           "the reference's torque scale is not applied: tau is taken as the "
                           "joint torques [N m]");
    }
    choices.emplace_back("reference_model",
                         "the torque of the reference identify result predicted on this run as "
                         "validate does; rows below its zero-velocity thresholds are left out of "
                         "the load fit too; its own uncertainty is not propagated");
    reference_text = "identify result (dict)";
  } else {  // the unloaded run's arrays: robot and load identified together
    static const char* const kRunKeys[] = {"t", "q", "tau", "dq", "ddq"};
    for (const auto& item : reference) {
      const std::string key = py::str(item.first);
      if (std::find(std::begin(kRunKeys), std::end(kRunKeys), key) == std::end(kRunKeys)) {
        throw py::value_error("reference: unknown key '" + key +
                              "'; give an identify() result (with 'parameters') or the unloaded "
                              "run {'t', 'q', 'tau'[, 'dq', 'ddq']}");
      }
    }
    for (const char* key : {"t", "q", "tau"}) {
      if (!reference.contains(key)) {
        throw py::value_error(std::string("reference has no '") + key +
                              "'; give an identify() result (with 'parameters') or the unloaded "
                              "run {'t', 'q', 'tau'[, 'dq', 'ddq']}");
      }
    }
    const auto optional_of = [&](const char* key) {
      return reference.contains(key) ? std::optional<RowMatrix>(reference[key].cast<RowMatrix>())
                                     : std::optional<RowMatrix>();
    };
    const JointRecord unloaded_raw =
        record_of(model, reference["t"].cast<Eigen::VectorXd>(), reference["q"].cast<RowMatrix>(),
                  reference["tau"].cast<RowMatrix>(), optional_of("dq"), optional_of("ddq"));
    SignalOptions signal;
    signal.filter = get("filter", true);
    signal.cutoff_hz = get("cutoff_hz", 0.0);
    options.hac_covariance = signal.filter;
    std::vector<std::pair<std::string, std::string>> reference_choices;
    const JointRecord loaded = preprocess(loaded_raw, signal, choices).record;
    const JointRecord unloaded = preprocess(unloaded_raw, signal, reference_choices).record;
    py::gil_scoped_release release;
    r = identify_load_from_torques(model, link, frame, ParameterLayout::full(), loaded, unloaded,
                                   options);
    reference_text = "unloaded run (arrays)";
  }
  std::vector<std::string> joints, determined;
  for (const auto& joint : model.joints) joints.push_back(joint.name);
  for (const auto& name : r.names) {
    if (std::find(r.not_excited.begin(), r.not_excited.end(), name) == r.not_excited.end())
      determined.push_back(name);
  }
  PayloadJsonContext context;
  context.model = "joint_torques";
  context.frame = {
      {"robot", model.name}, {"link", model.joints[link].link_name}, {"frame", frame_text}};
  context.extra = {{"reference", reference_text}, {"determined_by_torques", determined}};
  context.extra.update(filled);
  context.group_names = joints;
  context.choices = choices;
  return payload_to_json(r, context);
}

}  // namespace
}  // namespace dynid

// The compiled half of the Python package dynid (python/dynid/__init__.py re-exports it).
namespace dynid {

// Issue 31 (python/dynid/fleet.py): the per-file partial state of the stream, its exact merge and
// solve, and the drift comparison. Parts travel as the bytes of the .dpart format, which is what
// crosses a cluster's network (never the samples).
void bind_fleet(py::module_& m) {
  m.def(
      "stream_partial",
      [](const Model& model, const std::vector<std::string>& files, const std::string& robot,
         bool armature, bool viscous, bool coulomb, bool offset, bool asymmetric,
         const std::string& estimator, double confidence, const std::vector<double>& zero_velocity,
         bool householder, int threads) {
        if (estimator != "ols" && estimator != "wls") {
          throw Error("estimator must be 'ols' or 'wls' for a streamed part, not '" + estimator +
                      "'");
        }
        if (!(confidence > 0.0 && confidence < 1.0)) {
          throw Error("confidence must be in (0, 1), e.g. 0.999");
        }
        IdentifyOptions o;
        o.layout = layout_of(armature, viscous, coulomb, offset, asymmetric);
        o.estimator =
            estimator == "wls" ? IdentificationEstimator::kWls : IdentificationEstimator::kOls;
        o.confidence_level = confidence;
        o.signal.filter = false;
        o.signal.zero_velocity = zero_velocity;
        std::string bytes;
        {
          py::gil_scoped_release release;
          StreamPartial part = stream_partial(model, files, {}, o, {threads, !householder});
          part.options = {{"armature", armature},
                          {"viscous", viscous},
                          {"coulomb", coulomb},
                          {"offset", offset},
                          {"asymmetric", asymmetric},
                          {"estimator", estimator},
                          {"confidence_level", confidence},
                          {"zero_velocity", zero_velocity},
                          {"filter", false}};
          part.origin = stream_partial_origin(robot.empty() ? model.name : robot, model);
          bytes = stream_partial_bytes(part);
        }
        return py::bytes(bytes);
      },
      py::arg("model"), py::arg("files"), py::arg("robot") = "", py::arg("armature") = true,
      py::arg("viscous") = true, py::arg("coulomb") = true, py::arg("offset") = true,
      py::arg("asymmetric") = false, py::arg("estimator") = "ols", py::arg("confidence") = 0.999,
      py::arg("zero_velocity") = std::vector<double>{}, py::arg("householder") = false,
      py::arg("threads") = 1,
      "The accumulated least-squares state of CSV runs read in constant memory, as 'dynid "
      "identify --stream --partial' writes it (bytes of the .dpart format, docs/methods/fleet.md): "
      "files (q*, dq*, ddq*, tau* columns, no filtering), robot (the name or path model was "
      "loaded from, stored so that solve_partial can load it again), the per-joint columns, "
      "estimator ('ols', 'wls'), confidence, zero_velocity [rad/s] (1 or n values), householder "
      "(Householder QR instead of normal equations), threads (per file).");
  m.def(
      "merge_partials",
      [](const std::vector<std::string>& parts) {
        if (parts.empty()) throw Error("merge_partials needs at least one part");
        std::string bytes;
        {
          py::gil_scoped_release release;
          StreamPartial merged = stream_partial_from_bytes(parts.front(), "part 1");
          for (std::size_t i = 1; i < parts.size(); ++i) {
            merge_stream_partials(
                merged, stream_partial_from_bytes(parts[i], "part " + std::to_string(i + 1)),
                "part 1", "part " + std::to_string(i + 1));
          }
          bytes = stream_partial_bytes(merged);
        }
        return py::bytes(bytes);
      },
      py::arg("parts"),
      "Merges parts (bytes of stream_partial or merge_partials) exactly into one part, as 'dynid "
      "merge --partial'; refuses parts of another robot or option set (dynid.Error).");
  m.def(
      "solve_partial",
      [](const std::string& bytes, const std::optional<Model>& model) {
        const StreamPartial part = stream_partial_from_bytes(bytes, "part");
        JointSelection selection;
        std::string robot = stream_partial_robot(part, selection);
        Model loaded;
        if (model) {
          loaded = *model;
          robot = model->name;
        } else {
          RobotOptions options;
          options.selection = selection;
          loaded = load_robot(robot, options).model;
        }
        py::gil_scoped_release release;
        const IdentificationResult result = solve_stream_partial(loaded, part);
        const nlohmann::json out =
            identification_to_json(loaded, result, stream_partial_result_options(part, robot));
        py::gil_scoped_acquire acquire;
        return to_python(out);
      },
      py::arg("part"), py::arg("model") = py::none(),
      "Solves a part as 'dynid merge --out' does and returns the result dict (the keys of the "
      "result JSON); model: the robot (default: the one the part names, loaded here).");
  m.def(
      "compare",
      [](const std::vector<py::dict>& results, double alpha, std::vector<std::string> labels) {
        if (!labels.empty() && labels.size() != results.size()) {
          throw Error("labels: give one per result or none");
        }
        std::vector<DriftInput> inputs;
        std::vector<std::string> covariances, robots;
        for (std::size_t i = 0; i < results.size(); ++i) {
          if (labels.size() < results.size()) labels.push_back("result " + std::to_string(i));
          const nlohmann::json j = nlohmann::json::parse(
              py::module_::import("json").attr("dumps")(results[i]).cast<std::string>());
          std::string covariance;
          inputs.push_back(drift_input_of_result(j, labels[i], &covariance));
          covariances.push_back(covariance);
          robots.push_back(robot_of_result(j));
          if (!robots.back().empty() && !robots.front().empty() &&
              robots.back() != robots.front()) {
            throw Error(labels[i] + " is a result of robot '" + robots.back() + "', " + labels[0] +
                        " of '" + robots.front() + "'; compare results of one robot type");
          }
        }
        DriftOptions options;
        options.alpha = alpha;
        const DriftComparison c = compare_estimates(inputs, options);
        return to_python(drift_to_json(inputs, covariances, robots, c));
      },
      py::arg("results"), py::arg("alpha") = 0.01, py::arg("labels") = std::vector<std::string>{},
      "Per parameter, the change of each later result against the first, its standard deviation "
      "from both results, the z-score and Holm's verdict at the family-wise false-alarm rate "
      "alpha, as 'dynid compare --json' (results: dicts of identify, solve_partial or payload, "
      "or result JSONs loaded with json.load).");
}

}  // namespace dynid

PYBIND11_MODULE(_core, m) {
  using namespace dynid;
  using namespace dynid::binding;
  m.doc() =
      "dynid: identification of robot dynamic parameters (link inertias, actuator inertias, joint "
      "friction). Units SI; parameter names and order as in dynid's docs/design.md section 3. "
      "Arrays "
      "of samples are (samples x joints) float64.";
  m.attr("__version__") = kVersion;
  static PyObject* error_type = py::register_exception<Error>(m, "Error", PyExc_ValueError).ptr();
  // What escapes the library as another type is still a dynid.Error with a plain message: a
  // malformed result dict's JSON type error, a value pybind11 cannot convert.
  py::register_exception_translator([](std::exception_ptr p) {
    try {
      if (p) std::rethrow_exception(p);
    } catch (const nlohmann::json::exception& e) {
      std::string text = e.what();
      const auto tag = text.find("] ");
      if (!text.empty() && text[0] == '[' && tag != std::string::npos) text.erase(0, tag + 2);
      PyErr_SetString(error_type, ("a result value has the wrong type: " + text).c_str());
    } catch (const py::cast_error& e) {
      PyErr_SetString(error_type, (std::string("an argument has the wrong type: ") + e.what() +
                                   "; pass numbers and float64 arrays")
                                      .c_str());
    }
  });

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
      .def_property_readonly(
          "locked_joints",
          [](const Model& model) {
            std::map<std::string, double> locked;
            for (const JointLock& l : model.locked_joints) locked[l.name] = l.value;
            return locked;
          },
          "Joints of the robot file held fixed by load_model(lock=...): name -> value [rad or m]")
      .def(
          "summary", [](const Model& model) { return to_python(model_to_json(model)); },
          "The model as a dict with the keys of 'dynid model --json'")
      .def("__repr__", [](const Model& model) {
        return "<dynid.Model '" + model.name + "' with " + std::to_string(model.dof()) + " joints>";
      });

  m.def(
      "load_model",
      [](const std::string& path_or_name, const std::vector<std::string>& joints,
         const std::map<std::string, double>& lock, bool strict) {
        RobotOptions options;
        options.strict = strict;
        options.selection.joints = joints;
        for (const auto& [name, value] : lock) options.selection.locks.push_back({name, value});
        LoadedRobot loaded = load_robot(path_or_name, options);
        for (const std::string& w : loaded.warnings) {
          if (PyErr_WarnEx(PyExc_UserWarning, w.c_str(), 1) != 0) throw py::error_already_set();
        }
        return loaded.model;
      },
      py::arg("path_or_name"), py::arg("joints") = std::vector<std::string>{},
      py::arg("lock") = std::map<std::string, double>{}, py::arg("strict") = false,
      "Loads a built-in robot by short name (e.g. 'puma560') or a .urdf / .yaml model file. "
      "joints: the joints identified, in the log's order (default: all); every other moving joint "
      "is held fixed at lock[name] [rad or m] (default 0) and its links merge into the link "
      "carrying it (as the CLI's --joints/--lock). A non-physical link inertia is a UserWarning, "
      "or an error with strict=True (--strict).");

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
      "validate",
      [](const Model& model, const py::dict& result, const Eigen::VectorXd& t, const Samples& q,
         const Samples& tau, const std::optional<RowMatrix>& dq,
         const std::optional<RowMatrix>& ddq, const py::kwargs& kw) {
        const IdentifiedResultFile identified = identified_result(model, result, "result");
        nlohmann::json used;
        const IdentifyOptions options =
            kw.empty() ? options_of_result(model, identified) : identify_options(kw, used);
        const JointRecord record = record_of(model, t, q, tau, dq, ddq);
        ValidationResult v;
        {
          py::gil_scoped_release release;
          v = validate_torques(model, record, identified.names, identified.values, options,
                               identified.not_excited,
                               nominal_completion_of_result(model, identified, "result"));
        }
        std::vector<std::string> joints;
        for (const auto& joint : model.joints) joints.push_back(joint.name);
        nlohmann::json out = validation_to_json(model, v);
        out["plot"] = prediction_plot_json(v, joints);
        return to_python(out);
      },
      py::arg("model"), py::arg("result"), py::arg("t"), py::arg("q"), py::arg("tau"),
      py::arg("dq") = py::none(), py::arg("ddq") = py::none(),
      "Prediction errors of an identify() result (a dynid.identify dict, or the command line's "
      "result.json loaded with json.load) on another run, as 'dynid validate --json': t (m,) [s], "
      "q and tau (m x n), optional dq, ddq. Without options the run is processed as identify "
      "processed its own (the result's friction set, armature and filter, the cut-off and "
      "zero-velocity thresholds identify used), as the command line does; or give the same "
      "keyword options as to identify() to set them all. Returns a dict with the keys of the "
      "validate JSON, 'plot' (measured and predicted torques, residual histogram) included. A "
      "result of another robot is a dynid.Error.");

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
      "Inertial parameters of a gripped load (m mcx mcy mcz Ixx Ixy Ixz Iyy Iyz Izz about the "
      "sensor origin, sensor axes) from a wrist force/torque sensor on a robot, as 'dynid "
      "payload --robot R --sensor-link L' (P. Dutkiewicz, K. R. Kozlowski, W. S. Wroblewski, "
      "'Experimental Identification of Robot and Load Dynamic Parameters', 1993, section III): "
      "sensor_link names the link (or joint) that carries the sensor; t (m,) [s] (None with "
      "equations='static'), q (m x n), wrench (m x 6: fx fy fz mx my mz [N, N m], the force of the "
      "load on the sensor, sensor frame), optional dq, ddq. Options: sensor_pose [x, y, z, roll, "
      "pitch, yaw] of the sensor in the link frame [m, rad] (--sensor-pose), equations "
      "('differential', 'integral' or 'static': --model, or --static: rows are standing poses, "
      "only m and mc; not 'model', which names the robot), interval (integral window [s], 0.2), "
      "bias (bool: the six sensor offsets, --bias), "
      "wrench_sign (1 or -1), estimator ('ols', 'wls', 'rls'), confidence (0.999), cutoff_hz (0 "
      "= automatic), filter (bool). Returns a dict with the keys of the payload JSON "
      "(parameters, mass, com, inertia_com, physically_consistent, not_excited, ...). Other "
      "modes: payload_from_orientation (no robot model), payload_from_torques (no sensor).");

  m.def(
      "payload_from_orientation",
      [](const std::optional<Eigen::VectorXd>& t, const Samples& quaternion, const Samples& wrench,
         const std::optional<RowMatrix>& w, const std::optional<RowMatrix>& dw,
         const std::optional<RowMatrix>& a, const py::kwargs& kw) {
        return to_python(payload_from_orientation(t, quaternion, wrench, w, dw, a, kw));
      },
      py::arg("t"), py::arg("quaternion"), py::arg("wrench"), py::arg("w") = py::none(),
      py::arg("dw") = py::none(), py::arg("a") = py::none(),
      "Inertial parameters of a gripped load from a force/torque sensor whose own orientation is "
      "logged (no robot model), as 'dynid payload' with the columns qx qy qz qw [wx wy wz dwx dwy "
      "dwz ax ay az]: t (m,) [s] (None with equations='static'); quaternion (m x 4: qx qy qz qw, "
      "unit, "
      "the sensor frame in the base frame); wrench (m x 6: fx fy fz mx my mz [N, N m], the force "
      "of the load on the sensor, sensor frame); optional w (m x 3, angular velocity [rad/s]), dw "
      "(m x 3 [rad/s^2]) and a (m x 3, linear acceleration of the sensor origin [m/s^2], gravity "
      "not included), all in the sensor frame. Missing w and dw are central differences of the "
      "quaternion and of w; a missing a is taken as zero (the sensor turns about its origin; "
      "'choices' says so). Options: gravity [gx, gy, gz] in the base frame ([0, 0, -9.81]), "
      "equations ('differential', 'integral', 'static'), interval, bias, wrench_sign, estimator, "
      "confidence, as for payload(). Returns a dict with the keys of the payload JSON.");

  m.def(
      "payload_from_torques",
      [](const Model& model, const std::string& link, const Eigen::VectorXd& t, const Samples& q,
         const Samples& tau, const py::dict& reference, const std::optional<RowMatrix>& dq,
         const std::optional<RowMatrix>& ddq, const py::kwargs& kw) {
        return to_python(payload_from_torques(model, link, t, q, tau, reference, dq, ddq, kw));
      },
      py::arg("model"), py::arg("link"), py::arg("t"), py::arg("q"), py::arg("tau"),
      py::arg("reference"), py::arg("dq") = py::none(), py::arg("ddq") = py::none(),
      "Inertial parameters of a load on link `link` (link or joint name) from joint torques, "
      "without a sensor, as 'dynid payload --robot R --link L --reference ...': t (m,) [s], q "
      "and tau (m x n) of a run with the load gripped, optional dq, ddq. reference: either the "
      "unloaded robot's run as a dict {'t', 'q', 'tau'[, 'dq', 'ddq']} (robot and load "
      "identified together; --reference unloaded.csv), or an identify() result of the unloaded "
      "robot (a dynid.identify dict or the command line's result.json loaded with json.load; "
      "--reference result.json): the loaded run is then filtered and predicted as validate does "
      "with that result (its friction set, cut-off and zero-velocity thresholds) and the load is "
      "fitted to the torque the model does not explain. Options: frame [x, y, z, roll, pitch, "
      "yaw] of the frame the load is reported in, in the link frame [m, rad] (default the link "
      "frame; --frame), estimator ('ols', 'wls'), confidence (0.999), and with a reference run "
      "cutoff_hz (0 = automatic) and filter (bool). Returns a dict with the keys of the payload "
      "JSON (model 'joint_torques', determined_by_torques, not_excited, ...).");

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
  // One function per binding area, each in its own translation unit (python/bind_*.cpp).
  bind_identification(m);
  bind_experiments(m);
  dynid::bind_fleet(m);
}
