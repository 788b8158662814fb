// A stored result applied again (report/stored_result.hpp): the options the command line and the
// Python module rebuild from a result JSON, and the complete model of a result, whose dynamics
// must be those of the robot the result describes (oracle: RNEA of that robot).

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/report/stored_result.hpp"
#include "support/error_of.hpp"

namespace dynid {
namespace {

using testing::error_of;

IdentifiedResultFile result_with_options(const nlohmann::json& options) {
  IdentifiedResultFile f;
  f.options = options;
  return f;
}

TEST(FrictionLayout, ReadsTheTextFormOfFriction) {
  const ParameterLayout a = friction_layout("asymmetric,offset", false);
  EXPECT_TRUE(a.viscous && a.coulomb && a.asymmetric && a.offset);
  EXPECT_FALSE(a.armature);
  const ParameterLayout none = friction_layout("none", true);
  EXPECT_TRUE(none.armature);
  EXPECT_FALSE(none.viscous || none.coulomb || none.offset || none.asymmetric);
  EXPECT_THROW(friction_layout("viscous,sticky", true), UsageError);
}

TEST(ApplyFilterText, SetsFamilyOrderAndRipple) {
  SignalOptions s;
  apply_filter_text("chebyshev", s);
  EXPECT_EQ(s.family, LowpassFamily::kChebyshev1);
  EXPECT_EQ(s.order, 8);  // seed 2 §3.4
  apply_filter_text("butterworth:6", s);
  EXPECT_EQ(s.family, LowpassFamily::kButterworth);
  EXPECT_EQ(s.order, 6);
  apply_filter_text("none", s);
  EXPECT_FALSE(s.filter);
  EXPECT_THROW(apply_filter_text("bessel", s), UsageError);
  EXPECT_THROW(apply_filter_text("butterworth:x", s), UsageError);
}

TEST(ApplyFirText, ReadsTwoLagOrders) {
  ProjectionOptions p;
  apply_fir_text("3,4", p);
  EXPECT_EQ(p.m1, 3);
  EXPECT_EQ(p.m2, 4);
  EXPECT_THROW(apply_fir_text("3", p), UsageError);
  EXPECT_THROW(apply_fir_text("-1,2", p), UsageError);
  EXPECT_THROW(apply_fir_text("3,4x", p), UsageError);
}

// A result of the command line: text friction and filter, and what identify chose.
TEST(OptionsOfStoredResult, RebuildsTheCommandLinesOptionsAndWhatIdentifyChose) {
  IdentifiedResultFile f = result_with_options({{"friction", "viscous,coulomb"},
                                                {"armature", false},
                                                {"filter", "chebyshev:6:0.3"},
                                                {"savitzky_golay", true},
                                                {"torque_offset_s", 0.001},
                                                {"filter_coulomb_columns", true},
                                                {"torque_scale", {2.0, 3.0}},
                                                {"cutoff_hz", 0.0}});
  f.cutoff_hz = 12.5;
  f.zero_velocity_threshold = {0.01, 0.02};
  const StoredIdentifyOptions s = options_of_stored_result(f, "r.json", 2);
  const IdentifyOptions& o = s.options;
  EXPECT_TRUE(o.layout.viscous && o.layout.coulomb);
  EXPECT_FALSE(o.layout.armature || o.layout.offset || o.layout.asymmetric);
  EXPECT_EQ(o.signal.family, LowpassFamily::kChebyshev1);
  EXPECT_EQ(o.signal.order, 6);
  EXPECT_DOUBLE_EQ(o.signal.ripple_db, 0.3);
  EXPECT_DOUBLE_EQ(o.signal.cutoff_hz, 12.5);  // the cut-off identify used, not "auto"
  EXPECT_TRUE(o.signal.savitzky_golay && o.signal.filter_coulomb_columns);
  EXPECT_DOUBLE_EQ(o.signal.torque_time_offset, 0.001);
  EXPECT_EQ(o.signal.zero_velocity, (std::vector<double>{0.01, 0.02}));
  EXPECT_EQ(s.torque_scale, (std::vector<double>{2.0, 3.0}));
  // cut-off, thresholds, time shift (issue 26 item 7), torque scale: each said once
  EXPECT_EQ(s.notes.size(), 4u);
  // A result before time_shift_s has only torque_offset_s; a newer one wins with its own key.
  IdentifiedResultFile newer = f;
  newer.options["time_shift_s"] = 0.002;
  EXPECT_DOUBLE_EQ(options_of_stored_result(newer, "r.json", 2).options.signal.torque_time_offset,
                   0.002);

  StoredOptionOverrides over;
  over.cutoff = 5.0;
  over.zero_velocity = {0.1};
  over.torque_scale_given = true;
  over.time_shift = 0.0;
  const StoredIdentifyOptions given = options_of_stored_result(f, "r.json", 2, over);
  EXPECT_DOUBLE_EQ(given.options.signal.cutoff_hz, 5.0);
  EXPECT_EQ(given.options.signal.zero_velocity, (std::vector<double>{0.1}));
  EXPECT_TRUE(given.torque_scale.empty());
  EXPECT_DOUBLE_EQ(given.options.signal.torque_time_offset, 0.0);
  EXPECT_TRUE(given.notes.empty());
}

// A result of the Python module: booleans for the friction terms and the filter.
TEST(OptionsOfStoredResult, ReadsAPythonResultsBooleans) {
  const IdentifiedResultFile f = result_with_options({{"armature", true},
                                                      {"viscous", false},
                                                      {"coulomb", true},
                                                      {"offset", false},
                                                      {"asymmetric", false},
                                                      {"filter", false},
                                                      {"cutoff_hz", 7.0}});
  const IdentifyOptions o = options_of_stored_result(f, "result", 3).options;
  EXPECT_TRUE(o.layout.armature && o.layout.coulomb);
  EXPECT_FALSE(o.layout.viscous || o.layout.offset || o.layout.asymmetric);
  EXPECT_FALSE(o.signal.filter);
  EXPECT_DOUBLE_EQ(o.signal.cutoff_hz, 7.0);
  EXPECT_TRUE(o.signal.zero_velocity.empty());
}

TEST(OptionsOfStoredResult, AFileFaultNamesTheFileAndTheKey) {
  const std::string bad_term = error_of([] {
    options_of_stored_result(result_with_options({{"friction", "sticky"}}), "r.json", 2);
  });
  EXPECT_NE(bad_term.find("'r.json': options.friction: unknown term 'sticky'"), std::string::npos)
      << bad_term;
  // The file is at fault, not a flag: an Error, not a UsageError (exit 1, not 2).
  EXPECT_THROW(options_of_stored_result(result_with_options({{"filter", "bessel"}}), "r.json", 2),
               Error);
  try {
    options_of_stored_result(result_with_options({{"filter", "bessel"}}), "r.json", 2);
  } catch (const UsageError&) {
    ADD_FAILURE() << "a stored option's fault is reported as a usage error";
  } catch (const Error&) {
  }
  const std::string bad_type = error_of([] {
    options_of_stored_result(result_with_options({{"savitzky_golay", "yes"}}), "r.json", 2);
  });
  EXPECT_NE(bad_type.find("options.savitzky_golay has the wrong type"), std::string::npos)
      << bad_type;
}

// The complete model of a result identified on another robot of the same type (heavier links,
// friction): its dynamics are that robot's, whatever the nominal model's values.
TEST(CompletedModelOfResult, HasTheDynamicsOfTheRobotTheResultDescribes) {
  const Model nominal = load_robot("puma560");
  Model truth = nominal;
  const int n = nominal.dof();
  for (int j = 0; j < n; ++j) {
    truth.links[j] *= 1.0 + 0.1 * (j + 1);  // scaling all ten keeps each link physical
    truth.joints[j].friction.Fv = 0.5 + 0.1 * j;
    truth.joints[j].friction.Fc = 0.3 + 0.05 * j;
    truth.joints[j].friction.Ia = 0.01 * (j + 1);
  }
  BaseParameterOptions bo;
  bo.layout = friction_layout("viscous,coulomb", true);
  const BaseParameters base = compute_base_parameters(nominal, bo);
  IdentifiedResultFile f = result_with_options({{"friction", "viscous,coulomb"}});
  f.robot = nominal.name;
  f.names = base.names;
  f.values = base.reduce(bo.layout.parameters(truth));
  f.std_devs = 1e-6 * f.values.cwiseAbs().array() + 1e-9;  // well determined
  const CompletedModel c = completed_model_of_result(nominal, f, "r.json");
  EXPECT_TRUE(c.nominal_not_excited.empty());
  EXPECT_TRUE(c.nominal_badly_determined.empty());
  const nlohmann::json sources = parameter_sources_json(c);
  EXPECT_EQ(sources.at("identified").size(), base.names.size());
  std::srand(3);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = Eigen::VectorXd::Random(n) * 2.0;
    const Eigen::VectorXd dq = Eigen::VectorXd::Random(n);
    const Eigen::VectorXd ddq = Eigen::VectorXd::Random(n) * 3.0;
    const Eigen::VectorXd expected = rnea(truth, q, dq, ddq);
    const Eigen::VectorXd got = rnea(c.model, q, dq, ddq);
    EXPECT_LT((got - expected).norm(), 1e-9 * (1.0 + expected.norm())) << "state " << k;
    // The nominal model itself is measurably different: the test can fail.
    EXPECT_GT((rnea(nominal, q, dq, ddq) - expected).norm(), 1e-3 * (1.0 + expected.norm()));
  }
}

}  // namespace
}  // namespace dynid
