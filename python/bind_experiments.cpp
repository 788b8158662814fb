// excite(), simulate() and average() of the Python module (issue 29 item 3): the library's
// excite_fourier(), joint_experiment_reference(), simulate_run() and average_run(), which the
// command line calls too.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <vector>

#include "binding.hpp"
#include "dynid/common/error.hpp"
#include "dynid/load/load_identification.hpp"
#include "dynid/report/stored_result.hpp"
#include "dynid/sim/pid_gains.hpp"
#include "dynid/workflow/average_run.hpp"
#include "dynid/workflow/excite.hpp"
#include "dynid/workflow/simulate_run.hpp"

namespace dynid::binding {
namespace {

// The flags of the library's messages as the keywords of these functions.
const std::initializer_list<std::pair<const char*, const char*>> kExperimentFlags = {
    {"--harmonics", "harmonics"},
    {"--no-rest", "rest_at_ends=False"},
    {"--f0", "f0"},
    {"--rate", "rate"},
    {"--fmax", "fmax"},
    {"--velocity-limit", "velocity_limit"},
    {"--acceleration-limit", "acceleration_limit"},
    {"--torque-limit", "torque_limit"},
    {"--limit-fraction", "limit_fraction"},
    {"--z-min", "z_min"},
    {"--starts", "starts"},
    {"--max-evaluations", "max_evaluations"},
    {"--max-time", "max_time"},
    {"--allow-violations", "allow_violations=True"},
    {"--family", "family"},
    {"--joint", "joint"},
    {"--pose", "pose"},
    {"--range FROM:TO", "range=(FROM, TO)"},
    {"--range", "range"},
    {"--via", "via"},
    {"--velocity", "velocity"},
    {"--acceleration", "acceleration"},
    {"--cycles", "cycles"},
    {"--dwell", "dwell"},
    {"--duration", "duration"},
    {"--period S or --f0 HZ", "period (s) or f0 (Hz)"},
    {"--period", "period"},
    {"--skip-periods", "skip_periods"},
    {"--filter", "filter"},
    {"--cutoff HZ", "cutoff_hz"},
    {"--cutoff", "cutoff_hz"},
    {"--decimate", "decimate"},
    {"--wrench-noise", "wrench_noise"}};

// A trajectory as a dict of arrays: t (m,), q, dq, ddq (m × n).
py::dict trajectory_dict(const TrajectorySamples& s) {
  py::dict out;
  out["t"] = s.t;
  out["q"] = s.q;
  out["dq"] = s.dq;
  out["ddq"] = s.ddq;
  return out;
}

// `dynid excite`: the optimised Fourier excitation, or a one-joint reference with `family` other
// than 'fourier' or with `joint`.
py::dict excite(const Model& model, const py::kwargs& kw) {
  static const char* const kKeys[] = {"harmonics",
                                      "f0",
                                      "fmax",
                                      "criterion",
                                      "rate",
                                      "velocity_limit",
                                      "acceleration_limit",
                                      "torque_limit",
                                      "limit_fraction",
                                      "z_min",
                                      "starts",
                                      "seed",
                                      "max_evaluations",
                                      "max_time",
                                      "allow_violations",
                                      "rest_at_ends",
                                      "family",
                                      "joint",
                                      "pose",
                                      "range",
                                      "velocity",
                                      "acceleration",
                                      "cycles",
                                      "dwell",
                                      "via",
                                      "duration"};
  check_keywords(kw, kKeys);
  const auto get = keyword_getter(kw);
  const std::string family = get("family", std::string("fourier"));
  const int joint = get("joint", 0);
  const int n = model.dof();
  try {
    if (family != "fourier" || joint != 0) {  // a one-joint experiment reference
      for (const char* key : {"criterion", "fmax", "torque_limit", "z_min", "starts", "seed",
                              "max_evaluations", "max_time", "allow_violations"}) {
        if (kw.contains(key))
          throw py::value_error(std::string(key) +
                                " is for the optimised excitation (family='fourier' without "
                                "joint); a one-joint reference is checked against its limits");
      }
      JointReferenceOptions r;
      r.family = family;
      r.joint = joint - 1;
      r.pose = get("pose", std::vector<double>{});
      if (kw.contains("range")) {
        const auto range = kw["range"].cast<std::vector<double>>();
        if (range.size() != 2 || !std::isfinite(range[0]) || !std::isfinite(range[1]) ||
            range[0] == range[1])
          throw py::value_error("range must be (FROM, TO), two different finite positions");
        r.range = std::make_pair(range[0], range[1]);
      }
      r.velocity = get("velocity", 0.0);
      r.acceleration = get("acceleration", 0.0);
      r.cycles = get("cycles", 1);
      r.dwell = get("dwell", 0.0);
      r.via = get("via", std::vector<double>{});
      r.duration = get("duration", 0.0);
      r.harmonics = get("harmonics", 5);
      r.f0 = get("f0", 0.1);
      r.rest_at_ends = get("rest_at_ends", true);
      r.rate = get("rate", 100.0);
      r.limit_fraction = get("limit_fraction", 1.0);
      r.dq_max = get("velocity_limit", std::vector<double>{});
      r.ddq_max = get("acceleration_limit", std::vector<double>{});
      py::dict out;
      out["trajectory"] = trajectory_dict(joint_experiment_reference(model, r));
      return out;
    }
    ExcitationOptions options;
    const std::string criterion = get("criterion", std::string("cond"));
    if (criterion != "cond" && criterion != "logdet")
      throw py::value_error("criterion must be 'cond' or 'logdet', not '" + criterion + "'");
    options.criterion = criterion == "cond" ? ExcitationCriterion::kConditionNumber
                                            : ExcitationCriterion::kDOptimality;
    options.harmonics = get("harmonics", 5);
    options.f0 = get("f0", 0.1);
    options.f_max = get("fmax", 0.0);
    options.rest_at_ends = get("rest_at_ends", true);
    options.starts = get("starts", 4);
    options.seed = get("seed", 20261123u);
    options.max_evaluations = get("max_evaluations", 3000);
    options.max_time = get("max_time", 10.0);
    options.limit_fraction = get("limit_fraction", 1.0);
    if (kw.contains("z_min")) options.z_min = kw["z_min"].cast<double>();
    options.dq_max =
        joint_limits_of(get("velocity_limit", std::vector<double>{}), n, "--velocity-limit");
    options.ddq_max = joint_limits_of(get("acceleration_limit", std::vector<double>{}), n,
                                      "--acceleration-limit");
    options.tau_max =
        joint_limits_of(get("torque_limit", std::vector<double>{}), n, "--torque-limit");
    const double rate = get("rate", 100.0);
    const bool allow = get("allow_violations", false);
    Excitation e;
    {
      py::gil_scoped_release release;
      e = excite_fourier(model, options, rate, allow);
    }
    warn_all(e.warnings);
    py::dict out = to_python(e.json).cast<py::dict>();
    out["trajectory"] = trajectory_dict(e.samples);
    return out;
  } catch (const Error& e) {  // a usage error or one of the data (a missing limit): both name flags
    raise_with_keywords(e, kExperimentFlags);
  }
}

// `dynid simulate`: the reference (t, q[, dq, ddq]) run in closed loop on a simulated robot.
py::dict simulate(const Model& model, const Eigen::VectorXd& t, const Samples& q,
                  const std::optional<RowMatrix>& dq, const std::optional<RowMatrix>& ddq,
                  const py::kwargs& kw) {
  static const char* const kKeys[] = {
      "engine", "controller",     "params",       "gains",          "periods",
      "seed",   "position_noise", "torque_noise", "counts_per_rev", "delay",
      "truth",  "payload",        "payload_link", "sensor_pose",    "wrench_noise"};
  check_keywords(kw, kKeys);
  const auto get = keyword_getter(kw);
  check_samples(model, "q", t.size(), q);
  if (dq) check_samples(model, "dq", t.size(), *dq);
  if (ddq) check_samples(model, "ddq", t.size(), *ddq);
  if (!t.allFinite()) throw Error("t holds NaN or Inf");
  const std::string engine = get("engine", std::string("mujoco"));
  if (engine != "mujoco" && engine != "native")
    throw py::value_error("engine must be 'mujoco' or 'native', not '" + engine + "'");
  const std::string controller = get("controller", std::string("pid-feedforward"));
  if (controller != "pid" && controller != "pid-feedforward" && controller != "computed-torque")
    throw py::value_error(
        "controller must be 'pid', 'pid-feedforward' or 'computed-torque', not '" + controller +
        "'");
  if ((controller == "computed-torque") != kw.contains("params"))
    throw py::value_error(kw.contains("params")
                              ? "params is for controller='computed-torque'; drop it"
                              : "controller='computed-torque' needs params, the identify result "
                                "it is computed from");
  const int periods = get("periods", 25);
  if (periods < 1) throw py::value_error("periods must be >= 1");
  SimulateRunOptions options;
  SimulateOptions& s = options.simulate;
  s.feed_forward = controller == "pid"               ? FeedForward::kNone
                   : controller == "computed-torque" ? FeedForward::kInverseDynamics
                                                     : FeedForward::kComputedTorque;
  std::vector<std::string> warnings;
  if (kw.contains("params")) {
    const IdentifiedResultFile identified =
        identified_result(model, kw["params"].cast<py::dict>(), "params");
    CompletedModel completed = completed_model_of_result(model, identified, "params");
    for (const std::string& w : completed.warnings) warnings.push_back("params: " + w);
    s.controller_model = std::move(completed.model);
  }
  if (kw.contains("gains")) s.gains = read_pid_gains(kw["gains"].cast<std::string>(), model);
  s.plant.engine = engine == "mujoco" ? PlantEngine::kMujoco : PlantEngine::kNative;
  s.sensors.position_noise_std = get("position_noise", 0.0);
  s.sensors.torque_noise_std = get("torque_noise", 0.0);
  s.sensors.counts_per_rev = get("counts_per_rev", 0.0);
  const int delay = get("delay", 0);
  s.sensors.position_delay = s.sensors.torque_delay = delay;
  s.sensors.seed = get("seed", 1u);
  s.loop.periods = periods;
  options.truth = get("truth", false);
  if (kw.contains("payload")) {
    const auto phi = kw["payload"].cast<std::vector<double>>();
    if (phi.size() != 10)
      throw py::value_error(
          "payload must be the load's 10 parameters m mcx mcy mcz Ixx Ixy Ixz Iyy Iyz Izz about "
          "the sensor origin, sensor axes [kg, kg m, kg m^2]");
    if (!kw.contains("payload_link"))
      throw py::value_error("payload needs payload_link, the link that carries the sensor");
    MountedLoad load;
    load.mount.link = find_link(model, kw["payload_link"].cast<std::string>());
    if (kw.contains("sensor_pose")) {
      const auto pose = kw["sensor_pose"].cast<std::vector<double>>();
      if (pose.size() != 6)
        throw py::value_error("sensor_pose must be [x, y, z, roll, pitch, yaw] [m, rad]");
      load.mount.p_LS = Eigen::Vector3d(pose[0], pose[1], pose[2]);
      load.mount.R_LS = roll_pitch_yaw(pose[3], pose[4], pose[5]);
    }
    load.phi = Eigen::Map<const Eigen::VectorXd>(phi.data(), 10);
    options.load = load;
    options.wrench_noise = get("wrench_noise", std::vector<double>{});
  } else if (kw.contains("payload_link") || kw.contains("sensor_pose") ||
             kw.contains("wrench_noise")) {
    throw py::value_error("payload_link, sensor_pose and wrench_noise need payload");
  }
  SimulatedRun r;
  try {
    py::gil_scoped_release release;
    r = simulate_run(model, t, q, dq ? Eigen::MatrixXd(*dq) : Eigen::MatrixXd(),
                     ddq ? Eigen::MatrixXd(*ddq) : Eigen::MatrixXd(), options);
  } catch (const Error& e) {  // a usage error or one of the data (a missing limit): both name flags
    raise_with_keywords(e, kExperimentFlags);
  }
  warn_all(warnings);
  const Eigen::Index n = model.dof();
  py::dict out;
  out["columns"] = r.columns;
  out["data"] = r.data;
  out["t"] = Eigen::VectorXd(r.data.col(0));
  Eigen::Index at = 1;
  std::vector<const char*> blocks = {"qr", "q", "tau"};
  if (options.truth) blocks.insert(blocks.end(), {"dq", "ddq"});
  for (const char* name : blocks) {
    out[name] = Eigen::MatrixXd(r.data.middleCols(at, n));
    at += n;
  }
  if (options.load) out["wrench"] = Eigen::MatrixXd(r.data.rightCols(6));
  out["gains"] = to_python(pid_gains_to_json(model, r.pid, delay));
  return out;
}

// `dynid average`: the mean period of the columns {name: (m,)} sampled at t.
py::dict average(const Eigen::VectorXd& t, const py::dict& columns, const py::kwargs& kw) {
  static const char* const kKeys[] = {"period", "f0",        "start",   "skip_periods",
                                      "filter", "cutoff_hz", "decimate"};
  check_keywords(kw, kKeys);
  const auto get = keyword_getter(kw);
  const double period = get("period", 0.0), f0 = get("f0", 0.0);
  if ((period > 0.0) == (f0 > 0.0))
    throw py::value_error("give exactly one of period (s) or f0 (Hz), > 0");
  AverageRunOptions options;
  options.period = period > 0.0 ? period : 1.0 / f0;
  options.start = get("start", std::nan(""));
  options.skip_periods = get("skip_periods", 0);
  options.filter = get("filter", std::string("none"));
  options.cutoff_hz = get("cutoff_hz", 0.0);
  options.decimate = get("decimate", 1);
  std::vector<std::string> names;
  Eigen::MatrixXd x(t.size(), static_cast<Eigen::Index>(columns.size()));
  for (const auto& [key, value] : columns) {
    names.push_back(py::str(key));
    if (names.back() == "t") throw py::value_error("columns holds 't'; give the times as t");
    const auto column = value.cast<Eigen::VectorXd>();
    if (column.size() != t.size())
      throw Error("column " + names.back() + " has " + std::to_string(column.size()) +
                  " samples, t " + std::to_string(t.size()));
    x.col(static_cast<Eigen::Index>(names.size() - 1)) = column;
  }
  if (!x.allFinite() || !t.allFinite()) throw Error("t or a column holds NaN or Inf");
  AveragedRun a;
  try {
    py::gil_scoped_release release;
    a = average_run(t, x, names, options);
  } catch (const Error& e) {  // a usage error or one of the data (a missing limit): both name flags
    raise_with_keywords(e, kExperimentFlags);
  }
  warn_all(a.warnings);
  py::dict out = to_python(a.json).cast<py::dict>();
  out["columns"] = a.columns;
  out["mean"] = a.mean;
  return out;
}

}  // namespace

void bind_experiments(py::module_& m) {
  m.def("excite", &excite, py::arg("model"),
        "An excitation trajectory, as 'dynid excite'. Without family (or family='fourier' "
        "without joint): a finite Fourier series optimised for the condition number (or "
        "criterion='logdet') under the model's limits (J. Swevers et al. 1997; seed 2 §3.3); "
        "options harmonics (5), f0 (0.1 Hz), fmax, rate (100 Hz), velocity_limit, "
        "acceleration_limit, torque_limit (1 or n values), limit_fraction, z_min, starts (4), "
        "seed, max_evaluations (3000), max_time (10 s; 0 = none, reproducible), "
        "allow_violations, rest_at_ends (True). Returns the dict of 'excite --json' (criterion, "
        "value, condition_number, constraints_satisfied, coefficients, ...) plus trajectory "
        "{t, q, dq, ddq}: one period at rate. With family 'slope', 'bang-bang', 'trapezoid', "
        "'spline', or 'fourier' with joint: a one-joint experiment reference of seed 2 (joint "
        "1-based moves, the others at pose), options range (FROM, TO), velocity, acceleration, "
        "cycles, dwell, via, duration, rate, limit_fraction, velocity_limit, "
        "acceleration_limit; returns {trajectory}. A trajectory beyond a limit is a "
        "dynid.Error naming it.");
  m.def("simulate", &simulate, py::arg("model"), py::arg("t"), py::arg("q"),
        py::arg("dq") = py::none(), py::arg("ddq") = py::none(),
        "Runs the reference (t (m,) [s], one period; q, optional dq, ddq (m x n), central "
        "differences when absent) in closed loop on a simulated robot, as 'dynid simulate': "
        "engine ('mujoco' or 'native'), controller ('pid', 'pid-feedforward' or "
        "'computed-torque' with params, an identify result), gains (a gains file), periods (25), "
        "seed (1), position_noise [rad], torque_noise [N m], counts_per_rev, delay [samples], "
        "truth (also dq, ddq), payload (m mcx mcy mcz Ixx Ixy Ixz Iyy Iyz Izz about the sensor "
        "origin) on payload_link at sensor_pose [x, y, z, roll, pitch, yaw] with wrench_noise "
        "[F, M]. Returns columns and data (the run CSV), t, qr, q, tau (m x n) [, dq, ddq] "
        "[, wrench (m x 6)] and gains (the gains file's dict).");
  m.def("average", &average, py::arg("t"), py::arg("columns"),
        "The mean period of a periodic run and the noise of every channel, as 'dynid average "
        "--json' (B. Bona, A. Curatella 2005, §3.4): t (m,) [s], columns {name: (m,)} "
        "(e.g. q1, tau1, qr1), period [s] or f0 [Hz], start, skip_periods, filter ('none', "
        "'butterworth[:ORDER]', 'chebyshev[:ORDER[:RIPPLE_DB]]') with cutoff_hz and decimate "
        "(reference channels qr*, dqr*, ddqr* are not filtered). Returns the dict of the --json "
        "file (periods, channels with std, std_averaged, skewness, kurtosis, normality_p, ...; "
        "not its data and out file names) plus columns and mean (the --out CSV: phase t, then "
        "the columns).");
}

}  // namespace dynid::binding
