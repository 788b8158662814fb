// Native plant: dynid forward dynamics with the plant friction model, classical RK4.
#include <algorithm>
#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/mass_matrix.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "sim/plant_internal.hpp"

namespace dynid::detail {

namespace {

class NativePlant final : public Plant {
 public:
  NativePlant(const Model& model, double dt, const NativePlantOptions& options)
      : model_(model),
        options_(options),
        ws_(model_),
        dt_(dt),
        n_(model.dof()),
        q_(Eigen::VectorXd::Zero(n_)),
        dq_(Eigen::VectorXd::Zero(n_)),
        net_torque_(n_),
        friction_(n_),
        M_(n_, n_) {
    check_plant_friction(model_, options_.friction);
    if (!(options_.max_step > 0.0) || !std::isfinite(options_.max_step))
      throw Error("native plant max_step must be a finite value > 0 [s], e.g. 0.001");
    if (options_.substeps < 0) throw Error("native plant substeps must be >= 0 (0 = automatic)");
    for (auto* v : {&kq_, &kdq_}) {
      for (auto& k : *v) k = Eigen::VectorXd::Zero(n_);
    }
    q_stage_ = Eigen::VectorXd::Zero(n_);
    dq_stage_ = Eigen::VectorXd::Zero(n_);
    choose_substeps();
  }

  int dof() const override { return n_; }
  double dt() const override { return dt_; }
  double time() const override { return time_; }
  std::string engine() const override { return "native"; }
  const Eigen::VectorXd& q() const override { return q_; }
  const Eigen::VectorXd& dq() const override { return dq_; }

  void reset(const Eigen::Ref<const Eigen::VectorXd>& q0,
             const Eigen::Ref<const Eigen::VectorXd>& dq0) override {
    check_state(n_, q0, dq0);
    q_ = q0;
    dq_ = dq0;
    time_ = 0.0;
    steps_ = 0;
    choose_substeps();
  }

  void acceleration(const Eigen::Ref<const Eigen::VectorXd>& tau,
                    Eigen::Ref<Eigen::VectorXd> ddq) override {
    check_torque(n_, tau);
    rhs(q_, dq_, tau, ddq);
  }

  void step(const Eigen::Ref<const Eigen::VectorXd>& tau) override {
    check_torque(n_, tau);
    const double h = dt_ / substeps_;
    for (int s = 0; s < substeps_; ++s) {
      // Classical RK4 on x = (q, dq), x' = (dq, f(q, dq, tau)).
      kq_[0] = dq_;
      rhs(q_, dq_, tau, kdq_[0]);
      q_stage_ = q_ + 0.5 * h * kq_[0];
      dq_stage_ = dq_ + 0.5 * h * kdq_[0];
      kq_[1] = dq_stage_;
      rhs(q_stage_, dq_stage_, tau, kdq_[1]);
      q_stage_ = q_ + 0.5 * h * kq_[1];
      dq_stage_ = dq_ + 0.5 * h * kdq_[1];
      kq_[2] = dq_stage_;
      rhs(q_stage_, dq_stage_, tau, kdq_[2]);
      q_stage_ = q_ + h * kq_[2];
      dq_stage_ = dq_ + h * kdq_[2];
      kq_[3] = dq_stage_;
      rhs(q_stage_, dq_stage_, tau, kdq_[3]);
      q_ += (h / 6.0) * (kq_[0] + 2.0 * kq_[1] + 2.0 * kq_[2] + kq_[3]);
      dq_ += (h / 6.0) * (kdq_[0] + 2.0 * kdq_[1] + 2.0 * kdq_[2] + kdq_[3]);
    }
    ++steps_;
    time_ = steps_ * dt_;
    if (!q_.allFinite() || !dq_.allFinite())
      throw Error("native plant state became non-finite at t = " + std::to_string(time_) +
                  " s: lower the torque, or raise native.substeps or the friction "
                  "smoothing_velocity");
  }

 private:
  // ddq = M(q)⁻¹(tau − c(q, dq) − g(q) − F(dq)); M includes the armature Ia. The plant's own
  // (smoothed) friction F replaces the model's joint terms; forward_dynamics picks CRBA + LᵀDL or
  // the articulated-body algorithm by the model's shape.
  void rhs(const Eigen::VectorXd& q, const Eigen::VectorXd& dq,
           const Eigen::Ref<const Eigen::VectorXd>& tau, Eigen::Ref<Eigen::VectorXd> ddq) {
    RneaOptions options;
    options.joint_terms = false;
    plant_friction_torque(model_, options_.friction, dq, friction_);
    net_torque_ = tau - friction_;
    forward_dynamics(model_, ws_, q, dq, net_torque_, ddq, options);
  }

  // Enough sub-steps for h ≤ max_step and for explicit stability on the stiffest friction slope:
  // RK4's real stability interval is |λh| ≤ 2.78; λ_j ≈ slope_j / M_jj, with a factor 2 margin.
  void choose_substeps() {
    if (options_.substeps > 0) {
      substeps_ = options_.substeps;
      return;
    }
    double h = options_.max_step;
    mass_matrix(model_, ws_, q_, M_);
    for (int j = 0; j < n_; ++j) {
      const double slope =
          plant_friction_max_slope(model_.joints[j].friction, options_.friction, j);
      if (slope > 0.0) h = std::min(h, 1.39 * M_(j, j) / slope);
    }
    substeps_ = std::max(1, static_cast<int>(std::ceil(dt_ / h - 1e-9)));
  }

  Model model_;
  NativePlantOptions options_;
  Workspace ws_;
  double dt_;
  int n_;
  Eigen::VectorXd q_, dq_, net_torque_, friction_, q_stage_, dq_stage_;
  Eigen::VectorXd kq_[4], kdq_[4];
  Eigen::MatrixXd M_;
  double time_ = 0.0;
  long steps_ = 0;
  int substeps_ = 1;
};

}  // namespace

std::unique_ptr<Plant> make_native_plant(const Model& model, double dt,
                                         const NativePlantOptions& options) {
  return std::make_unique<NativePlant>(model, dt, options);
}

void check_state(int n, const Eigen::Ref<const Eigen::VectorXd>& q0,
                 const Eigen::Ref<const Eigen::VectorXd>& dq0) {
  if (q0.size() != n || dq0.size() != n)
    throw Error("plant reset: q0 and dq0 must have " + std::to_string(n) +
                " entries (one per joint), got " + std::to_string(q0.size()) + " and " +
                std::to_string(dq0.size()));
  if (!q0.allFinite() || !dq0.allFinite())
    throw Error("plant reset: q0 and dq0 must be finite (found NaN or Inf)");
}

void check_torque(int n, const Eigen::Ref<const Eigen::VectorXd>& tau) {
  if (tau.size() != n)
    throw Error("plant torque must have " + std::to_string(n) + " entries (one per joint), got " +
                std::to_string(tau.size()));
  if (!tau.allFinite()) throw Error("plant torque must be finite (found NaN or Inf)");
}

}  // namespace dynid::detail
