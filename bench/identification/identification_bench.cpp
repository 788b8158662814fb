// End-to-end identification throughput (CSV file → result) of the 7-DoF iiwa14 in streaming mode,
// and its peak memory, for 10⁵ and 10⁶ samples (issue 4 item 7). The run file is generated once
// per size in the temporary folder (joint-side t, q, dq, ddq, tau; torques from rnea + noise).
// Run: ./build/bench/identification_bench
#include <sys/resource.h>

#include <cstdio>
#include <filesystem>
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/identification/streaming_identification.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/model/robots.hpp"

namespace {

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
      const double t = 1e-3 * (k0 + k);
      for (int j = 0; j < n; ++j) {
        const double w = 0.4 + 0.2 * j;
        q[j] = 0.8 * std::sin(w * t + j);
        dq[j] = 0.8 * w * std::cos(w * t + j);
        ddq[j] = -0.8 * w * w * std::sin(w * t + j);
      }
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
  st.counters["samples_per_s"] = benchmark::Counter(static_cast<double>(samples),
                                                    benchmark::Counter::kIsIterationInvariantRate);
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  st.counters["peak_rss_MiB"] = usage.ru_maxrss / 1024.0;  // process peak so far (kB on Linux)
  st.counters["file_MiB"] = std::filesystem::file_size(path) / 1048576.0;
}

}  // namespace

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
