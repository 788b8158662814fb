// Issue 31 item 5: a simulated fleet of four planar2 arms, each identified twice (closed loop on
// the native plant, sensor noise fed back, in-memory identification with HAC intervals); between
// the two runs arm 2's joint-2 viscous friction grows by 20 %. dynid compare's statistics must
// flag that arm and parameter, and nothing on the other arms, at a family-wise rate of 1 %.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "dynid/estimation/parameter_drift.hpp"
#include "dynid/excitation/fourier_trajectory.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/identification/identify.hpp"
#include "dynid/io/json_writer.hpp"
#include "dynid/report/drift_report.hpp"
#include "dynid/report/html_report.hpp"
#include "dynid/report/identification_report.hpp"
#include "dynid/sim/simulate_reference.hpp"
#include "support/closed_loop_runs.hpp"

namespace dynid {
namespace {

constexpr double kFleetRate = 100.0;

// One nightly run of an arm: 3 periods of the planar2 test reference after a dropped start-up
// period, PID with the plant's own feed-forward, encoder and torque noise.
JointRecord fleet_run(const Model& arm, unsigned seed) {
  const TrajectorySamples tr =
      sample_trajectory(FourierTrajectory(testing::planar2_reference()), kFleetRate, false);
  SimulateOptions so = testing::noisy_sensors(2e-5, 0.02, seed, 4);
  so.plant.engine = PlantEngine::kNative;
  return testing::closed_loop_run(arm, tr, so);
}

// The result JSON of identify (as dynid identify writes it) read back as compare reads it.
DriftInput fleet_result(const Model& arm, const Model& robot, unsigned seed,
                        const std::string& label, std::string* covariance) {
  IdentifyOptions o;
  o.signal.cutoff_hz = 5.0;  // the reference's lines end at 0.8 Hz
  const IdentificationResult r = identify(robot, fleet_run(arm, seed), o);
  const nlohmann::json j = identification_to_json(robot, r, nlohmann::json::object());
  return drift_input_of_result(j, label, covariance);
}

TEST(FleetDrift, OneArmsViscousFrictionGrowthIsFlaggedAndNothingElse) {
  const Model nominal = testing::planar2_with_friction();
  constexpr int kArms = 4, kWorn = 2;
  for (int arm = 0; arm < kArms; ++arm) {
    Model tonight = nominal;
    if (arm == kWorn) tonight.joints[1].friction.Fv *= 1.2;  // 0.8 -> 0.96 N m s/rad
    std::string cov_old, cov_new;
    const std::vector<DriftInput> results = {
        fleet_result(nominal, nominal, 100 + arm, "arm" + std::to_string(arm) + "_old", &cov_old),
        fleet_result(tonight, nominal, 200 + arm, "arm" + std::to_string(arm) + "_new", &cov_new)};
    EXPECT_EQ(cov_old.rfind("Newey-West (HAC)", 0), 0u) << cov_old;
    const DriftComparison c = compare_estimates(results, {0.01});
    EXPECT_GT(c.tests, 10);
    std::vector<std::string> flagged;
    for (const ParameterDrift& d : c.rows) {
      if (d.flagged) flagged.push_back(d.name);
      if (d.name == "Fv2" && arm == kWorn) {
        // The change recovered: 0.16 within 3 of its standard deviations.
        EXPECT_NEAR(d.change, 0.16, 3.0 * d.std_dev);
        EXPECT_EQ(d.role, ParameterRole::kFriction);
      }
    }
    EXPECT_EQ(flagged, arm == kWorn ? std::vector<std::string>{"Fv2"} : std::vector<std::string>{})
        << "arm " << arm;
    if (arm != kWorn) continue;
    const nlohmann::json j = drift_to_json(results, {cov_old, cov_new}, {"planar2", "planar2"}, c);
    EXPECT_EQ(j["flagged_friction"], nlohmann::json::array({"Fv2"}));
    EXPECT_TRUE(j["flagged_payload"].empty());
    EXPECT_EQ(j["flagged"][0]["file"], "arm2_new");
    EXPECT_NE(drift_table(results, c).find("Fv2 (friction)"), std::string::npos);
    EXPECT_EQ(result_kind(j), "compare");
  }
}

}  // namespace
}  // namespace dynid
