#include "dynid/io/streaming_identification.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <condition_variable>
#include <cstdint>
#include <cstring>
#include <exception>
#include <filesystem>
#include <mutex>
#include <random>
#include <thread>

#include "dynid/common/error.hpp"
#include "dynid/estimation/streaming_least_squares.hpp"
#include "dynid/io/csv_chunk_reader.hpp"
#include "dynid/regressor/torque_regressor.hpp"

namespace dynid {

namespace {

// Random states at which the sparsity of the base regressor is probed; velocities alternate in
// sign so that one-sided (asymmetric Coulomb) columns are seen as well.
constexpr int kSparsityProbes = 8;
constexpr unsigned kSparsitySeed = 20261123;
// Upper bound on worker threads (each holds kQueueDepth chunks of text in memory).
constexpr int kMaxThreads = 8;
// Chunks queued per worker: enough to keep a worker busy while the reader serves the others.
constexpr std::size_t kQueueDepth = 3;

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

// Everything one worker needs to turn a chunk of samples into accumulated rows.
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
  CsvChunkReader::RowBlock block;  // the chunk being processed, parsed by this worker
  // Ring of chunks handed over by the reader, unparsed: [head, tail) are filled, in order.
  std::mutex mutex;
  std::condition_variable cv;
  std::array<CsvTextChunk, kQueueDepth> chunks;
  std::size_t head = 0, tail = 0;
  bool done = false;
  std::exception_ptr error;
  Eigen::Index error_block = -1;
};

// The per-run constants shared read-only by the workers.
struct StreamSetup {
  const Model* model = nullptr;
  const ParameterLayout* layout = nullptr;
  const BaseParameters* base = nullptr;
  std::string path;
  std::vector<std::vector<Eigen::Index>> active;  // base columns per joint
  // The same as offsets into a worker's n-row regressor storage (regressor column·n + joint), and
  // the other base columns, checked to be zero: the per-sample gather and check read Y with one
  // index and no multiplication.
  std::vector<std::vector<Eigen::Index>> active_offset, inactive_offset;
  std::vector<Eigen::Index> cq, cdq, cddq, ctau;
  Eigen::VectorXd threshold;
};

void process_block(const StreamSetup& s, Worker& w, const CsvChunkReader::RowBlock& block,
                   Eigen::Index first_row) {
  const Model& model = *s.model;
  const int n = model.dof();
  for (Eigen::Index k = 0; k < block.rows(); ++k) {
    // The CSV reader has already refused NaN and Inf fields, naming the line.
    for (int j = 0; j < n; ++j) {
      w.q[j] = block(k, s.cq[j]);
      w.dq[j] = block(k, s.cdq[j]);
      w.ddq[j] = block(k, s.cddq[j]);
    }
    torque_regressor(model, w.ws, *s.layout, w.q, w.dq, w.ddq, w.Y);
    const double* y = w.Y.data();
    for (int j = 0; j < n; ++j) {
      if (std::abs(w.dq[j]) < s.threshold[j]) continue;
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
        throw Error("internal: the regressor of joint " + model.joints[j].name +
                    " is non-zero in a column probed as structurally zero (data row " +
                    std::to_string(first_row + k + 1) + "); run without --stream and report it");
      }
      w.lsq.add_row_gathered(j, y, s.active_offset[j], block(k, s.ctau[j]));
    }
  }
}

// Reads the file once and accumulates every chunk; chunk k is processed by worker k mod W. The
// reader thread only cuts lines; each worker parses its own chunks, so the parse runs on every
// core instead of bounding the rate from one thread.
// Returns the merged accumulator. The first error in file order is rethrown after all threads
// have stopped, so no thread outlives the call. `progress` (may be empty) is told the fraction of
// the file's bytes cut so far, from this (the calling) thread only, so that a caller's progress
// line needs no lock.
StreamingLeastSquares accumulate(const StreamSetup& s, const StreamingOptions& lsq_options,
                                 int threads, Eigen::Index& samples,
                                 const ProgressCallback& progress, const std::string& what) {
  const int rank = s.base->rank;
  // Bytes of the data lines cut so far (text plus one terminator each; the header and comments
  // are not counted, so the fraction ends a little below 1) over the file size.
  std::error_code size_error;
  const auto file_bytes = std::filesystem::file_size(s.path, size_error);
  double cut_bytes = 0.0;
  const auto tell = [&](const CsvTextChunk& chunk) {
    if (!progress || size_error || file_bytes == 0) return;
    cut_bytes += static_cast<double>(chunk.text.size() + chunk.ends.size());
    progress(std::min(1.0, cut_bytes / static_cast<double>(file_bytes)), what);
  };
  std::vector<std::unique_ptr<Worker>> workers;
  for (int t = 0; t < threads; ++t) {
    workers.push_back(std::make_unique<Worker>(*s.model, *s.layout, rank, lsq_options));
  }
  CsvChunkReader reader(s.path);
  samples = 0;
  if (threads == 1) {
    Worker& w = *workers[0];
    while (reader.next_text(w.chunks[0])) {
      tell(w.chunks[0]);
      reader.parse_text(w.chunks[0], w.block);
      process_block(s, w, w.block, samples);
      samples += w.block.rows();
    }
    return std::move(w.lsq);
  }

  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t) {
    pool.emplace_back([&s, &reader, &w = *workers[t], t, threads] {
      for (Eigen::Index index = t;; index += threads) {
        std::unique_lock<std::mutex> lock(w.mutex);
        w.cv.wait(lock, [&w] { return w.head != w.tail || w.done; });
        if (w.head == w.tail) return;
        const CsvTextChunk& chunk = w.chunks[w.head % kQueueDepth];
        const bool failed = static_cast<bool>(w.error);
        lock.unlock();  // the reader only touches other slots while this one is in use
        if (!failed) {
          try {
            reader.parse_text(chunk, w.block);
            process_block(s, w, w.block, chunk.first_row);
          } catch (...) {
            lock.lock();
            w.error = std::current_exception();
            w.error_block = index;
            lock.unlock();
          }
        }
        lock.lock();
        ++w.head;
        lock.unlock();
        w.cv.notify_all();
      }
    });
  }
  std::exception_ptr reader_error;
  Eigen::Index index = 0;
  try {
    CsvTextChunk chunk;
    while (reader.next_text(chunk)) {
      tell(chunk);
      Worker& w = *workers[index % threads];
      std::unique_lock<std::mutex> lock(w.mutex);
      w.cv.wait(lock, [&w] { return w.tail - w.head < kQueueDepth; });
      if (w.error) break;
      const Eigen::Index rows = chunk.rows();
      std::swap(w.chunks[w.tail % kQueueDepth], chunk);  // both keep their storage
      ++w.tail;
      lock.unlock();
      w.cv.notify_all();
      samples += rows;
      ++index;
    }
  } catch (...) {
    reader_error = std::current_exception();
  }
  for (auto& w : workers) {
    {
      std::lock_guard<std::mutex> lock(w->mutex);
      w->done = true;
    }
    w->cv.notify_all();
  }
  for (auto& t : pool) t.join();
  // The earliest failing chunk decides which error the user sees.
  std::exception_ptr first = reader_error;
  Eigen::Index first_block = reader_error ? index : -1;
  for (auto& w : workers) {
    if (w->error && (first_block < 0 || w->error_block < first_block)) {
      first = w->error;
      first_block = w->error_block;
    }
  }
  if (first) std::rethrow_exception(first);
  for (int t = 1; t < threads; ++t) workers[0]->lsq.merge(workers[t]->lsq);
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
    reject("--torque-offset", "re-interpolating the torques needs the whole record");
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
  const int threads =
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
  result.choices.emplace_back("threads", std::to_string(threads) + " workers + 1 reader");
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
