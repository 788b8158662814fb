#pragma once

// Helpers shared by the estimation tests: seeded random problems and small oracles.

#include <random>
#include <string>

#include <gtest/gtest.h>
#include <Eigen/Core>

#include "dynid/common/error.hpp"

namespace dynid {
namespace estimation_testing {

inline Eigen::MatrixXd gaussian(Eigen::Index rows, Eigen::Index cols, std::mt19937& rng,
                                double scale = 1.0) {
  std::normal_distribution<double> n(0.0, scale);
  Eigen::MatrixXd a(rows, cols);
  for (Eigen::Index j = 0; j < cols; ++j)
    for (Eigen::Index i = 0; i < rows; ++i) a(i, j) = n(rng);
  return a;
}

inline double rel(const Eigen::MatrixXd& a, const Eigen::MatrixXd& b) {
  return (a - b).norm() / std::max(b.norm(), 1e-300);
}

/// Runs f, expects dynid::Error whose message contains every given fragment.
template <class F>
void expect_error(F f, std::initializer_list<std::string> fragments) {
  try {
    f();
    ADD_FAILURE() << "no dynid::Error thrown";
  } catch (const Error& e) {
    const std::string msg = e.what();
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
    for (const auto& f : fragments) EXPECT_NE(msg.find(f), std::string::npos) << msg;
  }
}

}  // namespace estimation_testing
}  // namespace dynid
