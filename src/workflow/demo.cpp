#include "dynid/workflow/demo.hpp"
#include "dynid/identification/validation.hpp"

#include <cstdio>
#include <filesystem>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/excitation/trapezoidal_trajectory.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/excitation_report.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/signal/period_averaging.hpp"
#include "dynid/sim/closed_loop.hpp"
#include "dynid/sim/pid_controller.hpp"
#include "dynid/sim/plant.hpp"
#include "dynid/sim/sensors.hpp"
#include "dynid/sim/simulate_reference.hpp"

namespace dynid {

namespace {

Reference to_reference(const TrajectorySamples& s) {
  return Reference{s.t, s.q, s.dq, s.ddq};
}

void write_run(const std::string& path, const ClosedLoopResult& r) {
  const Eigen::Index n = r.q.cols();
  std::vector<std::string> cols = {"t"};
  for (const char* p : {"qr", "q", "tau"})
    for (Eigen::Index j = 0; j < n; ++j) cols.push_back(p + std::to_string(j + 1));
  Eigen::MatrixXd data(r.t.size(), 1 + 3 * n);
  data << r.t, r.qr, r.q, r.tau;
  write_csv(path, cols, data);
}

std::string line(const std::string& name, double truth, double value, double rel, bool inside) {
  char buf[160];
  std::snprintf(buf, sizeof(buf), "%-8s %12.5g %12.5g %8.2f   %s\n", name.c_str(), truth, value,
                rel, inside ? "yes" : "NO");
  return buf;
}

}  // namespace

DemoResult run_demo(const DemoOptions& o, const std::function<void(const std::string&)>& progress) {
  namespace fs = std::filesystem;
  if (o.out_dir.empty()) throw UsageError("the demo needs an output folder");
  fs::create_directories(o.out_dir);
  const auto file = [&](const char* name) { return (fs::path(o.out_dir) / name).string(); };
  DemoResult out;
  Model model = load_robot(o.robot);
  const int n = model.dof();

  progress("1/6 optimising a " + std::to_string(o.harmonics) +
           "-harmonic Fourier excitation (condition number)");
  ExcitationOptions ex;
  ex.f0 = o.f0;
  ex.harmonics = o.harmonics;
  ex.layout = ParameterLayout::full();
  ex.starts = 2;
  ex.max_evaluations = 1500;
  ex.max_time = 0.0;
  ex.seed = o.seed;
  ex.dq_max = Eigen::VectorXd::Constant(n, 1.5);
  ex.ddq_max = Eigen::VectorXd::Constant(n, 6.0);
  for (int j = 0; j < n; ++j) {
    if (!std::isfinite(model.joints[j].limits.lower)) {
      ex.q_min = ex.q_min.size() ? ex.q_min : Eigen::VectorXd::Constant(n, -2.5);
      ex.q_max = ex.q_max.size() ? ex.q_max : Eigen::VectorXd::Constant(n, 2.5);
    }
  }
  // No torque limit beyond the model's (none for puma560): an unbounded limit has no margin to
  // report, where a stand-in like 1e6 N·m dwarfed the real margins in the report's chart.
  out.excitation = optimize_excitation(model, ex);
  out.reports.push_back({file("excitation.json"), excitation_to_json(out.excitation)});
  write_json(out.reports.back().source, out.reports.back().result);
  const TrajectorySamples traj =
      sample_trajectory(FourierTrajectory(out.excitation.coefficients), o.rate, false);
  write_trajectory_csv(file("traj.csv"), traj);

  progress("2/6 running " + std::to_string(o.periods) + " periods on the " +
           (o.mujoco ? "MuJoCo" : "native") + " plant with sensor noise");
  PlantOptions po;
  po.engine = o.mujoco ? PlantEngine::kMujoco : PlantEngine::kNative;
  po.dt = 1.0 / o.rate;
  auto plant = make_plant(model, po);
  PidController pid(model, default_pid_options(model, traj.q.row(0).transpose(), o.rate));
  SensorOptions so;
  so.counts_per_rev = 1 << 20;
  so.position_noise_std = o.position_noise;
  so.torque_noise_std = o.torque_noise;
  so.seed = o.seed;
  Sensors sensors(model, so);
  ClosedLoopOptions co;
  co.periods = o.periods;
  const ClosedLoopResult run = run_closed_loop(to_reference(traj), pid, *plant, sensors, co);
  write_run(file("run.csv"), run);

  progress("3/6 averaging the periods and identifying the base parameters");
  const int P = static_cast<int>(traj.t.size());
  PeriodAverageOptions pa;
  pa.skip_periods = 1;  // start-up transient
  const PeriodAverage q_avg = average_periods(run.q, P, pa);
  PeriodAverage tau_avg = average_periods(run.tau, P, pa);

  // Three copies of the mean period: the zero-phase filter and the differences then see a
  // periodic signal, and the middle copy (trimmed ends) is free of edge effects.
  JointRecord rec;
  rec.q.resize(3 * P, n);
  rec.tau.resize(3 * P, n);
  rec.q << q_avg.mean, q_avg.mean, q_avg.mean;
  rec.tau << tau_avg.mean, tau_avg.mean, tau_avg.mean;
  rec.t = Eigen::VectorXd::LinSpaced(3 * P, 0.0, (3 * P - 1) / o.rate);
  {
    std::vector<std::string> cols = {"t"};
    for (const char* p : {"q", "tau"})
      for (int j = 0; j < n; ++j) cols.push_back(p + std::to_string(j + 1));
    Eigen::MatrixXd data(P, 1 + 2 * n);
    data << traj.t, q_avg.mean, tau_avg.mean;
    write_csv(file("averaged.csv"), cols, data);
  }
  IdentifyOptions io;
  io.signal.trim = P;  // keep exactly the middle period
  // The excitation has no content above f0·harmonics (1 Hz by default), but the Coulomb torque
  // jumps at every velocity reversal; a 20 Hz cut-off keeps that jump short (±1/20 s), and the
  // rows within 5 % of the peak speed of a reversal, where the filtered jump is smeared, are left
  // out of the Coulomb fit.
  io.signal.cutoff_hz = 20.0;
  // The simulated controller logs the command it holds over the next step, centred half a step
  // after its time stamp; central differences centre q̈ on the stamp.
  io.signal.torque_time_offset = 0.5 / o.rate;
  // Filtering smears the Coulomb step of tau over ±1/cut-off at each reversal; filtering the sign
  // column alike keeps Fv and Fc unbiased (without it Fv1 of puma560 came out 9 % low).
  io.signal.filter_coulomb_columns = true;
  io.signal.zero_velocity = std::vector<double>(traj.dq.cols());
  for (Eigen::Index j = 0; j < traj.dq.cols(); ++j) {
    io.signal.zero_velocity[j] = 0.05 * traj.dq.col(j).cwiseAbs().maxCoeff();
  }
  out.identification = identify(model, rec, io);
  // The truth of each estimate: its base parameter, plus the share of any base parameter these
  // data do not excite (IdentificationResult::data_regrouping).
  out.truth = estimated_base_values(out.identification,
                                    out.identification.base.reduce(io.layout.parameters(model)));
  nlohmann::json used = {{"robot", o.robot},
                         {"friction", "viscous,coulomb,offset"},
                         {"armature", true},
                         {"filter", "auto"},
                         {"cutoff_hz", io.signal.cutoff_hz},
                         {"torque_offset_s", io.signal.torque_time_offset},
                         {"filter_coulomb_columns", io.signal.filter_coulomb_columns},
                         {"zero_velocity", io.signal.zero_velocity}};
  nlohmann::json result = identification_to_json(model, out.identification, used);
  std::vector<std::string> joint_names;
  for (const auto& joint : model.joints) joint_names.push_back(joint.name);
  // What the report plots: the averaged period's measured and predicted torques.
  result["plot"] = prediction_plot_json(
      validate_torques(model, rec, out.identification.names, out.identification.estimate.x, io),
      joint_names);
  out.reports.push_back({file("result.json"), result});
  write_json(out.reports.back().source, result);

  progress("4/6 validating on a trapezoidal move");
  Eigen::MatrixXd way(n, 3);
  way.col(0) = traj.q.row(0).transpose();
  way.col(1) = way.col(0) + Eigen::VectorXd::Constant(n, 0.8);
  way.col(2) = way.col(0);
  const TrapezoidalTrajectory move(way, Eigen::VectorXd::Constant(n, 1.0),
                                   Eigen::VectorXd::Constant(n, 3.0), 0.5);
  const TrajectorySamples mv = sample_trajectory(move, o.rate, true);
  auto plant2 = make_plant(model, po);
  PidController pid2(model, default_pid_options(model, mv.q.row(0).transpose(), o.rate));
  so.seed = o.seed + 1;
  Sensors sensors2(model, so);
  co.periods = 1;
  const ClosedLoopResult vrun = run_closed_loop(to_reference(mv), pid2, *plant2, sensors2, co);
  write_run(file("validation_run.csv"), vrun);
  JointRecord vrec;
  vrec.t = vrun.t;
  vrec.q = vrun.q;
  vrec.tau = vrun.tau;
  IdentifyOptions vo = io;
  vo.signal.trim = -1;
  // The rows left out of the second figure are those below the thresholds the fit used.
  const Eigen::VectorXd& fit_threshold = out.identification.zero_velocity_threshold;
  vo.signal.zero_velocity.assign(fit_threshold.data(), fit_threshold.data() + fit_threshold.size());
  out.validation =
      validate_torques(model, vrec, out.identification.names, out.identification.estimate.x, vo);
  nlohmann::json validation = validation_to_json(model, out.validation);
  validation["plot"] = prediction_plot_json(out.validation, joint_names);
  out.reports.push_back({file("validation.json"), validation});
  write_json(out.reports.back().source, validation);

  progress("5/6 comparing with the true parameters");
  std::ostringstream t;
  t << "identified vs true base parameters (" << o.robot << ", " << out.identification.rank
    << " base parameters, " << o.periods << " periods averaged, CI level "
    << 100 * out.identification.estimate.confidence_level << " %)\n";
  t << "name             true   identified      %std   truth in CI\n";
  if (!out.identification.not_excited.empty()) {
    t << "not excited by the run (not estimated; the estimates below include their share):";
    for (const auto& name : out.identification.not_excited) t << ' ' << name;
    t << '\n';
  }
  int inside = 0;
  const auto estimated = static_cast<int>(out.identification.names.size());
  for (int i = 0; i < estimated; ++i) {
    const bool in = out.identification.estimate.ci_lower[i] <= out.truth[i] &&
                    out.truth[i] <= out.identification.estimate.ci_upper[i];
    inside += in;
    t << line(out.identification.names[i], out.truth[i], out.identification.estimate.x[i],
              out.identification.estimate.relative_std_percent[i], in);
  }
  const ValidationResult& v = out.validation;
  char buf[512];
  std::snprintf(buf, sizeof(buf),
                "truth inside the interval for %d of %d; excitation condition number %.4g "
                "(constraints %s)\nidentification: relative torque error %.2f %% on the %ld "
                "joint rows fitted\nvalidation on a trapezoidal move: relative torque error over "
                "every row %.2f %%; without the %ld of %ld near-still rows (|dq_j| below the "
                "fit's thresholds) %.2f %%\nvalidation RMS per joint, every row:",
                inside, estimated, out.excitation.condition_number,
                out.excitation.constraints_satisfied ? "satisfied" : "violated",
                100 * out.identification.relative_error, static_cast<long>(out.identification.rows),
                100 * v.relative_error_all_rows, static_cast<long>(v.rows_excluded),
                static_cast<long>(v.rows + v.rows_excluded), 100 * v.relative_error_all);
  t << buf;
  for (int j = 0; j < n; ++j) t << ' ' << v.rms_all_rows[j];
  t << " N·m\n";
  out.table = t.str();
  progress("6/6 done; files in " + o.out_dir);
  return out;
}

}  // namespace dynid
