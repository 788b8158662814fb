#include "dynid/identification/integral_equations.hpp"

#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/dynamics/rnea.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/regressor/energy_regressor.hpp"
#include "dynid/signal/differentiation.hpp"
#include "regressor/friction_work.hpp"

namespace dynid {

namespace {

void check_processed(const Model& model, const JointRecord& r) {
  const int n = model.dof();
  const Eigen::Index m = r.t.size();
  auto check = [&](const Eigen::MatrixXd& x, const char* what) {
    if (x.rows() != m || x.cols() != n) {
      throw Error(std::string("integral model: ") + what + " has " + std::to_string(x.rows()) +
                  "×" + std::to_string(x.cols()) + " values; expected " + std::to_string(m) + "×" +
                  std::to_string(n) + " (samples × joints of model '" + model.name +
                  "'); preprocess the run first");
    }
    if (!x.allFinite())
      throw Error(std::string("integral model: ") + what + " contains NaN or Inf");
  };
  check(r.q, "q");
  check(r.dq, "dq");
  check(r.tau, "tau");
  for (Eigen::Index k = 0; k + 1 < m; ++k) {
    if (!(r.t[k + 1] > r.t[k])) {
      throw Error("integral model: time stamps must increase strictly (sample " +
                  std::to_string(k + 1) + ")");
    }
  }
}

// Divides the rows of `b` by the relative std of their errors under `weighting`
// (IntegralWeighting).
void weight_rows(const Model& model, const JointRecord& r, const Eigen::VectorXd& velocity_noise,
                 Eigen::Index steps, IntegralWeighting weighting, EquationBlock& b) {
  const Eigen::Index rows = b.y.size();
  const int n = model.dof();
  const bool momentum = weighting == IntegralWeighting::kEndpointMomentum &&
                        velocity_noise.size() == n && velocity_noise.maxCoeff() > 0.0;
  Eigen::VectorXd scale(rows);
  if (momentum) {
    // Momentum M(q)·q̇ by RNEA with q̈ := q̇ and no velocity, gravity or joint terms (O(n) per
    // end, not the O(n²) mass matrix), plus the armature's Ia·q̇.
    Workspace ws(model);
    Eigen::VectorXd p(n), zero = Eigen::VectorXd::Zero(n), end_variance(rows + 1);
    RneaOptions inertial;
    inertial.gravity = false;
    inertial.joint_terms = false;
    for (Eigen::Index i = 0; i <= rows; ++i) {
      const Eigen::Index k = i * steps;
      rnea(model, ws, r.q.row(k).transpose(), zero, r.dq.row(k).transpose(), p, inertial);
      for (int j = 0; j < n; ++j) p[j] += model.joints[j].friction.Ia * r.dq(k, j);
      end_variance[i] = (p.array().square() * velocity_noise.array().square()).sum();
    }
    for (Eigen::Index i = 0; i < rows; ++i)
      scale[i] = std::sqrt(end_variance[i] + end_variance[i + 1]);
  } else {
    for (Eigen::Index i = 0; i < rows; ++i) {
      double s2 = 0.0;
      for (Eigen::Index k = i * steps; k < (i + 1) * steps; ++k) {
        const double hk = r.t[k + 1] - r.t[k];
        s2 += hk * hk * r.dq.row(k).squaredNorm();
      }
      scale[i] = std::sqrt(s2);
    }
  }
  const double rms = std::sqrt(scale.squaredNorm() / static_cast<double>(rows));
  if (!(rms > 0.0)) return;
  // A row without motion carries no noise model and no information: leave it.
  for (Eigen::Index i = 0; i < rows; ++i) {
    const double s = scale[i] / rms;
    if (s > 1e-6) {
      b.W.row(i) /= s;
      b.y[i] /= s;
    }
  }
}

}  // namespace

EquationBlock integral_equations(const Model& model, const ParameterLayout& layout, bool coupling,
                                 const ProcessedRecord& processed, const IntegralOptions& options) {
  const JointRecord& r = processed.record;
  check_processed(model, r);
  const int n = model.dof();
  const Eigen::Index m = r.t.size();
  if (m < 2) throw Error("integral model: the run has fewer than two samples");
  const double duration = r.t[m - 1] - r.t[0];
  const double step = duration / static_cast<double>(m - 1);
  if (!(options.interval >= 0.0) || !std::isfinite(options.interval)) {
    throw UsageError("integral interval " + short_number(options.interval) +
                     " s is not a length; give a positive number of seconds (0 = automatic)");
  }
  const Eigen::Index steps = options.interval == 0.0
                                 ? kAutoIntervalSteps
                                 : static_cast<Eigen::Index>(std::llround(options.interval / step));
  if (steps < 1) {
    throw UsageError("integral interval " + short_number(options.interval) +
                     " s is shorter than two samples of the processed run (one step is " +
                     short_number(step) + " s); give at least " + short_number(step) + " s");
  }
  if (steps > m - 1) {
    throw UsageError("integral interval " + short_number(options.interval) +
                     " s is longer than the run (" + short_number(duration) +
                     " s after processing); give at most " + short_number(duration) + " s");
  }
  // A run in which no joint moves beyond its position noise carries no energy information.
  bool moves = false;
  for (int j = 0; j < n; ++j) {
    const double noise =
        processed.position_noise_std.size() == n ? processed.position_noise_std[j] : 0.0;
    const double range = r.q.col(j).maxCoeff() - r.q.col(j).minCoeff();
    moves |= range > std::max(10.0 * noise, 1e-9);
  }
  if (!moves) {
    throw Error(
        "integral model: no joint moves in the run (every position range is within its "
        "noise); record a run in which the joints move");
  }

  const int p = layout.columns(n);
  const int jc = layout.joint_columns();
  const std::vector<int> motors = coupling ? coupled_motors(model) : std::vector<int>{};
  const int cols = p + 3 * static_cast<int>(motors.size());
  std::vector<Eigen::RowVectorXd> n_k;
  for (int k : motors) {
    const Eigen::RowVectorXd row = model.transmission.N.row(k);
    n_k.push_back(row / row.cwiseAbs().maxCoeff());
  }
  const Eigen::Index intervals = (m - 1) / steps;

  EquationBlock b;
  b.W.setZero(intervals, cols);
  b.y.setZero(intervals);
  b.group.setZero(intervals);
  b.sample.resize(intervals);
  b.t.resize(intervals);
  b.columns = stacked_regressor_names(model, layout, coupling);
  b.group_names = {"energy"};

  // Energy row at a boundary sample: h(q, q̇) and, per coupled motor, ½(u² − Σ n_kj² q̇_j²) (the
  // energy of the motor's off-diagonal inertia terms, whose torque is coupling_regressor's Iam).
  Workspace ws(model);
  Eigen::VectorXd h_prev(cols), h_next(cols);
  const bool local = options.endpoint_window > 0.0 && m >= 3;
  if (!(options.endpoint_window >= 0.0) || !std::isfinite(options.endpoint_window)) {
    throw UsageError("integral endpoint window " + short_number(options.endpoint_window) +
                     " s is not a length; give a positive number of seconds (0 = off)");
  }
  // Endpoint velocities from the local quadratic through the positions within ± the window
  // (Savitzky–Golay slope), when asked; the power and friction columns keep the processed dq.
  Eigen::MatrixXd fitted;
  if (local) {
    SavitzkyGolayOptions sg;
    const Eigen::Index half = std::max<Eigen::Index>(
        1, std::min<Eigen::Index>(std::llround(options.endpoint_window / step), (m - 1) / 2));
    sg.window = static_cast<int>(2 * half + 1);
    sg.order = 2;
    sg.derivative = 1;
    fitted = savitzky_golay(r.t, r.q, sg);
  }
  const Eigen::MatrixXd& endpoint_dq = local ? fitted : r.dq;
  auto energy_row = [&](Eigen::Index k, Eigen::VectorXd& h) {
    const Eigen::VectorXd v = endpoint_dq.row(k).transpose();
    energy_regressor(model, ws, layout, r.q.row(k).transpose(), v, h.head(p));
    for (size_t c = 0; c < motors.size(); ++c) {
      const double u = n_k[c].dot(v);
      const double diag = (n_k[c].array().square().transpose() * v.array().square()).sum();
      h[p + 3 * static_cast<Eigen::Index>(c)] = 0.5 * (u * u - diag);
      h[p + 3 * static_cast<Eigen::Index>(c) + 1] = 0.0;
      h[p + 3 * static_cast<Eigen::Index>(c) + 2] = 0.0;
    }
  };
  Eigen::VectorXd power;
  if (options.rule != IntegrationRule::kZeroOrderHold) {
    power = (r.tau.array() * r.dq.array()).rowwise().sum();
  }
  // Parallel filtering of the Coulomb work (the one discontinuous term): the filtered torque's
  // Coulomb part is Fc_j·filter(sign q̇_j), so its power is q̇_j·(p_j − n_j) with the record's
  // filtered moving-positive/-negative indicators, integrated like τᵀq̇; ∫|q̇_j| of the filtered
  // velocity would miss the smeared step at every reversal.
  const bool parallel_coulomb = layout.coulomb && processed.moving_positive.rows() == m &&
                                processed.moving_negative.rows() == m;
  const int coulomb_within =
      (layout.armature ? 1 : 0) + (layout.viscous ? (layout.asymmetric ? 2 : 1) : 0);
  Eigen::MatrixXd coulomb_positive, coulomb_negative;  // m × n powers q̇_j·p_j, q̇_j·n_j
  if (parallel_coulomb) {
    coulomb_positive = r.dq.cwiseProduct(processed.moving_positive);
    coulomb_negative = r.dq.cwiseProduct(processed.moving_negative);
  }
  auto coulomb_work = [&](bool positive, Eigen::Index a, Eigen::Index e, int j) {
    const Eigen::MatrixXd& moving =
        positive ? processed.moving_positive : processed.moving_negative;
    if (options.rule == IntegrationRule::kZeroOrderHold) {
      double w = 0.0;
      for (Eigen::Index k = a; k < e; ++k) w += moving(k, j) * (r.q(k + 1, j) - r.q(k, j));
      return w;
    }
    return integrate_samples(r.t, (positive ? coulomb_positive : coulomb_negative).col(j), a, e,
                             options.rule);
  };
  // A coupled motor whose combination u = n_k·q̇ has one moving joint j on this run (the others
  // held, their velocity zero: a one-joint run of a parallelogram or a coupled wrist) turns with
  // that joint, u = n_kj·q̇_j, and its Coulomb work is exactly |n_kj| times the joint's. With
  // parallel filtering it is taken from the joint's filtered indicators, as the joint's own
  // column is: the data then tie the two columns exactly, and the data-identifiability stage
  // regroups the motor's parameter into the joint's and names it (on the IRp-6 joint-2 run, Fcm3
  // computed from the unfiltered ∫|u| was kept beside Fc2: 26.9 ± 219 and 1.9 ± 219).
  std::vector<int> single_joint(motors.size(), -1);
  if (parallel_coulomb) {
    for (size_t c = 0; c < motors.size(); ++c) {
      int moving = 0, joint = -1;
      for (int j = 0; j < n; ++j) {
        if (n_k[c][j] != 0.0 && (r.dq.col(j).array() != 0.0).any()) {
          ++moving;
          joint = j;
        }
      }
      if (moving == 1) single_joint[c] = joint;
    }
  }
  Eigen::VectorXd square(n);  // per-joint ∫q̇_j² of one step, reused by the coupled motors
  energy_row(0, h_prev);
  for (Eigen::Index i = 0; i < intervals; ++i) {
    const Eigen::Index a = i * steps, e = a + steps;
    energy_row(e, h_next);
    auto w = b.W.row(i);
    w = (h_next - h_prev).transpose();
    if (options.rule == IntegrationRule::kZeroOrderHold) {
      double y = 0.0;
      for (Eigen::Index k = a; k < e; ++k) y += r.tau.row(k).dot(r.q.row(k + 1) - r.q.row(k));
      b.y[i] = y;
    } else {
      b.y[i] = integrate_samples(r.t, power, a, e, options.rule);
    }
    for (Eigen::Index k = a; k < e; ++k) {
      const double hk = r.t[k + 1] - r.t[k];
      for (int j = 0; j < n; ++j) {
        const StepVelocityIntegrals s =
            step_velocity_integrals(hk, r.q(k + 1, j) - r.q(k, j), r.dq(k, j), r.dq(k + 1, j));
        square[j] = s.positive_square + s.negative_square;
        detail::add_friction_work(layout, s, w.segment(kLinkParams * n + jc * j, jc));
      }
      for (size_t c = 0; c < motors.size(); ++c) {
        const Eigen::RowVectorXd& nk = n_k[c];
        const StepVelocityIntegrals u = step_velocity_integrals(
            hk, nk.dot(r.q.row(k + 1) - r.q.row(k)), nk.dot(r.dq.row(k)), nk.dot(r.dq.row(k + 1)));
        const Eigen::Index col = p + 3 * static_cast<Eigen::Index>(c);
        w[col + 1] += u.positive_square + u.negative_square -
                      (nk.array().square().transpose() * square.array()).sum();
        if (single_joint[c] < 0) w[col + 2] += u.positive - u.negative;
      }
    }
    if (parallel_coulomb) {
      for (int j = 0; j < n; ++j) {
        const Eigen::Index col = kLinkParams * n + jc * j + coulomb_within;
        const double pos = coulomb_work(true, a, e, j);
        const double neg = coulomb_work(false, a, e, j);
        if (layout.asymmetric) {
          w[col] = pos;
          w[col + 1] = -neg;
        } else {
          w[col] = pos - neg;
        }
        for (size_t c = 0; c < motors.size(); ++c) {
          if (single_joint[c] == j)
            w[p + 3 * static_cast<Eigen::Index>(c) + 2] = std::abs(n_k[c][j]) * (pos - neg);
        }
      }
    }
    b.sample[i] = static_cast<int>(i);
    b.t[i] = r.t[e];
    std::swap(h_prev, h_next);
  }
  if (options.weighting != IntegralWeighting::kNone && !options.long_integrals) {
    weight_rows(model, r, processed.velocity_noise_std, steps, options.weighting, b);
  }
  if (options.long_integrals) {
    // Seed 1 §IV: [t0, t_b] for every interval end t_b; energy differences telescope and the
    // friction and power integrals add, so a long row is the running sum of the short ones.
    for (Eigen::Index i = 1; i < intervals; ++i) {
      b.W.row(i) += b.W.row(i - 1);
      b.y[i] += b.y[i - 1];
    }
  }
  return b;
}

SignalOptions integral_signal_options() {
  SignalOptions o;
  o.cutoff_hz = 10.0;
  o.decimate = 1;
  o.coulomb_width_fraction = 0.0;  // ∫|q̇| is continuous at rest: no band to model
  return o;
}

}  // namespace dynid
