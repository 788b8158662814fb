// `dynid identify` and `dynid validate --mode torque`: parse, validate, call the library, write.
#include <iostream>
#include <map>
#include <memory>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/io/streaming_identification.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/sim/simulate_reference.hpp"

namespace dynid::cli {
namespace {

struct IdentifyCliOptions {
  std::string robot, data, out, columns;
  std::string friction = "viscous,coulomb,offset";
  bool no_armature = false;
  std::string filter = "auto";
  double cutoff = 0.0, rate = 0.0, confidence = 0.999;
  int decimate = 0, trim = -1;
  std::string estimator = "ols";
  std::vector<double> zero_velocity;
  bool savgol = false;
  bool stream = false;
  int threads = 0;
  double torque_offset = 0.0;
  bool filter_coulomb = false;
};

std::vector<std::string> split(const std::string& text, char sep) {
  std::vector<std::string> out;
  std::stringstream s(text);
  std::string item;
  while (std::getline(s, item, sep)) out.push_back(item);
  return out;
}

ParameterLayout parse_friction(const std::string& text, bool armature) {
  ParameterLayout layout;
  layout.armature = armature;
  if (text == "none") return layout;
  for (const auto& item : split(text, ',')) {
    if (item == "viscous") {
      layout.viscous = true;
    } else if (item == "coulomb") {
      layout.coulomb = true;
    } else if (item == "offset") {
      layout.offset = true;
    } else if (item == "asymmetric") {
      layout.viscous = layout.coulomb = layout.asymmetric = true;
    } else {
      throw UsageError("--friction: unknown term '" + item +
                       "'; use a comma list of viscous, coulomb, offset, asymmetric, or none");
    }
  }
  return layout;
}

// --filter auto | none | butterworth[:ORDER] | chebyshev[:ORDER[:RIPPLE_DB]]
void parse_filter(const std::string& text, SignalOptions& s) {
  const auto parts = split(text, ':');
  const std::string kind = parts.empty() ? "" : parts[0];
  try {
    if (kind == "auto") return;
    if (kind == "none") {
      s.filter = false;
    } else if (kind == "butterworth" || kind == "chebyshev") {
      s.family = kind == "butterworth" ? LowpassFamily::kButterworth : LowpassFamily::kChebyshev1;
      if (kind == "chebyshev") s.order = 8;  // seed 2 §3.4
      if (parts.size() > 1) s.order = std::stoi(parts[1]);
      if (parts.size() > 2) s.ripple_db = std::stod(parts[2]);
    } else {
      throw UsageError("");
    }
  } catch (const std::exception&) {
    throw UsageError("--filter '" + text +
                     "' is not understood; use auto, none, butterworth[:ORDER] or "
                     "chebyshev[:ORDER[:RIPPLE_DB]] (the cut-off is --cutoff)");
  }
}

IdentificationEstimator parse_estimator(const std::string& text) {
  if (text == "ols") return IdentificationEstimator::kOls;
  if (text == "wls") return IdentificationEstimator::kWls;
  if (text == "rls") return IdentificationEstimator::kRls;
  throw UsageError("--estimator must be ols, wls or rls, not '" + text + "'");
}

IdentifyOptions library_options(const IdentifyCliOptions& o) {
  IdentifyOptions out;
  out.layout = parse_friction(o.friction, !o.no_armature);
  out.estimator = parse_estimator(o.estimator);
  out.confidence_level = o.confidence;
  if (!(o.confidence > 0.0 && o.confidence < 1.0)) {
    throw UsageError("--confidence must be in (0, 1), e.g. 0.999");
  }
  parse_filter(o.filter, out.signal);
  out.signal.cutoff_hz = o.cutoff;
  out.signal.decimate = o.decimate;
  out.signal.trim = o.trim;
  out.signal.zero_velocity = o.zero_velocity;
  out.signal.savitzky_golay = o.savgol;
  out.signal.torque_time_offset = o.torque_offset;
  out.signal.filter_coulomb_columns = o.filter_coulomb;
  return out;
}

nlohmann::json echo(const IdentifyCliOptions& o) {
  return {{"robot", o.robot},
          {"data", o.data},
          {"friction", o.friction},
          {"armature", !o.no_armature},
          {"filter", o.filter},
          {"cutoff_hz", o.cutoff},
          {"decimate", o.decimate},
          {"trim", o.trim},
          {"rate_hz", o.rate},
          {"estimator", o.estimator},
          {"confidence_level", o.confidence},
          {"zero_velocity", o.zero_velocity},
          {"savitzky_golay", o.savgol},
          {"torque_offset_s", o.torque_offset},
          {"filter_coulomb_columns", o.filter_coulomb},
          {"columns", o.columns}};
}

void add_signal_flags(CLI::App* cmd, IdentifyCliOptions& o) {
  cmd->add_option(
         "--filter", o.filter,
         "Zero-phase low-pass on q and tau: auto (Butterworth 4), none, butterworth[:ORDER], "
         "chebyshev[:ORDER[:RIPPLE_DB]] (default order 8, seed 2)")
      ->capture_default_str();
  cmd->add_option("--cutoff", o.cutoff,
                  "Filter cut-off [Hz], or auto (= 0, default): 1.5 x the highest frequency where "
                  "the position spectrum stands 10 dB above its noise floor, in [1 Hz, min(20 Hz, "
                  "rate/10)]")
      ->transform(CLI::Transformer(std::map<std::string, std::string>{{"auto", "0"}}));
  cmd->add_option("--decimate", o.decimate,
                  "Keep every N-th sample after filtering; 0 = rate/(10·cut-off)");
  cmd->add_option("--trim", o.trim,
                  "Samples dropped at each end after filtering; -1 = 3·rate/cut-off");
  cmd->add_option("--rate", o.rate, "Sample rate [Hz] when the file has no t column");
  cmd->add_option("--columns", o.columns, "Rename columns before lookup: from=to,from2=to2");
  cmd->add_flag("--savgol", o.savgol,
                "Differentiate with Savitzky-Golay instead of central differences");
  cmd->add_option("--friction", o.friction,
                  "Friction terms: comma list of viscous, coulomb, offset; or asymmetric; or none")
      ->capture_default_str();
  cmd->add_flag("--no-armature", o.no_armature, "Do not identify the actuator inertias Ia");
  cmd->add_option("--torque-offset", o.torque_offset,
                  "The torque logged at t acts at t + S [s]: half the sample period for a "
                  "command held over the next step (dynid simulate), -d for a sensor lagging d");
  cmd->add_flag("--filter-coulomb", o.filter_coulomb,
                "Filter the sign(dq) columns like tau (parallel filtering): unbiased Fv and Fc "
                "when the filter smears the Coulomb step at reversals");
}

void run_identify(const IdentifyCliOptions& o) {
  const IdentifyOptions options = library_options(o);
  const Model model = load_robot(o.robot);
  RunFileOptions file;
  file.columns = parse_column_mapping(o.columns);
  file.rate_hz = o.rate;
  const IdentificationResult result =
      o.stream ? identify_stream(model, o.data, file, options, {o.threads, true})
               : identify(model, read_joint_record(o.data, model, file), options);
  std::cout << identification_table(model, result);
  write_json(o.out, identification_to_json(model, result, echo(o)));
  std::cout << "wrote " << o.out << '\n';
}

struct ValidateCliOptions {
  std::string robot, params, data, json, columns, mode = "torque", trajectory, engine = "mujoco";
  double rate = 0.0;
  std::vector<double> zero_velocity;
};

void run_validate(const ValidateCliOptions& v) {
  if (v.mode != "torque" && v.mode != "simulation") {
    throw UsageError("--mode must be torque or simulation, not '" + v.mode + "'");
  }
  if (v.mode == "simulation" && v.trajectory.empty()) {
    throw UsageError(
        "--mode simulation needs --trajectory (the reference the measured run followed)");
  }
  if (v.engine != "mujoco" && v.engine != "native") {
    throw UsageError("--engine must be mujoco or native, not '" + v.engine + "'");
  }
  const Model model = load_robot(v.robot);
  std::vector<std::string> names;
  Eigen::VectorXd values;
  nlohmann::json used;
  read_identified_parameters(v.params, names, values, used);
  // The same friction set and signal processing as the identification that wrote the file.
  IdentifyCliOptions o;
  o.friction = used.value("friction", o.friction);
  o.no_armature = !used.value("armature", true);
  o.filter = used.value("filter", o.filter);
  o.cutoff = used.value("cutoff_hz", 0.0);
  o.savgol = used.value("savitzky_golay", false);
  o.torque_offset = used.value("torque_offset_s", 0.0);
  o.filter_coulomb = used.value("filter_coulomb_columns", false);
  o.zero_velocity = v.zero_velocity.empty() ? used.value("zero_velocity", std::vector<double>{})
                                            : v.zero_velocity;
  const IdentifyOptions options = library_options(o);
  RunFileOptions file;
  file.columns = parse_column_mapping(v.columns);
  file.rate_hz = v.rate;
  const JointRecord record = read_joint_record(v.data, model, file);
  if (v.mode == "simulation") {
    const JointRecord ref = read_reference(v.trajectory, model, file);
    PlantOptions plant;
    plant.engine = v.engine == "mujoco" ? PlantEngine::kMujoco : PlantEngine::kNative;
    const SimulationValidation sv =
        validate_run_by_simulation(identified_model(model, names, values, options), ref.t, ref.q,
                                   ref.dq, ref.ddq, record.q, record.tau, plant);
    std::cout << simulation_validation_table(model, sv);
    if (!v.json.empty()) {
      write_json(v.json, simulation_validation_to_json(model, sv));
      std::cout << "wrote " << v.json << '\n';
    }
    return;
  }
  const ValidationResult result = validate_torques(model, record, names, values, options);
  std::cout << validation_table(model, result);
  if (!v.json.empty()) {
    write_json(v.json, validation_to_json(model, result));
    std::cout << "wrote " << v.json << '\n';
  }
}

}  // namespace

void add_identify_command(CLI::App& app) {
  auto o = std::make_shared<IdentifyCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "identify", "Identify base parameters, friction and actuator inertias from a recorded run");
  cmd->add_option("--robot,-r", o->robot, "Built-in robot name or .urdf/.yaml model")->required();
  cmd->add_option(
         "--data,-d", o->data,
         "Run CSV: t (or --rate), q* or qm* (motor side), tau* or taum*, optional dq*, ddq*")
      ->required();
  cmd->add_option("--out,-o", o->out, "Result JSON file")->required();
  cmd->add_option("--estimator", o->estimator, "ols, wls (Gautier two-step) or rls (U-D recursive)")
      ->capture_default_str();
  cmd->add_option("--confidence", o->confidence, "Confidence level of the intervals")
      ->capture_default_str();
  cmd->add_option("--zero-velocity", o->zero_velocity,
                  "Drop rows of joint j with |dq_j| below this [rad/s] (1 or n values); "
                  "default max(1 % of max|dq_j|, 3 x its noise std), Coulomb columns filtered")
      ->delimiter(',');
  cmd->add_flag("--stream", o->stream,
                "Constant-memory mode for very long runs: reads the file in chunks; needs q, dq, "
                "ddq, tau columns and --filter none");
  cmd->add_option("--threads", o->threads,
                  "With --stream: worker threads (0 = one per core); the result does not depend "
                  "on it beyond round-off")
      ->capture_default_str();
  add_signal_flags(cmd, *o);
  cmd->callback([o] { run_identify(*o); });
}

void add_validate_command(CLI::App& app) {
  auto v = std::make_shared<ValidateCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "validate",
      "Predict the torques of another run with identified parameters and report errors");
  cmd->add_option("--robot,-r", v->robot, "Built-in robot name or .urdf/.yaml model")->required();
  cmd->add_option("--params,-p", v->params, "result.json written by dynid identify")->required();
  cmd->add_option("--data,-d", v->data, "Run CSV to predict (same format as identify)")->required();
  cmd->add_option("--json", v->json, "Write the per-joint errors as JSON");
  cmd->add_option("--mode", v->mode,
                  "torque (predict the measured torques) or simulation (simulate the identified "
                  "model under the same reference and controller, seed 2 §3.5)")
      ->capture_default_str();
  cmd->add_option("--trajectory", v->trajectory,
                  "With --mode simulation: the reference CSV of the run");
  cmd->add_option("--engine", v->engine, "With --mode simulation: mujoco or native")
      ->capture_default_str();
  cmd->add_option("--rate", v->rate, "Sample rate [Hz] when the file has no t column");
  cmd->add_option("--columns", v->columns, "Rename columns before lookup: from=to,from2=to2");
  cmd->add_option("--zero-velocity", v->zero_velocity,
                  "Leave rows of joint j with |dq_j| below this [rad/s] out of the torque "
                  "statistics (1 or n values); default: as the identification did; 0 keeps all")
      ->delimiter(',');
  cmd->callback([v] { run_validate(*v); });
}

}  // namespace dynid::cli
