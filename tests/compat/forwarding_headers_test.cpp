// The public header paths that issue 24 moved still compile for one release: each old path
// forwards to the header that now holds its declarations (docs/design.md section 2).

#include <type_traits>

#include <gtest/gtest.h>

#include "dynid/estimation/closed_loop.hpp"
#include "dynid/estimation/closed_loop_options.hpp"
#include "dynid/estimation/completed_model.hpp"
#include "dynid/estimation/cutoff_selection.hpp"
#include "dynid/estimation/decoupled_model.hpp"
#include "dynid/estimation/friction_experiment.hpp"
#include "dynid/estimation/gravity_experiment.hpp"
#include "dynid/estimation/identification.hpp"
#include "dynid/estimation/integral_equations.hpp"
#include "dynid/estimation/integral_options.hpp"
#include "dynid/estimation/known_friction.hpp"
#include "dynid/estimation/load_identification.hpp"
#include "dynid/estimation/maximum_likelihood.hpp"
#include "dynid/estimation/outlier_options.hpp"
#include "dynid/estimation/outliers.hpp"
#include "dynid/estimation/physical_parameters.hpp"
#include "dynid/estimation/pipeline.hpp"
#include "dynid/estimation/processed_slice.hpp"
#include "dynid/estimation/projection.hpp"
#include "dynid/io/streaming_identification.hpp"
#include "dynid/io/urdf_export.hpp"
#include "dynid/model/robots.hpp"

namespace dynid {
namespace {

// One declaration of each old header, named through its old include path.
TEST(ForwardingHeaders, OldPathsDeclareWhatTheyDeclaredBefore) {
  static_assert(std::is_class_v<ClosedLoopRun>);
  static_assert(std::is_class_v<ClosedLoopIdOptions>);
  static_assert(std::is_class_v<CompletedModel>);
  static_assert(std::is_class_v<CutoffSelection>);
  static_assert(std::is_class_v<DecoupledJointResult>);
  static_assert(std::is_class_v<FrictionExperimentResult>);
  static_assert(std::is_class_v<GravityExperimentResult>);
  static_assert(std::is_class_v<IntegralOptions>);
  static_assert(std::is_class_v<KnownFriction>);
  static_assert(std::is_class_v<LoadIdentificationResult>);
  static_assert(std::is_class_v<MaximumLikelihoodOptions>);
  static_assert(std::is_class_v<OutlierOptions>);
  static_assert(std::is_class_v<TorqueOutlier>);
  static_assert(std::is_class_v<PhysicalFit>);
  static_assert(std::is_class_v<DataIdentifiability>);
  static_assert(std::is_class_v<SignalProjector>);
  static_assert(std::is_class_v<StreamingIdentificationOptions>);
  static_assert(std::is_class_v<UrdfExport>);
  // estimation/identification.hpp was split in four: all of it is still reached.
  static_assert(std::is_class_v<JointRecord> && std::is_class_v<ProcessedRecord>);
  static_assert(std::is_class_v<IdentifyOptions> && std::is_class_v<ValidationResult>);
  EXPECT_NE(&processed_slice, nullptr);
  EXPECT_NE(&integral_equations, nullptr);
  const Model model = load_robot("planar2");
  const Model same = identified_model(model, {}, Eigen::VectorXd(), IdentifyOptions{});
  EXPECT_EQ(same.dof(), model.dof());
}

}  // namespace
}  // namespace dynid
