#include "dynid/identification/streaming_identification.hpp"

#include "dynid/identification/streaming_partial.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <exception>
#include <limits>
#include <random>
#include <thread>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/estimation/streaming_least_squares.hpp"
#include "dynid/io/csv_chunk_reader.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "dynid/signal/plausibility.hpp"

namespace dynid {

namespace {

// Random states at which the sparsity of the base regressor is probed; velocities alternate in
// sign so that one-sided (asymmetric Coulomb) columns are seen as well.
constexpr int kSparsityProbes = 8;
constexpr unsigned kSparsitySeed = 20261123;
// Every k-th sample of a block is checked for regressor entries in columns probed as structurally
// zero. The probe already shows them zero at random states (an analytic function that is not
// identically zero is non-zero almost everywhere), so the check guards against a defect in the
// probe or the regressor, which would show on nearly every sample; checking each sample cost
// 0.16 us of the 1.9 us per sample (iiwa14).
constexpr Eigen::Index kStructuralCheckStride = 16;
// Upper bound on worker threads.
constexpr int kMaxThreads = 8;

// The base regressor (rows: joint j of probe k at row k·n + j) at kSparsityProbes random states;
// velocities alternate in sign so that one-sided (asymmetric Coulomb) columns are seen as well.
// It fixes which columns each joint sees, and it is the partial result's fingerprint of the
// equations (kinematics, gravity, parameter set).
Eigen::MatrixXd probe_base_regressor(const Model& model, const ParameterLayout& layout,
                                     const BaseParameters& base) {
  const int n = model.dof();
  Workspace ws(model);
  Eigen::MatrixXd Y(n, layout.columns(n));
  Eigen::MatrixXd out(n * kSparsityProbes, base.rank);
  Eigen::VectorXd q(n), dq(n), ddq(n);
  std::mt19937 rng(kSparsitySeed);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), speed(0.2, 2.0);
  for (int probe = 0; probe < kSparsityProbes; ++probe) {
    for (int j = 0; j < n; ++j) {
      q[j] = angle(rng);
      dq[j] = (probe % 2 == 0 ? 1.0 : -1.0) * speed(rng);
      ddq[j] = angle(rng);
    }
    torque_regressor(model, ws, layout, q, dq, ddq, Y);
    for (int c = 0; c < base.rank; ++c) out.block(probe * n, c, n, 1) = Y.col(base.base[c]);
  }
  return out;
}

// Base columns (indices into base.base) that can be non-zero in each joint's torque row: the links
// of the joint's subtree and the joint's own friction. Read off the probe, since an analytic
// function that vanishes at random points vanishes everywhere.
std::vector<std::vector<Eigen::Index>> joint_base_columns(const Eigen::MatrixXd& probe, int n) {
  std::vector<std::vector<Eigen::Index>> columns(n);
  for (int j = 0; j < n; ++j) {
    for (Eigen::Index c = 0; c < probe.cols(); ++c) {
      bool seen = false;
      for (Eigen::Index r = j; r < probe.rows(); r += n) seen |= probe(r, c) != 0.0;
      if (seen) columns[j].push_back(c);
    }
  }
  return columns;
}

// Everything one worker needs to turn blocks of the file into accumulated rows.
struct Worker {
  Worker(const Model& model, const ParameterLayout& layout, int rank,
         const StreamingOptions& lsq_options)
      : ws(model),
        lsq(rank, model.dof(), lsq_options),
        Y(model.dof(), layout.columns(model.dof())),
        q(model.dof()),
        dq(model.dof()),
        ddq(model.dof()) {}
  Workspace ws;
  StreamingLeastSquares lsq;
  Eigen::MatrixXd Y;
  Eigen::VectorXd q, dq, ddq;
  CsvBlock block;  // the block being processed, read and parsed by this worker
  Eigen::Index samples = 0;
  std::exception_ptr error;        // the worker's first error; it then stops
  std::uint64_t error_offset = 0;  // file offset of the line it names (errors are ordered by it)
};

// The per-run constants shared read-only by the workers.
struct StreamSetup {
  const Model* model = nullptr;
  const ParameterLayout* layout = nullptr;
  const BaseParameters* base = nullptr;
  std::string path;
  std::size_t block_bytes = 0;
  std::vector<std::vector<Eigen::Index>> active;  // base columns per joint
  // The same as offsets into a worker's n-row regressor storage (regressor column·n + joint), and
  // the other base columns, checked to be zero: the per-sample gather and check read Y with one
  // index and no multiplication.
  std::vector<std::vector<Eigen::Index>> active_offset, inactive_offset;
  std::vector<Eigen::Index> cq, cdq, cddq, ctau;
  Eigen::VectorXd threshold;
};

// A row no robot run holds (signal/plausibility.hpp's fixed bounds: the stream never sees a whole
// column, so the median test of preprocess() cannot run) would overflow the accumulated normal
// equations into an all-NaN fit; refused naming the row.
void check_plausible_row(const StreamSetup& s, const CsvBlockReader& reader, Worker& w,
                         Eigen::Index k) {
  const CsvChunkReader::RowBlock& block = w.block.rows;
  const int n = s.model->dof();
  const std::pair<const std::vector<Eigen::Index>*, std::pair<const char*, double>> columns[] = {
      {&s.cq, {"q", kMaxPlausiblePosition}},
      {&s.cdq, {"dq", kMaxPlausibleVelocity}},
      {&s.cddq, {"ddq", kMaxPlausibleAcceleration}},
      {&s.ctau, {"tau", kMaxPlausibleTorque}}};
  for (const auto& [index, what] : columns) {
    for (int j = 0; j < n; ++j) {
      const double v = block(k, (*index)[static_cast<std::size_t>(j)]);
      if (std::abs(v) <= what.second) continue;
      w.block.error_offset = w.block.offsets[static_cast<std::size_t>(k)];
      throw Error("'" + s.path + "' data row " +
                  std::to_string(reader.position(w.block.error_offset).row) + ": " + what.first +
                  std::to_string(j + 1) + " = " + short_number(v) + " is beyond " +
                  short_number(what.second) +
                  " in magnitude, a corrupt sample (SI units assumed) that would make the "
                  "estimate not finite; remove or repair that row of the log");
    }
  }
}

void process_block(const StreamSetup& s, const CsvBlockReader& reader, Worker& w) {
  const Model& model = *s.model;
  const int n = model.dof();
  const CsvChunkReader::RowBlock& block = w.block.rows;
  for (Eigen::Index k = 0; k < block.rows(); ++k) {
    // The CSV reader has already refused NaN and Inf fields, naming the line.
    for (int j = 0; j < n; ++j) {
      w.q[j] = block(k, s.cq[j]);
      w.dq[j] = block(k, s.cdq[j]);
      w.ddq[j] = block(k, s.cddq[j]);
    }
    check_plausible_row(s, reader, w, k);
    torque_regressor(model, w.ws, *s.layout, w.q, w.dq, w.ddq, w.Y);
    const double* y = w.Y.data();
    const bool check = k % kStructuralCheckStride == 0;
    for (int j = 0; j < n; ++j) {
      if (std::abs(w.dq[j]) < s.threshold[j]) continue;
      if (!check) {
        w.lsq.add_row_gathered(j, y, s.active_offset[j], block(k, s.ctau[j]));
        continue;
      }
      // One test per joint instead of a branch per column: the OR of the entries' bit patterns
      // without their sign bits is zero only if every entry is ±0 (integer ORs, no dependency
      // chain of floating-point additions).
      std::uint64_t stray = 0;
      for (Eigen::Index off : s.inactive_offset[j]) {
        std::uint64_t bits;
        std::memcpy(&bits, y + off, sizeof bits);
        stray |= bits << 1;
      }
      if (stray != 0) {
        w.block.error_offset = w.block.offsets[static_cast<std::size_t>(k)];
        throw Error("internal: the regressor of joint " + model.joints[j].name +
                    " is non-zero in a column probed as structurally zero (data row " +
                    std::to_string(reader.position(w.block.error_offset).row) +
                    "); run without --stream and report it");
      }
      w.lsq.add_row_gathered(j, y, s.active_offset[j], block(k, s.ctau[j]));
    }
  }
}

// Reads the file once and accumulates every block; block b (CsvBlockReader: a fixed byte range
// of the file) is read, parsed and accumulated by worker b mod W, and the workers' sums are
// merged in worker order, so the result depends on W but not on timing. There is no reader
// thread: each worker reads its own text (pread) and parses it while it is in its core's cache,
// as W independent processes would. The calling thread is worker 0 and the only one to call
// `progress` (may be empty), with the fraction of the file's bytes done, so that a caller's
// progress line needs no lock. The first error in file order is rethrown after every thread has
// stopped, so no thread outlives the call.
StreamingLeastSquares accumulate(const StreamSetup& s, const StreamingOptions& lsq_options,
                                 int& threads, Eigen::Index& samples,
                                 const ProgressCallback& progress, const std::string& what) {
  const CsvBlockReader reader(s.path, {s.block_bytes});
  const std::int64_t blocks = reader.blocks();
  const int workers_used = static_cast<int>(std::min<std::int64_t>(threads, blocks));
  threads = workers_used;  // told back: a small file has fewer blocks than workers
  // Each worker builds its own state in its own thread (see run): built here, one after the
  // other, the workers' buffers came from one allocator arena, side by side, and two workers cost
  // 1.2x the CPU of one per sample (2.2-2.35 against 1.84-1.93 us on idle cores, iiwa14); built
  // in their threads, 1.82-1.90 us (docs/performance.md).
  std::vector<std::unique_ptr<Worker>> workers(static_cast<std::size_t>(workers_used));
  // Bytes of the blocks done (the header counted from the start, so that the fraction ends at 1).
  std::atomic<std::uint64_t> done{reader.block_begin(0)};
  // Offset of the earliest failing line known so far: a block that starts after it cannot hold
  // the first error and is skipped.
  std::atomic<std::uint64_t> first_error{std::numeric_limits<std::uint64_t>::max()};
  const double file_bytes = static_cast<double>(reader.file_bytes());
  const auto tell = [&] {
    if (progress && file_bytes > 0) progress(static_cast<double>(done.load()) / file_bytes, what);
  };
  std::vector<std::exception_ptr> start_errors(workers.size());
  const auto run = [&](int t) {
    std::unique_ptr<Worker>& slot = workers[static_cast<std::size_t>(t)];
    try {
      slot = std::make_unique<Worker>(*s.model, *s.layout, s.base->rank, lsq_options);
    } catch (...) {
      // Out of memory: no worker state to keep the error in, and none may escape a thread.
      start_errors[static_cast<std::size_t>(t)] = std::current_exception();
      first_error = 0;
      return;
    }
    Worker& w = *slot;
    for (std::int64_t b = t; b < blocks; b += workers_used) {
      if (reader.block_begin(b) > first_error.load(std::memory_order_relaxed)) return;
      try {
        reader.parse(b, w.block);
        process_block(s, reader, w);
      } catch (...) {
        w.error = std::current_exception();
        w.error_offset = w.block.error_offset;
        std::uint64_t seen = first_error.load();
        while (w.error_offset < seen && !first_error.compare_exchange_weak(seen, w.error_offset)) {
        }
        return;
      }
      w.samples += w.block.rows.rows();
      done += reader.block_begin(b + 1) - reader.block_begin(b);
      if (t == 0) tell();
    }
  };
  std::vector<std::thread> pool;
  std::exception_ptr caller_error;  // thread creation or the progress callback: stop, rethrow
  try {
    for (int t = 1; t < workers_used; ++t) pool.emplace_back(run, t);
    run(0);
  } catch (...) {
    caller_error = std::current_exception();
    first_error = 0;
  }
  for (auto& t : pool) t.join();
  if (caller_error) std::rethrow_exception(caller_error);
  for (const auto& e : start_errors)
    if (e) std::rethrow_exception(e);
  const Worker* failed = nullptr;
  for (const auto& w : workers) {
    if (w->error && (failed == nullptr || w->error_offset < failed->error_offset)) {
      failed = w.get();
    }
  }
  if (failed != nullptr) std::rethrow_exception(failed->error);
  // Worker 0 may have finished its share before the others: the fraction ends at 1.
  if (workers_used > 1) tell();
  samples = 0;
  for (const auto& w : workers) samples += w->samples;
  for (int t = 1; t < workers_used; ++t) workers[0]->lsq.merge(workers[t]->lsq);
  return std::move(workers[0]->lsq);
}

// Signal processing a single pass over the file cannot do: refused by name instead of being
// accepted and silently ignored (and then echoed as if applied).
void reject_unsupported_signal_options(const SignalOptions& s) {
  const SignalOptions defaults;
  auto reject = [](const char* flag, const char* why) {
    throw UsageError(std::string(flag) + " cannot be used with --stream (" + why + "); drop " +
                     flag + " or drop --stream");
  };
  if (s.cutoff_hz != defaults.cutoff_hz) reject("--cutoff", "the stream is not filtered");
  if (s.decimate != defaults.decimate) reject("--decimate", "every row is used");
  if (s.trim != defaults.trim) reject("--trim", "there is no filter transient to trim");
  if (s.savitzky_golay != defaults.savitzky_golay) {
    reject("--savgol", "the stream uses the dq and ddq columns as given");
  }
  if (s.torque_time_offset != defaults.torque_time_offset) {
    reject("--time-shift", "re-interpolating the torques needs the whole record");
  }
  if (s.filter_coulomb_columns != defaults.filter_coulomb_columns) {
    reject("--filter-coulomb", "the stream is not filtered");
  }
  for (const double v : s.zero_velocity) {
    if (!(v >= 0.0 && std::isfinite(v))) {
      throw UsageError("--zero-velocity values must be finite and >= 0 [rad/s]");
    }
  }
}

// The stream's checks of identify's options, before any file is opened.
void check_stream_options(const IdentifyOptions& options,
                          const StreamingIdentificationOptions& stream) {
  if (options.signal.filter) {
    throw UsageError(
        "streaming identification reads the file once and cannot filter it; use "
        "--filter none with dq and ddq columns, or drop --stream");
  }
  if (options.estimator != IdentificationEstimator::kOls &&
      options.estimator != IdentificationEstimator::kWls) {
    throw UsageError("streaming identification supports --estimator ols or wls");
  }
  reject_unsupported_signal_options(options.signal);
  if (options.outliers.policy == OutlierPolicy::kDrop) {
    throw UsageError(
        "--outliers drop cannot be used with --stream (the outlier test needs each sample's "
        "neighbours); drop --stream or clean the log");
  }
  if (stream.threads < 0) {
    throw UsageError("--threads is " + std::to_string(stream.threads) +
                     "; give 0 (one per core) or a positive count");
  }
}

BaseParameters stream_base_parameters(const Model& model, const IdentifyOptions& options) {
  BaseParameterOptions base_options = options.base;
  base_options.layout = options.layout;
  return compute_base_parameters(model, base_options);
}

// Column indices of q, dq, ddq and tau in `path`'s header, after the renames of `file`.
void resolve_stream_columns(const Model& model, const std::string& path, const RunFileOptions& file,
                            StreamSetup& s) {
  CsvChunkReader header(path);
  std::vector<std::string> columns = header.columns();
  for (auto& name : columns) {
    for (const auto& [from, to] : file.columns) {
      if (name == from) name = to;
    }
  }
  std::vector<std::string> joints;
  for (const Joint& j : model.joints) joints.push_back(j.name);
  for (const char* prefix : {"dq", "ddq"}) {
    if (!has_joint_columns(columns, joints, prefix)) {
      throw UsageError("'" + path + "' has no " + prefix +
                       "* columns; streaming identification needs q, dq, ddq and tau on the "
                       "joint side (drop --stream to derive them)");
    }
  }
  s.cq = resolve_joint_columns(columns, joints, "q", path);
  s.cdq = resolve_joint_columns(columns, joints, "dq", path);
  s.cddq = resolve_joint_columns(columns, joints, "ddq", path);
  s.ctau = resolve_joint_columns(columns, joints, "tau", path);
}

const char* accumulation_name(Accumulation a) {
  return a == Accumulation::kNormalEquations ? "normal_equations" : "householder";
}

// stream_partial() that also tells the worker count it used (the result's `threads` choice);
// `pass` + file name is what the progress callback is told.
StreamPartial accumulate_runs(const Model& model, const std::vector<std::string>& paths,
                              const RunFileOptions& file, const IdentifyOptions& options,
                              const StreamingIdentificationOptions& stream, int& threads_used,
                              const std::string& pass) {
  check_stream_options(options, stream);
  if (paths.empty()) throw UsageError("streaming identification needs at least one run file");
  const int n = model.dof();
  const BaseParameters base = stream_base_parameters(model, options);
  const int rank = base.rank;
  StreamPartial part;
  part.probe = probe_base_regressor(model, options.layout, base);

  StreamSetup s;
  s.model = &model;
  s.layout = &options.layout;
  s.base = &base;
  s.block_bytes = stream.block_bytes;
  s.threshold = given_zero_velocity(options.signal.zero_velocity, n);
  if (s.threshold.size() == 0) s.threshold = Eigen::VectorXd::Zero(n);  // no automatic rule here
  s.active = joint_base_columns(part.probe, n);
  s.active_offset.resize(n);
  s.inactive_offset.resize(n);
  for (int j = 0; j < n; ++j) {
    for (Eigen::Index c = 0, a = 0; c < rank; ++c) {
      const bool active = a < static_cast<Eigen::Index>(s.active[j].size()) && s.active[j][a] == c;
      (active ? s.active_offset[j] : s.inactive_offset[j]).push_back(base.base[c] * n + j);
      a += active;
    }
  }
  StreamingOptions lsq_options;
  lsq_options.group_columns = s.active;
  lsq_options.accumulation =
      stream.normal_equations ? Accumulation::kNormalEquations : Accumulation::kHouseholder;

  std::vector<std::string> joints;
  for (const Joint& j : model.joints) joints.push_back(j.name);
  const ParameterLayout& l = options.layout;
  part.identity = {
      {"robot", model.name},
      {"joints", joints},
      {"parameters", base.names},
      {"layout",
       {{"armature", l.armature},
        {"viscous", l.viscous},
        {"coulomb", l.coulomb},
        {"offset", l.offset},
        {"asymmetric", l.asymmetric},
        {"coupling", options.coupling}}},
      {"estimator", options.estimator == IdentificationEstimator::kWls ? "wls" : "ols"},
      {"confidence_level", options.confidence_level},
      {"zero_velocity_threshold",
       std::vector<double>(s.threshold.data(), s.threshold.data() + s.threshold.size())},
      {"accumulation", accumulation_name(lsq_options.accumulation)}};

  threads_used = 0;
  for (std::size_t i = 0; i < paths.size(); ++i) {
    s.path = paths[i];
    resolve_stream_columns(model, s.path, file, s);
    int threads =
        stream.threads > 0
            ? std::min(stream.threads, kMaxThreads)
            : std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxThreads);
    // Each file's share of the progress line, so that it runs once from 0 to 1.
    ProgressCallback progress;
    if (options.progress) {
      const double files = static_cast<double>(paths.size());
      progress = [&options, i, files](double fraction, const std::string& what) {
        options.progress((static_cast<double>(i) + fraction) / files, what);
      };
    }
    StreamRun run;
    run.file = s.path;
    const StreamingLeastSquares lsq =
        accumulate(s, lsq_options, threads, run.samples, progress, pass + s.path);
    threads_used = std::max(threads_used, threads);
    run.state = lsq.state();
    part.runs.push_back(std::move(run));
  }
  return part;
}

std::string first_pass(const StreamingIdentificationOptions& stream) {
  return stream.normal_equations ? "reading " : "Householder QR pass over ";
}

}  // namespace

StreamPartial stream_partial(const Model& model, const std::vector<std::string>& paths,
                             const RunFileOptions& file, const IdentifyOptions& options,
                             const StreamingIdentificationOptions& stream) {
  int threads = 0;
  return accumulate_runs(model, paths, file, options, stream, threads, first_pass(stream));
}

IdentifyOptions stream_partial_options(const StreamPartial& part) {
  IdentifyOptions o;
  try {
    const nlohmann::json& id = part.identity;
    const nlohmann::json& l = id.at("layout");
    o.layout = ParameterLayout::rigid();
    o.layout.armature = l.at("armature").get<bool>();
    o.layout.viscous = l.at("viscous").get<bool>();
    o.layout.coulomb = l.at("coulomb").get<bool>();
    o.layout.offset = l.at("offset").get<bool>();
    o.layout.asymmetric = l.at("asymmetric").get<bool>();
    o.coupling = l.at("coupling").get<bool>();
    const std::string estimator = id.at("estimator").get<std::string>();
    if (estimator != "ols" && estimator != "wls") throw Error("estimator '" + estimator + "'");
    o.estimator =
        estimator == "wls" ? IdentificationEstimator::kWls : IdentificationEstimator::kOls;
    o.confidence_level = id.at("confidence_level").get<double>();
    if (!(o.confidence_level > 0.0 && o.confidence_level < 1.0)) throw Error("confidence level");
    o.signal.zero_velocity = id.at("zero_velocity_threshold").get<std::vector<double>>();
    for (double v : o.signal.zero_velocity)
      if (!(v >= 0.0 && std::isfinite(v))) throw Error("zero-velocity threshold");
  } catch (const std::exception& e) {
    throw Error(std::string("partial result: malformed identity (") + e.what() +
                "); re-make the part with dynid identify --stream --partial");
  }
  o.signal.filter = false;
  return o;
}

IdentificationResult solve_stream_partial(const Model& model, const StreamPartial& part) {
  if (part.runs.empty()) throw Error("partial result: no run to solve; the part is corrupt");
  const IdentifyOptions options = stream_partial_options(part);
  const int n = model.dof();
  IdentificationResult result;
  result.base = stream_base_parameters(model, options);
  // The model given must make the equations the part was accumulated with.
  std::vector<std::string> joints;
  for (const Joint& j : model.joints) joints.push_back(j.name);
  const Eigen::MatrixXd probe = probe_base_regressor(model, options.layout, result.base);
  const double scale = std::max(1.0, part.probe.cwiseAbs().maxCoeff());
  if (part.identity.value("robot", "") != model.name ||
      part.identity.value("joints", nlohmann::json::array()) != nlohmann::json(joints) ||
      part.identity.value("parameters", nlohmann::json::array()) !=
          nlohmann::json(result.base.names) ||
      probe.rows() != part.probe.rows() || probe.cols() != part.probe.cols() ||
      !((probe - part.probe).cwiseAbs().maxCoeff() <= 1e-9 * scale)) {
    throw Error("the partial result was accumulated on robot '" + part.identity.value("robot", "") +
                "' with other equations than robot '" + model.name +
                "' makes (joints, parameter set or kinematics differ); give the robot the parts "
                "were made with");
  }
  result.names = result.base.names;
  result.expressions = result.base.expressions;
  result.unidentifiable = result.base.unidentifiable_names();
  result.rank = result.base.rank;
  StreamingLeastSquares lsq = StreamingLeastSquares::from_state(part.runs.front().state);
  Eigen::Index samples = part.runs.front().samples;
  for (std::size_t i = 1; i < part.runs.size(); ++i) {
    lsq.merge(StreamingLeastSquares::from_state(part.runs[i].state));
    samples += part.runs[i].samples;
  }
  if (lsq.parameters() != result.rank || lsq.groups() != n) {
    throw Error("partial result: its state has " + std::to_string(lsq.parameters()) +
                " parameters in " + std::to_string(lsq.groups()) + " groups for " +
                std::to_string(result.rank) + " base parameters of " + std::to_string(n) +
                " joints; the part is corrupt");
  }
  if (lsq.rows() <= result.rank) {
    const std::string where = part.runs.size() == 1 ? "'" + part.runs.front().file + "'"
                                                    : std::to_string(part.runs.size()) + " runs";
    throw Error("only " + std::to_string(lsq.rows()) + " equations in " + where + " for " +
                std::to_string(result.rank) + " base parameters; record a longer run");
  }
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = result.names;
  result.estimate = options.estimator == IdentificationEstimator::kWls ? lsq.solve_weighted(eo)
                                                                       : lsq.solve_ordinary(eo);
  const bool normal = lsq.state().accumulation == Accumulation::kNormalEquations;
  result.choices.emplace_back("mode",
                              "streaming (constant memory), no filtering, dq and ddq as given");
  result.choices.emplace_back("accumulation",
                              normal ? "normal equations (column-equilibrated condition of [W y] "
                                       "within 1e5)"
                                     : "Householder QR");
  result.choices.emplace_back("covariance",
                              "white-noise sigma^2 (W^T W)^-1 (the stream keeps no residual "
                              "series for a HAC sandwich): too narrow if the residuals are "
                              "correlated; identify without --stream for intervals that allow it");
  const Eigen::VectorXd threshold = given_zero_velocity(options.signal.zero_velocity, n);
  result.zero_velocity_threshold = threshold.size() == n ? threshold : Eigen::VectorXd::Zero(n);
  result.samples = samples;
  result.rows = lsq.rows();
  result.residual_rms = result.estimate.group_rms;
  result.joint_relative_error = result.estimate.group_relative_error;
  result.relative_error = result.estimate.relative_error;
  result.condition_number = result.estimate.summary.condition_number;
  result.warnings = result.estimate.summary.warnings;
  // The stream keeps no regressor to split off unexcited columns: its data rank is the solve's
  // numerical rank (unexcited parameters keep σ = inf here; identify without --stream names them).
  result.data_rank = static_cast<int>(result.estimate.summary.rank);
  for (const StreamRun& r : part.runs) {
    const StreamingLeastSquares run_lsq = StreamingLeastSquares::from_state(r.state);
    RunSummary run;
    run.file = r.file;
    run.samples = r.samples;
    run.rows = run_lsq.rows();
    run.relative_error = run_lsq.relative_error(result.estimate.x);
    run.zero_velocity_threshold = result.zero_velocity_threshold;
    result.runs.push_back(run);
  }
  return result;
}

IdentificationResult identify_stream(const Model& model, const std::vector<std::string>& paths,
                                     const RunFileOptions& file, const IdentifyOptions& options,
                                     const StreamingIdentificationOptions& stream) {
  int threads = 0;
  StreamPartial part =
      accumulate_runs(model, paths, file, options, stream, threads, first_pass(stream));
  IdentificationResult result;
  try {
    result = solve_stream_partial(model, part);
  } catch (const NormalEquationsError& e) {
    StreamingIdentificationOptions householder = stream;
    householder.normal_equations = false;
    part = accumulate_runs(model, paths, file, options, householder, threads,
                           "second pass (Householder QR) over ");
    result = solve_stream_partial(model, part);
    for (auto& [key, value] : result.choices) {
      if (key == "accumulation") value = std::string("Householder QR, second pass: ") + e.what();
    }
  }
  result.choices.emplace_back("threads", std::to_string(threads) +
                                             " workers, each reading and parsing its own blocks of "
                                             "the file");
  return result;
}

IdentificationResult identify_stream(const Model& model, const std::string& path,
                                     const RunFileOptions& file, const IdentifyOptions& options,
                                     const StreamingIdentificationOptions& stream) {
  return identify_stream(model, std::vector<std::string>{path}, file, options, stream);
}

}  // namespace dynid
