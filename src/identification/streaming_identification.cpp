#include "dynid/identification/streaming_identification.hpp"

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

// Base columns (indices into base.base) that can be non-zero in each joint's torque row: the links
// of the joint's subtree and the joint's own friction. Probed numerically at random states, since
// an analytic function that vanishes at random points vanishes everywhere.
std::vector<std::vector<Eigen::Index>> joint_base_columns(const Model& model,
                                                          const ParameterLayout& layout,
                                                          const BaseParameters& base) {
  const int n = model.dof();
  Workspace ws(model);
  Eigen::MatrixXd Y(n, layout.columns(n));
  Eigen::VectorXd q(n), dq(n), ddq(n);
  std::mt19937 rng(kSparsitySeed);
  std::uniform_real_distribution<double> angle(-3.0, 3.0), speed(0.2, 2.0);
  std::vector<std::vector<char>> seen(n, std::vector<char>(base.rank, 0));
  for (int probe = 0; probe < kSparsityProbes; ++probe) {
    for (int j = 0; j < n; ++j) {
      q[j] = angle(rng);
      dq[j] = (probe % 2 == 0 ? 1.0 : -1.0) * speed(rng);
      ddq[j] = angle(rng);
    }
    torque_regressor(model, ws, layout, q, dq, ddq, Y);
    for (int j = 0; j < n; ++j)
      for (int c = 0; c < base.rank; ++c) seen[j][c] |= Y(j, base.base[c]) != 0.0;
  }
  std::vector<std::vector<Eigen::Index>> columns(n);
  for (int j = 0; j < n; ++j)
    for (int c = 0; c < base.rank; ++c)
      if (seen[j][c]) columns[j].push_back(c);
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

}  // namespace

IdentificationResult identify_stream(const Model& model, const std::string& path,
                                     const RunFileOptions& file, const IdentifyOptions& options,
                                     const StreamingIdentificationOptions& stream) {
  if (options.signal.filter) {
    throw UsageError(
        "streaming identification reads the file once and cannot filter it; use "
        "--filter none with dq and ddq columns, or drop --stream");
  }
  if (options.estimator == IdentificationEstimator::kRls) {
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
  const int n = model.dof();
  IdentificationResult result;
  BaseParameterOptions base_options = options.base;
  base_options.layout = options.layout;
  result.base = compute_base_parameters(model, base_options);
  result.names = result.base.names;
  result.expressions = result.base.expressions;
  result.unidentifiable = result.base.unidentifiable_names();
  result.rank = result.base.rank;
  const int rank = result.rank;

  StreamSetup s;
  s.model = &model;
  s.layout = &options.layout;
  s.base = &result.base;
  s.path = path;
  s.block_bytes = stream.block_bytes;
  {
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
  s.threshold = given_zero_velocity(options.signal.zero_velocity, n);
  if (s.threshold.size() == 0) s.threshold = Eigen::VectorXd::Zero(n);  // no automatic rule here
  s.active = joint_base_columns(model, options.layout, result.base);
  s.active_offset.resize(n);
  s.inactive_offset.resize(n);
  for (int j = 0; j < n; ++j) {
    for (Eigen::Index c = 0, a = 0; c < rank; ++c) {
      const bool active = a < static_cast<Eigen::Index>(s.active[j].size()) && s.active[j][a] == c;
      (active ? s.active_offset[j] : s.inactive_offset[j]).push_back(result.base.base[c] * n + j);
      a += active;
    }
  }
  int threads =
      stream.threads > 0
          ? std::min(stream.threads, kMaxThreads)
          : std::clamp(static_cast<int>(std::thread::hardware_concurrency()), 1, kMaxThreads);
  StreamingOptions lsq_options;
  lsq_options.group_columns = s.active;
  lsq_options.accumulation =
      stream.normal_equations ? Accumulation::kNormalEquations : Accumulation::kHouseholder;

  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = result.names;
  const auto solve = [&](const StreamingLeastSquares& lsq) {
    if (lsq.rows() <= rank) {
      throw Error("only " + std::to_string(lsq.rows()) + " equations in '" + path + "' for " +
                  std::to_string(rank) + " base parameters; record a longer run");
    }
    return options.estimator == IdentificationEstimator::kWls ? lsq.solve_weighted(eo)
                                                              : lsq.solve_ordinary(eo);
  };
  Eigen::Index samples = 0;
  StreamingLeastSquares lsq =
      accumulate(s, lsq_options, threads, samples, options.progress, "reading " + path);
  std::string accumulation = stream.normal_equations
                                 ? "normal equations (column-equilibrated condition of [W y] "
                                   "within 1e5)"
                                 : "Householder QR";
  try {
    result.estimate = solve(lsq);
  } catch (const NormalEquationsError& e) {
    lsq_options.accumulation = Accumulation::kHouseholder;
    lsq = accumulate(s, lsq_options, threads, samples, options.progress,
                     "second pass (Householder QR) over " + path);
    result.estimate = solve(lsq);
    accumulation = std::string("Householder QR, second pass: ") + e.what();
  }
  result.choices.emplace_back("mode",
                              "streaming (constant memory), no filtering, dq and ddq as given");
  result.choices.emplace_back("accumulation", accumulation);
  result.choices.emplace_back("threads", std::to_string(threads) +
                                             " workers, each reading and parsing its own blocks of "
                                             "the file");
  result.zero_velocity_threshold = s.threshold;
  result.choices.emplace_back("covariance",
                              "white-noise sigma^2 (W^T W)^-1 (the stream keeps no residual "
                              "series for a HAC sandwich): too narrow if the residuals are "
                              "correlated; identify without --stream for intervals that allow it");
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
  RunSummary run;
  run.file = path;
  run.samples = samples;
  run.rows = result.rows;
  run.relative_error = result.relative_error;
  run.zero_velocity_threshold = s.threshold;
  result.runs.push_back(run);
  return result;
}

}  // namespace dynid
