// `dynid identify` and `dynid validate --mode torque`: parse, validate, call the library, write.
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <string>

#include "commands.hpp"
#include "dynid/common/error.hpp"
#include "dynid/common/input_file.hpp"
#include "dynid/common/message.hpp"
#include "dynid/common/progress.hpp"
#include "dynid/experiments/decoupled_model.hpp"
#include "dynid/experiments/friction_experiment.hpp"
#include "dynid/experiments/gravity_experiment.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/option_text.hpp"
#include "dynid/identification/streaming_identification.hpp"
#include "dynid/identification/streaming_partial.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/atomic_file.hpp"
#include "dynid/io/closed_loop_file.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/io/joint_state_log.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/io/model_summary.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/physical/completed_model.hpp"
#include "dynid/physical/identified_model.hpp"
#include "dynid/physical/physical_parameters.hpp"
#include "dynid/report/control_report.hpp"
#include "dynid/report/experiment_report.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/report/stored_result.hpp"
#include "dynid/sim/pid_gains.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "dynid/workflow/identify_runs.hpp"
#include "flag_checks.hpp"
#include "partial_support.hpp"
#include "robot_flags.hpp"
#include "run_flags.hpp"

namespace dynid::cli {
namespace {

struct IdentifyCliOptions {
  std::string robot, data, out;
  RunFlags run;                   // --rate, --columns, --torque-scale, --rows, --time, ...
  RobotFlags robot_flags;         // --joints, --lock, --strict
  std::vector<std::string> runs;  // --data, repeatable (identify)
  std::string history;            // --history (identify, rls)
  std::string friction = "viscous,coulomb,offset";
  bool no_armature = false;
  std::string filter = "auto";
  double cutoff = 0.0, confidence = 0.999;
  int decimate = 0, trim = -1;
  std::string estimator = "ols";
  std::vector<double> zero_velocity;
  bool savgol = false;
  bool stream = false;
  int threads = 0;
  std::string partial;       // --partial (with --stream): the accumulated state, for dynid merge
  bool householder = false;  // --householder (with --stream)
  bool filter_coulomb = false;
  std::vector<double> coulomb_width;  // --coulomb-width
  std::string outliers = "report";
  std::string model = "differential";  // --model
  double interval = 0.01;              // --interval (integral model)
  bool long_integrals = false;         // --long (integral model)
  int joint = 0;                       // --joint (gravity, friction, decoupled), 1-based
  std::string params;                  // --params (friction: compensation model)
  bool physical = false;               // --physical

  std::vector<std::string> friction_known;  // --friction-known, repeatable
  std::string closed_loop = "none";         // --closed-loop
  std::string fir;                          // --fir M1,M2
  double period = 0.0, f0 = 0.0;            // --period S, --f0 HZ (spectral)
  std::string noise, noise_std;             // --noise FILE, --noise-std q=S,tau=S (ml)
  std::string repeat;                       // --repeat periods|runs
  std::string report;                       // --report
  bool quiet = false;                       // --quiet
};

// The run named by `flag` must be a readable file (so the error names the flag the user gave).
void require_readable(const std::string& path, const char* flag) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (fs::is_directory(path, ec)) {
    // A ROS 2 bag is a folder (the library reads its .db3 files).
    if (joint_state_log_format(path) != JointStateLogFormat::kNone) return;
    throw Error(std::string(flag) + " '" + path + "' is a folder; give the file");
  }
  require_regular_file(path, flag);  // opening a FIFO to test it would wait for a writer
  if (!std::ifstream(path)) {
    throw Error(std::string(flag) + " '" + path +
                "' cannot be opened (missing or unreadable); check the path");
  }
}

// The folder of an output named by `flag` must exist, so that a bad path fails before any work
// and before any other output is written.
void require_output_folder(const std::string& path, const char* flag) {
  namespace fs = std::filesystem;
  if (path.empty()) return;
  const fs::path parent = fs::path(path).parent_path();
  std::error_code ec;
  if (!parent.empty() && !fs::is_directory(parent, ec)) {
    throw Error(std::string(flag) + " '" + path + "': folder '" + parent.string() +
                "' does not exist; create it or write elsewhere");
  }
}

// One line per processing choice on stderr (the result JSON keeps them under `choices`).
void echo_choices(const char* command, const RunFileReport& read,
                  const std::vector<std::pair<std::string, std::string>>& choices) {
  // Choices quote input (file names): one_line() keeps each of them on one printable line.
  for (const auto& w : read.warnings) std::cerr << "warning: " << one_line(w) << '\n';
  for (const auto& note : read.notes) std::cerr << command << ": " << one_line(note) << '\n';
  for (const auto& [key, value] : choices)
    std::cerr << command << ": " << key << ": " << one_line(value) << '\n';
}

std::vector<std::string> joint_names(const Model& model) {
  std::vector<std::string> names;
  for (const auto& joint : model.joints) names.push_back(joint.name);
  return names;
}

// --report: the result just written, as one HTML page.
void write_report(const std::string& path, const std::string& source,
                  const nlohmann::json& result) {
  if (path.empty()) return;
  write_html_report(path, {{source, result}}, {});
  std::cout << "wrote " << path << '\n';
}

void warn(const std::string& text) {
  std::cerr << "warning: " << one_line(text) << '\n';
}

}  // namespace

namespace {

IdentificationEstimator parse_estimator(const std::string& text) {
  if (text == "ols") return IdentificationEstimator::kOls;
  if (text == "wls") return IdentificationEstimator::kWls;
  if (text == "rls") return IdentificationEstimator::kRls;
  if (text == "ml") return IdentificationEstimator::kMl;
  throw UsageError("--estimator must be ols, wls, rls or ml, not '" + text + "'");
}

IdentifyOptions library_options(const IdentifyCliOptions& o) {
  IdentifyOptions out;
  out.layout = friction_layout(o.friction, !o.no_armature);
  out.estimator = parse_estimator(o.estimator);
  out.confidence_level = o.confidence;
  if (!(o.confidence > 0.0 && o.confidence < 1.0)) {
    throw UsageError("--confidence must be in (0, 1), e.g. 0.999");
  }
  apply_filter_text(o.filter, out.signal);
  out.signal.cutoff_hz = o.cutoff;
  out.signal.decimate = o.decimate;
  out.signal.trim = o.trim;
  out.signal.zero_velocity = o.zero_velocity;
  out.signal.savitzky_golay = o.savgol;
  out.signal.torque_time_offset = o.run.shift();
  out.signal.filter_coulomb_columns = o.filter_coulomb;
  out.signal.coulomb_width = o.coulomb_width;
  if (o.outliers != "report" && o.outliers != "drop") {
    throw UsageError("--outliers must be report or drop, not '" + o.outliers + "'");
  }
  out.outliers.policy = o.outliers == "drop" ? OutlierPolicy::kDrop : OutlierPolicy::kReport;
  if (o.closed_loop == "projection") {
    out.closed_loop.method = ClosedLoopMethod::kProjection;
  } else if (o.closed_loop == "spectral") {
    out.closed_loop.method = ClosedLoopMethod::kSpectral;
  } else if (o.closed_loop != "none") {
    throw UsageError("--closed-loop must be none, projection or spectral, not '" + o.closed_loop +
                     "'");
  }
  if (!o.fir.empty()) {
    if (o.closed_loop != "projection")
      throw UsageError("--fir sets the projection's FIR orders: it needs --closed-loop projection");
    apply_fir_text(o.fir, out.closed_loop.projection);
  }
  if (o.period != 0.0 || o.f0 != 0.0) {
    if (o.closed_loop != "spectral")
      throw UsageError(
          "--period/--f0 give the reference's period: they need --closed-loop spectral");
    if ((o.period != 0.0) == (o.f0 != 0.0) || !(o.period >= 0.0) || !(o.f0 >= 0.0))
      throw UsageError("give one of --period S or --f0 HZ, > 0");
    out.closed_loop.period = o.period > 0.0 ? o.period : 1.0 / o.f0;
  }
  if (o.model == "integral") {
    out.model = IdentificationModel::kIntegral;
    if (!(o.interval >= 0.0)) {
      throw UsageError("--interval " + short_number(o.interval) +
                       " is negative; give the interval length in seconds, e.g. 0.01");
    }
    out.integral.interval = o.interval;
    out.integral.long_integrals = o.long_integrals;
  }
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
          {"rate_hz", o.run.rate},
          {"estimator", o.estimator},
          {"confidence_level", o.confidence},
          {"zero_velocity", o.zero_velocity},
          {"savitzky_golay", o.savgol},
          {"torque_offset_s", o.run.shift()},  // the old name of time_shift_s
          {"time_shift_s", o.run.shift()},
          {"filter_coulomb_columns", o.filter_coulomb},
          {"coulomb_width", o.coulomb_width},
          {"outliers", o.outliers},
          {"model", o.model},
          {"columns", o.run.columns},
          {"torque_scale", o.run.torque_scale},
          {"torque_bias", o.run.torque_bias},
          {"topic", o.run.topic},
          {"rows", o.run.rows},
          {"time", o.run.time},
          {"friction_known", o.friction_known},
          {"closed_loop", o.closed_loop},
          {"fir", o.fir},
          {"period", o.period},
          {"f0", o.f0},
          {"noise", o.noise},
          {"noise_std", o.noise_std},
          {"repeat", o.repeat},
          {"joints", o.robot_flags.joints},
          {"lock", o.robot_flags.locks},
          {"strict", o.robot_flags.strict}};
}

void add_signal_flags(CLI::App* cmd, IdentifyCliOptions& o) {
  cmd->add_option(
         "--filter", o.filter,
         "Zero-phase low-pass on q and tau: auto (Butterworth 4), none, butterworth[:ORDER], "
         "chebyshev[:ORDER[:RIPPLE_DB]] (default order 8, as in B. Bona, A. Curatella, "
         "Closed-loop rigid model identification of an industrial robot, 2005)")
      ->capture_default_str();
  cmd->add_option("--cutoff", o.cutoff,
                  "Filter cut-off [Hz], or auto (= 0, default): the best torque prediction on "
                  "held-out blocks among cut-offs from 1.5 x the highest frequency where the "
                  "position spectrum stands 20 dB above its noise floor up to min(20 Hz, rate/10)")
      ->transform(CLI::Transformer(std::map<std::string, std::string>{{"auto", "0"}}));
  cmd->add_option("--decimate", o.decimate,
                  "Keep every N-th sample after filtering; 0 = rate/(10·cut-off)");
  cmd->add_option("--trim", o.trim,
                  "Samples dropped at each end after filtering; -1 = 3·rate/cut-off");
  add_run_flags(cmd, o.run);
  cmd->add_flag("--savgol", o.savgol,
                "Differentiate with Savitzky-Golay instead of central differences");
  cmd->add_option("--friction", o.friction,
                  "Friction terms: comma list of viscous, coulomb, offset; or asymmetric; or none")
      ->capture_default_str();
  cmd->add_flag("--no-armature", o.no_armature, "Do not identify the actuator inertias Ia");
  cmd->add_flag("--filter-coulomb", o.filter_coulomb,
                "Filter the sign(dq) columns like tau (parallel filtering): unbiased Fv and Fc "
                "when the filter smears the Coulomb step at reversals");
  cmd->add_option("--coulomb-width", o.coulomb_width,
                  "Transition velocity v_c [rad/s] of the smooth Coulomb law "
                  "Fc*erf(dq/(sqrt(2) v_c)) in the filtered Coulomb columns (1 or n values); "
                  "default 0: the expected sign of the noisy velocity. With --zero-velocity 0 it "
                  "keeps every row and models the pre-sliding band instead (docs/methods)")
      ->delimiter(',');
}

// One warning per option that has no effect in the combination given.
void warn_identify_no_effect(const IdentifyCliOptions& o, const CLI::App& cmd) {
  const bool given_filter_options = cmd.count("--cutoff") || cmd.count("--filter-coulomb");
  if (o.filter == "none" && given_filter_options) {
    warn("--cutoff and --filter-coulomb have no effect with --filter none");
  }
  if (!o.stream && cmd.count("--threads")) warn("--threads has no effect without --stream");
  if (o.closed_loop == "none") return;
  // The closed-loop preparation keeps the reference's band (the lines up to it, or the FIR's
  // span), computes the derivatives from the reference and keeps every row: these flags would
  // change nothing in that band, so they are named, not silently dropped.
  const std::string seed2 =
      " (the projection keeps only the reference's band); to filter and resample as Bona and "
      "Curatella did, give it to dynid average (--filter chebyshev:8 --cutoff 80 --decimate 5 on "
      "the averaged period)";
  const std::pair<const char*, std::string> ignored[] = {
      {"--filter", seed2},
      {"--cutoff", seed2},
      {"--decimate", seed2},
      {"--trim", " (no filter edges to trim)"},
      {"--savgol", " (the derivatives come from the reference, analytically)"},
      {"--zero-velocity", " (every row is kept so that the projection applies to whole signals)"},
      {"--filter-coulomb", " (the regressor columns are projected like tau)"}};
  for (const auto& [flag, why] : ignored)
    if (cmd.count(flag)) warn(std::string(flag) + " has no effect with --closed-loop" + why);
}

}  // namespace

CompletedModel completed_model_from_result(const Model& model, const std::string& params,
                                           const std::string& command) {
  if (params.empty()) {
    CompletedModel nominal;
    nominal.model = model;
    return nominal;
  }
  const IdentifiedResultFile f = read_identification_result(params);
  require_same_robot(f.robot, model.name, "'" + params + "'", "give a result of this robot");
  CompletedModel c = completed_model_of_result(model, f, params);
  for (const std::string& w : c.warnings) warn(command + ": '" + params + "': " + w);
  return c;
}

namespace {

// `identify --model gravity|friction|decoupled`: seed 2's dedicated experiments on one joint.
void run_experiment(const IdentifyCliOptions& o, const IdentifyOptions& options,
                    const RunFileOptions& file) {
  if (o.stream) throw UsageError("--stream is for the differential model; drop it");
  if (options.estimator != IdentificationEstimator::kOls) {
    throw UsageError("--model " + o.model + " fits by least squares; drop --estimator");
  }
  const Model model = load_cli_robot(o.robot, o.robot_flags,
                                     {"identify", o.runs, file.columns, {}, "", file.topic});
  if (!o.params.empty()) require_readable(o.params, "--params");
  RunFileReport read;
  std::vector<JointRecord> runs;
  for (const auto& path : o.runs) runs.push_back(read_joint_record(path, model, file, &read));
  nlohmann::json used = echo(o);
  used["joint"] = o.joint;
  used["data_runs"] = o.runs;
  std::optional<IdentifiedResultFile> params;
  ExperimentCompensation compensation;
  if (o.model == "friction" && !o.params.empty()) {
    params = read_identification_result(o.params);
    require_same_robot(params->robot, model.name, "'" + o.params + "'",
                       "give a result of this robot");
    compensation = {&*params, o.params};
  }
  std::vector<std::string> warnings;
  const nlohmann::json result =
      identify_joint_experiment(model, runs, joint_experiment_of(o.model), o.joint - 1, options,
                                used, compensation, warnings);
  for (const std::string& w : warnings) warn("identify: " + w);
  std::vector<std::pair<std::string, std::string>> echoed;
  for (auto& [k, v] : result["choices"].items()) echoed.emplace_back(k, v.get<std::string>());
  echo_choices("identify", read, echoed);
  std::cout << experiment_table(result);
  write_json(o.out, result);
  std::cout << "wrote " << o.out << '\n';
  write_report(o.report, o.out, result);
}

void run_identify(IdentifyCliOptions o, const CLI::App& cmd) {
  o.data = o.runs.empty() ? std::string() : o.runs.front();
  if (o.model != "differential" && o.model != "integral" && o.model != "gravity" &&
      o.model != "friction" && o.model != "decoupled") {
    throw UsageError(
        "--model must be differential, integral, gravity, friction or decoupled, not '" + o.model +
        "'");
  }
  const bool experiment = o.model == "gravity" || o.model == "friction" || o.model == "decoupled";
  if (!experiment && cmd.count("--joint")) warn("--joint has no effect with --model " + o.model);
  if (o.model != "friction" && !o.params.empty()) {
    warn("--params has no effect with --model " + o.model);
  }
  if (o.model != "integral" && (cmd.count("--interval") || o.long_integrals)) {
    warn("--interval and --long have no effect with --model " + o.model);
  }
  if (o.model == "integral" && o.stream) {
    throw UsageError("--stream is for the differential model; drop it with --model integral");
  }
  if (!o.friction_known.empty()) {
    if (o.model != "differential" || o.stream) {
      throw UsageError(
          "--friction-known is for the differential model in memory; drop it, or "
          "drop --model/--stream");
    }
    if (cmd.count("--friction") && o.friction != "none") {
      throw UsageError("--friction-known replaces the friction columns; drop --friction");
    }
    o.friction = "none";  // only the rigid body (and armature) is estimated (seed 2 §3.4)
    for (const auto& f : o.friction_known) require_readable(f, "--friction-known");
  }
  const RunFileOptions file = run_file_options(o.run);  // first: it checks the time shift
  IdentifyOptions options = library_options(o);
  if (!o.history.empty() && options.estimator != IdentificationEstimator::kRls) {
    throw UsageError("--history needs --estimator rls (the batch estimators have no history)");
  }
  if (!o.stream && (!o.partial.empty() || o.householder)) {
    throw UsageError("--partial and --householder are for --stream; add --stream or drop them");
  }
  if (o.out.empty() && o.partial.empty()) {
    throw UsageError("--out is required (with --stream, --partial alone is enough)");
  }
  if (o.out.empty() && (!o.report.empty() || o.physical)) {
    throw UsageError("--report and --physical need --out (the result they describe)");
  }
  require_output_folder(o.partial, "--partial");
  if (o.stream && !o.history.empty()) {
    throw UsageError("--history needs the in-memory mode (drop --stream)");
  }
  options.record_history = !o.history.empty();
  for (const auto& run : o.runs) require_readable(run, "--data");
  require_output_folder(o.out, "--out");
  require_output_folder(o.history, "--history");
  require_output_folder(o.report, "--report");
  for (const auto& run : o.runs) {
    if (o.stream && joint_state_log_format(run) != JointStateLogFormat::kNone) {
      throw UsageError("--stream reads a CSV run in chunks; '" + run +
                       "' is a ROS log, read in memory: drop --stream");
    }
  }
  if (o.stream && (!o.run.torque_scale.empty() || !file.torque_bias.empty() ||
                   !file.window.empty() || columns_by_position(file.columns))) {
    throw UsageError(
        "--stream reads named columns as they are; --torque-scale, --torque-bias, --rows, --time "
        "and --columns by position need the in-memory mode (drop --stream)");
  }
  if (options.estimator != IdentificationEstimator::kMl &&
      (!o.noise.empty() || !o.noise_std.empty()))
    throw UsageError(
        "--noise and --noise-std are the noise of --estimator ml; add it or drop them");
  if (options.estimator == IdentificationEstimator::kMl && (o.stream || experiment))
    throw UsageError("--estimator ml needs the differential model in memory; drop --stream");
  if (!o.noise.empty() && !o.noise_std.empty())
    throw UsageError("give --noise FILE or --noise-std q=S,tau=S, not both");
  if (!o.noise.empty()) require_readable(o.noise, "--noise");
  if (!o.repeat.empty() && o.repeat != "periods" && o.repeat != "runs")
    throw UsageError("--repeat must be periods or runs, not '" + o.repeat + "'");
  const bool closed = options.closed_loop.method != ClosedLoopMethod::kNone;
  if ((closed || !o.repeat.empty()) && (o.stream || experiment || o.model != "differential"))
    throw UsageError(
        "--closed-loop and --repeat work on the differential model in memory; drop "
        "--stream and --model");
  warn_identify_no_effect(o, cmd);
  if (experiment) {
    run_experiment(o, options, file);
    return;
  }
  const Model model = load_cli_robot(o.robot, o.robot_flags,
                                     {"identify", o.runs, file.columns, {}, "", file.topic});
  RunFileReport read;
  IdentifiedRuns identified;
  IdentificationResult& result = identified.result;
  IdentifyRunsOptions run_options;
  run_options.repeat = o.repeat;
  run_options.physical = o.physical;
  std::optional<OutputBatch> outputs;  // with --partial
  std::vector<JointRecord> records;
  std::optional<JointRecord> physical_run;
  if (o.stream) {
    // Reading the big file is the whole wait: the line counts its bytes.
    ProgressLine progress("identify", progress_wanted(o.quiet));
    options.progress = progress.callback();
    const StreamingIdentificationOptions stream{o.threads, !o.householder};
    if (o.partial.empty()) {
      result = identify_stream(model, o.runs, file, options, stream);
    } else {
      StreamPartial part = stream_partial(model, o.runs, file, options, stream);
      part.options = partial_options(echo(o));
      part.origin = stream_partial_origin(o.robot, model);
      outputs.emplace();  // the part, the result and its report, or none of them
      write_stream_partial(o.partial, part);
      std::cout << "wrote " << o.partial << " (" << part.runs.size() << " runs)\n";
      if (o.out.empty()) {
        outputs->commit();
        return;
      }
      result = solve_merged_part(model, part);
    }
    progress.finish();
    options.progress = nullptr;  // it refers to this scope's line
    // The physical fit's torque errors are measured on the run, read here only for it.
    if (o.physical) physical_run = read_joint_record(o.runs.front(), model, file);
  } else {
    // Each run read on its own (same column mapping, window and torque scale for every run).
    // Reading a big file is most of the wait; the stages after it report as one step.
    ProgressLine progress("identify", progress_wanted(o.quiet));
    const double steps = static_cast<double>(o.runs.size() + 1);
    for (size_t i = 0; i < o.runs.size(); ++i) {
      progress.update(static_cast<double>(i) / steps, "reading " + o.runs[i]);
      records.push_back(read_joint_record(o.runs[i], model, file, &read));
    }
    progress.update((steps - 1.0) / steps, "filtering and estimating");
    // identify()'s stages (preparation, estimate, ML iterations) fill the last step of the line.
    options.progress = [&progress, steps](double fraction, const std::string& what) {
      progress.update((steps - 1.0 + fraction) / steps, what);
    };
    for (const auto& f : o.friction_known) {
      const IdentifiedResultFile known = read_identification_result(f);
      require_same_robot(known.robot, model.name, "--friction-known '" + f + "'",
                         "give a result of this robot");
      add_known_friction(options.known_friction, model, known.names, known.values, f);
    }
    std::string noise_file;
    if (!o.noise.empty()) options.noise = read_sensor_noise(o.noise, model, o.runs[0], &noise_file);
    if (!o.noise_std.empty()) options.noise = parse_noise_std(o.noise_std, model.dof());
    std::vector<ReferenceRecord> references;
    if (closed || o.repeat == "periods") {
      for (size_t i = 0; i < o.runs.size(); ++i)
        references.push_back(read_reference_columns(o.runs[i], model, file, records[i]));
    }
    identified = identify_runs(model, records, references, options, run_options);
    progress.finish();
    options.progress = nullptr;  // it refers to this scope's line
    for (size_t i = 0; i < result.runs.size(); ++i) result.runs[i].file = o.runs[i];
    if (!noise_file.empty()) result.choices.emplace_back("noise_file", noise_file);
  }
  echo_choices("identify", read, result.choices);
  std::cout << identification_table(model, result);
  nlohmann::json used = echo(o);
  if (o.runs.size() > 1) used["data_runs"] = o.runs;
  if (!o.history.empty()) used["history"] = o.history;
  identified_runs_to_json(model, records, options, run_options, used, identified,
                          physical_run ? &*physical_run : nullptr);
  const nlohmann::json& out = identified.json;
  if (identified.repeated) {
    std::cout << "repeated over " << identified.repeated->n << " " << o.repeat
              << ": mean, std and t/sqrt(n-1)*std per parameter in " << o.out << '\n';
  }
  if (identified.physical) {
    const PhysicalCheck& c = *identified.physical;
    std::cout << physical_parameters_text(c.fit, c.physical_error, c.free_error);
  }
  for (const std::string& w : identified.warnings) warn(w);
  write_json(o.out, out);
  std::cout << "wrote " << o.out << '\n';
  if (!o.history.empty()) {
    write_rls_history(o.history, result);
    std::cout << "wrote " << o.history << '\n';
  }
  write_report(o.report, o.out, out);
  if (outputs) outputs->commit();
}

struct ValidateCliOptions {
  std::string robot, params, data, json, mode = "torque", trajectory, engine = "mujoco";
  RunFlags run;  // --rate, --columns, --torque-scale, ...: default the ones stored in --params
  RobotFlags robot_flags;  // --joints, --lock, --strict: default the ones stored in --params
  std::string predicted;
  std::string controller, gains, histograms;  // --mode simulation: the run's loop, error PDFs
  std::string report;                         // --report
  std::vector<double> zero_velocity;
  double cutoff = 0.0;
};

void run_validate(const ValidateCliOptions& v, const CLI::App& cmd) {
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
  RunFileOptions file = run_file_options(v.run);
  require_readable(v.params, "--params");
  require_readable(v.data, "--data");
  require_output_folder(v.json, "--json");
  require_output_folder(v.predicted, "--predicted");
  require_output_folder(v.report, "--report");
  if (v.mode == "simulation") {
    require_readable(v.trajectory, "--trajectory");
    if (!v.predicted.empty()) warn("--predicted has no effect with --mode simulation");
    if (!v.gains.empty()) require_readable(v.gains, "--gains");
    require_output_folder(v.histograms, "--histograms");
    if (cmd.count("--zero-velocity")) warn("--zero-velocity has no effect with --mode simulation");
  } else {
    if (!v.trajectory.empty()) warn("--trajectory has no effect with --mode torque");
    if (cmd.count("--engine")) warn("--engine has no effect with --mode torque");
    if (!v.controller.empty() || !v.gains.empty() || !v.histograms.empty()) {
      warn("--controller, --gains and --histograms have no effect with --mode torque");
    }
  }
  const IdentifiedResultFile identified = read_identification_result(v.params);
  const Model model = load_cli_robot(
      v.robot, v.robot_flags,
      {"validate", {v.data}, file.columns, selection_stored_in(v.params), v.params, file.topic});
  require_same_robot(identified.robot, model.name, "'" + v.params + "'",
                     "validate with the robot the parameters were identified on");
  std::vector<std::string> names = identified.names;
  Eigen::VectorXd values = identified.values;
  RunFileReport read;
  StoredOptionOverrides overrides;
  if (cmd.count("--cutoff")) overrides.cutoff = v.cutoff;
  overrides.zero_velocity = v.zero_velocity;
  overrides.torque_scale_given = run_flag_given(cmd, "--torque-scale");
  overrides.columns_given = run_flag_given(cmd, "--columns");
  overrides.rate_given = run_flag_given(cmd, "--rate");
  overrides.torque_bias_given = run_flag_given(cmd, "--torque-bias");
  overrides.topic_given = run_flag_given(cmd, "--topic");
  if (run_flag_given(cmd, "--time-shift")) overrides.time_shift = v.run.shift();
  const StoredIdentifyOptions stored =
      options_of_stored_result(identified, v.params, model.dof(), overrides);
  stored.apply_to(file);
  read.notes.insert(read.notes.end(), stored.notes.begin(), stored.notes.end());
  IdentifyOptions options = stored.options;
  add_stored_known_friction(identified, v.params, model, names, values, options);
  const JointRecord record = [&] {
    try {
      return read_joint_record(v.data, model, file, &read);
    } catch (const Error& e) {
      // A rename stored by identify may not fit this run: say where it came from and the fix.
      const std::string text = e.what();
      if (stored.columns.empty() || text.find("--columns") == std::string::npos) throw;
      throw Error(text + " (the --columns given to identify, stored in '" + v.params +
                  "'; give --columns for this run)");
    }
  }();
  if (v.mode == "simulation") {
    RunFileOptions reference_file;
    if (!columns_by_position(file.columns)) reference_file.columns = file.columns;
    const JointRecord ref = read_reference(v.trajectory, model, reference_file);
    PlantOptions plant;
    plant.engine = v.engine == "mujoco" ? PlantEngine::kMujoco : PlantEngine::kNative;
    // The run's own loop: --gains, else the gains file simulate wrote beside the run.
    PidGains gains;
    const std::string beside = gains_file_for_run(v.data);
    if (!v.gains.empty()) {
      gains = read_pid_gains(v.gains, model);
    } else if (std::error_code ec; std::filesystem::exists(beside, ec)) {  // a FIFO is refused
      gains = read_pid_gains(beside, model);
      read.notes.push_back("controller gains from '" + beside + "'");
    }
    const std::string controller =
        !v.controller.empty() ? v.controller
                              : (!gains.controller.empty() ? gains.controller : "pid-feedforward");
    if (controller != "pid" && controller != "pid-feedforward" && controller != "computed-torque") {
      throw UsageError("--controller must be pid, pid-feedforward or computed-torque, not '" +
                       controller + "'");
    }
    const FeedForward feed_forward = controller == "pid" ? FeedForward::kNone
                                     : controller == "computed-torque"
                                         ? FeedForward::kInverseDynamics
                                         : FeedForward::kComputedTorque;
    read.notes.push_back("controller " + controller);
    echo_choices("validate", read, {});
    const CompletedModel completed = completed_model_of_result(model, identified, v.params);
    for (const std::string& w : completed.warnings) warn("validate: '" + v.params + "': " + w);
    const SimulationValidation sv =
        validate_run_by_simulation(completed.model, ref.t, ref.q, ref.dq, ref.ddq, record.q,
                                   record.tau, plant, feed_forward, gains);
    std::cout << simulation_validation_table(model, sv);
    if (!v.histograms.empty()) {
      write_error_histograms(v.histograms, model, sv);
      std::cout << "wrote " << v.histograms << '\n';
    }
    nlohmann::json out = simulation_validation_to_json(model, sv);
    out["parameter_sources"] = parameter_sources_json(completed);
    if (!v.json.empty()) {
      write_json(v.json, out);
      std::cout << "wrote " << v.json << '\n';
    }
    write_report(v.report, v.json.empty() ? v.data : v.json, out);
    return;
  }
  ValidationResult result;
  try {
    result = validate_torques(model, record, names, values, options, identified.not_excited,
                              nominal_completion_of_result(model, identified, v.params));
  } catch (const UsageError& e) {  // --zero-velocity is the user's own when given
    if (!v.zero_velocity.empty()) throw;
    throw stored_option_error(e, v.params);
  }
  // Closed-loop results are validated on the measured torques: the question is how well the model
  // predicts what the robot measures (docs/methods/closed_loop.md, "Validation").
  const std::string closed =
      ResultFileOptions{identified.options, v.params}.get("closed_loop", std::string("none"));
  if (closed != "none")
    result.choices.emplace_back(
        "closed_loop",
        "identified with --closed-loop " + closed +
            "; validated on this run's measured torques, filtered and not projected (a projection "
            "keeps only the reference's band and would hide the noise and the loop's response "
            "the model must predict)");
  echo_choices("validate", read, result.choices);
  for (const std::string& w : result.warnings) warn("validate: " + w);
  if (!result.rms.allFinite() || !result.relative_error.allFinite() ||
      !std::isfinite(result.relative_error_all) || !std::isfinite(result.relative_error_all_rows)) {
    throw Error("the predicted torques overflow: the parameter values in '" + v.params +
                "' (largest |value| " +
                short_number(values.size() ? values.cwiseAbs().maxCoeff() : 0.0) +
                ") or the torques in '" + v.data +
                "' are implausibly large; check both files and their units");
  }
  std::cout << validation_table(model, result);
  nlohmann::json out = validation_to_json(model, result);
  out["plot"] = prediction_plot_json(result, joint_names(model));
  if (!v.json.empty()) {
    write_json(v.json, out);
    std::cout << "wrote " << v.json << '\n';
  }
  write_report(v.report, v.json.empty() ? v.data : v.json, out);
  if (!v.predicted.empty()) {
    write_validation_predictions(v.predicted, result);
    std::cout << "wrote " << v.predicted << '\n';
  }
}

}  // namespace

void add_identify_command(CLI::App& app) {
  auto o = std::make_shared<IdentifyCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "identify", "Identify base parameters, friction and actuator inertias from a recorded run");
  cmd->add_option("--robot,-r", o->robot, "Built-in robot name or .urdf/.yaml model")->required();
  cmd->add_option("--data,-d", o->runs,
                  "Run CSV: t (or --rate), q* or qm* (motor side), tau* or taum*, optional dq*, "
                  "ddq*; repeat --data to identify from several runs together (each is "
                  "processed on its own, their equations are stacked)")
      ->required()
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_option("--out,-o", o->out, "Result JSON file (optional with --stream --partial)");
  cmd->add_flag("--quiet,-q", o->quiet,
                "No progress line on stderr (shown only when stderr is a terminal)");
  cmd->add_option("--report", o->report,
                  "Also write a self-contained HTML report of the result (as dynid report)");
  cmd->add_option("--history", o->history,
                  "With --estimator rls: write the estimate after every equation as CSV (t, then "
                  "NAME and NAME_std per parameter), to watch when each parameter settles");
  cmd->add_option("--model", o->model,
                  "differential (joint torques, default), integral (energy over intervals: "
                  "Dutkiewicz, Kozlowski, Wroblewski 1993), or one joint's dedicated experiment "
                  "(Bona, Curatella 2005): gravity (constant-velocity slopes; over all q "
                  "when the runs hold the other joints at different poses), friction "
                  "(bang-bang moves, inertia and gravity compensated) or decoupled (one joint "
                  "moving, the others held)");
  cmd->add_option("--interval", o->interval,
                  "Integral model: interval length [s] (default 0.01; 0 = two samples)");
  cmd->add_flag("--long", o->long_integrals,
                "Integral model: long integrals growing from the first sample");
  cmd->add_option("--joint", o->joint, "gravity, friction, decoupled: the joint (1-based)");
  cmd->add_option("--params", o->params,
                  "friction: result.json whose identified model compensates inertia and gravity "
                  "(default: the robot's nominal model), or the --model gravity or decoupled "
                  "result of the same joint, whose gravity (and inertia) is used instead");
  cmd->add_option("--friction-known", o->friction_known,
                  "Result JSON of identify --model friction or decoupled (repeat per joint): its "
                  "asymmetric friction is subtracted from the measured torque and only the "
                  "rigid-body base parameters (and armature) are estimated (Bona, Curatella 2005, "
                  "section 3.4)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  cmd->add_flag("--physical", o->physical,
                "Also fit physically consistent standard parameters (mass > 0, realisable "
                "inertia, friction >= 0; log-Cholesky, Rucker and Wensing 2022) to the estimate");
  cmd->add_option("--estimator", o->estimator,
                  "ols, wls (Gautier two-step), rls (U-D recursive) or ml (maximum likelihood with "
                  "noisy q and tau: B. Bona, A. Curatella, Closed-loop rigid model "
                  "identification of an industrial robot, 2005)")
      ->capture_default_str();
  cmd->add_option("--closed-loop", o->closed_loop,
                  "none (filter the measured signals), projection (project q and tau, and the "
                  "regressor alike, on the lagged references qr*: Forssell and Ljung, A "
                  "projection method for closed-loop identification, 2000) or spectral (keep a "
                  "periodic reference's lines, derivatives analytic); both need qr1..qrn columns")
      ->capture_default_str();
  cmd->add_option("--fir", o->fir,
                  "With --closed-loop projection: FIR orders M1,M2 (future, past reference "
                  "lags); default: the smallest passing a remainder-reference correlation test");
  cmd->add_option("--period", o->period,
                  "With --closed-loop spectral: the reference's period [s] (default: detected "
                  "from qr, which must then repeat exactly)");
  cmd->add_option("--f0", o->f0,
                  "With --closed-loop spectral: the fundamental [Hz] instead of --period");
  cmd->add_option(
      "--noise", o->noise,
      "With --estimator ml: noise JSON of dynid average --json (q<j>, tau<j>: std_averaged "
      "when --data is its mean period, else the raw std)");
  cmd->add_option("--noise-std", o->noise_std,
                  "With --estimator ml: raw sensor noise q=S,tau=S [rad, N m] for every joint; "
                  "default: estimated from the data (white floor of each spectrum)");
  cmd->add_option("--repeat", o->repeat,
                  "periods or runs: also identify each whole period (or each --data run) alone "
                  "and report mean, std and t/sqrt(n-1)*std per parameter (Bona and Curatella "
                  "2005, Table 3)");
  cmd->add_option("--confidence", o->confidence, "Confidence level of the intervals")
      ->capture_default_str();
  cmd->add_option("--zero-velocity", o->zero_velocity,
                  "Drop rows of joint j with |dq_j| below this [rad/s] (1 or n values); "
                  "default max(1 % of max|dq_j|, 3 x its noise std), Coulomb columns filtered")
      ->delimiter(',');
  cmd->add_flag(
      "--stream", o->stream,
      "Constant-memory mode for very long runs: reads each --data file in chunks (several "
      "files: the fit of all their rows); needs q, dq, ddq, tau columns and --filter "
      "none");
  cmd->add_option("--partial", o->partial,
                  "With --stream: also write the accumulated least-squares state of the --data "
                  "runs to this file (.dpart, docs/methods/fleet.md), for dynid merge; --out is "
                  "then optional");
  cmd->add_flag("--householder", o->householder,
                "With --stream: accumulate Householder QR factors from the start instead of "
                "normal equations (about 3x slower, backward stable): for parts whose merged "
                "normal equations dynid merge finds too ill-conditioned");
  cmd->add_option("--threads", o->threads,
                  "With --stream: worker threads (0 = one per core); the result does not depend "
                  "on it beyond round-off")
      ->capture_default_str();
  add_signal_flags(cmd, *o);
  add_robot_flags(cmd, o->robot_flags);
  cmd->add_option("--outliers", o->outliers,
                  "Gross torque outliers (Hampel test): report (warn, keep them) or drop (replace "
                  "each by its neighbours' median)")
      ->capture_default_str();
  cmd->callback([o, cmd] { run_identify(*o, *cmd); });
}

void add_validate_command(CLI::App& app) {
  auto v = std::make_shared<ValidateCliOptions>();
  CLI::App* cmd = app.add_subcommand(
      "validate",
      "Predict the torques of another run with identified parameters and report errors");
  cmd->add_option("--robot,-r", v->robot, "Built-in robot name or .urdf/.yaml model")->required();
  add_robot_flags(cmd, v->robot_flags, RobotFlagDefaults::kStoredInParams);
  cmd->add_option("--params,-p", v->params, "result.json written by dynid identify")->required();
  cmd->add_option("--data,-d", v->data, "Run CSV to predict (same format as identify)")->required();
  cmd->add_option("--json", v->json,
                  "Write the per-joint errors as JSON (with `plot`: measured and predicted "
                  "torques decimated for display, residual histogram)");
  cmd->add_option("--report", v->report,
                  "Also write a self-contained HTML report of the validation (as dynid report)");
  cmd->add_option("--mode", v->mode,
                  "torque (predict the measured torques) or simulation (simulate the identified "
                  "model under the same reference and controller, as in B. Bona, A. Curatella, "
                  "Closed-loop rigid model identification of an industrial robot, 2005)")
      ->capture_default_str();
  cmd->add_option("--trajectory", v->trajectory,
                  "With --mode simulation: the reference CSV of the run");
  cmd->add_option("--engine", v->engine, "With --mode simulation: mujoco or native")
      ->capture_default_str();
  cmd->add_option("--controller", v->controller,
                  "With --mode simulation: the loop the run was made with, pid, pid-feedforward or "
                  "computed-torque (with the identified model); default: the controller named in "
                  "the gains file, else pid-feedforward");
  cmd->add_option("--gains", v->gains,
                  "With --mode simulation: YAML/JSON with kp, ki, kd lists; default: "
                  "<data>.gains.json beside the run when present (simulate writes it), else the "
                  "bandwidth rule");
  cmd->add_option("--histograms", v->histograms,
                  "With --mode simulation: write the position and torque error PDFs as CSV, per "
                  "joint bin centre, density and the Gaussian of the same mean and std");
  cmd->add_option("--predicted", v->predicted,
                  "Write t and, per joint, measured torque, predicted torque, residual and a "
                  "left-out flag as CSV (tau<j>, tau_pred<j>, residual<j>, left_out<j>)");
  add_run_flags(cmd, v->run, RunFlagDefaults::kStoredInParams);
  cmd->add_option("--cutoff", v->cutoff,
                  "Filter cut-off [Hz] for this run; default: the cut-off identify used (stored "
                  "in --params); auto (= 0) chooses again from this run")
      ->transform(CLI::Transformer(std::map<std::string, std::string>{{"auto", "0"}}));
  cmd->add_option("--zero-velocity", v->zero_velocity,
                  "Rows of joint j with |dq_j| below this [rad/s] are left out of the second "
                  "(near-still-free) error figure (1 or n values); default: the thresholds "
                  "identify used; 0 keeps all")
      ->delimiter(',');
  cmd->callback([v, cmd] { run_validate(*v, *cmd); });
}

}  // namespace dynid::cli
