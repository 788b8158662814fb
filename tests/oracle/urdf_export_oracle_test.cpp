// The exported URDF (physical/urdf_export.hpp), loaded by dynid, by KDL and by MuJoCo, predicts the
// torques of the identified base model Y_b·θ_b (issue 15 item 3).
#include <cstdio>
#include <fstream>
#include <memory>
#include <random>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "dynid/dynamics/rnea.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/io/urdf_writer.hpp"
#include "dynid/model/robots.hpp"
#include "dynid/model/urdf_loader.hpp"
#include "dynid/physical/urdf_export.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "oracle/kdl_bridge.hpp"
#include "oracle/oracle_support.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::random_vector;

// A consistent "identified" set away from the nominal one: every mass and inertia changed, centres
// of mass moved, per-joint terms changed (the role of identify --physical's standard_parameters).
Eigen::VectorXd identified_parameters(const Model& nominal, const ParameterLayout& layout,
                                      unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  const int n = nominal.dof();
  Eigen::VectorXd theta = layout.parameters(nominal);
  for (int j = 0; j < n; ++j) {
    const ComInertial in = com_inertial(nominal.links[j]);
    const double m = in.mass * (0.9 + 0.2 * u(rng)) + 0.3;
    const Eigen::Vector3d c = in.com + 0.02 * random_vector(3, rng);
    // Scaling keeps the triangle inequalities; adding a multiple of 1 keeps them too.
    const Eigen::Matrix3d R =
        Eigen::AngleAxisd(u(rng), Eigen::Vector3d(u(rng), u(rng), 1.0).normalized()).matrix();
    const Eigen::Matrix3d I_C =
        R * in.inertia * R.transpose() * (1.0 + u(rng)) + 0.01 * Eigen::Matrix3d::Identity();
    theta.segment<kLinkParams>(kLinkParams * j) = link_params_from_com(m, c, I_C);
  }
  for (Eigen::Index k = kLinkParams * n; k < theta.size(); ++k) theta[k] += 0.05 + 0.1 * u(rng);
  return theta;
}

// The identified terms no URDF holds (Ia, Fo) and those a loader may not apply (Fv, Fc).
Eigen::VectorXd joint_terms(const Model& m, const Eigen::VectorXd& dq, const Eigen::VectorXd& ddq,
                            bool ia_fo, bool fv, bool fc) {
  Eigen::VectorXd tau = Eigen::VectorXd::Zero(m.dof());
  for (int j = 0; j < m.dof(); ++j) {
    const JointFriction& f = m.joints[j].friction;
    if (ia_fo) tau[j] += f.Ia * ddq[j] + f.Fo;
    if (fv) tau[j] += f.Fv * dq[j];
    if (fc) tau[j] += f.Fc * (dq[j] > 0.0 ? 1.0 : dq[j] < 0.0 ? -1.0 : 0.0);
  }
  return tau;
}

struct MujocoDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
  void operator()(mjData* d) const { mj_deleteData(d); }
};

class UrdfExportOracle : public ::testing::TestWithParam<const char*> {};

TEST_P(UrdfExportOracle, ExportedUrdfPredictsTheIdentifiedBaseModel) {
  const Model nominal = load_robot(GetParam());
  const int n = nominal.dof();
  const ParameterLayout layout = ParameterLayout::full();
  BaseParameterOptions bo;
  bo.layout = layout;
  const BaseParameters base = compute_base_parameters(nominal, bo);
  const Eigen::VectorXd theta = identified_parameters(nominal, layout, 7);
  const Eigen::VectorXd theta_b = base.reduce(theta);

  const UrdfExport exported = export_urdf(nominal, layout.names(n), theta, "test.json");
  // Ia and Fo of every joint are named as not held by the URDF.
  EXPECT_EQ(exported.not_in_urdf.size(), static_cast<size_t>(2 * n));
  const std::string path = ::testing::TempDir() + "/export_oracle_" + nominal.name + ".urdf";
  std::ofstream(path) << exported.text;

  const Model reloaded = load_urdf(path);
  ASSERT_EQ(reloaded.dof(), n);
  std::vector<std::string> names;
  for (const Joint& j : reloaded.joints) names.push_back(j.name);
  const double gravity[3] = {0.0, 0.0, -9.81};
  kdl::Tree kdl(exported.text, kdl::UrdfSource::kText, names, gravity);
  char error[1000] = "";
  std::unique_ptr<mjModel, MujocoDeleter> mj(mj_loadXML(path.c_str(), nullptr, error, 1000));
  std::remove(path.c_str());
  ASSERT_TRUE(mj) << error;
  std::unique_ptr<mjData, MujocoDeleter> md(mj_makeData(mj.get()));
  // Coulomb friction is MuJoCo's frictionloss, a soft constraint rather than Fc·sign(dq): the
  // constraints are switched off and Fc added as for KDL. Damping is MuJoCo's own.
  mj->opt.disableflags |= mjDSBL_CONSTRAINT;
  ASSERT_EQ(mj->nv, n);
  std::vector<int> dof(n);
  for (int j = 0; j < n; ++j) {
    const int id = mj_name2id(mj.get(), mjOBJ_JOINT, nominal.joints[j].name.c_str());
    ASSERT_GE(id, 0) << nominal.joints[j].name;
    dof[j] = mj->jnt_dofadr[id];
    EXPECT_EQ(mj->dof_damping[dof[j]], exported.model.joints[j].friction.Fv);
    EXPECT_EQ(mj->dof_armature[dof[j]], 0.0);
  }

  Workspace ws(nominal), ws_reloaded(reloaded);
  Eigen::MatrixXd Y(n, layout.columns(n));
  std::mt19937 rng(11);
  double worst_dynid = 0.0, worst_kdl = 0.0, worst_mujoco = 0.0;
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(n, rng, 2.5), dq = random_vector(n, rng, 2.0),
                          ddq = random_vector(n, rng, 5.0);
    torque_regressor(nominal, ws, layout, q, dq, ddq, Y);
    const Eigen::VectorXd tau_base = base.select(Y) * theta_b;

    Eigen::VectorXd tau(n);
    rnea(reloaded, ws_reloaded, q, dq, ddq, tau);
    tau += joint_terms(exported.model, dq, ddq, true, false, false);
    worst_dynid = std::max(worst_dynid, (tau - tau_base).norm() / tau_base.norm());

    ASSERT_GE(kdl.inverse_dynamics(q.data(), dq.data(), ddq.data(), tau.data()), 0);
    tau += joint_terms(exported.model, dq, ddq, true, true, true);
    worst_kdl = std::max(worst_kdl, (tau - tau_base).norm() / tau_base.norm());

    for (int j = 0; j < n; ++j) {
      md->qpos[dof[j]] = q[j];
      md->qvel[dof[j]] = dq[j];
      md->qacc[dof[j]] = ddq[j];
    }
    mj_inverse(mj.get(), md.get());
    for (int j = 0; j < n; ++j) tau[j] = md->qfrc_inverse[dof[j]];
    tau += joint_terms(exported.model, dq, ddq, true, false, true);
    worst_mujoco = std::max(worst_mujoco, (tau - tau_base).norm() / tau_base.norm());
  }
  EXPECT_LT(worst_dynid, testing::kOracleTolerance);
  EXPECT_LT(worst_kdl, testing::kOracleTolerance);
  EXPECT_LT(worst_mujoco, testing::kOracleTolerance);
  std::printf("%s: relative torque difference dynid %.2g, KDL %.2g, MuJoCo %.2g\n",
              nominal.name.c_str(), worst_dynid, worst_kdl, worst_mujoco);
}

// iiwa14 is a URDF with fixed links (edited in place); puma560 an MDH table (written by to_urdf).
INSTANTIATE_TEST_SUITE_P(Robots, UrdfExportOracle, ::testing::Values("iiwa14", "puma560"));

}  // namespace
}  // namespace dynid
