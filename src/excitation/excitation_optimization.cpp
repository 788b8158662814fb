#include "dynid/excitation/excitation_optimization.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <nlopt.hpp>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/regressor/torque_regressor.hpp"

namespace dynid {

namespace {

using Clock = std::chrono::steady_clock;
constexpr double kInf = std::numeric_limits<double>::infinity();

// Options resolved against the model: harmonics, limits, base columns and variable bounds.
struct Problem {
  int n = 0;
  std::vector<int> harmonics;
  double f0 = 0.0;
  double w = 0.0;  // 2π f0
  Eigen::VectorXd q_min, q_max, dq_max, ddq_max, tau_max;
  std::vector<int> base;
  std::vector<std::string> base_names;
  int dim = 0;  // decision variables: per joint a(N_i), b(N_i), q0
  std::vector<double> lb, ub;
};

Eigen::VectorXd resolve_limit(const Eigen::VectorXd& given, const Model& model, int n,
                              const std::string& name, double (*from_model)(const Joint&)) {
  if (given.size() == 0) {
    Eigen::VectorXd v(n);
    for (int j = 0; j < n; ++j) v[j] = from_model(model.joints[j]);
    return v;
  }
  if (given.size() != n)
    throw Error("excitation " + name + ": needs one value per joint (" + std::to_string(n) +
                "), got " + std::to_string(given.size()));
  for (int j = 0; j < n; ++j)
    if (std::isnan(given[j]))
      throw Error("excitation " + name + " of joint " + std::to_string(j + 1) +
                  ": NaN; give a number or inf for no limit");
  return given;
}

Problem resolve(const Model& model, const ExcitationOptions& o, double base_seconds = 0.0) {
  Problem p;
  p.n = model.dof();
  const int n = p.n;
  if (n < 1) throw Error("excitation model: has no joint; load a robot with at least one joint");
  if (!std::isfinite(o.f0) || o.f0 <= 0.0)
    throw Error("excitation f0: the fundamental frequency must be finite and > 0 Hz, got " +
                std::to_string(o.f0));
  if (o.harmonics_per_joint.empty()) {
    p.harmonics.assign(static_cast<size_t>(n), o.harmonics);
  } else if (static_cast<int>(o.harmonics_per_joint.size()) != n) {
    throw Error("excitation harmonics_per_joint: needs one entry per joint (" + std::to_string(n) +
                "), got " + std::to_string(o.harmonics_per_joint.size()));
  } else {
    p.harmonics = o.harmonics_per_joint;
  }
  for (int j = 0; j < n; ++j)
    if (p.harmonics[j] < 1)
      throw Error("excitation harmonics of joint " + std::to_string(j + 1) +
                  ": need at least 1 harmonic, got " + std::to_string(p.harmonics[j]));
  const int n_max = *std::max_element(p.harmonics.begin(), p.harmonics.end());
  if (!(o.f_max >= 0.0)) throw Error("excitation f_max: must be >= 0 Hz (0 = no bandwidth limit)");
  if (o.f_max > 0.0 && n_max * o.f0 > o.f_max * (1.0 + 1e-12))
    throw Error("excitation bandwidth: " + std::to_string(n_max) + " harmonics of f0 = " +
                std::to_string(o.f0) + " Hz reach " + std::to_string(n_max * o.f0) +
                " Hz > f_max = " + std::to_string(o.f_max) + " Hz; lower the harmonics or f0");
  if (!(o.limit_fraction > 0.0 && o.limit_fraction <= 1.0))
    throw Error("excitation limit_fraction: must be in (0, 1]");
  if (!(o.grid_margin >= 0.0 && o.grid_margin < 0.5))
    throw Error("excitation grid_margin: must be in [0, 0.5)");
  if (!(o.workspace_margin >= 0.0)) throw Error("excitation workspace_margin: must be >= 0 m");
  if (o.samples_per_period < 0 || o.check_samples_per_period < 0)
    throw Error("excitation samples_per_period: must be >= 0 (0 = default)");
  if (o.starts < 1) throw Error("excitation starts: need at least 1 start");
  if (o.max_evaluations < 1) throw Error("excitation max_evaluations: need at least 1");
  if (!(o.max_time >= 0.0)) throw Error("excitation max_time: must be >= 0 s (0 = no limit)");
  if (std::isnan(o.z_min) || o.box_min.hasNaN() || o.box_max.hasNaN())
    throw Error("excitation workspace: NaN in z_min/box; use -inf/inf for no limit");
  if ((o.box_min.array() >= o.box_max.array()).any())
    throw Error("excitation workspace box: box_min must be below box_max on every axis");
  p.f0 = o.f0;
  p.w = 2.0 * M_PI * o.f0;

  p.q_min =
      resolve_limit(o.q_min, model, n, "q_min", [](const Joint& j) { return j.limits.lower; });
  p.q_max =
      resolve_limit(o.q_max, model, n, "q_max", [](const Joint& j) { return j.limits.upper; });
  p.dq_max =
      resolve_limit(o.dq_max, model, n, "dq_max", [](const Joint& j) { return j.limits.velocity; });
  p.ddq_max = resolve_limit(o.ddq_max, model, n, "ddq_max", [](const Joint&) { return kInf; });
  p.tau_max =
      resolve_limit(o.tau_max, model, n, "tau_max", [](const Joint& j) { return j.limits.effort; });
  const double f = o.limit_fraction;
  for (int j = 0; j < n; ++j) {
    if (!(p.q_min[j] < p.q_max[j]))
      throw Error("excitation position limits of joint " + std::to_string(j + 1) +
                  ": q_min must be below q_max");
    if (!(p.dq_max[j] > 0.0) || !(p.ddq_max[j] > 0.0) || !(p.tau_max[j] > 0.0))
      throw Error("excitation limits of joint " + std::to_string(j + 1) +
                  ": dq_max, ddq_max and tau_max must be > 0 (inf = no limit)");
    if (std::isfinite(p.q_min[j]) && std::isfinite(p.q_max[j])) {
      const double mid = 0.5 * (p.q_min[j] + p.q_max[j]), half = 0.5 * (p.q_max[j] - p.q_min[j]);
      p.q_min[j] = mid - f * half;
      p.q_max[j] = mid + f * half;
    }
    p.dq_max[j] *= f;
    p.ddq_max[j] *= f;
    p.tau_max[j] *= f;
  }

  BaseParameterOptions bo;
  bo.layout = o.layout;
  bo.max_seconds = base_seconds;
  const BaseParameters bp = compute_base_parameters(model, bo);
  p.base = bp.base;
  p.base_names = bp.names;

  // Bounds of the decision variables: |a_ik|, |b_ik| <= min(dq_max, ddq_max/(ω k), ω k·range/2),
  // each term alone keeps that harmonic within the limit; q0 inside the position range.
  for (int j = 0; j < n; ++j) {
    const double range = p.q_max[j] - p.q_min[j];
    std::vector<double> bound(static_cast<size_t>(p.harmonics[j]));
    for (int k = 1; k <= p.harmonics[j]; ++k) {
      const double wk = p.w * k;
      const double bnd = std::min({p.dq_max[j], p.ddq_max[j] / wk, wk * 0.5 * range});
      if (!std::isfinite(bnd))
        throw Error("joint " + std::to_string(j + 1) + " (" + model.joints[j].name +
                    ") has no finite position, velocity or acceleration limit to bound its "
                    "excitation: give --velocity-limit or --acceleration-limit, "
                    "or position limits in the robot model");
      bound[static_cast<size_t>(k - 1)] = bnd;
    }
    for (int rep = 0; rep < 2; ++rep)
      for (double bnd : bound) {
        p.lb.push_back(-bnd);
        p.ub.push_back(bnd);
      }
    const bool finite = std::isfinite(range);
    p.lb.push_back(finite ? p.q_min[j] : (std::isfinite(p.q_min[j]) ? p.q_min[j] : -M_PI));
    p.ub.push_back(finite ? p.q_max[j] : (std::isfinite(p.q_max[j]) ? p.q_max[j] : M_PI));
    if (!(p.lb.back() < p.ub.back())) {
      p.lb.back() = std::isfinite(p.q_min[j]) ? p.q_min[j] : p.q_max[j] - 2 * M_PI;
      p.ub.back() = std::isfinite(p.q_max[j]) ? p.q_max[j] : p.q_min[j] + 2 * M_PI;
    }
  }
  p.dim = static_cast<int>(p.lb.size());
  return p;
}

enum class Kind { kPosUpper, kPosLower, kVel, kAcc, kTorque, kFloor, kBoxMin, kBoxMax };

// One constraint group: worst over samples of `value − limit` must be <= 0.
struct Group {
  Kind kind;
  int index;     // joint or axis
  double limit;  // limit used in the evaluation (tightened inside the optimisation)
  double scale;  // normalisation of g
  std::string name;
};

// Evaluates criterion and constraints of one trajectory on a grid of `samples` per period.
// Allocation happens in the constructor only.
class Evaluator {
 public:
  Evaluator(const Model& model, const Problem& pb, const ExcitationOptions& o, int samples,
            bool tighten, bool keep_regressor)
      : model_(model),
        pb_(pb),
        layout_(o.layout),
        samples_(samples),
        keep_(keep_regressor),
        ws_(model),
        cols_(o.layout.columns(model.dof())),
        p_(static_cast<int>(pb.base.size())) {
    const int n = pb.n;
    const double gm = tighten ? o.grid_margin : 0.0;
    const double wm = tighten ? o.workspace_margin : 0.0;
    for (int j = 0; j < n; ++j) {
      const std::string q = "q" + std::to_string(j + 1);
      const double range = pb.q_max[j] - pb.q_min[j];
      const double pscale = std::isfinite(range) ? range : 1.0;
      if (std::isfinite(pb.q_max[j]))
        groups_.push_back(
            {Kind::kPosUpper, j, pb.q_max[j] - gm * pscale, pscale, "position max " + q});
      if (std::isfinite(pb.q_min[j]))
        groups_.push_back(
            {Kind::kPosLower, j, -(pb.q_min[j] + gm * pscale), pscale, "position min " + q});
      if (std::isfinite(pb.dq_max[j]))
        groups_.push_back({Kind::kVel, j, pb.dq_max[j] * (1 - gm), pb.dq_max[j], "velocity " + q});
      if (std::isfinite(pb.ddq_max[j]))
        groups_.push_back(
            {Kind::kAcc, j, pb.ddq_max[j] * (1 - gm), pb.ddq_max[j], "acceleration " + q});
      if (std::isfinite(pb.tau_max[j]))
        groups_.push_back(
            {Kind::kTorque, j, pb.tau_max[j] * (1 - gm), pb.tau_max[j], "torque " + q});
    }
    const char* axes = "xyz";
    if (std::isfinite(o.z_min))
      groups_.push_back({Kind::kFloor, 2, -(o.z_min + wm), 0.1, "workspace z_min"});
    for (int a = 0; a < 3; ++a) {
      if (std::isfinite(o.box_min[a]))
        groups_.push_back({Kind::kBoxMin, a, -(o.box_min[a] + wm), 0.1,
                           std::string("workspace box min ") + axes[a]});
      if (std::isfinite(o.box_max[a]))
        groups_.push_back({Kind::kBoxMax, a, o.box_max[a] - wm, 0.1,
                           std::string("workspace box max ") + axes[a]});
    }
    has_torque_ = has_workspace_ = false;
    for (const Group& g : groups_) {
      has_torque_ |= g.kind == Kind::kTorque;
      has_workspace_ |=
          g.kind == Kind::kFloor || g.kind == Kind::kBoxMin || g.kind == Kind::kBoxMax;
    }
    const int n_max = *std::max_element(pb.harmonics.begin(), pb.harmonics.end());
    sin_.resize(samples, n_max);
    cos_.resize(samples, n_max);
    for (int s = 0; s < samples; ++s) {
      const double t = s / (samples * pb.f0);
      for (int k = 1; k <= n_max; ++k) {
        sin_(s, k - 1) = std::sin(pb.w * k * t);
        cos_(s, k - 1) = std::cos(pb.w * k * t);
      }
    }
    Q_.resize(samples, n);
    DQ_.resize(samples, n);
    DDQ_.resize(samples, n);
    q_.resize(n);
    dq_.resize(n);
    ddq_.resize(n);
    tau_.resize(n);
    Y_.resize(n, cols_);
    YbT_.resize(p_, n);
    A_.resize(p_, p_);
    tmp_a_.resize(n_max);
    tmp_b_.resize(n_max);
    worst_.resize(static_cast<Eigen::Index>(groups_.size()));
    worst_time_.resize(static_cast<Eigen::Index>(groups_.size()));
    g.resize(static_cast<Eigen::Index>(groups_.size()));
    if (keep_) Wb.resize(static_cast<Eigen::Index>(samples) * n, p_);
  }

  int constraints() const { return static_cast<int>(groups_.size()); }

  // Decision vector -> coefficients (projected when rest_at_ends).
  static void unpack(const Problem& pb, const double* x, bool rest, FourierCoefficients& c) {
    int o = 0;
    for (int j = 0; j < pb.n; ++j) {
      const int nj = pb.harmonics[j];
      for (int k = 0; k < nj; ++k) c.a[j][k] = x[o + k];
      for (int k = 0; k < nj; ++k) c.b[j][k] = x[o + nj + k];
      c.q0[j] = x[o + 2 * nj];
      o += 2 * nj + 1;
    }
    if (rest) project_rest_at_ends(c);
  }

  // Criterion, constraint values g (normalised, <= 0 holds) and worst values per group.
  void run(const FourierCoefficients& c) {
    const int n = pb_.n;
    for (int j = 0; j < n; ++j) {  // eqs. 17–19 on the whole grid
      const int nj = pb_.harmonics[j];
      const auto S = sin_.leftCols(nj);
      const auto C = cos_.leftCols(nj);
      for (int k = 0; k < nj; ++k) {
        const double wk = pb_.w * (k + 1);
        tmp_a_[k] = c.a[j][k] / wk;
        tmp_b_[k] = c.b[j][k] / wk;
      }
      Q_.col(j).noalias() = S * tmp_a_.head(nj) - C * tmp_b_.head(nj);
      Q_.col(j).array() += c.q0[j];
      DQ_.col(j).noalias() = C * c.a[j] + S * c.b[j];
      for (int k = 0; k < nj; ++k) {
        const double wk = pb_.w * (k + 1);
        tmp_a_[k] = -c.a[j][k] * wk;
        tmp_b_[k] = c.b[j][k] * wk;
      }
      DDQ_.col(j).noalias() = S * tmp_a_.head(nj) + C * tmp_b_.head(nj);
    }
    A_.setZero();
    worst_.setConstant(-kInf);
    worst_time_.setZero();
    for (int s = 0; s < samples_; ++s) {
      if (deadline != Clock::time_point::max() && Clock::now() > deadline)
        throw nlopt::forced_stop();
      q_ = Q_.row(s).transpose();
      dq_ = DQ_.row(s).transpose();
      ddq_ = DDQ_.row(s).transpose();
      torque_regressor(model_, ws_, layout_, q_, dq_, ddq_, Y_);
      for (int c2 = 0; c2 < p_; ++c2) YbT_.row(c2) = Y_.col(pb_.base[c2]).transpose();
      A_.selfadjointView<Eigen::Lower>().rankUpdate(YbT_);
      if (keep_) Wb.middleRows(static_cast<Eigen::Index>(s) * n, n) = YbT_.transpose();
      if (has_torque_) rnea(model_, ws_, q_, dq_, ddq_, tau_);
      // The joint origins in the world frame (rnea and the regressor compute local poses only).
      if (has_workspace_) forward_kinematics(model_, ws_, q_);
      const double t = s / (samples_ * pb_.f0);
      for (size_t gi = 0; gi < groups_.size(); ++gi) {
        const Group& gr = groups_[gi];
        double v = -kInf;
        switch (gr.kind) {
          case Kind::kPosUpper:
            v = q_[gr.index];
            break;
          case Kind::kPosLower:
            v = -q_[gr.index];
            break;
          case Kind::kVel:
            v = std::abs(dq_[gr.index]);
            break;
          case Kind::kAcc:
            v = std::abs(ddq_[gr.index]);
            break;
          case Kind::kTorque:
            v = std::abs(tau_[gr.index]);
            break;
          case Kind::kFloor:
          case Kind::kBoxMin:
            for (int j = 0; j < n; ++j) v = std::max(v, -ws_.links[j].p_WJ[gr.index]);
            break;
          case Kind::kBoxMax:
            for (int j = 0; j < n; ++j) v = std::max(v, ws_.links[j].p_WJ[gr.index]);
            break;
        }
        if (v > worst_[gi]) {
          worst_[gi] = v;
          worst_time_[gi] = t;
        }
      }
    }
    for (size_t gi = 0; gi < groups_.size(); ++gi)
      g[gi] = (worst_[gi] - groups_[gi].limit) / groups_[gi].scale;
    // κ and log det from the eigenvalues of W_bᵀW_b (σ_i² = λ_i); tiny λ are clamped so that the
    // objective stays finite for the optimiser on rank-deficient trajectories.
    es_.compute(A_, Eigen::EigenvaluesOnly);
    const Eigen::VectorXd& lam = es_.eigenvalues();
    const double lmax = lam[p_ - 1];
    if (!(lmax > 0.0)) {
      log_cond = 0.5 * std::log(1e16);
      log_det = -1e3;
      return;
    }
    const double floor = lmax * 1e-16;
    log_cond = 0.5 * std::log(lmax / std::max(lam[0], floor));
    log_det = 0.0;
    for (int i = 0; i < p_; ++i) log_det += std::log(std::max(lam[i], floor));
  }

  std::vector<ConstraintMargin> margins() const {
    std::vector<ConstraintMargin> out;
    for (size_t gi = 0; gi < groups_.size(); ++gi) {
      const Group& gr = groups_[gi];
      ConstraintMargin m;
      m.name = gr.name;
      m.margin = gr.limit - worst_[gi];
      m.time = worst_time_[gi];
      // Lower bounds are evaluated negated (−q ≤ −q_min): report them as given.
      const bool lower =
          gr.kind == Kind::kPosLower || gr.kind == Kind::kFloor || gr.kind == Kind::kBoxMin;
      m.limit = lower ? -gr.limit : gr.limit;
      m.reached = lower ? -worst_[gi] : worst_[gi];
      const bool prismatic =
          gr.kind != Kind::kFloor && gr.kind != Kind::kBoxMin && gr.kind != Kind::kBoxMax &&
          model_.joints[static_cast<size_t>(gr.index)].type == JointType::kPrismatic;
      switch (gr.kind) {
        case Kind::kPosUpper:
        case Kind::kPosLower:
          m.unit = prismatic ? "m" : "rad";
          break;
        case Kind::kVel:
          m.unit = prismatic ? "m/s" : "rad/s";
          break;
        case Kind::kAcc:
          m.unit = prismatic ? "m/s²" : "rad/s²";
          break;
        case Kind::kTorque:
          m.unit = prismatic ? "N" : "N·m";
          break;
        case Kind::kFloor:
        case Kind::kBoxMin:
        case Kind::kBoxMax:
          m.unit = "m";
          break;
      }
      m.relative = m.margin / gr.scale;
      out.push_back(m);
    }
    return out;
  }

  /// Evaluations past this instant throw nlopt::forced_stop (checked per sample: one evaluation of
  /// a large tree can take minutes).
  Clock::time_point deadline = Clock::time_point::max();

  Eigen::VectorXd g;      // normalised constraint values, <= 0 holds
  double log_cond = 0.0;  // log κ(W_b)
  double log_det = 0.0;   // log det(W_bᵀW_b)
  Eigen::MatrixXd Wb;     // stacked base regressor (keep_regressor only)

 private:
  const Model& model_;
  const Problem& pb_;
  ParameterLayout layout_;
  int samples_;
  bool keep_;
  Workspace ws_;
  int cols_, p_;
  std::vector<Group> groups_;
  bool has_torque_ = false, has_workspace_ = false;
  Eigen::MatrixXd sin_, cos_, Q_, DQ_, DDQ_, Y_, YbT_, A_;
  Eigen::VectorXd q_, dq_, ddq_, tau_, tmp_a_, tmp_b_, worst_, worst_time_;
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> es_;
};

int optimisation_samples(const Problem& pb, const ExcitationOptions& o) {
  if (o.samples_per_period > 0) return o.samples_per_period;
  return 15 * *std::max_element(pb.harmonics.begin(), pb.harmonics.end());
}

// Fine-grid evaluation with the untightened limits; fills every reported field but the budget.
ExcitationResult check(const Model& model, const Problem& pb, const ExcitationOptions& o,
                       const FourierCoefficients& c, int samples,
                       Clock::time_point deadline = Clock::time_point::max()) {
  Evaluator ev(model, pb, o, samples, false, true);
  ev.deadline = deadline;
  try {
    ev.run(c);
  } catch (const nlopt::forced_stop&) {
    throw Error(
        "excitation max_time: the final check of the optimised trajectory on the fine "
        "grid did not finish within another max_time; raise --max-time or lower the "
        "check samples");
  }
  ExcitationResult r;
  r.coefficients = c;
  r.criterion = o.criterion;
  const Eigen::VectorXd sv = Eigen::BDCSVD<Eigen::MatrixXd>(ev.Wb).singularValues();
  r.condition_number = sv[sv.size() - 1] > 0.0 ? sv[0] / sv[sv.size() - 1] : kInf;
  r.log_det = 2.0 * sv.array().log().sum();
  r.value = o.criterion == ExcitationCriterion::kConditionNumber ? r.condition_number : -r.log_det;
  r.margins = ev.margins();
  r.constraints_satisfied = true;
  for (const ConstraintMargin& m : r.margins)
    if (!(m.margin >= 0.0)) r.constraints_satisfied = false;
  r.base_names = pb.base_names;
  return r;
}

// State shared with the NLopt callbacks.
struct Context {
  const Problem* pb = nullptr;
  Evaluator* ev = nullptr;
  bool rest = true;
  bool d_optimal = false;
  FourierCoefficients c;
  std::vector<double> last_x;
  double f = 0.0;
  Eigen::VectorXd g;
  int evaluations = 0;
  Clock::time_point deadline = Clock::time_point::max();
  std::vector<double> best_x;  // best feasible point, else least violating
  double best_f = kInf;
  double best_violation = kInf;
  // Finite-difference derivatives (SLSQP) at grad_x.
  std::vector<double> grad_x;
  Eigen::VectorXd grad_f;
  Eigen::MatrixXd jac_g;  // constraints × dim
  // Progress within a start, so that the line moves during the optimisation, not only between
  // starts (it sat at 25 % for the whole budget when the first of 4 starts used it up).
  ProgressCallback progress;
  int start = 0, starts = 1, start_evaluations = 0, max_evaluations = 1;
  Clock::time_point begin = Clock::now();

  void report_progress() {
    const double in_start =
        std::min(1.0, static_cast<double>(evaluations - start_evaluations) / max_evaluations);
    double fraction = (start + in_start) / starts;
    if (deadline != Clock::time_point::max()) {
      const double total = std::chrono::duration<double>(deadline - begin).count();
      const double spent = std::chrono::duration<double>(Clock::now() - begin).count();
      if (total > 0.0) fraction = std::max(fraction, spent / total);
    }
    progress(std::min(fraction, 0.99), "start " + std::to_string(start + 1) + "/" +
                                           std::to_string(starts) + ", evaluation " +
                                           std::to_string(evaluations));
  }

  void compute(const double* x) {
    const int dim = pb->dim;
    if (!last_x.empty() && std::equal(x, x + dim, last_x.begin())) return;
    if (Clock::now() > deadline) throw nlopt::forced_stop();
    Evaluator::unpack(*pb, x, rest, c);
    ev->run(c);
    ++evaluations;
    if (progress && evaluations % 20 == 0) report_progress();
    last_x.assign(x, x + dim);
    f = d_optimal ? -ev->log_det : ev->log_cond;
    g = ev->g;
    const double viol = g.size() > 0 ? std::max(0.0, g.maxCoeff()) : 0.0;
    if (viol < best_violation || (viol == 0.0 && f < best_f)) {
      best_violation = viol;
      best_f = f;
      best_x = last_x;
    }
  }

  void derivatives(const double* x) {
    const int dim = pb->dim;
    if (!grad_x.empty() && std::equal(x, x + dim, grad_x.begin())) return;
    std::vector<double> xh(x, x + dim);
    compute(x);
    const double f0 = f;
    const Eigen::VectorXd g0 = g;
    grad_f.resize(dim);
    jac_g.resize(g0.size(), dim);
    for (int i = 0; i < dim; ++i) {
      const double h = 1e-6 * std::max(1.0, std::abs(x[i]));
      xh[i] = x[i] + h;
      compute(xh.data());
      grad_f[i] = (f - f0) / h;
      jac_g.col(i) = (g - g0) / h;
      xh[i] = x[i];
    }
    compute(x);
    grad_x.assign(x, x + dim);
  }
};

double objective_cb(unsigned, const double* x, double* grad, void* data) {
  auto* ctx = static_cast<Context*>(data);
  if (grad != nullptr) {
    ctx->derivatives(x);
    for (int i = 0; i < ctx->pb->dim; ++i) grad[i] = ctx->grad_f[i];
  }
  ctx->compute(x);
  return ctx->f;
}

void constraints_cb(unsigned m, double* result, unsigned, const double* x, double* grad,
                    void* data) {
  auto* ctx = static_cast<Context*>(data);
  if (grad != nullptr) {
    ctx->derivatives(x);
    for (unsigned r = 0; r < m; ++r)
      for (int i = 0; i < ctx->pb->dim; ++i) grad[r * ctx->pb->dim + i] = ctx->jac_g(r, i);
  }
  ctx->compute(x);
  for (unsigned r = 0; r < m; ++r) result[r] = ctx->g[r];
}

}  // namespace

const ConstraintMargin* tightest_constraint(const ExcitationResult& r) {
  const ConstraintMargin* out = nullptr;
  for (const ConstraintMargin& m : r.margins)
    if (out == nullptr || !(m.relative >= out->relative)) out = &m;  // NaN: the most violated
  return out;
}

ExcitationResult evaluate_excitation(const Model& model, const FourierCoefficients& coefficients,
                                     const ExcitationOptions& options, int samples_per_period) {
  const Problem pb = resolve(model, options);
  coefficients.validate();
  if (coefficients.dof() != pb.n)
    throw Error("excitation coefficients: have " + std::to_string(coefficients.dof()) +
                " joints, the model has " + std::to_string(pb.n));
  for (int j = 0; j < pb.n; ++j)
    if (coefficients.a[j].size() != pb.harmonics[j])
      throw Error("excitation coefficients of joint " + std::to_string(j + 1) + ": " +
                  std::to_string(coefficients.a[j].size()) + " harmonics, options say " +
                  std::to_string(pb.harmonics[j]) + "; make harmonics_per_joint match");
  if (coefficients.f0 != pb.f0)
    throw Error("excitation coefficients: f0 differs from options.f0; make them equal");
  if (samples_per_period < 1)
    throw Error("excitation samples_per_period: need at least 1 sample per period");
  FourierCoefficients c = coefficients;
  if (options.rest_at_ends) project_rest_at_ends(c);
  return check(model, pb, options, c, samples_per_period);
}

ExcitationResult optimize_excitation(const Model& model, const ExcitationOptions& options) {
  const auto t_begin = Clock::now();
  // The base parameters count against the budget too (minutes for a tree of hundreds of links).
  const Problem pb = resolve(model, options, options.max_time);
  const int samples = optimisation_samples(pb, options);
  Evaluator ev(model, pb, options, samples, true, false);

  Context ctx;
  ctx.pb = &pb;
  ctx.ev = &ev;
  ctx.rest = options.rest_at_ends;
  ctx.d_optimal = options.criterion == ExcitationCriterion::kDOptimality;
  ctx.c = FourierCoefficients::zeros(pb.harmonics, pb.f0);
  const auto budget =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(options.max_time));
  if (options.max_time > 0.0) ctx.deadline = t_begin + budget;
  ev.deadline = ctx.deadline;
  ctx.progress = options.progress;
  ctx.starts = options.starts;
  ctx.max_evaluations = options.max_evaluations;
  ctx.begin = t_begin;

  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  const int m = ev.constraints();
  int starts_feasible = 0;
  for (int start = 0; start < options.starts; ++start) {
    ctx.start = start;
    ctx.start_evaluations = ctx.evaluations;
    if (Clock::now() > ctx.deadline) break;
    // Random start: coefficients uniform in their bounds, q0 near the middle of the range, then
    // the harmonic part scaled down (bisection on the amplitude) until every constraint holds.
    std::vector<double> x0(static_cast<size_t>(pb.dim));
    for (int i = 0; i < pb.dim; ++i)
      x0[i] = 0.5 * (pb.lb[i] + pb.ub[i]) + 0.5 * unit(rng) * (pb.ub[i] - pb.lb[i]);
    int o = 0;
    std::vector<bool> is_offset(static_cast<size_t>(pb.dim), false);
    for (int j = 0; j < pb.n; ++j) {
      o += 2 * pb.harmonics[j];
      const double mid = 0.5 * (pb.lb[o] + pb.ub[o]), half = 0.5 * (pb.ub[o] - pb.lb[o]);
      x0[o] = mid + 0.25 * unit(rng) * half;
      is_offset[o] = true;
      ++o;
    }
    try {
      auto scaled = [&](double s) {
        std::vector<double> x = x0;
        for (int i = 0; i < pb.dim; ++i)
          if (!is_offset[i]) x[i] *= s;
        return x;
      };
      auto worst = [&](const std::vector<double>& x) {
        ctx.compute(x.data());
        return m > 0 ? ctx.g.maxCoeff() : -1.0;
      };
      if (worst(x0) > 0.0) {
        double lo = 0.0, hi = 1.0;
        for (int it = 0; it < 12; ++it) {
          const double mid = 0.5 * (lo + hi);
          (worst(scaled(mid)) <= 0.0 ? lo : hi) = mid;
        }
        if (lo > 0.0) x0 = scaled(lo);
      }

      nlopt::algorithm alg = nlopt::LN_COBYLA;
      if (options.algorithm == ExcitationAlgorithm::kAugLagBobyqa) alg = nlopt::AUGLAG;
      if (options.algorithm == ExcitationAlgorithm::kSlsqp) alg = nlopt::LD_SLSQP;
      nlopt::opt opt(alg, static_cast<unsigned>(pb.dim));
      opt.set_lower_bounds(pb.lb);
      opt.set_upper_bounds(pb.ub);
      opt.set_min_objective(objective_cb, &ctx);
      if (m > 0)
        opt.add_inequality_mconstraint(
            constraints_cb, &ctx,
            std::vector<double>(static_cast<size_t>(m), options.constraint_tolerance));
      opt.set_ftol_rel(options.relative_tolerance);
      opt.set_xtol_rel(options.relative_tolerance);
      opt.set_maxeval(options.max_evaluations);
      if (options.max_time > 0.0) {
        const double left = std::chrono::duration<double>(ctx.deadline - Clock::now()).count();
        if (left <= 0.0) break;
        opt.set_maxtime(left);
      }
      if (alg == nlopt::AUGLAG) {
        nlopt::opt local(nlopt::LN_BOBYQA, static_cast<unsigned>(pb.dim));
        local.set_ftol_rel(options.relative_tolerance);
        local.set_xtol_rel(options.relative_tolerance);
        local.set_maxeval(options.max_evaluations);
        opt.set_local_optimizer(local);
      }
      if (alg == nlopt::LN_COBYLA) {
        std::vector<double> step(static_cast<size_t>(pb.dim));
        for (int i = 0; i < pb.dim; ++i) step[i] = 0.1 * (pb.ub[i] - pb.lb[i]);
        opt.set_initial_step(step);
      }
      std::vector<double> x = x0;
      double f_opt = 0.0;
      try {
        opt.optimize(x, f_opt);
      } catch (const nlopt::roundoff_limited&) {
      } catch (const nlopt::forced_stop&) {
      }
      ctx.compute(x.data());
      if (m == 0 || ctx.g.maxCoeff() <= 0.0) ++starts_feasible;
      if (options.progress) {
        options.progress((start + 1.0) / options.starts, "start " + std::to_string(start + 1) +
                                                             "/" + std::to_string(options.starts));
      }
    } catch (const nlopt::forced_stop&) {
      break;  // out of time during the start's set-up
    }
  }
  if (ctx.best_x.empty())
    throw Error("excitation max_time: the budget ended before the first evaluation; raise it");

  FourierCoefficients c = FourierCoefficients::zeros(pb.harmonics, pb.f0);
  Evaluator::unpack(pb, ctx.best_x.data(), options.rest_at_ends, c);
  const int check_samples =
      options.check_samples_per_period > 0 ? options.check_samples_per_period : 10 * samples;
  // The two final checks get one more budget of max_time, so a run ends within about twice it.
  const Clock::time_point check_deadline =
      options.max_time > 0.0 ? Clock::now() + budget : Clock::time_point::max();
  ExcitationResult r = check(model, pb, options, c, check_samples, check_deadline);
  const ExcitationResult coarse = check(model, pb, options, c, samples, check_deadline);
  r.value = coarse.value;
  r.evaluations = ctx.evaluations;
  r.starts_feasible = starts_feasible;
  r.seconds = std::chrono::duration<double>(Clock::now() - t_begin).count();
  return r;
}

}  // namespace dynid
