#pragma once

#include <memory>
#include <string>

#include <Eigen/Core>

#include "dynid/model/model.hpp"
#include "dynid/sim/plant_friction.hpp"

namespace dynid {

/// A simulated robot: joint state (q, dq) advanced by a fixed sample time dt under a joint torque
/// held constant over the sample (zero-order hold, as a digital controller applies it).
class Plant {
 public:
  virtual ~Plant() = default;

  /// Number of joints n.
  virtual int dof() const = 0;
  /// Sample time of one step() [s].
  virtual double dt() const = 0;
  /// Simulated time since the last reset() [s].
  virtual double time() const = 0;
  /// Engine name, "native" or "mujoco".
  virtual std::string engine() const = 0;

  /// Sets the state to (q0, dq0) (size n each, [rad or m], [rad/s or m/s]) and the time to 0.
  /// Throws dynid::Error on a wrong size or a non-finite value.
  virtual void reset(const Eigen::Ref<const Eigen::VectorXd>& q0,
                     const Eigen::Ref<const Eigen::VectorXd>& dq0) = 0;

  /// Advances the state by dt with joint torque tau (size n, [N·m or N]) held constant.
  /// Throws dynid::Error when the state becomes non-finite (the message says how to fix it).
  virtual void step(const Eigen::Ref<const Eigen::VectorXd>& tau) = 0;

  /// Joint acceleration at the current state under torque tau (no state change).
  virtual void acceleration(const Eigen::Ref<const Eigen::VectorXd>& tau,
                            Eigen::Ref<Eigen::VectorXd> ddq) = 0;

  /// Current joint positions (size n).
  virtual const Eigen::VectorXd& q() const = 0;
  /// Current joint velocities (size n).
  virtual const Eigen::VectorXd& dq() const = 0;
};

/// Which simulator runs the plant.
enum class PlantEngine {
  kNative,  ///< dynid's forward dynamics integrated by classical RK4
  kMujoco,  ///< MuJoCo 2.2 on the model exported by to_urdf()
};

/// MuJoCo's integrators usable for the plant.
enum class MujocoIntegrator {
  kRk4,       ///< 4th-order Runge–Kutta (mjINT_RK4)
  kImplicit,  ///< implicit in velocity (mjINT_IMPLICIT): damping treated implicitly
};

/// Options of the native engine.
struct NativePlantOptions {
  double max_step = 1e-3;  ///< largest internal RK4 step [s] (≥ 1 kHz); dt is split into sub-steps
  int substeps = 0;        ///< internal RK4 steps per dt; 0 = automatic (max_step and stability)
  PlantFrictionOptions friction;  ///< plant friction (smoothed Coulomb, optional Stribeck)
};

/// Options of the MuJoCo engine.
struct MujocoPlantOptions {
  MujocoIntegrator integrator = MujocoIntegrator::kRk4;  ///< MuJoCo integrator; timestep = dt
  bool coulomb = true;  ///< Coulomb Fc as MuJoCo dof_frictionloss (its soft-constraint model)
  bool enforce_limits = false;  ///< keep MuJoCo's joint-limit constraints (native has none)
  double bound_mass = 1e-6;     ///< MJCF compiler boundmass [kg]: MuJoCo rejects massless
                                ///< moving bodies (e.g. puma560 link1), masses get this floor
  double bound_inertia = 1e-9;  ///< MJCF compiler boundinertia [kg·m²]: floor on the principal
                                ///< inertias, for the same reason
};

/// Options of make_plant().
struct PlantOptions {
  PlantEngine engine = PlantEngine::kNative;  ///< simulator
  double dt = 1e-3;                           ///< sample time of step() [s]; > 0
  NativePlantOptions native;                  ///< used when engine == kNative
  MujocoPlantOptions mujoco;                  ///< used when engine == kMujoco
};

/// Builds a plant for `model` (copied) at rest at q = 0.
/// Native: ddq = M(q)⁻¹(tau − c(q, dq) − g(q) − F(dq)) with M including Ia (mass_matrix), the
/// bias from rnea without joint terms and F from plant_friction_torque(), integrated by classical
/// RK4 (Hairer–Nørsett–Wanner I.1) with sub-steps of at most max_step.
/// MuJoCo: mj_loadXML on to_urdf(model, {.mujoco_compiler_tag = true}) from an in-memory VFS;
/// joints matched by name; dof_armature = Ia, dof_damping = Fv, dof_frictionloss = Fc (when
/// mujoco.coulomb), gravity = model.gravity, timestep = dt; contacts (and limits unless
/// enforce_limits) disabled; Fo subtracted from the applied torque; masses and principal inertias
/// below bound_mass / bound_inertia raised to them (a massless link gains at most that much).
/// Throws dynid::Error for a non-positive dt, bad friction options, or a model MuJoCo rejects.
std::unique_ptr<Plant> make_plant(const Model& model, const PlantOptions& options = {});

}  // namespace dynid
