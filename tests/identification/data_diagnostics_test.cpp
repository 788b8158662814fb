// Issue 26 items 5 and 6 in the library: find_lockstep_joints() against correlations computed here
// by hand, nominal_base_values() against the closed-form planar2 ZZ1R, and identify()'s progress
// through its real stages. Oracles: the data built here (a joint made a multiple of another, an
// independent one, a still one) and the closed form of tests/support/planar2.hpp.
#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/identification/data_diagnostics.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/model/robots.hpp"
#include "support/error_of.hpp"
#include "support/planar2.hpp"

namespace dynid {
namespace {

TEST(LockstepJoints, PairsAboveTheThresholdInEveryRunOnly) {
  const int m = 500;
  Eigen::MatrixXd v(m, 4);
  for (int k = 0; k < m; ++k) {
    const double t = 0.01 * k;
    v(k, 0) = std::sin(t) + 0.2 * std::sin(3.1 * t);
    v(k, 1) = -0.5 * v(k, 0) + 0.03 * std::cos(7.3 * t);  // nearly proportional, anti-correlated
    v(k, 2) = std::cos(2.2 * t);                          // independent
    v(k, 3) = 0.0;                                        // still
  }
  // The correlation of joints 1 and 2, by hand.
  const Eigen::VectorXd a = v.col(0).array() - v.col(0).mean();
  const Eigen::VectorXd b = v.col(1).array() - v.col(1).mean();
  const double r = a.dot(b) / std::sqrt(a.squaredNorm() * b.squaredNorm());
  ASSERT_LT(r, -0.99);
  const std::vector<LockstepJoints> pairs = find_lockstep_joints({v});
  ASSERT_EQ(pairs.size(), 1u);
  EXPECT_EQ(pairs[0].first, 0);
  EXPECT_EQ(pairs[0].second, 1);
  EXPECT_NEAR(pairs[0].correlation, r, 1e-12);
  // A second run in which joint 2 moves on its own: no longer lockstep over the runs.
  Eigen::MatrixXd other = v;
  other.col(1) = v.col(2);
  EXPECT_TRUE(find_lockstep_joints({v, other}).empty());
  EXPECT_NE(testing::error_of([&] {
              find_lockstep_joints({v, Eigen::MatrixXd::Zero(m, 3)});
            }).find("runs of one robot"),
            std::string::npos);
}

TEST(NominalBaseValues, ClosedFormZz1rAndNoneForFrictionTheModelLacks) {
  const Model model = load_robot("planar2");
  BaseParameterOptions bo;
  bo.layout = ParameterLayout::rigid();
  bo.layout.viscous = true;
  const BaseParameters base = compute_base_parameters(model, bo);
  const std::vector<std::optional<double>> nominal = nominal_base_values(model, base, bo.layout);
  ASSERT_EQ(nominal.size(), base.names.size());
  bool zz1r = false;
  for (size_t i = 0; i < base.names.size(); ++i) {
    if (base.names[i] == "ZZ1R") {
      zz1r = true;
      ASSERT_TRUE(nominal[i].has_value());
      EXPECT_NEAR(*nominal[i], 2.0 / 12 + 2.0 * 0.25 + 1.5, 1e-12);  // I1 + m1·c1² + m2·l1²
    }
    if (base.names[i].rfind("Fv", 0) == 0) {
      EXPECT_FALSE(nominal[i].has_value()) << base.names[i];
    }
  }
  EXPECT_TRUE(zz1r);
  // A model that gives friction has a nominal friction value.
  Model rubbing = model;
  rubbing.joints[1].friction.Fv = 0.7;
  const std::vector<std::optional<double>> given = nominal_base_values(rubbing, base, bo.layout);
  for (size_t i = 0; i < base.names.size(); ++i) {
    if (base.names[i] == "Fv2") {
      EXPECT_EQ(given[i], std::optional<double>(0.7));
    }
  }
}

TEST(IdentifyProgress, AdvancesThroughTheStages) {
  const Model model = load_robot("planar2");
  JointRecord run;
  const int m = 1500;
  run.t.resize(m);
  run.q.resize(m, 2);
  run.dq.resize(m, 2);
  run.ddq.resize(m, 2);
  run.tau.resize(m, 2);
  for (int k = 0; k < m; ++k) {
    const testing::Planar2Sample s = testing::planar2_sample(k, 0.01);
    run.t[k] = s.t;
    run.q.row(k) << s.q[0], s.q[1];
    run.dq.row(k) << s.dq[0], s.dq[1];
    run.ddq.row(k) << s.ddq[0], s.ddq[1];
    run.tau.row(k) << s.tau[0], s.tau[1];
  }
  IdentifyOptions options;
  options.layout = ParameterLayout::rigid();
  std::vector<double> fractions;
  std::vector<std::string> stages;
  options.progress = [&](double f, const std::string& what) {
    fractions.push_back(f);
    stages.push_back(what);
  };
  identify(model, std::vector<JointRecord>{run, run}, options);
  ASSERT_GE(fractions.size(), 4u);  // two runs, base parameters, estimate
  EXPECT_TRUE(std::is_sorted(fractions.begin(), fractions.end()));
  EXPECT_EQ(fractions.front(), 0.0);
  EXPECT_GT(fractions[1], 0.0);  // the second run moves the line
  EXPECT_NE(stages[1].find("run 2/2"), std::string::npos) << stages[1];
  EXPECT_NE(stages.back().find("estimating"), std::string::npos) << stages.back();
}

}  // namespace
}  // namespace dynid
