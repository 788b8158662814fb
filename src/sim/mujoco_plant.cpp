// MuJoCo plant: the model exported by to_urdf() and loaded from an in-memory VFS.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include <mujoco/mujoco.h>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/io/urdf_writer.hpp"
#include "sim/plant_internal.hpp"

namespace dynid::detail {

namespace {

// Frictionloss constraint stiffness (see the constructor): time constant in steps, impedance.
constexpr double kFrictionTimeConstantSteps = 2.0;
constexpr double kFrictionImpedance = 0.9999;

// MuJoCo prints its warnings to stdout, where they would mix with dynid's results: keep the last
// one instead; step() turns the one that matters (divergence) into dynid's own error.
thread_local std::string last_mujoco_warning;

void keep_mujoco_warning(const char* message) {
  last_mujoco_warning = message ? message : "";
}

// MuJoCo's default error handler prints and waits for Enter; it must not return (MuJoCo's C code
// cannot be unwound by an exception), so it ends the process with dynid's one-line error. Output
// files are only written after a simulation, so nothing is left half-written.
void fail_on_mujoco_error(const char* message) {
  std::fprintf(stderr, "error: MuJoCo failed: %s; use --engine native or check the model\n",
               one_line(message ? message : "").c_str());
  std::fflush(stderr);
  std::_Exit(1);
}

void install_mujoco_handlers() {
  static const bool installed = [] {
    mju_user_warning = keep_mujoco_warning;
    mju_user_error = fail_on_mujoco_error;
    return true;
  }();
  (void)installed;
}

struct VfsDeleter {
  void operator()(mjVFS* vfs) const {
    mj_deleteVFS(vfs);
    delete vfs;
  }
};
struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};

class MujocoPlant final : public Plant {
 public:
  MujocoPlant(const Model& model, double dt, const MujocoPlantOptions& options)
      : n_(model.dof()),
        dt_(dt),
        q_(Eigen::VectorXd::Zero(n_)),
        dq_(Eigen::VectorXd::Zero(n_)),
        offset_(n_),
        asymmetry_v_(n_),
        asymmetry_c_(n_) {
    install_mujoco_handlers();
    UrdfWriteOptions urdf_options;
    urdf_options.mujoco_compiler_tag = true;
    std::string urdf = to_urdf(model, urdf_options);
    // MuJoCo refuses moving bodies without mass or inertia: add the compiler's floors.
    const std::string tag = "angle=\"radian\"";
    const std::size_t at = urdf.find(tag);
    if (at != std::string::npos && (options.bound_mass > 0.0 || options.bound_inertia > 0.0)) {
      std::ostringstream bounds;
      bounds.precision(17);
      bounds << " boundmass=\"" << options.bound_mass << "\" boundinertia=\""
             << options.bound_inertia << "\"";
      urdf.insert(at + tag.size(), bounds.str());
    }
    const std::string file = "dynid_plant.urdf";
    std::unique_ptr<mjVFS, VfsDeleter> vfs(new mjVFS);
    mj_defaultVFS(vfs.get());
    if (mj_makeEmptyFileVFS(vfs.get(), file.c_str(), static_cast<int>(urdf.size())) != 0)
      throw Error("mujoco plant: cannot create the in-memory URDF for model '" + model.name + "'");
    const int index = mj_findFileVFS(vfs.get(), file.c_str());
    std::memcpy(vfs->filedata[index], urdf.data(), urdf.size());
    char error[1000] = "";
    m_.reset(mj_loadXML(file.c_str(), vfs.get(), error, sizeof(error)));
    if (!m_)
      throw Error("mujoco plant: MuJoCo rejected model '" + model.name + "': " + error +
                  " (use the native engine or fix the model)");
    if (m_->nq != n_ || m_->nv != n_)
      throw Error("mujoco plant: MuJoCo built " + std::to_string(m_->nv) + " DoF for model '" +
                  model.name + "' with " + std::to_string(n_) + " joints; use the native engine");
    d_.reset(mj_makeData(m_.get()));
    qpos_.resize(n_);
    dof_.resize(n_);
    for (int j = 0; j < n_; ++j) {
      const Joint& joint = model.joints[j];
      const int id = mj_name2id(m_.get(), mjOBJ_JOINT, joint.name.c_str());
      if (id < 0)
        throw Error("mujoco plant: joint '" + joint.name + "' missing after the URDF import");
      qpos_[j] = m_->jnt_qposadr[id];
      dof_[j] = m_->jnt_dofadr[id];
      m_->dof_armature[dof_[j]] = joint.friction.Ia;
      m_->dof_damping[dof_[j]] = joint.friction.Fv;
      m_->dof_frictionloss[dof_[j]] = options.coulomb ? joint.friction.Fc : 0.0;
      offset_[j] = joint.friction.Fo;
      asymmetry_v_[j] = joint.friction.Fva;
      asymmetry_c_[j] = options.coulomb ? joint.friction.Fca : 0.0;
      // MuJoCo's frictionloss is a soft constraint: with the default solref (0.02 s) and solimp
      // (0.9–0.95) a light joint (wrist) sees a force proportional to its speed well before Fc,
      // i.e. viscous friction, and identification then finds Fc ≈ 0. The stiffest settings the
      // step allows (time constant 2·dt, impedance 0.9999) make it the Coulomb friction the model
      // describes (the wrist Fc of puma560 is then recovered within its interval, tests/sim).
      m_->dof_solref[2 * dof_[j]] = kFrictionTimeConstantSteps * dt;
      m_->dof_solref[2 * dof_[j] + 1] = 1.0;
      m_->dof_solimp[5 * dof_[j]] = kFrictionImpedance;
      m_->dof_solimp[5 * dof_[j] + 1] = kFrictionImpedance;
    }
    for (int k = 0; k < 3; ++k) m_->opt.gravity[k] = model.gravity[k];
    m_->opt.timestep = dt;
    m_->opt.integrator = options.integrator == MujocoIntegrator::kRk4 ? mjINT_RK4 : mjINT_IMPLICIT;
    m_->opt.disableflags |= mjDSBL_CONTACT | mjDSBL_EQUALITY;
    if (!options.enforce_limits) m_->opt.disableflags |= mjDSBL_LIMIT;
    reset(q_, dq_);
  }

  int dof() const override { return n_; }
  double dt() const override { return dt_; }
  double time() const override { return d_->time; }
  std::string engine() const override { return "mujoco"; }
  const Eigen::VectorXd& q() const override { return q_; }
  const Eigen::VectorXd& dq() const override { return dq_; }

  void reset(const Eigen::Ref<const Eigen::VectorXd>& q0,
             const Eigen::Ref<const Eigen::VectorXd>& dq0) override {
    check_state(n_, q0, dq0);
    mj_resetData(m_.get(), d_.get());
    for (int j = 0; j < n_; ++j) {
      d_->qpos[qpos_[j]] = q0[j];
      d_->qvel[dof_[j]] = dq0[j];
    }
    q_ = q0;
    dq_ = dq0;
  }

  void acceleration(const Eigen::Ref<const Eigen::VectorXd>& tau,
                    Eigen::Ref<Eigen::VectorXd> ddq) override {
    apply(tau);
    mj_forward(m_.get(), d_.get());
    for (int j = 0; j < n_; ++j) ddq[j] = d_->qacc[dof_[j]];
  }

  void step(const Eigen::Ref<const Eigen::VectorXd>& tau) override {
    apply(tau);
    const int bad = d_->warning[mjWARN_BADQACC].number;
    const double start = d_->time;  // MuJoCo resets the time with the state when it diverges
    mj_step(m_.get(), d_.get());
    for (int j = 0; j < n_; ++j) {
      q_[j] = d_->qpos[qpos_[j]];
      dq_[j] = d_->qvel[dof_[j]];
    }
    if (d_->warning[mjWARN_BADQACC].number != bad || !q_.allFinite() || !dq_.allFinite())
      throw Error("mujoco plant: the simulation diverged at t = " + std::to_string(start + dt_) +
                  " s (MuJoCo: " + one_line(last_mujoco_warning) +
                  "); check the reference and the model, lower the torque or the sample time dt");
  }

 private:
  // Joint torque tau minus the constant offset Fo and the friction asymmetry Fva·|dq| +
  // Fca·|sign dq| (seed 2 eq. 2), which MuJoCo has no term for; the sign is smoothed as in the
  // native plant (tanh(dq/v_s), v_s = 0.01 rad/s) and taken at the start of the step.
  void apply(const Eigen::Ref<const Eigen::VectorXd>& tau) {
    check_torque(n_, tau);
    for (int j = 0; j < n_; ++j) {
      const double v = d_->qvel[dof_[j]];
      d_->qfrc_applied[dof_[j]] = tau[j] - offset_[j] - asymmetry_v_[j] * std::abs(v) -
                                  asymmetry_c_[j] * std::abs(std::tanh(v / 1e-2));
    }
  }

  int n_;
  double dt_;
  Eigen::VectorXd q_, dq_, offset_, asymmetry_v_, asymmetry_c_;
  std::vector<int> qpos_, dof_;
  std::unique_ptr<mjModel, ModelDeleter> m_;
  std::unique_ptr<mjData, DataDeleter> d_;
};

}  // namespace

std::unique_ptr<Plant> make_mujoco_plant(const Model& model, double dt,
                                         const MujocoPlantOptions& options) {
  return std::make_unique<MujocoPlant>(model, dt, options);
}

}  // namespace dynid::detail

namespace dynid {

std::unique_ptr<Plant> make_plant(const Model& model, const PlantOptions& options) {
  if (!(options.dt > 0.0) || !std::isfinite(options.dt))
    throw Error("plant dt must be a finite sample time > 0 [s], e.g. 0.001");
  if (model.dof() == 0) throw Error("plant model '" + model.name + "' has no joints");
  if (options.engine == PlantEngine::kMujoco)
    return detail::make_mujoco_plant(model, options.dt, options.mujoco);
  return detail::make_native_plant(model, options.dt, options.native);
}

}  // namespace dynid
