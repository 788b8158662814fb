// dynid excite --family slope|bang-bang|trapezoid|spline --joint J (issue 14 item 1): the moving
// joint follows the shape its family promises (checked on the written CSV against closed forms:
// cruise speed, triangular peak sqrt(a·D), via-points), the other joints stay at --pose, and
// limits and missing parameters give one error line, exit 2 and no file.
#include <cmath>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "dynid/io/csv_reader.hpp"
#include "support/cli_run.hpp"

namespace dynid {
namespace {

std::filesystem::path scratch() {
  const auto dir = std::filesystem::path(::testing::TempDir()) / "excite_family";
  std::filesystem::create_directories(dir);
  return dir;
}

CsvTable excite(const std::string& args) {
  // One file per test: ctest runs the tests of this file in parallel processes.
  const std::string test_name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
  const std::string out = (scratch() / (test_name + ".csv")).string();
  std::filesystem::remove(out);
  const testing::CliResult r = testing::run_dynid("excite " + args + " --out " + out, scratch());
  EXPECT_EQ(r.code, 0) << r.err;
  return read_csv(out);
}

Eigen::VectorXd column(const CsvTable& t, const std::string& name) {
  for (size_t c = 0; c < t.columns.size(); ++c)
    if (t.columns[c] == name) return t.data.col(static_cast<Eigen::Index>(c));
  ADD_FAILURE() << "no column " << name;
  return {};
}

TEST(ExciteFamilyCli, SlopeCruisesAtTheVelocityWithTheOtherJointAtThePose) {
  const CsvTable t = excite(
      "--robot planar2 --family slope --joint 2 --range -0.5:0.5 --velocity 0.3 "
      "--acceleration 2 --pose 0.4,0 --cycles 2 --rate 200");
  const Eigen::VectorXd q1 = column(t, "q1"), q2 = column(t, "q2"), dq2 = column(t, "dq2");
  EXPECT_EQ((q1.array() - 0.4).abs().maxCoeff(), 0.0);
  EXPECT_NEAR(q2.minCoeff(), -0.5, 1e-9);
  EXPECT_NEAR(q2.maxCoeff(), 0.5, 1e-9);
  EXPECT_NEAR(dq2.maxCoeff(), 0.3, 1e-9);
  EXPECT_NEAR(dq2.minCoeff(), -0.3, 1e-9);
  EXPECT_NEAR(q2[0], -0.5, 1e-12);
  EXPECT_NEAR(dq2[0], 0.0, 1e-12);
  // The last sample is within one period (1/200 s) of the end, where the joint decelerates at 2.
  EXPECT_LE(std::abs(dq2[dq2.size() - 1]), 2.0 / 200);
  // Two cycles: the joint crosses 0 upwards twice.
  int up = 0;
  for (Eigen::Index k = 1; k < q2.size(); ++k) up += q2[k - 1] < 0.0 && q2[k] >= 0.0;
  EXPECT_EQ(up, 2);
}

TEST(ExciteFamilyCli, BangBangPeaksAtTheTriangularSpeed) {
  const CsvTable t = excite(
      "--robot planar2 --family bang-bang --joint 1 --range 0:1 --acceleration 2 --rate 1000");
  const Eigen::VectorXd dq1 = column(t, "dq1"), ddq1 = column(t, "ddq1"), q2 = column(t, "q2");
  EXPECT_NEAR(dq1.cwiseAbs().maxCoeff(), std::sqrt(2.0 * 1.0), 2e-3);  // sqrt(a·D), sampled
  EXPECT_NEAR(ddq1.cwiseAbs().maxCoeff(), 2.0, 1e-9);
  EXPECT_EQ(q2.cwiseAbs().maxCoeff(), 0.0);
}

TEST(ExciteFamilyCli, TrapezoidCruisesAndSplinePassesItsViaPoints) {
  CsvTable t = excite(
      "--robot planar2 --family trapezoid --joint 1 --range 0:1 --velocity 0.5 --acceleration 2 "
      "--dwell 0.5");
  EXPECT_NEAR(column(t, "dq1").maxCoeff(), 0.5, 1e-9);
  EXPECT_NEAR(column(t, "q1").maxCoeff(), 1.0, 1e-9);
  t = excite(
      "--robot planar2 --family spline --joint 2 --via 0,0.8,-0.4,0 --duration 3 --rate 100");
  const Eigen::VectorXd time = column(t, "t"), q2 = column(t, "q2"), dq2 = column(t, "dq2");
  ASSERT_EQ(time.size(), 301);
  EXPECT_NEAR(q2[0], 0.0, 1e-12);
  EXPECT_NEAR(q2[100], 0.8, 1e-9);
  EXPECT_NEAR(q2[200], -0.4, 1e-9);
  EXPECT_NEAR(q2[300], 0.0, 1e-9);
  EXPECT_NEAR(dq2[0], 0.0, 1e-12);
  EXPECT_NEAR(dq2[300], 0.0, 1e-9);
}

// --family fourier --joint J: one period, exactly periodic in the written CSV, the other joints at
// the pose, the range reached, and the written derivatives consistent with the written positions.
TEST(ExciteFamilyCli, FourierOfOneJointIsPeriodicOverItsRange) {
  const CsvTable t = excite(
      "--robot planar2 --family fourier --joint 2 --range -0.5:0.3 --pose 0.4,0 --f0 0.2 "
      "--harmonics 4 --rate 200");
  ASSERT_EQ(t.data.rows(), 1001);  // 5 s at 200 Hz, both ends
  const Eigen::VectorXd q1 = column(t, "q1"), dq1 = column(t, "dq1"), q2 = column(t, "q2"),
                        dq2 = column(t, "dq2"), ddq2 = column(t, "ddq2");
  EXPECT_EQ((q1.array() - 0.4).abs().maxCoeff(), 0.0);
  EXPECT_EQ(dq1.cwiseAbs().maxCoeff(), 0.0);
  EXPECT_NEAR(q2.minCoeff(), -0.5, 1e-4);
  EXPECT_NEAR(q2.maxCoeff(), 0.3, 1e-4);
  const Eigen::Index last = t.data.rows() - 1;
  EXPECT_NEAR((t.data.row(0).tail(6) - t.data.row(last).tail(6)).norm(), 0.0, 1e-9);
  EXPECT_NEAR(dq2[0], 0.0, 1e-9);  // at rest at the ends by default
  EXPECT_NEAR(ddq2[0], 0.0, 1e-9);
  // Central differences at 200 Hz: truncation error h^2/6 times the third derivative, about
  // 4e-6 * (2 pi 0.8)^3 * 0.4 = 2e-4 for dq.
  for (Eigen::Index k = 1; k < last; ++k) {
    EXPECT_NEAR((q2[k + 1] - q2[k - 1]) * 100.0, dq2[k], 1e-3) << k;
    EXPECT_NEAR((dq2[k + 1] - dq2[k - 1]) * 100.0, ddq2[k], 1e-2) << k;
  }
}

TEST(ExciteFamilyCli, BadParametersGiveOneErrorLineAndNoFile) {
  const std::string out = (scratch() / "never.csv").string();
  std::filesystem::remove(out);
  struct Case {
    std::string args, fragment;
  } cases[] = {
      {"--robot planar2 --family slope --joint 3 --range 0:1 --velocity 1 --acceleration 1",
       "--joint 3"},
      {"--robot planar2 --family slope --joint 1 --velocity 1 --acceleration 1", "--range"},
      {"--robot planar2 --family slope --joint 1 --range 0:1 --acceleration 1", "--velocity"},
      {"--robot planar2 --family wobble --joint 1", "--family"},
      {"--robot planar2 --family slope --joint 1 --range 0:0.01 --velocity 1 --acceleration 1",
       "--family slope"},
      {"--robot planar2 --family trapezoid --joint 1 --range 0:1 --velocity 0.5 --acceleration 2 "
       "--velocity-limit 0.2",
       "above its limit"},
      {"--robot puma560 --family trapezoid --joint 2 --range 0:2 --velocity 0.5 --acceleration 2",
       "outside its allowed range"},
      {"--robot planar2 --family spline --joint 1 --via 0,1", "--duration"},
      {"--robot planar2 --family bang-bang --joint 1 --range 0:1 --acceleration 1 --pose 1,2,3",
       "--pose"},
      {"--robot planar2 --family fourier --joint 3 --range 0:1", "--joint 3"},
      {"--robot planar2 --family fourier --joint 1", "--range"},
      {"--robot puma560 --family fourier --joint 2 --range 0:3", "outside its allowed range"},
      {"--robot planar2 --family fourier --joint 1 --range 0:1 --velocity-limit 0.1",
       "narrow --range"},
      {"--robot planar2 --family fourier --joint 1 --range 0:1 --harmonics 1", "--harmonics"},
  };
  for (const Case& c : cases) {
    const testing::CliResult r =
        testing::run_dynid("excite " + c.args + " --out " + out, scratch());
    EXPECT_EQ(r.code, 2) << c.args << "\n" << r.err;
    EXPECT_EQ(testing::error_contract_problem(r.err), "") << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.fragment), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_FALSE(std::filesystem::exists(out)) << c.args;
  }
}

}  // namespace
}  // namespace dynid
