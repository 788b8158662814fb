// The demo's whole loop (excitation optimisation, closed-loop run on a plant that integrates the
// forward dynamics, period averaging, filtering, identification) recovers the true base parameters
// of planar2 and puma560 within their 99.9 % confidence intervals (issue 5). The torques come from
// the plants, never from the regressor. With k parameters at level 0.999 the chance of more than
// one (planar2, 13) or two (puma560, 58) misses is below 1e-4, so those are the bounds.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/io/csv_reader.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/workflow/demo.hpp"

namespace dynid {
namespace {

int outside(const DemoResult& r, std::string* names = nullptr) {
  const Estimate& e = r.identification.estimate;
  int misses = 0;
  for (Eigen::Index i = 0; i < r.truth.size(); ++i) {
    if (r.truth[i] < e.ci_lower[i] || r.truth[i] > e.ci_upper[i]) {
      ++misses;
      if (names) *names += r.identification.names[i] + " ";
    }
  }
  return misses;
}

// Median over parameters of the default (HAC) σ over the white-noise σ.
double median_hac_over_white(const Estimate& e) {
  std::vector<double> r;
  for (Eigen::Index i = 0; i < e.std_dev.size(); ++i) {
    if (e.std_dev_white.size() == e.std_dev.size() && e.std_dev_white[i] > 0.0 &&
        std::isfinite(e.std_dev[i]))
      r.push_back(e.std_dev[i] / e.std_dev_white[i]);
  }
  if (r.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::nth_element(r.begin(), r.begin() + r.size() / 2, r.end());
  return r[r.size() / 2];
}

// sqrt(mean over parameters of ((x̂ − truth)/σ)²) with the default σ: about 1 when the intervals
// are calibrated, well below 1 when they are wider than the errors need.
double rms_standardised_error(const DemoResult& r) {
  const Estimate& e = r.identification.estimate;
  double sum = 0.0;
  int used = 0;
  for (Eigen::Index i = 0; i < r.truth.size(); ++i) {
    if (!(std::isfinite(e.std_dev[i]) && e.std_dev[i] > 0.0)) continue;
    const double z = (e.x[i] - r.truth[i]) / e.std_dev[i];
    sum += z * z;
    ++used;
  }
  return used ? std::sqrt(sum / used) : 0.0;
}

DemoResult demo(const std::string& robot, bool mujoco, unsigned seed) {
  DemoOptions o;
  o.robot = robot;
  o.mujoco = mujoco;
  o.seed = seed;
  o.out_dir = ::testing::TempDir() + "/demo_" + robot + (mujoco ? "_mujoco_" : "_native_") +
              std::to_string(seed);
  return run_demo(o, [](const std::string&) {});
}

// Runs the demo for each seed; at most `max_outside` truths may lie outside their intervals.
std::vector<DemoResult> expect_truth_inside(const std::string& robot, bool mujoco,
                                            std::initializer_list<unsigned> seeds,
                                            Eigen::Index parameters, int max_outside) {
  std::vector<DemoResult> results;
  for (unsigned seed : seeds) {
    results.push_back(demo(robot, mujoco, seed));
    const DemoResult& r = results.back();
    EXPECT_EQ(r.truth.size(), parameters);
    std::string missed;
    EXPECT_LE(outside(r, &missed), max_outside) << robot << " seed " << seed << ": " << missed;
    std::printf("%s seed %u: median HAC/white sigma %.2f, rms (estimate - truth)/sigma %.2f\n",
                robot.c_str(), seed, median_hac_over_white(r.identification.estimate),
                rms_standardised_error(r));
    // "Truth inside" would be vacuous if the default intervals were much wider than the errors:
    // calibrated intervals give an rms near 1; measured 0.37-0.59 (planar2's HAC intervals are
    // ~2.8x the white ones on a filtered residual with lag-1 0.86-0.91, and wider than its errors
    // need), so 0.3 fails when they grow by a further ~25 % or more.
    EXPECT_GT(rms_standardised_error(r), 0.3) << robot << " seed " << seed;
    EXPECT_TRUE(r.excitation.constraints_satisfied);
  }
  return results;
}

TEST(DemoPipeline, Planar2RecoversTheTruthWithinItsIntervals) {
  for (const DemoResult& r : expect_truth_inside("planar2", false, {7u, 11u}, 13, 1)) {
    EXPECT_LT(r.identification.relative_error, 0.005);
  }
}

TEST(DemoPipeline, Puma560OnMujocoRecoversTheTruthWithinItsIntervals) {
  for (const DemoResult& r : expect_truth_inside("puma560", true, {7u, 3u}, 58, 2)) {
    EXPECT_LT(r.validation.relative_error_all, 0.02);
  }
}

// Negative control: the same averaged planar2 run identified without the half-sample torque
// alignment is biased. Its white intervals miss most truths; the default (HAC) ones widen with the
// misalignment's slow residual instead of missing, so the defect must show in the result itself:
// a HAC/white ratio far above the aligned run's and the correlated-residual warning. Either way
// the tests above can fail.
TEST(DemoPipeline, WithoutTorqueAlignmentTheIntervalsMissTheTruth) {
  const DemoResult r = demo("planar2", false, 7);
  const CsvTable avg = read_csv(::testing::TempDir() + "/demo_planar2_native_7/averaged.csv");
  const Eigen::Index P = avg.rows();
  JointRecord rec;
  rec.q.resize(3 * P, 2);
  rec.tau.resize(3 * P, 2);
  const Eigen::MatrixXd q = avg.data.middleCols(1, 2), tau = avg.data.middleCols(3, 2);
  rec.q << q, q, q;
  rec.tau << tau, tau, tau;
  rec.t = Eigen::VectorXd::LinSpaced(3 * P, 0.0, (3 * P - 1) / 1000.0);
  IdentifyOptions io;
  io.signal.trim = static_cast<int>(P);
  io.signal.cutoff_hz = 20.0;
  io.signal.filter_coulomb_columns = true;
  io.signal.zero_velocity = {0.05 * 1.5, 0.05 * 1.5};
  io.signal.torque_time_offset = 0.5e-3;
  const IdentificationResult aligned = identify(load_robot("planar2"), rec, io);
  io.signal.torque_time_offset = 0.0;
  const IdentificationResult raw = identify(load_robot("planar2"), rec, io);
  int aligned_out = 0, raw_white_out = 0;
  for (Eigen::Index i = 0; i < r.truth.size(); ++i) {
    aligned_out +=
        r.truth[i] < aligned.estimate.ci_lower[i] || r.truth[i] > aligned.estimate.ci_upper[i];
    raw_white_out +=
        r.truth[i] < raw.estimate.ci_lower_white[i] || r.truth[i] > raw.estimate.ci_upper_white[i];
  }
  const double aligned_ratio = median_hac_over_white(aligned.estimate);
  const double raw_ratio = median_hac_over_white(raw.estimate);
  std::printf("median HAC/white sigma: aligned %.2f, misaligned %.2f; white misses %d\n",
              aligned_ratio, raw_ratio, raw_white_out);
  EXPECT_LE(aligned_out, 1);
  EXPECT_GE(raw_white_out, 5);
  EXPECT_GT(raw_ratio, 3.0);
  EXPECT_GT(raw_ratio, 1.5 * aligned_ratio);
  bool warned = false;
  for (const std::string& w : raw.estimate.summary.warnings) {
    warned = warned || w.find("correlated") != std::string::npos;
  }
  EXPECT_TRUE(warned);
}

}  // namespace
}  // namespace dynid
