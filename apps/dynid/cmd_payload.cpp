// `dynid payload`: a gripped load's inertial parameters from a wrist force/torque sensor (seed 1
// §III). Parse, validate, call the library (load/load_identification.hpp), write JSON.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/common/progress.hpp"
#include "dynid/identification/cutoff_selection.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/csv_reader.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/joint_columns.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/load/load_identification.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/report/payload_report.hpp"
#include "dynid/report/stored_result.hpp"
#include "dynid/version.hpp"
#include "flag_checks.hpp"
#include "robot_flags.hpp"
#include "run_flags.hpp"

namespace dynid::cli {
namespace {

struct PayloadCliOptions {
  std::string data, robot, sensor_link, sensor_pose, out, history;
  RunFlags run;                        // --rate, --columns, --torque-scale, --rows, --time, ...
  RobotFlags robot_flags;              // --joints, --lock, --strict
  std::string link, reference, frame;  // joint-torque mode
  std::string report;                  // --report: HTML page of the result
  std::string model = "differential";
  std::string estimator = "ols";
  std::string gravity = "0 0 -9.81";
  std::string components;  // --components: the wrench equations used, default all six
  double interval = 0.2, wrench_sign = 1.0, confidence = 0.999, cutoff = 0.0;
  bool bias = false, standing = false, no_filter = false;
  bool quiet = false;  // --quiet
};

// Columns `names` as an m×k block, or empty when none is present; some but not all is an error.
Eigen::MatrixXd optional_columns(const CsvTable& table, const std::vector<std::string>& names) {
  std::size_t present = 0;
  for (const auto& name : names) present += table.find(name).has_value();
  if (present == 0) return {};
  Eigen::MatrixXd x(table.rows(), static_cast<Eigen::Index>(names.size()));
  for (std::size_t c = 0; c < names.size(); ++c) {
    // index() names the file, the missing column and the header when only some are present.
    x.col(static_cast<Eigen::Index>(c)) = table.data.col(table.index(names[c]));
  }
  return x;
}

// The result JSON (docs/cli.md, `dynid payload`), the echo on stderr, the RLS history.
void write_result(const PayloadCliOptions& cli, const LoadIdentificationResult& r,
                  const char* model_name, const nlohmann::json& frame, const nlohmann::json& extra,
                  const std::vector<std::pair<std::string, std::string>>& choices,
                  const std::vector<std::string>& group_names, bool with_inertia) {
  const Estimate& e = r.estimate;
  const bool mass_known =
      std::find(r.not_excited.begin(), r.not_excited.end(), "m") == r.not_excited.end();
  const nlohmann::json out =
      payload_to_json(r, {model_name, frame, extra, group_names, with_inertia, choices});
  for (const auto& [key, value] : choices) {
    std::cerr << "payload: " << key << ": " << one_line(value) << '\n';
  }
  for (const auto& w : e.summary.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  if (!r.physics.consistent) {
    std::cerr << "warning: the identified load is not physically consistent: "
              << one_line(r.physics.violated) << '\n';
  }
  OutputBatch outputs;  // the result, its history and its report, or none of them
  write_json(cli.out, out);
  if (!cli.history.empty()) {
    std::vector<std::string> columns = {"row"};
    for (const auto& name : r.names) columns.push_back(name);
    Eigen::MatrixXd history(r.history.rows(), r.history.cols() + 1);
    history.col(0) =
        Eigen::VectorXd::LinSpaced(r.history.rows(), 1.0, static_cast<double>(r.history.rows()));
    history.rightCols(r.history.cols()) = r.history;
    write_csv(cli.history, columns, history);
  }
  if (!cli.report.empty()) write_html_report(cli.report, {{cli.out, out}}, {});
  outputs.commit();
  std::cout << "payload: m "
            << (mass_known ? "= " + std::to_string(e.x(0)) + " kg" : "not determined");
  if (r.physics.mass > 0.0) std::cout << ", c = " << r.physics.com.transpose() << " m";
  std::cout << (r.physics.consistent ? ", physically consistent" : ", NOT physically consistent")
            << "; wrote " << cli.out << '\n';
  if (!cli.report.empty()) std::cout << "wrote " << cli.report << '\n';
}

// The JSON of a load from joint torques: where it is expressed and which parameters the torques
// determine.
void write_torque_result(const PayloadCliOptions& cli, const LoadIdentificationResult& r,
                         const Model& model, int link,
                         const std::vector<std::pair<std::string, std::string>>& choices,
                         const ValidationResult* reference = nullptr) {
  std::vector<std::string> joints;
  for (const auto& joint : model.joints) joints.push_back(joint.name);
  const nlohmann::json where = {{"robot", model.name},
                                {"link", model.joints[link].link_name},
                                {"frame", cli.frame.empty() ? "link frame" : cli.frame}};
  std::vector<std::string> determined;
  for (const auto& name : r.names) {
    if (std::find(r.not_excited.begin(), r.not_excited.end(), name) == r.not_excited.end())
      determined.push_back(name);
  }
  nlohmann::json extra = {{"reference", cli.reference}, {"determined_by_torques", determined}};
  if (reference != nullptr) {
    // The reference model's parameters predicted at nominal values on this run (issue 25 item 2).
    extra["completed"] = reference->completed;
    extra["filled_share"] = reference->filled_share;
  }
  write_result(cli, r, "joint_torques", where, extra, choices, joints, true);
}

// `--link LINK --reference result.json`: the load from the torque that the identified model of
// the unloaded robot does not explain. The loaded run is processed and predicted exactly as
// `dynid validate` does with that result (same options, cut-off and zero-velocity thresholds).
void run_payload_from_result(const PayloadCliOptions& cli, const CLI::App& cmd,
                             LoadIdentificationOptions options, const Model& model, int link,
                             const LoadFrame& frame, RunFileOptions file) {
  const IdentifiedResultFile identified = read_identification_result(cli.reference);
  require_same_robot(identified.robot, model.name, "--reference '" + cli.reference + "'",
                     "give a result of the robot that carries the load");
  RunFileReport read;
  // The loaded run is read as identify read the unloaded one, unless a run flag says otherwise.
  StoredOptionOverrides overrides;
  overrides.torque_scale_given = run_flag_given(cmd, "--torque-scale");
  overrides.columns_given = run_flag_given(cmd, "--columns");
  overrides.rate_given = run_flag_given(cmd, "--rate");
  overrides.torque_bias_given = run_flag_given(cmd, "--torque-bias");
  overrides.topic_given = run_flag_given(cmd, "--topic");
  if (run_flag_given(cmd, "--time-shift")) overrides.time_shift = cli.run.shift();
  const StoredIdentifyOptions stored =
      options_of_stored_result(identified, cli.reference, model.dof(), overrides);
  stored.apply_to(file);
  read.notes.insert(read.notes.end(), stored.notes.begin(), stored.notes.end());
  const IdentifyOptions& identify = stored.options;
  if (cli.cutoff != 0.0 || cli.no_filter) {
    std::cerr << "warning: --cutoff and --no-filter have no effect with a result.json reference: "
                 "the loaded run is filtered as identify filtered the unloaded one\n";
  }
  const JointRecord loaded_raw = read_joint_record(cli.data, model, file, &read);
  for (const auto& w : read.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  for (const auto& note : read.notes) std::cerr << "payload: " << one_line(note) << '\n';
  const ValidationResult predicted = validate_torques(
      model, loaded_raw, identified.names, identified.values, identify, identified.not_excited,
      nominal_completion_of_result(model, identified, cli.reference));
  for (const std::string& w : predicted.warnings) std::cerr << "warning: payload: " << w << '\n';
  // Filtering correlates neighbouring residuals: intervals from the HAC sandwich.
  options.hac_covariance = identify.signal.filter;
  options.record_history = false;
  const LoadIdentificationResult r = identify_load_from_unexplained_torques(
      model, link, frame, predicted.processed.record, predicted.predicted,
      predicted.zero_velocity_threshold, options);
  std::vector<std::pair<std::string, std::string>> choices = predicted.choices;
  choices.emplace_back("reference_model",
                       "the torque of '" + cli.reference +
                           "' (identify result) predicted on this run as dynid validate does; "
                           "rows below its zero-velocity thresholds are left out of the load fit "
                           "too; its own uncertainty is not propagated");
  write_torque_result(cli, r, model, link, choices, &predicted);
}

// `--link LINK --reference unloaded.csv`: robot and load together from joint torques.
void run_payload_from_torques(const PayloadCliOptions& cli, const CLI::App& cmd,
                              LoadIdentificationOptions options) {
  if (cli.robot.empty())
    throw UsageError("--link needs --robot R: the robot that carries the load");
  if (cli.reference.empty()) {
    throw UsageError("--link needs --reference: a run of the robot without the load (CSV)");
  }
  if (cli.standing || !cli.sensor_link.empty() || !cli.sensor_pose.empty() || cli.bias) {
    throw UsageError(
        "--link (load from joint torques) does not take --static, --bias, "
        "--sensor-link or --sensor-pose; use --frame to place the load's frame");
  }
  const RunFileOptions file = run_file_options(cli.run);
  const Model model = load_cli_robot(cli.robot, cli.robot_flags,
                                     {"payload",
                                      {cli.data},
                                      file.columns,
                                      selection_stored_in(cli.reference),
                                      cli.reference,
                                      file.topic});
  LoadFrame frame;
  if (!cli.frame.empty()) {
    const auto pose =
        flag_numbers(cli.frame, 6, "--frame",
                     "\"x y z roll pitch yaw\" [m, rad] of the frame in the link frame");
    frame.p_LF = Eigen::Vector3d(pose[0], pose[1], pose[2]);
    frame.R_LF = roll_pitch_yaw(pose[3], pose[4], pose[5]);
  }
  const int link = find_link(model, cli.link);
  const bool json_reference =
      cli.reference.size() >= 5 && cli.reference.substr(cli.reference.size() - 5) == ".json";
  if (json_reference) return run_payload_from_result(cli, cmd, options, model, link, frame, file);
  // The stages on a progress line (payload was silent for 44 s on a long run).
  ProgressLine progress("payload", progress_wanted(cli.quiet));
  progress.update(0.0, "reading the runs");
  // Both runs are read alike; the window (--rows, --time) is of the loaded run only.
  RunFileReport read;
  const JointRecord loaded_raw = read_joint_record(cli.data, model, file, &read);
  RunFileOptions reference_file = file;
  reference_file.window = {};
  const JointRecord unloaded_raw = read_joint_record(cli.reference, model, reference_file, &read);
  for (const auto& w : read.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  for (const auto& note : read.notes) std::cerr << "payload: " << one_line(note) << '\n';
  // The automatic cut-off of identify (held-out torque prediction) on the unloaded run, for both.
  IdentifyOptions identify;
  identify.layout = ParameterLayout::full();
  identify.signal.filter = !cli.no_filter;
  identify.signal.cutoff_hz = cli.cutoff;
  identify.signal.torque_time_offset = cli.run.shift();
  progress.update(0.1, "choosing the cut-off on the reference run");
  const CutoffSelection cutoff = select_cutoff(model, unloaded_raw, identify);
  const SignalOptions signal = cutoff.signal;
  std::vector<std::pair<std::string, std::string>> choices, reference_choices;
  progress.update(0.6, "filtering both runs");
  const JointRecord loaded = preprocess(loaded_raw, signal, choices).record;
  echo_cutoff_selection(cutoff, choices);
  const JointRecord unloaded = preprocess(unloaded_raw, signal, reference_choices).record;
  // Filtering correlates neighbouring residuals: intervals from the HAC sandwich.
  options.hac_covariance = signal.filter;
  options.record_history = false;
  progress.update(0.8, "estimating the load");
  const LoadIdentificationResult r = identify_load_from_torques(
      model, link, frame, ParameterLayout::full(), loaded, unloaded, options);
  progress.finish();
  write_torque_result(cli, r, model, link, choices);
}

void run_payload(const PayloadCliOptions& cli, const CLI::App& cmd) {
  if (cli.out.empty()) throw UsageError("--out is required: the JSON file to write");
  if (const auto folder = std::filesystem::path(cli.report).parent_path();
      !folder.empty() && !std::filesystem::is_directory(folder)) {
    throw Error("--report '" + cli.report + "': folder '" + folder.string() +
                "' does not exist; create it or write elsewhere");
  }
  LoadEquationOptions equations;
  if (cli.model == "differential") {
    equations.model = LoadModelKind::kDifferential;
  } else if (cli.model == "integral") {
    equations.model = LoadModelKind::kIntegral;
  } else {
    throw UsageError("--model '" + cli.model + "': use differential or integral");
  }
  if (cli.standing) equations.model = LoadModelKind::kStatic;
  if (!(cli.wrench_sign == 1.0 || cli.wrench_sign == -1.0)) {
    throw UsageError(
        "--wrench-sign must be 1 (force of the load on the sensor, as sensor drivers "
        "report it) or -1 (force of the sensor on the load)");
  }
  if (!(cli.interval > 0.0)) throw UsageError("--interval must be a positive window in seconds");
  equations.interval = cli.interval;
  equations.bias = cli.bias;
  equations.wrench_sign = cli.wrench_sign;
  if (!cli.components.empty()) {
    if (!cli.link.empty()) {
      throw UsageError(
          "--components chooses among a wrist sensor's six equations; a load from joint torques "
          "(--link) has none: drop --components");
    }
    equations.components = load_components_from_text(cli.components, "--components");
  }
  LoadIdentificationOptions options;
  options.confidence_level = cli.confidence;
  if (cli.estimator == "ols") {
    options.estimator = LoadEstimator::kOls;
  } else if (cli.estimator == "wls") {
    options.estimator = LoadEstimator::kWls;
  } else if (cli.estimator == "rls") {
    options.estimator = LoadEstimator::kRls;
  } else {
    throw UsageError("--estimator '" + cli.estimator + "': use ols, wls or rls");
  }
  if (!cli.history.empty() && options.estimator != LoadEstimator::kRls) {
    throw UsageError("--history needs --estimator rls (the estimate after every wrench sample)");
  }
  options.record_history = !cli.history.empty();
  if (!cli.link.empty()) return run_payload_from_torques(cli, cmd, options);
  if (!cli.reference.empty() || !cli.frame.empty()) {
    throw UsageError(
        "--reference and --frame are for a load from joint torques: give --link LINK (the link "
        "that carries the load), or drop them for a wrist-sensor run");
  }
  if (!cli.robot.empty() && cli.sensor_link.empty()) {
    throw UsageError("--robot needs --sensor-link LINK: the link that carries the sensor");
  }
  if (cli.robot.empty() && (!cli.sensor_link.empty() || !cli.sensor_pose.empty())) {
    throw UsageError(
        "--sensor-link and --sensor-pose need --robot (or give the sensor's own "
        "orientation qx qy qz qw in the data)");
  }

  for (const char* flag : {"--torque-scale", "--torque-bias", "--time-shift"}) {
    if (run_flag_given(cmd, flag)) {
      std::cerr << "warning: " << flag
                << " has no effect on a wrist-sensor run (it is for joint torques, with --link); "
                   "the sensor's own offsets are --bias\n";
    }
  }
  ProgressLine progress("payload", progress_wanted(cli.quiet));
  progress.update(0.0, "reading the run");
  RunFileReport read;
  const RunFileOptions file = run_file_options(cli.run);
  RunTable run = read_run_table(cli.data, file, read, false);
  for (const auto& w : read.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  for (const auto& note : read.notes) std::cerr << "payload: " << one_line(note) << '\n';
  const CsvTable& table = run.table;
  const std::vector<std::string> wrench_names = {"fx", "fy", "fz", "mx", "my", "mz"};
  std::string missing;
  for (const auto& name : wrench_names) {
    if (!table.find(name)) missing += (missing.empty() ? "" : " ") + name;
  }
  if (!missing.empty()) {
    throw Error("--data '" + cli.data + "' has no wrench column(s) " + missing +
                "; the sensor reading needs fx fy fz mx my mz [N, N m] (rename with --columns)");
  }
  Eigen::MatrixXd wrench(table.rows(), 6);
  for (int c = 0; c < 6; ++c) wrench.col(c) = table.data.col(table.index(wrench_names[c]));
  if (equations.model != LoadModelKind::kStatic && run.t.size() == 0) {
    throw Error("--data '" + cli.data +
                "' has no t column; a moving load needs time stamps: add t, give the sample "
                "rate with --rate HZ, or give --static for standing poses");
  }
  const Eigen::VectorXd t = equations.model == LoadModelKind::kStatic ? Eigen::VectorXd() : run.t;

  std::vector<std::pair<std::string, std::string>> choices;
  SensorMotion motion;
  nlohmann::json frame;
  if (!cli.robot.empty()) {
    const Model model = load_cli_robot(cli.robot, cli.robot_flags,
                                       {"payload", {cli.data}, file.columns, {}, "", file.topic});
    SensorMount mount;
    mount.link = find_link(model, cli.sensor_link);
    if (!cli.sensor_pose.empty()) {
      const auto pose =
          flag_numbers(cli.sensor_pose, 6, "--sensor-pose",
                       "\"x y z roll pitch yaw\" [m, rad] of the sensor in the link frame");
      mount.p_LS = Eigen::Vector3d(pose[0], pose[1], pose[2]);
      mount.R_LS = roll_pitch_yaw(pose[3], pose[4], pose[5]);
    }
    std::vector<std::string> joint_names;
    for (const auto& joint : model.joints) joint_names.push_back(joint.name);
    JointRecord record;
    record.t = t;
    record.q = joint_signal(table, joint_names, "q");
    if (equations.model == LoadModelKind::kStatic) {
      motion = sensor_motion_from_joints(model, record, mount);
    } else {
      if (has_joint_columns(table.columns, joint_names, "dq"))
        record.dq = joint_signal(table, joint_names, "dq");
      if (has_joint_columns(table.columns, joint_names, "ddq"))
        record.ddq = joint_signal(table, joint_names, "ddq");
      SignalOptions signal;
      signal.filter = !cli.no_filter;
      signal.cutoff_hz = cli.cutoff;
      // The automatic cut-off by held-out prediction of the wrench, as identify chooses its own.
      progress.update(0.2, "choosing the cut-off and filtering");
      PreparedLoadRun run =
          prepare_sensor_run(model, mount, record, wrench, signal, equations, choices);
      // Filtering correlates neighbouring residuals: intervals from the HAC sandwich.
      options.hac_covariance = signal.filter;
      wrench = std::move(run.wrench);
      motion = sensor_motion_from_joints(model, run.record, mount);
    }
    frame = {{"robot", model.name}, {"sensor_link", model.joints[mount.link].link_name}};
  } else {
    const std::vector<std::string> quat_names = {"qx", "qy", "qz", "qw"};
    OrientationLog log;
    log.quaternion = optional_columns(table, quat_names);
    if (log.quaternion.size() == 0) {
      throw Error("--data '" + cli.data +
                  "' has neither the sensor orientation qx qy qz qw nor joint data: give the "
                  "quaternion columns, or joint columns q1..qn with --robot R --sensor-link LINK");
    }
    if (equations.model != LoadModelKind::kStatic) {
      log.t = t;
      log.w = optional_columns(table, {"wx", "wy", "wz"});
      log.dw = optional_columns(table, {"dwx", "dwy", "dwz"});
      log.a = optional_columns(table, {"ax", "ay", "az"});
    }
    const auto g = flag_numbers(cli.gravity, 3, "--gravity", "\"gx gy gz\" in m/s^2, base frame");
    motion = sensor_motion_from_orientation(log, Eigen::Vector3d(g[0], g[1], g[2]), choices);
    frame = {{"orientation", "qx qy qz qw from the data"}};
  }
  progress.update(0.8, "estimating the load");
  const EquationBlock block = load_equations(motion, wrench, equations);
  const LoadIdentificationResult r = identify_load(block, options);
  progress.finish();
  const char* model_name = equations.model == LoadModelKind::kStatic     ? "static"
                           : equations.model == LoadModelKind::kIntegral ? "integral"
                                                                         : "differential";
  nlohmann::json extra = {{"wrench_sign", cli.wrench_sign}};
  if (equations.model == LoadModelKind::kIntegral) extra["interval"] = cli.interval;
  extra["components"] = block.group_names;
  write_result(cli, r, model_name, frame, extra, choices, block.group_names,
               equations.model != LoadModelKind::kStatic);
}

}  // namespace

void add_payload_command(CLI::App& app) {
  auto o = std::make_shared<PayloadCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "payload",
      "Inertial parameters of a gripped load (m, mc, inertia about the sensor origin) from a "
      "wrist force/torque sensor: Dutkiewicz, Kozlowski, Wroblewski, \"Experimental "
      "Identification of Robot and Load Dynamic Parameters\" (1993)");
  cmd->add_option("--data,-d", o->data,
                  "CSV with the sensor reading fx fy fz mx my mz [N, N m] in the sensor frame "
                  "(the force and moment the load exerts on the sensor, as drivers report it), t "
                  "[s] unless --static, and either joint columns q1..qn (with --robot) or the "
                  "sensor orientation qx qy qz qw (unit quaternion, sensor frame in the base "
                  "frame) with optional wx wy wz, dwx dwy dwz, ax ay az (sensor frame)")
      ->required();
  cmd->add_option("--out,-o", o->out, "JSON result to write (atomically)")->required();
  cmd->add_option("--report", o->report,
                  "Also write a self-contained HTML report of the result (as dynid report)");
  cmd->add_option("--robot,-r", o->robot,
                  "Built-in robot name or .urdf / .yaml model: the sensor's motion comes from "
                  "its kinematics and q (dq, ddq derived and filtered as in identify)");
  add_robot_flags(cmd, o->robot_flags);
  cmd->add_option("--sensor-link", o->sensor_link, "Link (or joint) name that carries the sensor");
  cmd->add_option("--sensor-pose", o->sensor_pose,
                  "\"x y z roll pitch yaw\" of the sensor frame in the link frame [m, rad], URDF "
                  "roll-pitch-yaw convention; default: the link frame");
  cmd->add_option("--model", o->model,
                  "differential (per-sample wrench equations) or integral (wrench integrated "
                  "over windows of --interval, no accelerations needed)")
      ->capture_default_str();
  cmd->add_option("--interval", o->interval,
                  "Integral model: window length [s] (consecutive, non-overlapping)")
      ->capture_default_str();
  cmd->add_option("--components", o->components,
                  "Comma-separated wrench equations to use, of fx,fy,fz,mx,my,mz (default all "
                  "six): forces determine m and mc, moments mc and the inertias; Dutkiewicz, "
                  "Kozlowski, Wroblewski (1993) found the integral model better on the "
                  "components the motion excites");
  cmd->add_flag("--bias", o->bias,
                "Identify the six constant sensor offsets fx0 fy0 fz0 mx0 my0 mz0 too");
  cmd->add_flag("--static", o->standing,
                "Rows are standing poses (no t needed): only m, mc (and offsets) are "
                "identifiable, inertias are not reported");
  cmd->add_option("--wrench-sign", o->wrench_sign,
                  "1: columns are the force of the load on the sensor (a load at rest reads "
                  "+m g); -1: the force of the sensor on the load")
      ->capture_default_str();
  cmd->add_option("--estimator", o->estimator,
                  "ols, wls (one noise variance per wrench component) or rls (U-D recursive "
                  "least squares)")
      ->capture_default_str();
  cmd->add_option("--history", o->history,
                  "With --estimator rls: CSV of the estimate after every wrench equation");
  cmd->add_option("--confidence", o->confidence, "Student-t interval level in (0, 1)")
      ->capture_default_str();
  cmd->add_option("--gravity", o->gravity,
                  "Without --robot: gravity \"gx gy gz\" in the base frame [m/s^2]")
      ->capture_default_str();
  cmd->add_option("--cutoff", o->cutoff,
                  "With --robot: low-pass cut-off [Hz] for q and the wrench; 0 = automatic");
  cmd->add_flag("--quiet,-q", o->quiet,
                "No progress line on stderr (shown only when stderr is a terminal)");
  cmd->add_flag("--no-filter", o->no_filter, "With --robot: do not low-pass q and the wrench");
  add_run_flags(cmd, o->run);
  cmd->add_option("--link", o->link,
                  "Without a sensor: the link (or joint) that carries the load; --data is then a "
                  "run with the load (t, q*, tau*) and --reference one without it");
  cmd->add_option("--reference", o->reference,
                  "With --link: CSV run of the robot without the load (same or another "
                  "trajectory; robot and load are identified together), or the result.json of "
                  "dynid identify on the unloaded robot (the load from the torque that model "
                  "does not explain, the run processed as dynid validate does)");
  cmd->add_option("--frame", o->frame,
                  "With --link: \"x y z roll pitch yaw\" of the frame (e.g. the tool flange) in "
                  "the link frame [m, rad] in which the load is reported; default the link frame");
  cmd->callback([o, cmd] { run_payload(*o, *cmd); });
}

}  // namespace dynid::cli
