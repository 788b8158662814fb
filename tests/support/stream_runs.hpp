#pragma once

// Runs for the streaming-identification tests: smooth multi-sine joint motion with torques from
// RNEA (not the regressor the stream accumulates), optional viscous friction and Gaussian noise,
// written as a CSV with t, q*, dq*, ddq*, tau*.

#include <cmath>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/csv_writer.hpp"
#include "dynid/model/model.hpp"

namespace dynid::testing {

/// Writes `samples` samples at 100 Hz to TempDir()/name and returns the path. Joint j moves as
/// sin(w t + j + phase) + 0.3 sin(3 w t), w = 0.5 + 0.3 j + 0.1 phase; tau = RNEA + viscous·dq +
/// N(0, sigma²) with std::mt19937(seed).
inline std::string write_stream_run(const Model& model, int samples, double sigma,
                                    const std::string& name, unsigned seed = 9, double phase = 0.0,
                                    double viscous = 0.0) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
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
      const double w = 0.5 + 0.3 * j + 0.1 * phase;
      q[j] = std::sin(w * t + j + phase) + 0.3 * std::sin(3 * w * t);
      dq[j] = w * std::cos(w * t + j + phase) + 0.9 * w * std::cos(3 * w * t);
      ddq[j] = -w * w * std::sin(w * t + j + phase) - 2.7 * w * w * std::sin(3 * w * t);
    }
    rnea(model, ws, q, dq, ddq, tau);
    for (int j = 0; j < n; ++j) tau[j] += viscous * dq[j] + (sigma > 0.0 ? noise(rng) : 0.0);
    data.row(k) << t, q.transpose(), dq.transpose(), ddq.transpose(), tau.transpose();
  }
  const std::string path = ::testing::TempDir() + "/" + name;
  write_csv(path, cols, data);
  return path;
}

}  // namespace dynid::testing
