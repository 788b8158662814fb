// Seed 1's IRp-6 experiment (§VI) in simulation, the integral-model part of issue 11 item 6: the
// built-in irp6 moved by rest-to-rest quintic-spline moves of joint 1 alone, joint 2 alone and
// joints 1 and 3 together (seed 1 §VI-A), in one closed-loop run on MuJoCo at 2 kHz (0.5 ms, the
// IRp-6 logger) with encoder and torque noise. Identified with short and long integrals and with
// the differential model; the truth must lie inside the 99.9 % intervals of the short-integral
// and differential estimates; seed 1 found long integrals worse than short ones, and here they are
// better (see the second test). Which sensor error reverses that, and the example's pipeline with
// the IRp-6's sensors: the IntegralIrp6Example tests and the on-demand study at the end
// (docs/methods/identification.md §4a).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/excitation/polynomial_spline.hpp"
#include "dynid/excitation/trajectory_samples.hpp"
#include "dynid/identification/integral_equations.hpp"
#include "dynid/identification/validation.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/identification_report.hpp"
#include "identification/integral_support.hpp"

namespace dynid {
namespace {

Reference seed1_moves(double ts) {
  // Via-points (q1, q2, q3) [rad], 1.2 s per move, at rest at every via-point.
  Eigen::MatrixXd points(3, 8);
  points << 0.0, 1.0, -0.5, -0.5, -0.5, 0.7, -0.3, 0.0,  //
      -1.3, -1.3, -1.3, -0.9, -1.6, -1.6, -1.6, -1.3,    //
      0.0, 0.0, 0.0, 0.0, 0.0, 0.8, -0.6, 0.0;
  const Eigen::VectorXd times = Eigen::VectorXd::LinSpaced(8, 0.0, 7 * 1.2);
  SplineOptions so;
  so.order = SplineOrder::kQuintic;
  so.velocities = Eigen::MatrixXd::Zero(3, 8);
  so.accelerations = Eigen::MatrixXd::Zero(3, 8);
  const TrajectorySamples s =
      sample_trajectory(PolynomialSpline(times, points, so), 1.0 / ts, false);
  return Reference{s.t, s.q, s.dq, s.ddq};
}

struct Irp6Results {
  BaseParameters base;
  Eigen::VectorXd truth;
  Estimate short_integrals, long_integrals;
  IdentificationResult differential;
  /// Torque-prediction error of each estimate on the run (validate_torques, differential
  /// processing): short integrals, long integrals, differential.
  double short_torque = 0.0, long_torque = 0.0, differential_torque = 0.0;
};

Estimate integral_estimate(const Model& model, const ParameterLayout& layout,
                           const ProcessedRecord& p, const BaseParameters& base,
                           bool long_integrals) {
  IntegralOptions o;
  o.long_integrals = long_integrals;
  return integral_testing::estimate_with_intervals(integral_equations(model, layout, true, p, o),
                                                   base);
}

const Irp6Results& results() {
  static const Irp6Results r = [] {
    Irp6Results out;
    const Model model = load_robot("irp6");
    const double ts = 5e-4;
    SensorOptions so;
    so.position_noise_std = 2e-5;
    so.torque_noise_std = 0.5;
    so.seed = 7;
    PlantOptions plant;
    plant.engine = PlantEngine::kMujoco;
    const ClosedLoopResult run = integral_testing::simulate(model, seed1_moves(ts), ts, so, plant);
    const JointRecord rec{run.t, run.q, {}, {}, run.tau};
    IdentifyOptions io;
    io.signal.torque_time_offset = 0.5 * ts;  // the logged torque is held for one period
    out.differential = identify(model, rec, io);
    out.base = out.differential.base;
    out.truth = out.base.reduce(
        Eigen::VectorXd((Eigen::VectorXd(io.layout.columns(3) + 3) << io.layout.parameters(model),
                         Eigen::VectorXd::Zero(3))
                            .finished()));
    std::vector<std::pair<std::string, std::string>> choices;
    const ProcessedRecord p = preprocess(rec, integral_signal_options(), choices);
    out.short_integrals = integral_estimate(model, io.layout, p, out.base, false);
    out.long_integrals = integral_estimate(model, io.layout, p, out.base, true);
    auto torque = [&](const Estimate& e) {
      return validate_torques(model, rec, out.base.names, e.x, io).relative_error_all;
    };
    out.short_torque = torque(out.short_integrals);
    out.long_torque = torque(out.long_integrals);
    out.differential_torque = torque(out.differential.estimate);
    return out;
  }();
  return r;
}

int outside(const Estimate& e, const Eigen::VectorXd& truth, const std::vector<std::string>& names,
            const char* what) {
  int count = 0;
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    const bool in = e.ci_lower[i] <= truth[i] && truth[i] <= e.ci_upper[i];
    count += !in;
    std::cout << what << " " << names[i] << " " << e.x[i] << " ± " << e.ci_upper[i] - e.x[i]
              << " (truth " << truth[i] << ")" << (in ? "" : " OUTSIDE") << "\n";
  }
  return count;
}

TEST(IntegralIrp6, TruthInsideIntervalsShortIntegralsAndDifferential) {
  const Irp6Results& r = results();
  EXPECT_EQ(r.short_integrals.summary.rank, r.base.rank);
  EXPECT_LE(outside(r.short_integrals, r.truth, r.base.names, "short"), 1);
  EXPECT_LE(outside(r.differential.estimate, r.truth, r.base.names, "differential"), 1);
}

// Seed 1 §VI found long integrals worse than short ones on the real IRp-6. In this simulation
// they are better: over 10 ms intervals of these slow 1.2 s moves the kinetic-energy change is
// small against the endpoint velocity noise, which enters every short row twice (e_{i+1} − e_i)
// but a long row only through its two ends while its energy change grows; the friction and
// torque-noise errors that long integrals accumulate stay small here (no torque bias, white
// noise). The test pins the measured order (short 6.3 %, long 0.70 %, differential 0.54 % torque
// prediction error on the run); docs/methods/identification.md §4 has the puma560 and TX40 figures.
TEST(IntegralIrp6, LongIntegralsBeatShortOnesHereUnlikeSeed1) {
  const Irp6Results& r = results();
  std::cout << "torque prediction error on the run: short integrals " << r.short_torque
            << ", long integrals " << r.long_torque << ", differential " << r.differential_torque
            << "\n";
  EXPECT_LT(r.long_torque, 0.5 * r.short_torque);
  EXPECT_GT(r.long_torque, r.differential_torque);
  // Long rows' errors are a random walk (lag-1 autocorrelation ≈ 1): the HAC intervals are then
  // only a rough guide; how many parameters they miss is reported, not asserted.
  std::cout << outside(r.long_integrals, r.truth, r.base.names, "long")
            << " parameters outside the long-integral intervals\n";
}

// The pipeline of examples/irp6/run.sh, reduced to one period per run: three MuJoCo runs at 2 kHz
// (joint 1; joint 2; joints 1 and 3, seed 1 §VI-A) with the example's IRp-6 sensors (resolver
// quantised to 2^18 counts per revolution, 0.5 N·m white torque noise, a constant current offset
// of 0.8, −0.6, 0.5 N·m), identified together through identify() with the integral model.
constexpr double kOffset[3] = {0.8, -0.6, 0.5};  // current-measurement offset [N·m]

struct ExampleUnion {
  IdentificationResult short_fo, short_seed1, long_seed1;
  IdentificationResult joint1;       // the joint-1 run alone, short integrals
  IdentificationResult joint2_long;  // the joint-2 run alone, long integrals, seed 1's friction
  Eigen::VectorXd all;        // standard parameters of the full layout, coupling columns zero
  Eigen::VectorXd all_seed1;  // the same without the Fo columns
};

Reference via_point_moves(const Eigen::MatrixXd& points, double ts) {
  const Eigen::Index m = points.cols();
  SplineOptions so;
  so.order = SplineOrder::kQuintic;
  so.velocities = Eigen::MatrixXd::Zero(3, m);
  so.accelerations = Eigen::MatrixXd::Zero(3, m);
  const TrajectorySamples s = sample_trajectory(
      PolynomialSpline(Eigen::VectorXd::LinSpaced(m, 0.0, (m - 1) * 1.2), points, so), 1.0 / ts,
      false);
  return Reference{s.t, s.q, s.dq, s.ddq};
}

const ExampleUnion& example_union() {
  static const ExampleUnion u = [] {
    ExampleUnion out;
    const Model model = load_robot("irp6");
    const double ts = 5e-4;
    std::vector<Eigen::MatrixXd> points(3, Eigen::MatrixXd(3, 4));
    points[0] << 0, 1, -0.5, 0, -1.3, -1.3, -1.3, -1.3, 0, 0, 0, 0;
    points[1] << 0, 0, 0, 0, -1.3, -0.9, -1.6, -1.3, 0, 0, 0, 0;
    points[2] << 0, 0.7, -0.3, 0, -1.3, -1.3, -1.3, -1.3, 0, 0.4, -0.25, 0;
    PlantOptions plant;
    plant.engine = PlantEngine::kMujoco;
    std::vector<JointRecord> runs;
    for (int r = 0; r < 3; ++r) {
      SensorOptions so;
      so.counts_per_rev = 262144;
      so.torque_noise_std = 0.5;
      so.seed = 21 + r;
      const ClosedLoopResult run =
          integral_testing::simulate(model, via_point_moves(points[r], ts), ts, so, plant);
      JointRecord rec{run.t, run.q, {}, {}, run.tau};
      rec.tau.rowwise() += Eigen::RowVector3d(kOffset[0], kOffset[1], kOffset[2]);
      runs.push_back(rec);
    }
    IdentifyOptions io;
    io.signal.torque_time_offset = 0.5 * ts;
    io.model = IdentificationModel::kIntegral;
    out.short_fo = identify(model, runs, io);
    out.joint1 = identify(model, runs[0], io);
    out.all = (Eigen::VectorXd(io.layout.columns(3) + 3) << io.layout.parameters(model),
               Eigen::VectorXd::Zero(3))
                  .finished();
    // The measured torque carries the offset: the Fo that explains it is the plant's plus b.
    const std::vector<std::string> names = io.layout.names(3);
    for (int j = 0; j < 3; ++j) {
      const auto at = std::find(names.begin(), names.end(), "Fo" + std::to_string(j + 1));
      out.all[at - names.begin()] += kOffset[j];
    }
    io.layout.offset = false;  // seed 1's friction model: viscous and Coulomb only
    out.all_seed1 = (Eigen::VectorXd(io.layout.columns(3) + 3) << io.layout.parameters(model),
                     Eigen::VectorXd::Zero(3))
                        .finished();
    out.short_seed1 = identify(model, runs, io);
    io.integral.long_integrals = true;
    out.long_seed1 = identify(model, runs, io);
    out.joint2_long = identify(model, runs[1], io);
    return out;
  }();
  return u;
}

// The truth of what a (possibly data-rank-deficient) result estimates: each kept base parameter
// plus the data regrouping of the not-excited ones, from the model's own standard parameters.
Eigen::VectorXd estimated_truth(const IdentificationResult& res, const Eigen::VectorXd& all) {
  return estimated_base_values(res, res.base.reduce(all));
}

// Largest relative error of the joints' viscous and Coulomb estimates (their truths are not
// regrouped: 26 N·m·s and 28.75 N·m on every joint of the built-in irp6; the coupled motor's
// Fvm3, Fcm3 are zero in the plant and left out).
double friction_error(const IdentificationResult& res, const Eigen::VectorXd& truth) {
  double worst = 0.0;
  for (size_t i = 0; i < res.names.size(); ++i) {
    const std::string& n = res.names[i];
    if ((n.rfind("Fv", 0) == 0 || n.rfind("Fc", 0) == 0) && n.find('m') == std::string::npos)
      worst = std::max(worst, std::abs(res.estimate.x[i] / truth[i] - 1.0));
  }
  return worst;
}

TEST(IntegralIrp6Example, UnionOfTheThreeRunsHasTheTruthInsideItsIntervals) {
  const ExampleUnion& u = example_union();
  const IdentificationResult& r = u.short_fo;
  // No run moves joint 2 with joint 3 or fast enough for the small link-2 inertias: what the union
  // leaves undetermined is named, not estimated (the example prints it).
  for (const auto& n : r.not_excited) std::cout << "not excited: " << n << "\n";
  EXPECT_GE(r.data_rank, 20);
  EXPECT_LT(r.data_rank, r.rank);
  const Eigen::VectorXd truth = estimated_truth(r, u.all);
  int outside = 0;
  for (Eigen::Index i = 0; i < truth.size(); ++i) {
    const bool in = r.estimate.ci_lower[i] <= truth[i] && truth[i] <= r.estimate.ci_upper[i];
    outside += !in;
    if (!in) std::cout << r.names[i] << " " << r.estimate.x[i] << " truth " << truth[i] << "\n";
  }
  EXPECT_LE(outside, 1) << "of " << truth.size() << " at 99.9 %";
  EXPECT_LT(friction_error(r, truth), 0.05);
}

// Joints 2 and 3 are held while joint 1 moves; their quantised positions never leave their count,
// so no noise is measurable on them, and the round-off of their filtered velocities must not make
// their friction look excited (it did: Fv2 = 4e21 ± 1e22 in the example before the still-joint
// rule also held joints whose position is constant).
TEST(IntegralIrp6Example, JointsHeldOnOneEncoderCountAreNotExcited) {
  const IdentificationResult& r = example_union().joint1;
  for (const char* name : {"Fv2", "Fc2", "Fv3", "Fc3"}) {
    EXPECT_NE(std::find(r.not_excited.begin(), r.not_excited.end(), name), r.not_excited.end())
        << name;
  }
  for (Eigen::Index i = 0; i < r.estimate.x.size(); ++i)
    EXPECT_LT(r.estimate.std_dev[i], 1e3) << r.names[i] << " = " << r.estimate.x[i];
}

// Joint 2 moves alone: motor 3 (q_m3 = q2 + q3, the IRp-6's parallelogram drive) turns with it,
// u = q̇2, so its Coulomb work is Fc2's column exactly and the two are one parameter. They were
// both kept (Fc2 26.9 ± 219, Fcm3 1.9 ± 219 with long integrals: the motor's column was the
// unfiltered ∫|u| beside the joint's parallel-filtered one); now the two columns are equal to
// round-off, so the data regroup them into one parameter named as the base set names its
// regroupings, Fc2R = Fc2 + Fcm3 = 28.75 N·m (Fcm3 is 0 in the plant), and say so (issue 28
// item 7).
TEST(IntegralIrp6Example, MotorTurningWithOneJointIsRegroupedIntoItsFriction) {
  const IdentificationResult& r = example_union().joint2_long;
  ASSERT_NE(std::find(r.not_excited.begin(), r.not_excited.end(), "Fcm3"), r.not_excited.end());
  ASSERT_NE(std::find(r.data_regrouped.begin(), r.data_regrouped.end(), "Fcm3"),
            r.data_regrouped.end());
  const auto fc2 = std::find(r.names.begin(), r.names.end(), "Fc2");
  ASSERT_NE(fc2, r.names.end());
  const auto i = fc2 - r.names.begin();
  const auto j =
      std::find(r.not_excited.begin(), r.not_excited.end(), "Fcm3") - r.not_excited.begin();
  EXPECT_NEAR(r.data_regrouping(i, j), 1.0, 1e-6);
  ASSERT_EQ(r.labels.size(), r.names.size());
  EXPECT_EQ(r.labels[static_cast<size_t>(i)], "Fc2R");
  const std::string& expression = r.expressions[static_cast<size_t>(i)];
  EXPECT_EQ(expression.rfind("Fc2R = Fc2", 0), 0u) << expression;
  EXPECT_NE(expression.find("+ 1*Fcm3 (on these data)"), std::string::npos) << expression;
  bool named = false;
  for (const auto& w : r.warnings)
    named |= w.rfind(
                 "Fcm3 is regrouped on these data: its column is a combination of the "
                 "estimated ones to round-off",
                 0) == 0 &&
             w.find(expression) != std::string::npos;
  EXPECT_TRUE(named);
  // The parameters the data leave undetermined keep their wording.
  bool undetermined = false;
  for (const auto& w : r.warnings) undetermined |= w.find(" is not excited: ") != std::string::npos;
  EXPECT_TRUE(undetermined);
  EXPECT_LT(r.estimate.std_dev[i], 0.1 * 28.75) << r.estimate.x[i];
  EXPECT_NEAR(r.estimate.x[i], 28.75, 0.1 * 28.75);
  for (size_t k = 0; k < r.names.size(); ++k)
    if (r.labels[k] != r.names[k])
      std::cout << "regrouped on these data: " << r.expressions[k] << "\n";
  // The result file reports Fc2R and keeps the base name a later command looks up.
  const nlohmann::json file =
      identification_to_json(load_robot("irp6"), r, nlohmann::json::object());
  const nlohmann::json& p = file["parameters"][static_cast<size_t>(i)];
  EXPECT_EQ(p["name"], "Fc2R");
  EXPECT_EQ(p["base_name"], "Fc2");
  EXPECT_EQ(p["expression"], expression);
  EXPECT_EQ(file["data_regrouped"].get<std::vector<std::string>>(), r.data_regrouped);
  EXPECT_EQ(identification_result_from_json(file, "joint2.json").names, r.names);
  EXPECT_NE(identification_table(load_robot("irp6"), r).find("Fc2R "), std::string::npos);
  // The union: joints 2 and 3 each move alone in one run, so Fcm3 = Fc2 + Fc3 on the union.
  const IdentificationResult& all = example_union().long_seed1;
  EXPECT_NE(std::find(all.not_excited.begin(), all.not_excited.end(), "Fcm3"),
            all.not_excited.end());
}

// Seed 1's ranking, from its mechanism: an unmodelled constant torque offset b_j does the work
// b_j·Δq_j over an interval. Short rows see b_j·q̇_j·h, small and of either sign; a long row sees
// b_j·(q_j(t) − q_j(t_0)), as large as the change of potential energy it is fitted with. With seed
// 1's friction model (no Fo column) long integrals then recover the friction worse than short
// ones (docs/methods/identification.md §4, "Short against long integrals").
TEST(IntegralIrp6Example, UnmodelledTorqueOffsetMakesLongIntegralsWorseThanShortOnes) {
  const ExampleUnion& u = example_union();
  const double short_error =
      friction_error(u.short_seed1, estimated_truth(u.short_seed1, u.all_seed1));
  const double long_error =
      friction_error(u.long_seed1, estimated_truth(u.long_seed1, u.all_seed1));
  std::cout << "largest friction error, no Fo column: short " << short_error << ", long "
            << long_error << "; with Fo, short "
            << friction_error(u.short_fo, estimated_truth(u.short_fo, u.all)) << "\n";
  EXPECT_GT(long_error, 1.5 * short_error);
}

// Which sensor imperfection makes long integrals worse than short ones (seed 1 §VI-A)? One
// ingredient at a time on the IRp-6 run above, identified through identify() with short and long
// integrals; the error is the torque prediction of each estimate on the run's true states and
// applied torques (so it measures the parameters, not the sensors). On demand only (≈ 1 min):
//   identification_tests --gtest_also_run_disabled_tests --gtest_filter='*SensorIngredientsStudy'
// Results in docs/methods/identification.md §4, "Short against long integrals".
struct Ingredient {
  const char* name;
  SensorOptions sensors;                             // in the loop (encoder, white torque noise)
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  // constant torque offset [N·m]
  Eigen::Vector3d drift = Eigen::Vector3d::Zero();   // offset reached linearly at the end [N·m]
  double tach_noise = -1.0;   // tachometer white noise [rad/s]; < 0: dq derived from q
  double tach_offset = 0.0;   // tachometer offset [rad/s] (all joints)
  bool stribeck = false;      // native plant with a Stribeck bump the model does not have
  bool offset_column = true;  // identify Fo (seed 1's model has none)
};

TEST(IntegralIrp6, DISABLED_SensorIngredientsStudy) {
  const Model model = load_robot("irp6");
  const double ts = 5e-4;
  const Reference ref = seed1_moves(ts);
  std::vector<Ingredient> list;
  auto add = [&](const char* name) -> Ingredient& {
    list.push_back(Ingredient{name, {}});
    list.back().sensors.seed = 7;
    return list.back();
  };
  add("ideal sensors");
  add("encoder white 2e-5 rad").sensors.position_noise_std = 2e-5;
  add("encoder quantised 2^18/rev").sensors.counts_per_rev = 262144;
  add("encoder quantised 2^16/rev").sensors.counts_per_rev = 65536;
  add("torque white 0.5 N·m").sensors.torque_noise_std = 0.5;
  add("torque offset (Fo identified)").offset << 0.8, -0.6, 0.5;
  {
    Ingredient& i = add("torque offset (no Fo, seed 1)");
    i.offset << 0.8, -0.6, 0.5;
    i.offset_column = false;
  }
  add("torque drift 0 -> 0.5 N·m").drift << 0.5, -0.5, 0.5;
  {
    Ingredient& i = add("torque drift, no Fo");
    i.drift << 0.5, -0.5, 0.5;
    i.offset_column = false;
  }
  add("tachometer white 5e-3 rad/s").tach_noise = 5e-3;
  {
    Ingredient& i = add("tachometer offset 2e-3 rad/s");
    i.tach_noise = 0.0;
    i.tach_offset = 2e-3;
  }
  add("unmodelled Stribeck (native)").stribeck = true;
  add("ideal sensors (native)");
  std::printf("%-32s %9s %9s %6s %6s\n", "ingredient", "short", "long", "out_s", "out_l");
  for (const Ingredient& ing : list) {
    PlantOptions plant;
    const bool native = std::string(ing.name).find("native") != std::string::npos;
    plant.engine = native ? PlantEngine::kNative : PlantEngine::kMujoco;
    if (ing.stribeck) {
      plant.native.friction.stiction = Eigen::VectorXd(3);
      for (int j = 0; j < 3; ++j)
        plant.native.friction.stiction[j] = 2.0 * model.joints[j].friction.Fc;
      plant.native.friction.stribeck_velocity = 0.1;
    }
    const ClosedLoopResult run = integral_testing::simulate(model, ref, ts, ing.sensors, plant);
    JointRecord rec{run.t, run.q, {}, {}, run.tau};
    std::mt19937_64 rng(11);
    std::normal_distribution<double> normal;
    const double duration = run.t[run.t.size() - 1];
    for (Eigen::Index k = 0; k < rec.tau.rows(); ++k) {
      rec.tau.row(k) += (ing.offset + ing.drift * (run.t[k] / duration)).transpose();
    }
    if (ing.tach_noise >= 0.0) {
      rec.dq = run.dq_true;
      for (Eigen::Index i = 0; i < rec.dq.size(); ++i)
        rec.dq.data()[i] += ing.tach_offset + ing.tach_noise * normal(rng);
    }
    IdentifyOptions io;
    io.signal.torque_time_offset = 0.5 * ts;
    io.layout.offset = ing.offset_column;
    io.model = IdentificationModel::kIntegral;
    const JointRecord clean{run.t, run.q_true, run.dq_true, {}, run.tau_true};
    double err[2];
    int out[2];
    for (int l = 0; l < 2; ++l) {
      io.integral.long_integrals = l == 1;
      const IdentificationResult res = identify(model, rec, io);
      Eigen::VectorXd all((Eigen::VectorXd(io.layout.columns(3) + 3) << io.layout.parameters(model),
                           Eigen::VectorXd::Zero(3))
                              .finished());
      const Eigen::VectorXd truth = res.base.reduce(all);
      out[l] = 0;
      for (size_t i = 0; i < res.names.size(); ++i) {
        const auto at = std::find(res.base.names.begin(), res.base.names.end(), res.names[i]);
        const double t = truth[at - res.base.names.begin()];
        out[l] += !(res.estimate.ci_lower[i] <= t && t <= res.estimate.ci_upper[i]);
      }
      IdentifyOptions vo;
      vo.signal.torque_time_offset = 0.5 * ts;
      vo.layout = io.layout;
      err[l] = validate_torques(model, clean, res.names, res.estimate.x, vo, res.not_excited)
                   .relative_error_all;
    }
    std::printf("%-32s %8.2f%% %8.2f%% %6d %6d\n", ing.name, 100 * err[0], 100 * err[1], out[0],
                out[1]);
  }
}

}  // namespace
}  // namespace dynid
