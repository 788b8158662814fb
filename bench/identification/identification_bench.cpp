// End-to-end identification throughput (CSV file → result) of the 7-DoF iiwa14 in streaming mode,
// and its peak memory, for 10⁵ and 10⁶ samples (issue 4 item 7). The run file is generated once
// per size in the temporary folder (joint-side t, q, dq, ddq, tau; torques from rnea + noise).
// BM_IdentifyBatch: batch identify() of in-memory runs of 10⁴…2·10⁵ samples (issue 30 item 1).
// Run: ./build/bench/identification_bench
#include <sys/resource.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/identification/streaming_identification.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/model/robots.hpp"

namespace {

// The benchmark run's joint-side state at sample k (1 kHz): one sine per joint, 0.4-1.6 rad/s.
void bench_state(long k, Eigen::VectorXd& q, Eigen::VectorXd& dq, Eigen::VectorXd& ddq) {
  const double t = 1e-3 * static_cast<double>(k);
  for (Eigen::Index j = 0; j < q.size(); ++j) {
    const double w = 0.4 + 0.2 * static_cast<double>(j);
    q[j] = 0.8 * std::sin(w * t + static_cast<double>(j));
    dq[j] = 0.8 * w * std::cos(w * t + static_cast<double>(j));
    ddq[j] = -0.8 * w * w * std::sin(w * t + static_cast<double>(j));
  }
}

// Samples per second and the process's peak memory so far (kB on Linux).
void throughput_counters(benchmark::State& st, long samples) {
  st.counters["samples_per_s"] = benchmark::Counter(static_cast<double>(samples),
                                                    benchmark::Counter::kIsIterationInvariantRate);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  st.counters["peak_rss_MiB"] = usage.ru_maxrss / 1024.0;
}

std::string run_file(const dynid::Model& model, long samples) {
  const std::string path = (std::filesystem::temp_directory_path() /
                            ("dynid_bench_iiwa14_" + std::to_string(samples) + ".csv"))
                               .string();
  if (std::filesystem::exists(path)) return path;
  const int n = model.dof();
  std::vector<std::string> cols = {"t"};
  for (const char* p : {"q", "dq", "ddq", "tau"})
    for (int j = 0; j < n; ++j) cols.push_back(p + std::to_string(j + 1));
  const long chunk = 100000;
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.2);
  dynid::Workspace ws(model);
  Eigen::VectorXd q(n), dq(n), ddq(n), tau(n);
  std::FILE* f = std::fopen((path + ".tmp").c_str(), "w");
  for (size_t c = 0; c < cols.size(); ++c) std::fprintf(f, "%s%s", c ? "," : "", cols[c].c_str());
  std::fprintf(f, "\n");
  Eigen::MatrixXd data(chunk, 1 + 4 * n);
  for (long k0 = 0; k0 < samples; k0 += chunk) {
    const long m = std::min(chunk, samples - k0);
    for (long k = 0; k < m; ++k) {
      const double t = 1e-3 * static_cast<double>(k0 + k);
      bench_state(k0 + k, q, dq, ddq);
      dynid::rnea(model, ws, q, dq, ddq, tau);
      for (int j = 0; j < n; ++j) tau[j] += noise(rng);
      data.row(k) << t, q.transpose(), dq.transpose(), ddq.transpose(), tau.transpose();
    }
    std::string text = dynid::format_csv(cols, data.topRows(m));
    const size_t header_end = text.find('\n') + 1;
    std::fwrite(text.data() + header_end, 1, text.size() - header_end, f);
  }
  std::fclose(f);
  std::filesystem::rename(path + ".tmp", path);
  return path;
}

void BM_IdentifyStream(benchmark::State& st) {
  const dynid::Model model = dynid::load_robot("iiwa14");
  const long samples = st.range(0);
  const std::string path = run_file(model, samples);
  dynid::IdentifyOptions o;
  o.signal.filter = false;
  const dynid::StreamingIdentificationOptions so{static_cast<int>(st.range(1)), st.range(2) != 0,
                                                 static_cast<std::size_t>(st.range(3)) << 10};
  for (auto _ : st) {
    const auto r = dynid::identify_stream(model, path, {}, o, so);
    benchmark::DoNotOptimize(r.estimate.x.data());
  }
  throughput_counters(st, samples);
  st.counters["file_MiB"] = std::filesystem::file_size(path) / 1048576.0;
}

// Batch identify() of an in-memory run of `samples` (the data of BM_IdentifyStream, --filter
// none): issue 30 item 1, linear in the samples once the HAC meat is
// (bartlett_long_run_covariance).
void BM_IdentifyBatch(benchmark::State& st) {
  const dynid::Model model = dynid::load_robot("iiwa14");
  const long samples = st.range(0);
  const int n = model.dof();
  dynid::JointRecord r;
  r.t.resize(samples);
  r.q.resize(samples, n);
  r.dq.resize(samples, n);
  r.ddq.resize(samples, n);
  r.tau.resize(samples, n);
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.2);
  dynid::Workspace ws(model);
  Eigen::VectorXd q(n), dq(n), ddq(n), tau(n);
  for (long k = 0; k < samples; ++k) {
    bench_state(k, q, dq, ddq);
    dynid::rnea(model, ws, q, dq, ddq, tau);
    for (int j = 0; j < n; ++j) tau[j] += noise(rng);
    r.t[k] = 1e-3 * static_cast<double>(k);
    r.q.row(k) = q.transpose();
    r.dq.row(k) = dq.transpose();
    r.ddq.row(k) = ddq.transpose();
    r.tau.row(k) = tau.transpose();
  }
  dynid::IdentifyOptions o;
  o.signal.filter = false;
  for (auto _ : st) {
    const auto result = dynid::identify(model, r, o);
    benchmark::DoNotOptimize(result.estimate.x.data());
  }
  throughput_counters(st, samples);
}

}  // namespace

BENCHMARK(BM_IdentifyBatch)
    ->ArgName("samples")
    ->Arg(10000)
    ->Arg(20000)
    ->Arg(50000)
    ->Arg(100000)
    ->Arg(200000)
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

// Arguments: samples, worker threads, normal equations (1) or Householder (0) accumulation, KiB
// of the file per block (StreamingIdentificationOptions::block_bytes; 256 is the default).
BENCHMARK(BM_IdentifyStream)
    ->ArgNames({"samples", "threads", "normal_equations", "block_KiB"})
    ->Args({100000, 1, 0, 256})
    ->Args({100000, 1, 1, 256})
    ->Args({100000, 2, 1, 256})
    ->Args({1000000, 1, 1, 256})
    ->Args({1000000, 2, 1, 256})
    ->Args({1000000, 2, 1, 64})
    ->Args({1000000, 2, 1, 1024})
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

BENCHMARK_MAIN();
