// compare_estimates (issue 31 item 3): z-scores and Holm's step-down against p-values computed
// here from Boost's normal distribution, and the parameter roles.
#include <cmath>
#include <limits>
#include <vector>

#include <gtest/gtest.h>
#include <boost/math/distributions/normal.hpp>

#include "dynid/common/error.hpp"
#include "dynid/estimation/parameter_drift.hpp"

namespace dynid {
namespace {

// Two-sided p-value of a standard normal z, the oracle.
double drift_two_sided(double z) {
  const boost::math::normal n;
  return 2.0 * boost::math::cdf(boost::math::complement(n, std::abs(z)));
}

DriftInput drift_input(const std::string& label, const std::vector<std::string>& names,
                       const std::vector<double>& values, double sd) {
  DriftInput in;
  in.label = label;
  in.names = names;
  in.values =
      Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  in.std_devs = Eigen::VectorXd::Constant(in.values.size(), sd);
  return in;
}

TEST(ParameterDrift, HolmStepDownFlagsWhatBonferroniWouldMiss) {
  // σ = 1/√2 in each result: the difference has σ 1, so the changes are the z-scores.
  const double s = 1.0 / std::sqrt(2.0);
  const std::vector<std::string> names = {"ZZ1R", "Fv1", "Fc2", "Ia1"};
  const DriftInput before = drift_input("old", names, {1.0, 2.0, 3.0, 4.0}, s);
  const DriftInput after = drift_input("new", names, {6.0, 5.0, 5.5, 4.1}, s);
  const DriftComparison c = compare_estimates({before, after}, {0.01});
  ASSERT_EQ(c.rows.size(), 4u);
  EXPECT_EQ(c.tests, 4);
  const double z[] = {5.0, 3.0, 2.5, 0.1};
  for (int i = 0; i < 4; ++i) {
    EXPECT_NEAR(c.rows[i].z, z[i], 1e-12);
    EXPECT_NEAR(c.rows[i].std_dev, 1.0, 1e-12);
    EXPECT_NEAR(c.rows[i].p_value, drift_two_sided(z[i]), 1e-12 * drift_two_sided(z[i]) + 1e-300);
  }
  // Holm: 4·p(5) and 3·p(3) = 0.0081 are ≤ 0.01; 2·p(2.5) = 0.025 is not, and the step-down
  // stops. Bonferroni (4·p(3) = 0.0108) would have missed Fv1.
  EXPECT_NEAR(c.rows[1].p_adjusted, 3.0 * drift_two_sided(3.0), 1e-12);
  EXPECT_GT(4.0 * drift_two_sided(3.0), 0.01);
  EXPECT_TRUE(c.rows[0].flagged);
  EXPECT_TRUE(c.rows[1].flagged);
  EXPECT_FALSE(c.rows[2].flagged);
  EXPECT_FALSE(c.rows[3].flagged);
  EXPECT_NEAR(c.rows[2].p_adjusted, 2.0 * drift_two_sided(2.5), 1e-12);
  EXPECT_NEAR(c.rows[3].p_adjusted, std::max(2.0 * drift_two_sided(2.5), drift_two_sided(0.1)),
              1e-12);
  // The first step's critical |z|: the (1 − α/(2m)) quantile.
  EXPECT_NEAR(drift_two_sided(c.first_critical_z), 0.01 / 4.0, 1e-12);
  EXPECT_EQ(c.rows[1].role, ParameterRole::kFriction);
}

TEST(ParameterDrift, UndeterminedAndMissingParametersAreLeftOutOfTheFamily) {
  DriftInput a = drift_input("a", {"XX2R", "Fv1", "Fo1"}, {1.0, 2.0, 3.0}, 0.1);
  DriftInput b = drift_input("b", {"Fv1", "XX2R", "m"}, {2.05, 1.0, 0.5}, 0.1);
  DriftInput c = drift_input("c", {"XX2R", "Fv1"}, {1.0, 3.0}, 0.1);
  a.std_devs[0] = std::numeric_limits<double>::infinity();  // not excited in the baseline
  const DriftComparison d = compare_estimates({a, b, c});
  // XX2R and Fv1 are in every result (Fv1 found by name, not position); Fo1 and m are not.
  ASSERT_EQ(d.rows.size(), 4u);
  EXPECT_EQ(d.not_shared, (std::vector<std::string>{"m", "Fo1"}));
  EXPECT_FALSE(d.rows[0].tested);
  EXPECT_FALSE(d.rows[0].flagged);
  EXPECT_EQ(d.tests, 2);
  EXPECT_NEAR(d.rows[2].change, 0.05, 1e-12);  // Fv1, result 1
  EXPECT_FALSE(d.rows[2].flagged);
  EXPECT_NEAR(d.rows[3].change, 1.0, 1e-12);  // Fv1, result 2: z = 7.07
  EXPECT_TRUE(d.rows[3].flagged);
  EXPECT_THROW(compare_estimates({a}), Error);
  EXPECT_THROW(compare_estimates({a, b}, {1.5}), Error);
  DriftInput wrong = a;
  wrong.values.resize(2);
  EXPECT_THROW(compare_estimates({a, wrong}), Error);
}

TEST(ParameterDrift, RolesFromNames) {
  EXPECT_EQ(parameter_role("Fv2"), ParameterRole::kFriction);
  EXPECT_EQ(parameter_role("Fc2R"), ParameterRole::kFriction);
  EXPECT_EQ(parameter_role("Fcn12"), ParameterRole::kFriction);
  EXPECT_EQ(parameter_role("Fcm3"), ParameterRole::kFriction);
  EXPECT_EQ(parameter_role("Ia4"), ParameterRole::kArmature);
  EXPECT_EQ(parameter_role("mcx"), ParameterRole::kPayload);
  EXPECT_EQ(parameter_role("Izz"), ParameterRole::kPayload);
  EXPECT_EQ(parameter_role("ZZ1R"), ParameterRole::kInertial);
  EXPECT_EQ(parameter_role("M3"), ParameterRole::kInertial);
  EXPECT_EQ(parameter_role("MX2R"), ParameterRole::kInertial);
  EXPECT_STREQ(to_string(ParameterRole::kFriction), "friction");
}

}  // namespace
}  // namespace dynid
