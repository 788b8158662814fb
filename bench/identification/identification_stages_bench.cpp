// Where the CPU time of streaming identification goes (issue 16 item 3; `perf record -e cpu-clock`
// on the whole `dynid identify --stream` gives the shares, docs/performance.md): the per-sample
// stages of `dynid identify --stream` for the 7-DoF iiwa14, full layout (98 columns, 69 base), each
// timed alone on the same 4096 samples (one chunk):
//   CsvBlocks     CsvBlockReader::parse of every block of the file of those samples, as one
//                 worker of identify_stream does (pread, cut lines, parse into a row-major block)
//   CsvParse      CsvChunkReader::parse_text of the 29-column text (t, q, dq, ddq, tau) into a
//                 row-major block: the parse alone, of text already in memory
//   Regressor     torque_regressor, one call per sample
//   Accumulate    per joint: StreamingLeastSquares::add_row_gathered of its base columns out of
//                 the regressor's storage, normal equations, per-joint column subsets (as
//                 identify_stream, without its structural-zero check)
// Figures are per chunk; divide by 4096 for the cost per sample.
// Run: ./build/bench/identification_stages_bench --benchmark_repetitions=3
//      --benchmark_report_aggregates_only=true
#include <cstdio>
#include <filesystem>
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/estimation/streaming_least_squares.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/io/csv_chunk_reader.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/regressor/torque_regressor.hpp"

namespace {

constexpr int kSamples = 4096;

struct Run {
  dynid::Model model = dynid::load_robot("iiwa14");
  dynid::ParameterLayout layout = dynid::ParameterLayout::full();
  dynid::BaseParameters base;
  Eigen::MatrixXd q, dq, ddq, tau;                       // n × samples
  std::vector<std::vector<Eigen::Index>> joint_columns;  // base columns a joint's row can reach
  std::string csv;

  Run() {
    dynid::BaseParameterOptions bo;
    bo.layout = layout;
    base = dynid::compute_base_parameters(model, bo);
    const int n = model.dof();
    q.resize(n, kSamples);
    dq.resize(n, kSamples);
    ddq.resize(n, kSamples);
    tau.resize(n, kSamples);
    std::mt19937 rng(1);
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    dynid::Workspace ws(model);
    std::vector<std::string> cols = {"t"};
    for (const char* p : {"q", "dq", "ddq", "tau"})
      for (int j = 0; j < n; ++j) cols.push_back(p + std::to_string(j + 1));
    Eigen::MatrixXd data(kSamples, 1 + 4 * n);
    Eigen::MatrixXd Y(n, layout.columns(n));
    std::vector<std::vector<char>> seen(n, std::vector<char>(base.rank, 0));
    for (int k = 0; k < kSamples; ++k) {
      for (int j = 0; j < n; ++j) {
        q(j, k) = u(rng);
        dq(j, k) = u(rng);
        ddq(j, k) = u(rng);
      }
      Eigen::VectorXd t(n);
      dynid::rnea(model, ws, q.col(k), dq.col(k), ddq.col(k), t);
      tau.col(k) = t;
      data.row(k) << 1e-3 * k, q.col(k).transpose(), dq.col(k).transpose(), ddq.col(k).transpose(),
          t.transpose();
      if (k < 8) {  // the sparsity of each joint's row, probed at random states
        dynid::torque_regressor(model, ws, layout, q.col(k), dq.col(k), ddq.col(k), Y);
        for (int j = 0; j < n; ++j)
          for (int c = 0; c < base.rank; ++c) seen[j][c] |= Y(j, base.base[c]) != 0.0;
      }
    }
    joint_columns.resize(n);
    for (int j = 0; j < n; ++j)
      for (int c = 0; c < base.rank; ++c)
        if (seen[j][c]) joint_columns[j].push_back(c);
    csv = (std::filesystem::temp_directory_path() / "dynid_stages_bench.csv").string();
    dynid::write_csv(csv, cols, data);
  }
};

const Run& run() {
  static const Run r;
  return r;
}

void BM_StageCsvBlocks(benchmark::State& st) {
  const Run& r = run();
  const dynid::CsvBlockReader reader(r.csv);
  dynid::CsvBlock block;
  for (auto _ : st) {
    for (std::int64_t b = 0; b < reader.blocks(); ++b) {
      reader.parse(b, block);
      benchmark::DoNotOptimize(block.rows.data());
    }
  }
  st.counters["ns_per_sample"] = benchmark::Counter(
      kSamples * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_StageCsvParse(benchmark::State& st) {
  const Run& r = run();
  dynid::CsvChunkReader reader(r.csv);
  dynid::CsvTextChunk chunk;
  reader.next_text(chunk);  // the whole file is one chunk
  dynid::CsvChunkReader::RowBlock block;
  for (auto _ : st) {
    reader.parse_text(chunk, block);
    benchmark::DoNotOptimize(block.data());
  }
  st.counters["ns_per_sample"] = benchmark::Counter(
      kSamples * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_StageRegressor(benchmark::State& st) {
  const Run& r = run();
  const int n = r.model.dof();
  dynid::Workspace ws(r.model);
  Eigen::MatrixXd Y(n, r.layout.columns(n));
  for (auto _ : st) {
    for (int k = 0; k < kSamples; ++k) {
      dynid::torque_regressor(r.model, ws, r.layout, r.q.col(k), r.dq.col(k), r.ddq.col(k), Y);
      benchmark::DoNotOptimize(Y.data());
    }
  }
  st.counters["ns_per_sample"] = benchmark::Counter(
      kSamples * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_StageAccumulate(benchmark::State& st) {
  const Run& r = run();
  const int n = r.model.dof();
  dynid::Workspace ws(r.model);
  Eigen::MatrixXd Y(n, r.layout.columns(n));
  // One regressor per sample is computed outside the timed region and reused for every chunk.
  std::vector<Eigen::MatrixXd> Ys(kSamples);
  for (int k = 0; k < kSamples; ++k) {
    dynid::torque_regressor(r.model, ws, r.layout, r.q.col(k), r.dq.col(k), r.ddq.col(k), Y);
    Ys[k] = Y;
  }
  dynid::StreamingOptions o;
  o.accumulation = dynid::Accumulation::kNormalEquations;
  o.group_columns = r.joint_columns;
  dynid::StreamingLeastSquares lsq(r.base.rank, n, o);
  std::vector<std::vector<Eigen::Index>> offsets(n);  // entry (j, c) of Y at c·n + j
  for (int j = 0; j < n; ++j)
    for (Eigen::Index c : r.joint_columns[j]) offsets[j].push_back(r.base.base[c] * n + j);
  for (auto _ : st) {
    for (int k = 0; k < kSamples; ++k) {
      for (int j = 0; j < n; ++j) lsq.add_row_gathered(j, Ys[k].data(), offsets[j], r.tau(j, k));
    }
  }
  st.counters["ns_per_sample"] = benchmark::Counter(
      kSamples * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_StageCsvBlocks)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StageCsvParse)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StageRegressor)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_StageAccumulate)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();
