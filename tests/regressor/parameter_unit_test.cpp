// parameter_unit: the SI unit of each parameter name, by kind and by the type of its joint
// (every third joint of random_tree(…, prismatic = true) is prismatic: joint 3 here).
#include <gtest/gtest.h>

#include "dynid/model/robots.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/regressor/parameter_layout.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

TEST(ParameterUnit, KindAndJointTypeGiveTheUnit) {
  const Model model = testing::random_tree(4, 3, true, true);
  ASSERT_EQ(model.joints[2].type, JointType::kPrismatic);
  ASSERT_EQ(model.joints[0].type, JointType::kRevolute);
  EXPECT_EQ(parameter_unit(model, "XX1"), "kg·m²");
  EXPECT_EQ(parameter_unit(model, "ZZ2R"), "kg·m²");
  EXPECT_EQ(parameter_unit(model, "MX2R"), "kg·m");
  EXPECT_EQ(parameter_unit(model, "M3"), "kg");
  EXPECT_EQ(parameter_unit(model, "Ia1"), "kg·m²");
  EXPECT_EQ(parameter_unit(model, "Ia3"), "kg");
  EXPECT_EQ(parameter_unit(model, "Fv1"), "N·m·s/rad");
  EXPECT_EQ(parameter_unit(model, "Fvn3"), "N·s/m");
  EXPECT_EQ(parameter_unit(model, "Fc2R"), "N·m");
  EXPECT_EQ(parameter_unit(model, "Fcp3"), "N");
  EXPECT_EQ(parameter_unit(model, "Fo3"), "N");
  // Every name the layout makes has a unit.
  for (const auto& name : ParameterLayout::full().names(model.dof())) {
    EXPECT_FALSE(parameter_unit(model, name).empty()) << name;
  }
  // Coupled motors (the IRp-6's motor 3 turns with q2 + q3): every coupling column has a unit.
  const Model irp6 = load_robot("irp6");
  const std::vector<std::string> coupled = coupling_column_names(irp6);
  ASSERT_FALSE(coupled.empty());
  for (const auto& name : coupled) EXPECT_FALSE(parameter_unit(irp6, name).empty()) << name;
  EXPECT_EQ(parameter_unit(irp6, "Fcm3"), "N·m");
  EXPECT_EQ(parameter_unit(irp6, "Iam3"), "kg·m²");
  for (const char* other : {"Fo5", "XX0", "foo", "XX1Q", "M", "12", "XX99999"}) {
    EXPECT_EQ(parameter_unit(model, other), "") << other;
  }
}

}  // namespace
}  // namespace dynid
