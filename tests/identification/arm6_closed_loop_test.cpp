// Issue 25 item 1: ../shared/regressions/arm6-closed-loop (README there), a closed-loop run of a
// 6-joint arm with non-standard joint axes simulated with Orocos KDL (not dynid's equations), in
// which every joint moves. dynid 0.1.0 reported a column-scaled condition number of 8e7 there,
// declared Fc6 (Fo6 with an offset) "not excited" and refused to validate. The cause was the base
// set: Gautier's rule regrouped ZZ_j (weight ~0.01 when a joint axis is tilted by ~0.1 rad from a
// frame axis) into XX_j and YY_j, leaving base columns that are nearly dependent on every
// trajectory; the data-rank sweep then dropped the last column, Fc6. With threshold pivoting
// (docs/methods/model.md, "Well-conditioned base columns") every parameter is estimated, the
// true friction lies inside its intervals and the held-out run is predicted as well as an
// independent least-squares fit does (0.91 %). With the independent fit's 10 Hz cut-off every
// base parameter's truth lies inside its interval; the default cut-off (20 Hz by held-out
// prediction, 1.64 % against 1.65 % at 12.5 Hz) lets through enough differentiated position
// noise to bias four inertial parameters by 3.5–5.5 σ (errors in variables; issue 25 item 4 is
// the cut-off choice). Skips when ../shared is absent.
#include <cstdlib>
#include <filesystem>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>

#include "dynid/identification/identify.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/io/joint_record_file.hpp"
#include "dynid/model/robots.hpp"

namespace dynid {
namespace {

namespace fs = std::filesystem;

const std::string kDir = std::string(DYNID_SHARED_DIR) + "/regressions/arm6-closed-loop";

// True friction of the KDL plant (README): tau_f = Fv·dq + Fc·tanh(dq/0.01).
constexpr double kFv[6] = {3.0, 4.0, 2.0, 0.5, 0.4, 0.15};
constexpr double kFc[6] = {2.5, 3.5, 1.8, 0.6, 0.5, 0.2};
// The independent OLS of the README predicts valid.csv.gz at this relative error.
constexpr double kIndependentError = 0.0091;

// The run decompressed into the test's scratch folder (dynid reads plain CSV).
std::string unpacked(const std::string& name) {
  // One copy per test process: ctest runs the cases in parallel, and a copy another process is
  // still writing would be read half-written (or make the case skip).
  const fs::path out =
      fs::path(::testing::TempDir()) / ("arm6_" + std::to_string(::getpid()) + "_" + name);
  const std::string command = "gzip -dc '" + kDir + "/" + name + ".gz' > '" + out.string() + "'";
  if (std::system(command.c_str()) != 0) return "";
  return out.string();
}

ParameterLayout layout(bool offset) {
  ParameterLayout l;
  l.armature = true;  // the default of dynid identify; the URDF has none (truth 0)
  l.viscous = true;
  l.coulomb = true;
  l.offset = offset;
  return l;
}

struct Arm6Run {
  Model model;
  JointRecord ident, valid;
};

// One identification: with or without the offset column, the cut-off automatic (0) or given.
struct Case {
  bool offset;
  double cutoff_hz;
};

class Arm6ClosedLoop : public ::testing::TestWithParam<Case> {
 protected:
  static void SetUpTestSuite() {
    if (!fs::exists(kDir + "/ident.csv.gz") || !fs::exists(kDir + "/valid.csv.gz")) return;
    const std::string ident = unpacked("ident.csv"), valid = unpacked("valid.csv");
    if (ident.empty() || valid.empty()) return;
    run_ = new Arm6Run{load_robot(kDir + "/arm6_odd.urdf"), {}, {}};
    run_->ident = read_joint_record(ident, run_->model);
    run_->valid = read_joint_record(valid, run_->model);
  }
  static void TearDownTestSuite() {
    delete run_;
    run_ = nullptr;
  }
  void SetUp() override {
    if (run_ == nullptr) GTEST_SKIP() << "regression run not found (or gzip missing) at " << kDir;
  }
  static IdentificationResult identify_with(const Case& c) {
    IdentifyOptions o;
    o.layout = layout(c.offset);
    o.signal.cutoff_hz = c.cutoff_hz;
    return identify(run_->model, run_->ident, o);
  }
  // The true base parameters: the URDF's links, no armature, the README's friction, no offset.
  static Eigen::VectorXd truth(const IdentificationResult& r, bool offset) {
    const ParameterLayout l = layout(offset);
    Eigen::VectorXd theta = l.parameters(run_->model);
    const int per = l.joint_columns();
    for (int j = 0; j < 6; ++j) {
      const int at = kLinkParams * 6 + per * j;
      theta[at] = 0.0;         // Ia
      theta[at + 1] = kFv[j];  // Fv
      theta[at + 2] = kFc[j];  // Fc
      if (offset) theta[at + 3] = 0.0;
    }
    const Eigen::VectorXd all = r.base.reduce(theta);
    Eigen::VectorXd out(static_cast<Eigen::Index>(r.names.size()));
    for (size_t i = 0; i < r.names.size(); ++i) {
      const auto it = std::find(r.base.names.begin(), r.base.names.end(), r.names[i]);
      out[static_cast<Eigen::Index>(i)] = all[it - r.base.names.begin()];
    }
    return out;
  }
  static Arm6Run* run_;
};
Arm6Run* Arm6ClosedLoop::run_ = nullptr;

TEST_P(Arm6ClosedLoop, EveryParameterIsEstimatedAndTheTruthLiesInsideItsIntervals) {
  const Case c = GetParam();
  const IdentificationResult r = identify_with(c);
  EXPECT_TRUE(r.not_excited.empty()) << r.not_excited.front();
  EXPECT_EQ(r.data_rank, r.rank);
  EXPECT_EQ(static_cast<int>(r.names.size()), r.rank);
  EXPECT_EQ(r.rank, c.offset ? 61 : 55);
  const Eigen::VectorXd t = truth(r, c.offset);
  std::string friction_outside, outside;
  for (size_t i = 0; i < r.names.size(); ++i) {
    const auto k = static_cast<Eigen::Index>(i);
    EXPECT_TRUE(std::isfinite(r.estimate.std_dev[k])) << r.names[i];
    if (t[k] >= r.estimate.ci_lower[k] && t[k] <= r.estimate.ci_upper[k]) continue;
    outside += " " + r.names[i];
    if (r.names[i][0] == 'F') friction_outside += " " + r.names[i];
  }
  EXPECT_TRUE(friction_outside.empty())
      << "friction outside its 99.9 % interval:" << friction_outside;
  if (c.cutoff_hz > 0.0) {
    EXPECT_TRUE(outside.empty()) << "truth outside the 99.9 % interval:" << outside;
  }
  // Joint 6's friction, which 0.1.0 called not excited, is determined to a few percent.
  for (const char* name : {"Fv6", "Fc6"}) {
    const auto i = std::find(r.names.begin(), r.names.end(), name) - r.names.begin();
    ASSERT_LT(i, static_cast<long>(r.names.size())) << name;
    EXPECT_LT(r.estimate.std_dev[i], 0.1 * std::abs(r.estimate.x[i])) << name;
  }
}

TEST_P(Arm6ClosedLoop, ValidationPredictsTheHeldOutRunAsWellAsAnIndependentFit) {
  const Case c = GetParam();
  const IdentificationResult r = identify_with(c);
  IdentifyOptions same;
  same.layout = layout(c.offset);
  same.signal.cutoff_hz = r.processed.cutoff_hz;
  same.signal.zero_velocity.assign(r.zero_velocity_threshold.data(),
                                   r.zero_velocity_threshold.data() + 6);
  same.signal.filter_coulomb_columns = true;
  const ValidationResult v =
      validate_torques(run_->model, run_->valid, r.names, r.estimate.x, same, r.not_excited);
  EXPECT_LT(v.relative_error_all_rows, 1.5 * kIndependentError);
  EXPECT_LT(v.relative_error_all, 1.5 * kIndependentError);
}

INSTANTIATE_TEST_SUITE_P(Friction, Arm6ClosedLoop,
                         ::testing::Values(Case{false, 0.0}, Case{true, 0.0}, Case{false, 10.0}),
                         [](const ::testing::TestParamInfo<Case>& info) {
                           return std::string(info.param.offset ? "WithOffset" : "ViscousCoulomb") +
                                  (info.param.cutoff_hz > 0.0 ? "At10Hz" : "");
                         });

}  // namespace
}  // namespace dynid
