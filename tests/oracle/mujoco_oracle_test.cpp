// RNEA (with armature and viscous friction), the mass matrix and the articulated-body forward
// dynamics against MuJoCo's mj_inverse and qM on the same URDF text.
#include <cstdio>
#include <fstream>
#include <random>

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include "dynid/dynamics/articulated_body.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/io/urdf_writer.hpp"
#include "oracle/oracle_support.hpp"
#include "support/random_models.hpp"

namespace dynid {
namespace {

using testing::random_tree;
using testing::random_vector;

struct MujocoModel {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  ~MujocoModel() {
    if (d) mj_deleteData(d);
    if (m) mj_deleteModel(m);
  }
};

void load(const Model& model, MujocoModel& out) {
  UrdfWriteOptions options;
  options.mujoco_compiler_tag = true;
  const std::string path = ::testing::TempDir() + "/mujoco_oracle_" + model.name + ".urdf";
  std::ofstream(path) << to_urdf(model, options);
  char error[1000] = "";
  out.m = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  std::remove(path.c_str());
  ASSERT_NE(out.m, nullptr) << error;
  out.d = mj_makeData(out.m);
  for (int k = 0; k < 3; ++k) out.m->opt.gravity[k] = model.gravity[k];
  out.m->opt.disableflags |= mjDSBL_CONSTRAINT;  // joint limits must not act in this comparison
}

Eigen::Matrix3d rotation(const mjtNum* quat) {
  mjtNum R[9];
  mju_quat2Mat(R, quat);
  return Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(R);
}

// A dynid model rebuilt from MuJoCo's compiled body and joint data (body frames = link frames for
// an imported URDF). MuJoCo diagonalises each inertia tensor with an iterative eigen solver when it
// compiles, so the compiled bodies differ from the URDF's in the 9th digit; comparing the
// algorithms on identical parameters keeps that import step out of the 1e-9 check.
Model from_compiled(const Model& original, const mjModel* m, const std::vector<int>& joint_ids) {
  Model out = original;
  for (int j = 0; j < out.dof(); ++j) {
    const int jid = joint_ids[j];
    const int b = m->jnt_bodyid[jid];
    Joint& joint = out.joints[j];
    joint.R_PJ = rotation(m->body_quat + 4 * b);
    joint.p_PJ = Eigen::Map<const Eigen::Vector3d>(m->body_pos + 3 * b);
    joint.axis = Eigen::Map<const Eigen::Vector3d>(m->jnt_axis + 3 * jid);
    const Eigen::Matrix3d R_i = rotation(m->body_iquat + 4 * b);
    const Eigen::Vector3d d = Eigen::Map<const Eigen::Vector3d>(m->body_inertia + 3 * b);
    out.links[j] = link_params_from_com(m->body_mass[b],
                                        Eigen::Map<const Eigen::Vector3d>(m->body_ipos + 3 * b),
                                        R_i * d.asDiagonal() * R_i.transpose());
  }
  out.finalize();
  return out;
}

class MujocoOracle : public ::testing::TestWithParam<unsigned> {};

TEST_P(MujocoOracle, RneaMatchesMjInverse) {
  const unsigned seed = GetParam();
  Model model = random_tree(8, seed, true, seed % 2 == 0);
  for (auto& j : model.joints) j.friction.Fc = j.friction.Fo = 0.0;  // not plain mj_inverse terms
  MujocoModel mj;
  load(model, mj);
  ASSERT_EQ(mj.m->nv, 8);
  std::vector<int> dof(8), ids(8);
  for (int j = 0; j < 8; ++j) {
    const int id = ids[j] = mj_name2id(mj.m, mjOBJ_JOINT, model.joints[j].name.c_str());
    ASSERT_GE(id, 0) << model.joints[j].name;
    ASSERT_EQ(mj.m->jnt_pos[3 * id] * mj.m->jnt_pos[3 * id] +
                  mj.m->jnt_pos[3 * id + 1] * mj.m->jnt_pos[3 * id + 1] +
                  mj.m->jnt_pos[3 * id + 2] * mj.m->jnt_pos[3 * id + 2],
              0.0);
    dof[j] = mj.m->jnt_dofadr[id];
    ASSERT_EQ(mj.m->jnt_qposadr[id], dof[j]);  // hinge and slide joints only
    mj.m->dof_armature[dof[j]] = model.joints[j].friction.Ia;
    EXPECT_NEAR(mj.m->dof_damping[dof[j]], model.joints[j].friction.Fv, 1e-15);
  }
  // The import itself: frames, masses and first moments are exact; the rotational inertia carries
  // the accuracy of MuJoCo's iterative 3×3 eigen solver (seen: up to 2e-7 of the tensor's norm).
  const Model compiled = from_compiled(model, mj.m, ids);
  for (int j = 0; j < 8; ++j) {
    EXPECT_LT((compiled.joints[j].R_PJ - model.joints[j].R_PJ).norm(), 1e-14);
    EXPECT_LT((compiled.joints[j].p_PJ - model.joints[j].p_PJ).norm(), 1e-14);
    EXPECT_LT((compiled.links[j].tail<4>() - model.links[j].tail<4>()).norm(), 1e-12);
    EXPECT_LT((compiled.links[j].head<6>() - model.links[j].head<6>()).norm(),
              1e-6 * model.links[j].head<6>().norm());
  }
  Workspace ws(compiled);
  std::mt19937 rng(seed);
  for (int k = 0; k < 20; ++k) {
    const Eigen::VectorXd q = random_vector(8, rng, 3.0), dq = random_vector(8, rng, 2.0),
                          ddq = random_vector(8, rng, 5.0);
    for (int j = 0; j < 8; ++j) {
      mj.d->qpos[dof[j]] = q[j];
      mj.d->qvel[dof[j]] = dq[j];
      mj.d->qacc[dof[j]] = ddq[j];
    }
    mj_inverse(mj.m, mj.d);
    Eigen::VectorXd tau(8), tau_mj(8);
    rnea(compiled, ws, q, dq, ddq, tau);
    for (int j = 0; j < 8; ++j) tau_mj[j] = mj.d->qfrc_inverse[dof[j]];
    EXPECT_LT((tau - tau_mj).norm() / tau_mj.norm(), testing::kOracleTolerance) << "state " << k;
    // The articulated-body algorithm takes MuJoCo's torque back to the acceleration it was given
    // (the comparison carries cond(M), as the KDL forward dynamics check).
    Eigen::VectorXd ddq_aba(8);
    articulated_body_forward_dynamics(compiled, ws, q, dq, tau_mj, ddq_aba);
    EXPECT_LT((ddq_aba - ddq).norm() / ddq.norm(), 1e3 * testing::kOracleTolerance)
        << "state " << k;
    // Mass matrix (armature included) against MuJoCo's composite-rigid-body qM, made dense.
    std::vector<mjtNum> dense(8 * 8);
    mj_fullM(mj.m, dense.data(), mj.d->qM);
    Eigen::MatrixXd M(8, 8), M_mj(8, 8);
    mass_matrix(compiled, ws, q, M);
    for (int i = 0; i < 8; ++i) {
      for (int j = 0; j < 8; ++j) M_mj(i, j) = dense[8 * dof[i] + dof[j]];
    }
    EXPECT_LT((M - M_mj).norm() / M_mj.norm(), testing::kOracleTolerance) << "state " << k;
  }
}

INSTANTIATE_TEST_SUITE_P(RandomTrees, MujocoOracle, ::testing::Values(1u, 2u, 3u, 4u));

}  // namespace
}  // namespace dynid
