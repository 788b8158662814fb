#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/io/streaming_identification.hpp"
#include "dynid/model/robots.hpp"

namespace dynid {
namespace {

// A puma560 run with noisy torques written as CSV; streaming (chunked, constant memory) and
// in-memory identification must give the same estimate and statistics.
std::string write_run(const Model& model, int samples) {
  std::mt19937 rng(9);
  std::normal_distribution<double> noise(0.0, 0.3);
  const int n = model.dof();
  std::vector<std::string> cols = {"t"};
  for (const char* p : {"q", "dq", "ddq", "tau"})
    for (int j = 0; j < n; ++j) cols.push_back(p + std::to_string(j + 1));
  Eigen::MatrixXd data(samples, 1 + 4 * n);
  Workspace ws(model);
  Eigen::VectorXd q(n), dq(n), ddq(n), tau(n);
  for (int k = 0; k < samples; ++k) {
    const double t = 0.01 * k;
    for (int j = 0; j < n; ++j) {
      const double w = 0.5 + 0.3 * j;
      q[j] = std::sin(w * t + j) + 0.3 * std::sin(3 * w * t);
      dq[j] = w * std::cos(w * t + j) + 0.9 * w * std::cos(3 * w * t);
      ddq[j] = -w * w * std::sin(w * t + j) - 2.7 * w * w * std::sin(3 * w * t);
    }
    rnea(model, ws, q, dq, ddq, tau);
    for (int j = 0; j < n; ++j) tau[j] += noise(rng);
    data.row(k) << t, q.transpose(), dq.transpose(), ddq.transpose(), tau.transpose();
  }
  const std::string path = ::testing::TempDir() + "/stream_run.csv";
  write_csv(path, cols, data);
  return path;
}

TEST(StreamingIdentification, EqualsInMemoryIdentification) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 3000);
  IdentifyOptions o;
  o.signal.filter = false;
  o.signal.zero_velocity = {0.05};
  for (auto estimator : {IdentificationEstimator::kOls, IdentificationEstimator::kWls}) {
    o.estimator = estimator;
    const IdentificationResult s = identify_stream(model, path, {}, o);
    const IdentificationResult m = identify(model, read_joint_record(path, model), o);
    ASSERT_EQ(s.names, m.names);
    EXPECT_EQ(s.rows, m.rows);
    EXPECT_LT((s.estimate.x - m.estimate.x).norm(), 1e-9 * m.estimate.x.norm());
    EXPECT_LT((s.estimate.std_dev - m.estimate.std_dev).norm(), 1e-7 * m.estimate.std_dev.norm());
    EXPECT_NEAR(s.relative_error, m.relative_error, 1e-10);
  }
}

TEST(StreamingIdentification, RefusesFilteringAndMissingDerivatives) {
  const Model model = load_robot("puma560");
  const std::string path = write_run(model, 100);
  IdentifyOptions o;  // filter on by default
  try {
    identify_stream(model, path, {}, o);
    FAIL();
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("--filter none"), std::string::npos);
  }
  o.signal.filter = false;
  RunFileOptions rename;
  rename.columns = {{"dq1", "v1"}};
  EXPECT_THROW(identify_stream(model, path, rename, o), Error);
}

}  // namespace
}  // namespace dynid
