// Report generation for a 10^5-sample, 6-joint run (issue 15 item 7: aim <= 1 s, file <= 5 MB):
// the plot section identify and validate store (decimated torques, residual histograms over every
// sample) and the HTML page made from a result holding it. The counter `bytes` is the page size.
// Run: ./build/bench/report_bench
#include <random>

#include <benchmark/benchmark.h>

#include "dynid/report/html_report.hpp"

namespace {

constexpr int kSamples = 100000, kJoints = 6, kParameters = 60;

struct Run {
  Eigen::VectorXd t;
  Eigen::MatrixXd measured, predicted;
  std::vector<std::string> names;
};

const Run& run() {
  static const Run r = [] {
    Run out;
    out.t = Eigen::VectorXd::LinSpaced(kSamples, 0.0, (kSamples - 1) / 1000.0);
    out.measured.resize(kSamples, kJoints);
    out.predicted.resize(kSamples, kJoints);
    std::mt19937 rng(3);
    std::normal_distribution<double> noise(0.0, 0.2);
    for (int j = 0; j < kJoints; ++j) {
      out.names.push_back("joint" + std::to_string(j + 1));
      for (int k = 0; k < kSamples; ++k) {
        out.predicted(k, j) = 10.0 * std::sin(0.2 * (j + 1) * out.t(k));
        out.measured(k, j) = out.predicted(k, j) + noise(rng);
      }
    }
    return out;
  }();
  return r;
}

// An identify result as identification_to_json writes it, with the plot section.
nlohmann::json identify_result() {
  const Run& r = run();
  nlohmann::json params = nlohmann::json::array();
  for (int i = 0; i < kParameters; ++i) {
    const double v = 1.0 + i, s = 0.01 * (i + 1);
    params.push_back({{"name", "P" + std::to_string(i)},
                      {"value", v},
                      {"std", s},
                      {"relative_std_percent", 100.0 * s / v},
                      {"ci_low", v - 3.3 * s},
                      {"ci_high", v + 3.3 * s}});
  }
  return {{"model", {{"name", "bench"}, {"joints", r.names}}},
          {"parameters", params},
          {"rank", kParameters},
          {"data_rank", kParameters},
          {"condition_number", 100.0},
          {"samples", kSamples},
          {"rows", kSamples * kJoints},
          {"residual_rms", std::vector<double>(kJoints, 0.2)},
          {"joint_relative_error", std::vector<double>(kJoints, 0.03)},
          {"relative_error", 0.03},
          {"plot", dynid::prediction_plot_json(r.t, r.measured, r.predicted, r.names)}};
}

void BM_PlotSection(benchmark::State& state) {
  const Run& r = run();
  for (auto _ : state) {
    benchmark::DoNotOptimize(dynid::prediction_plot_json(r.t, r.measured, r.predicted, r.names));
  }
}
BENCHMARK(BM_PlotSection)->Unit(benchmark::kMillisecond);

// identify --report: the plot section and the page.
void BM_IdentifyReport(benchmark::State& state) {
  std::size_t bytes = 0;
  for (auto _ : state) {
    const std::string html = dynid::html_report({{"result.json", identify_result()}}, {});
    bytes = html.size();
    benchmark::DoNotOptimize(html.data());
  }
  state.counters["bytes"] = static_cast<double>(bytes);
}
BENCHMARK(BM_IdentifyReport)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
