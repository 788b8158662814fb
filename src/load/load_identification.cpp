#include "dynid/load/load_identification.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/recursive_least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/regressor/load_regressor.hpp"
#include "dynid/signal/differentiation.hpp"

namespace dynid {
namespace {

const char* const kComponents[6] = {"fx", "fy", "fz", "mx", "my", "mz"};

Eigen::Vector3d row3(const Eigen::MatrixXd& x, Eigen::Index k) {
  return x.row(k).transpose();
}

void check_rows(const Eigen::MatrixXd& x, Eigen::Index m, Eigen::Index cols, const char* what) {
  if (x.rows() != m || x.cols() != cols) {
    throw Error(std::string(what) + " has " + std::to_string(x.rows()) + "×" +
                std::to_string(x.cols()) + " values where " + std::to_string(m) + "×" +
                std::to_string(cols) + " are needed; give one row per sample");
  }
}

void check_gravity(const Eigen::Vector3d& gravity) {
  if (!gravity.allFinite() || !(gravity.norm() > 0.0)) {
    throw Error(
        "the gravity vector is zero or not finite; the load's mass is seen only through "
        "gravity: give the base-frame gravity, e.g. 0 0 -9.81 m/s^2");
  }
}

}  // namespace

int find_link(const Model& model, const std::string& name) {
  std::string names;
  for (int j = 0; j < model.dof(); ++j) {
    if (model.joints[j].link_name == name || model.joints[j].name == name) return j;
    names += (j ? ", " : "") + model.joints[j].link_name;
  }
  throw UsageError("link '" + name + "' is not a moving link of robot '" + model.name +
                   "'; links are " + names);
}

Eigen::Matrix3d roll_pitch_yaw(double roll, double pitch, double yaw) {
  return (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

SensorMotion sensor_motion_from_joints(const Model& model, const JointRecord& record,
                                       const SensorMount& mount) {
  const int n = model.dof();
  if (mount.link < 0 || mount.link >= n) {
    throw Error("sensor link index " + std::to_string(mount.link) + " is outside 0.." +
                std::to_string(n - 1));
  }
  check_gravity(model.gravity);
  const Eigen::Index m = record.q.rows();
  check_rows(record.q, m, n, "q");
  const bool standing = record.dq.size() == 0 && record.ddq.size() == 0;
  if (!standing) {
    check_rows(record.dq, m, n, "dq");
    check_rows(record.ddq, m, n, "ddq");
  }
  SensorMotion out;
  out.t = record.t;
  out.w.resize(m, 3);
  out.dw.resize(m, 3);
  out.a.resize(m, 3);
  out.v.resize(m, 3);
  out.g.resize(m, 3);
  Workspace ws(model);
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  const Eigen::Matrix3d Rt = mount.R_LS.transpose();
  const Eigen::Vector3d& p = mount.p_LS;
  for (Eigen::Index k = 0; k < m; ++k) {
    const Eigen::VectorXd q = record.q.row(k).transpose();
    if (standing) {
      forward_kinematics(model, ws, q, zero, zero, false);
    } else {
      forward_kinematics(model, ws, q, record.dq.row(k).transpose(), record.ddq.row(k).transpose(),
                         false);
    }
    const LinkState& s = ws.links[mount.link];
    out.w.row(k) = (Rt * s.w).transpose();
    out.dw.row(k) = (Rt * s.dw).transpose();
    out.a.row(k) = (Rt * (s.a + s.dw.cross(p) + s.w.cross(s.w.cross(p)))).transpose();
    out.v.row(k) = (Rt * (s.v + s.w.cross(p))).transpose();
    out.g.row(k) = ((s.R_WJ * mount.R_LS).transpose() * model.gravity).transpose();
  }
  return out;
}

SensorMotion sensor_motion_from_orientation(
    const OrientationLog& log, const Eigen::Vector3d& gravity,
    std::vector<std::pair<std::string, std::string>>& choices) {
  check_gravity(gravity);
  const Eigen::Index m = log.quaternion.rows();
  check_rows(log.quaternion, m, 4, "the quaternion qx qy qz qw");
  if (log.w.size()) check_rows(log.w, m, 3, "the angular velocity wx wy wz");
  if (log.dw.size()) check_rows(log.dw, m, 3, "the angular acceleration dwx dwy dwz");
  if (log.a.size()) check_rows(log.a, m, 3, "the linear acceleration ax ay az");
  const bool standing = log.t.size() == 0;
  if (!standing && log.t.size() != m) {
    throw Error("t has " + std::to_string(log.t.size()) + " samples and the quaternion " +
                std::to_string(m));
  }
  // Quaternions with the sign flipped between rows describe the same rotation; a central
  // difference across the flip would be meaningless, so make the sequence continuous first.
  Eigen::MatrixXd quat = log.quaternion;
  for (Eigen::Index k = 0; k < m; ++k) {
    const double norm = quat.row(k).norm();
    if (!(std::abs(norm - 1.0) <= 1e-3)) {
      throw Error("row " + std::to_string(k + 1) + ": the quaternion qx qy qz qw has norm " +
                  std::to_string(norm) +
                  ", not 1; give the unit quaternion of the sensor frame (normalise the log)");
    }
    quat.row(k) /= norm;
    if (k > 0 && quat.row(k).dot(quat.row(k - 1)) < 0.0) quat.row(k) *= -1.0;
  }
  SensorMotion out;
  out.t = log.t;
  out.g.resize(m, 3);
  for (Eigen::Index k = 0; k < m; ++k) {
    const Eigen::Quaterniond qk(quat(k, 3), quat(k, 0), quat(k, 1), quat(k, 2));
    out.g.row(k) = (qk.toRotationMatrix().transpose() * gravity).transpose();
  }
  if (standing) {
    out.w = out.dw = out.a = Eigen::MatrixXd::Zero(m, 3);
    return out;
  }
  if (log.w.size()) {
    out.w = log.w;
    choices.emplace_back("w", "from the data");
  } else {
    // q̇ = ½ q ⊗ (0, ω_S), so ω_S = 2·vec(q̄ ⊗ q̇).
    const Eigen::MatrixXd dquat = central_difference(log.t, quat, 1);
    out.w.resize(m, 3);
    for (Eigen::Index k = 0; k < m; ++k) {
      const Eigen::Quaterniond qk(quat(k, 3), quat(k, 0), quat(k, 1), quat(k, 2));
      const Eigen::Quaterniond dk(dquat(k, 3), dquat(k, 0), dquat(k, 1), dquat(k, 2));
      out.w.row(k) = (2.0 * (qk.conjugate() * dk).vec()).transpose();
    }
    choices.emplace_back("w", "derived from the quaternion by central differences");
  }
  if (log.dw.size()) {
    out.dw = log.dw;
    choices.emplace_back("dw", "from the data");
  } else {
    out.dw = central_difference(log.t, out.w, 1);
    choices.emplace_back("dw", "derived from w by central differences");
  }
  if (log.a.size()) {
    out.a = log.a;
    choices.emplace_back("a", "from the data");
  } else {
    out.a = Eigen::MatrixXd::Zero(m, 3);
    choices.emplace_back("a",
                         "no ax ay az columns: the sensor origin is taken as not accelerating "
                         "(only rotations about it); give ax ay az otherwise");
  }
  return out;
}

PreparedLoadRun prepare_load_run(const JointRecord& record,
                                 const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                                 const SignalOptions& options,
                                 std::vector<std::pair<std::string, std::string>>& choices) {
  if (wrench.rows() != record.q.rows() || wrench.cols() != 6) {
    throw Error("the wrench has " + std::to_string(wrench.rows()) + " rows of " +
                std::to_string(wrench.cols()) + " values where " + std::to_string(record.q.rows()) +
                " rows of fx fy fz mx my mz are needed");
  }
  JointRecord joints = record;
  joints.tau = Eigen::MatrixXd::Zero(record.q.rows(), record.q.cols());
  ProcessedRecord processed = preprocess(joints, options, choices);
  // The wrench through preprocess() as positions with the first run's resolved cut-off, trim and
  // decimation: the same filter, edges and rows, without a second copy of the processing.
  SignalOptions same = options;
  same.cutoff_hz = processed.cutoff_hz;
  same.trim = processed.trim;
  same.decimate = processed.decimate;
  JointRecord force;
  force.t = record.t;
  force.q = wrench;
  force.tau = Eigen::MatrixXd::Zero(wrench.rows(), 6);
  std::vector<std::pair<std::string, std::string>> ignored;
  PreparedLoadRun out;
  out.wrench = preprocess(force, same, ignored).record.q;
  out.record = std::move(processed.record);
  // The load equations have no Coulomb columns: that choice of preprocess() does not apply.
  choices.erase(std::remove_if(choices.begin(), choices.end(),
                               [](const auto& c) { return c.first == "coulomb_columns"; }),
                choices.end());
  choices.emplace_back("wrench", options.filter ? "filtered, trimmed and decimated like q"
                                                : "not filtered; trimmed and decimated like q");
  return out;
}

std::vector<std::string> load_parameter_names(const LoadEquationOptions& options) {
  std::vector<std::string> names = {"m", "mcx", "mcy", "mcz"};
  if (options.model != LoadModelKind::kStatic) {
    for (const char* name : {"Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz"}) names.emplace_back(name);
  }
  if (options.bias) {
    for (int c = 0; c < 6; ++c) {
      if (options.components[c]) names.push_back(std::string(kComponents[c]) + "0");
    }
  }
  return names;
}

std::array<bool, 6> load_components_from_text(const std::string& list, const std::string& flag) {
  std::array<bool, 6> chosen = {false, false, false, false, false, false};
  bool any = false;
  std::size_t begin = 0;
  while (begin <= list.size()) {
    const std::size_t end = std::min(list.find(',', begin), list.size());
    const std::string name = list.substr(begin, end - begin);
    const auto it = std::find_if(std::begin(kComponents), std::end(kComponents),
                                 [&](const char* c) { return name == c; });
    if (it == std::end(kComponents)) {
      throw UsageError(flag + " '" + list + "': '" + name +
                       "' is not a wrench component; give a comma-separated list of fx, fy, fz, "
                       "mx, my, mz");
    }
    auto& slot = chosen[static_cast<std::size_t>(it - std::begin(kComponents))];
    if (slot) throw UsageError(flag + " '" + list + "' names '" + name + "' twice; name it once");
    slot = any = true;
    begin = end + 1;
  }
  if (!any) throw UsageError(flag + " is empty; give some of fx, fy, fz, mx, my, mz");
  return chosen;
}

EquationBlock load_equations(const SensorMotion& motion,
                             const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                             const LoadEquationOptions& options) {
  const Eigen::Index m = wrench.rows();
  if (wrench.cols() != 6) throw Error("the wrench needs the six columns fx fy fz mx my mz");
  if (!wrench.allFinite()) throw Error("the wrench has NaN or Inf values; clean the data");
  check_rows(motion.g, m, 3, "the gravity in the sensor frame");
  if (!(options.wrench_sign == 1.0 || options.wrench_sign == -1.0)) {
    throw UsageError("the wrench sign must be +1 or -1");
  }
  const bool standing = options.model == LoadModelKind::kStatic;
  if (!standing) {
    check_rows(motion.w, m, 3, "w");
    check_rows(motion.dw, m, 3, "dw");
    check_rows(motion.a, m, 3, "the sensor acceleration");
    if (motion.t.size() != m) {
      throw Error(
          "the load's motion needs a time stamp t per sample (or use the static model "
          "for standing poses)");
    }
  }
  EquationBlock block;
  block.columns = load_parameter_names(options);
  // The chosen scalar equations (seed 1 §VI-B): rows of the other components are never formed.
  std::vector<int> rows_of;
  for (int c = 0; c < 6; ++c) {
    if (options.components[c]) {
      rows_of.push_back(c);
      block.group_names.emplace_back(kComponents[c]);
    }
  }
  if (rows_of.empty()) throw UsageError("no wrench component is chosen; choose some of fx..mz");
  const auto c_rows = static_cast<Eigen::Index>(rows_of.size());
  const auto p = static_cast<Eigen::Index>(block.columns.size());
  const Eigen::Index inertial = standing ? 4 : 10;
  // Seed 1's W is the wrench the sensor exerts on the load: the negative of a driver's reading.
  const double to_seed = -options.wrench_sign;
  // Equation `index` fills rows c_rows·index … of its chosen components; the bias column of the
  // i-th chosen component is inertial + i.
  auto fill = [&](Eigen::Index index, double time, const Eigen::Matrix<double, 6, 10>& K,
                  const Eigen::Matrix<double, 6, 1>& y, double bias_scale) {
    for (Eigen::Index i = 0; i < c_rows; ++i) {
      const Eigen::Index row = c_rows * index + i;
      const int c = rows_of[static_cast<std::size_t>(i)];
      block.W.row(row).head(inertial) = K.row(c).head(inertial);
      if (options.bias) block.W(row, inertial + i) = to_seed * bias_scale;
      block.y(row) = y(c);
      block.group(row) = static_cast<int>(i);
      block.sample(row) = static_cast<int>(index);
      block.t(row) = time;
    }
  };
  auto resize = [&](Eigen::Index equations) {
    block.W.setZero(c_rows * equations, p);
    block.y.resize(c_rows * equations);
    block.group.resize(c_rows * equations);
    block.sample.resize(c_rows * equations);
    block.t.resize(c_rows * equations);
  };
  const Eigen::Vector3d zero = Eigen::Vector3d::Zero();
  if (standing && m < (options.bias ? 3 : 2)) {
    throw Error("the static model needs at least " + std::to_string(options.bias ? 3 : 2) +
                " standing poses with different sensor orientations" +
                (options.bias ? " (3 with the six offsets)" : "") + "; the data have " +
                std::to_string(m));
  }
  if (options.model != LoadModelKind::kIntegral) {
    resize(m);
    for (Eigen::Index k = 0; k < m; ++k) {
      const auto K = standing ? load_regressor(zero, zero, zero, row3(motion.g, k))
                              : load_regressor(row3(motion.w, k), row3(motion.dw, k),
                                               row3(motion.a, k), row3(motion.g, k));
      fill(k, standing ? 0.0 : motion.t(k), K, to_seed * wrench.row(k).transpose(), 1.0);
    }
    return block;
  }
  // Integral model: windows of `interval` seconds, the trapezoidal rule on the samples.
  const double span = motion.t(m - 1) - motion.t(0);
  const double step = span / static_cast<double>(std::max<Eigen::Index>(m - 1, 1));
  if (!(options.interval >= step) || !std::isfinite(options.interval)) {
    throw UsageError("--interval " + short_number(options.interval) +
                     " s is shorter than one sample step (" + short_number(step) +
                     " s); give a window of several samples");
  }
  const auto per_window =
      std::max<Eigen::Index>(1, static_cast<Eigen::Index>(std::llround(options.interval / step)));
  const Eigen::Index windows = (m - 1) / per_window;
  if (c_rows * windows < p + 1) {
    throw Error("the run of " + short_number(span) + " s gives " + std::to_string(windows) +
                " integration windows of " + short_number(options.interval) + " s, too few for " +
                std::to_string(p) + " parameters; shorten --interval or record a longer run");
  }
  resize(windows);
  const bool have_v = motion.v.rows() == m;
  for (Eigen::Index w = 0; w < windows; ++w) {
    const Eigen::Index k0 = w * per_window, k1 = k0 + per_window;
    Eigen::Matrix<double, 6, 10> K = Eigen::Matrix<double, 6, 10>::Zero();
    Eigen::Matrix<double, 6, 1> y = Eigen::Matrix<double, 6, 1>::Zero();
    for (Eigen::Index k = k0; k < k1; ++k) {
      const double h = 0.5 * (motion.t(k + 1) - motion.t(k));
      for (const Eigen::Index i : {k, k + 1}) {
        const Eigen::Vector3d wi = row3(motion.w, i);
        // The part of K without time derivatives: eqs. 30–31's ∫[ω×][ω×], ∫[ω×][·ω], ∫ω×v and
        // ∫R g; without v the translational acceleration is integrated as given.
        const Eigen::Vector3d trans =
            have_v ? Eigen::Vector3d(wi.cross(row3(motion.v, i))) : row3(motion.a, i);
        K.noalias() += h * load_regressor(wi, zero, trans, row3(motion.g, i));
        y.noalias() += h * to_seed * wrench.row(i).transpose();
      }
    }
    // The derivatives integrate exactly: ∫ω̇ = ω|, ∫(v̇ in S) + ω×v = v| (eqs. 30–31).
    const Eigen::Vector3d dv =
        have_v ? Eigen::Vector3d(row3(motion.v, k1) - row3(motion.v, k0)) : zero;
    K += load_regressor(zero, row3(motion.w, k1) - row3(motion.w, k0), dv, zero);
    fill(w, motion.t(k1), K, y, motion.t(k1) - motion.t(k0));
  }
  return block;
}

LoadPhysics load_physics(const Eigen::Ref<const Eigen::VectorXd>& phi, bool with_inertia) {
  LoadPhysics out;
  out.mass = phi(0);
  if (!(out.mass > 0.0)) {
    out.violated = "mass not positive (m = " + short_number(out.mass) + " kg)";
    return out;
  }
  const Eigen::Vector3d h = phi.segment<3>(1);
  out.com = h / out.mass;
  if (!with_inertia) {
    out.consistent = true;
    return out;
  }
  Eigen::Matrix3d I_P;
  I_P << phi(4), phi(5), phi(6),  //
      phi(5), phi(7), phi(8),     //
      phi(6), phi(8), phi(9);
  // Seed 1 eq. 24 with c = h/m: m[(cᵀc)1 − ccᵀ] = [(hᵀh)1 − hhᵀ]/m.
  out.inertia_com =
      I_P - (h.squaredNorm() * Eigen::Matrix3d::Identity() - h * h.transpose()) / out.mass;
  const Eigen::Vector3d d =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(out.inertia_com, Eigen::EigenvaluesOnly)
          .eigenvalues();
  if (!(d(0) > 0.0)) {
    out.violated =
        "inertia about the centre of mass not positive definite (smallest principal "
        "moment " +
        short_number(d(0)) + " kg m^2)";
    return out;
  }
  // Principal moments of a real body: each at most the sum of the other two.
  if (!(d(2) <= d(0) + d(1))) {
    out.violated = "principal moments break the triangle inequality (" + short_number(d(2)) +
                   " > " + short_number(d(0)) + " + " + short_number(d(1)) + " kg m^2)";
    return out;
  }
  out.consistent = true;
  return out;
}

namespace {

// The U-D recursion (seed 1 §IV) starts from a prior P0 = c·I, so a column no row reaches keeps
// its prior value 0 with a finite σ, and its Estimate carries no residual statistics: the result
// showed relative error 0 and undetermined inertias as 0 ± 0. The batch factorisation of the same
// rows names the columns in W's null space (σ = ∞ for them, as OLS reports them), and the
// residual statistics are those of the recursive estimate itself.
void rls_residual_statistics(const EquationBlock& block, const EstimationOptions& estimation,
                             Estimate& e) {
  const Estimate batch = ordinary_least_squares(block.W, block.y, block.group, estimation);
  e.unidentifiable = batch.unidentifiable;
  for (const Eigen::Index j : e.unidentifiable) {
    e.std_dev(j) = e.relative_std_percent(j) = std::numeric_limits<double>::infinity();
    e.ci_lower(j) = -std::numeric_limits<double>::infinity();
    e.ci_upper(j) = std::numeric_limits<double>::infinity();
  }
  const Eigen::VectorXd residual = block.y - block.W * e.x;
  const auto rows = static_cast<double>(std::max<Eigen::Index>(residual.size(), 1));
  e.residual_rms = std::sqrt(residual.squaredNorm() / rows);
  e.relative_error = residual.norm() / std::max(block.y.norm(), 1e-300);
  const Eigen::Index groups = block.group.size() ? block.group.maxCoeff() + 1 : 0;
  Eigen::VectorXd e2 = Eigen::VectorXd::Zero(groups), y2 = e2, m = e2;
  for (Eigen::Index i = 0; i < block.group.size(); ++i) {
    e2(block.group(i)) += residual(i) * residual(i);
    y2(block.group(i)) += block.y(i) * block.y(i);
    m(block.group(i)) += 1.0;
  }
  e.group_rows = m;
  e.group_rms = (e2.array() / m.array()).sqrt();  // NaN for a group without rows
  e.group_relative_error = (e2.array() / y2.array().max(1e-300)).sqrt();
}

// Joint torques determine only combinations of a robot's parameters, and of a load's when the
// runs do not move every joint that carries it.
const char* const kTorqueRemedy =
    "the joint torques of these runs do not determine them alone (the robot's own parameters "
    "need not be: only the load's are reported); load parameters among them are listed under "
    "not_excited: a run that moves the load's joints more, or a wrist force/torque sensor "
    "(--sensor-link), determines them";

// The block's estimate by the estimator of `options`, with the HAC sandwich when asked.
// `remedy`: what the user of dynid payload can do about undetermined columns (the estimator's
// "regroup" means nothing to someone who gave a run).
Estimate estimate_block(const EquationBlock& block, const LoadIdentificationOptions& options,
                        Eigen::MatrixXd* history, const std::string& remedy) {
  EstimationOptions estimation;
  estimation.confidence_level = options.confidence_level;
  estimation.names = block.columns;
  estimation.rank_deficient_remedy = remedy;
  Estimate estimate;
  if (options.estimator == LoadEstimator::kOls) {
    estimate = ordinary_least_squares(block.W, block.y, block.group, estimation);
  } else if (options.estimator == LoadEstimator::kWls) {
    estimate = weighted_least_squares(block.W, block.y, block.group, estimation);
  } else {
    RecursiveLeastSquaresOptions rls;
    rls.record_history = options.record_history;
    estimate = recursive_least_squares(block.W, block.y, rls, estimation,
                                       options.record_history ? history : nullptr);
    rls_residual_statistics(block, estimation, estimate);
  }
  if (options.hac_covariance) {
    // The sandwich needs the rows the estimator solved: WLS divides group g's rows by σ_g.
    Eigen::MatrixXd W = block.W;
    Eigen::VectorXd y = block.y;
    if (options.estimator == LoadEstimator::kWls) {
      for (Eigen::Index i = 0; i < W.rows(); ++i) {
        const double v = estimate.group_variance(block.group(i));
        const double s = v > 0.0 && std::isfinite(v) ? 1.0 / std::sqrt(v) : 1.0;
        W.row(i) *= s;
        y(i) *= s;
      }
    }
    const Eigen::VectorXd residual = y - W * estimate.x;
    apply_hac_covariance(estimate, W, residual, block.sample, estimation);
  }
  return estimate;
}

// The mass checks of identify_load: no load, or the wrench logged with the other sign.
void check_mass(const Estimate& e) {
  if (e.ci_upper(0) < 0.0) {
    throw Error("the identified mass is negative (" + short_number(e.x(0)) + " kg, interval " +
                short_number(e.ci_lower(0)) + ".." + short_number(e.ci_upper(0)) +
                "): the wrench was logged as the force on the load, not on the sensor; give "
                "--wrench-sign -1");
  }
  if (!(e.ci_lower(0) > 0.0)) {
    throw Error("the data show no load: the mass " + short_number(e.x(0)) +
                " kg is not distinguishable from zero (interval " + short_number(e.ci_lower(0)) +
                ".." + short_number(e.ci_upper(0)) +
                "); check that a load was gripped and that the data columns are the right ones");
  }
}

// Rows of `e` restricted to parameters first..first+count-1 (x, σ, intervals, covariance).
Estimate slice(const Estimate& e, Eigen::Index first, Eigen::Index count) {
  Estimate out = e;
  out.x = e.x.segment(first, count);
  out.covariance = e.covariance.block(first, first, count, count);
  out.std_dev = e.std_dev.segment(first, count);
  out.relative_std_percent = e.relative_std_percent.segment(first, count);
  out.ci_lower = e.ci_lower.segment(first, count);
  out.ci_upper = e.ci_upper.segment(first, count);
  for (Eigen::VectorXd* v : {&out.std_dev_white, &out.ci_lower_white, &out.ci_upper_white}) {
    if (v->size()) *v = v->segment(first, count).eval();
  }
  out.unidentifiable.clear();
  for (const Eigen::Index j : e.unidentifiable) {
    if (j >= first && j < first + count) out.unidentifiable.push_back(j - first);
  }
  out.poorly_excited.clear();
  for (const Eigen::Index j : e.poorly_excited) {
    if (j >= first && j < first + count) out.poorly_excited.push_back(j - first);
  }
  out.dependent_columns.clear();
  return out;
}

}  // namespace

CutoffSelection select_load_cutoff(const Model& model, const SensorMount& mount,
                                   const JointRecord& record,
                                   const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                                   const SignalOptions& signal,
                                   const LoadEquationOptions& equations,
                                   const CutoffSelectionOptions& selection) {
  const Eigen::MatrixXd reading = wrench;
  const CutoffEquationBuilder build = [&](const SignalOptions& s) {
    std::vector<std::pair<std::string, std::string>> ignored;
    const PreparedLoadRun run = prepare_load_run(record, reading, s, ignored);
    const EquationBlock block =
        load_equations(sensor_motion_from_joints(model, run.record, mount), run.wrench, equations);
    CutoffEquations e;
    e.W = block.W;
    e.y = block.y;
    e.sample = block.sample;
    return e;
  };
  // The load's equations hold ω×(ω×c) and ω×(I·ω): products of two motion signals.
  CutoffSelectionOptions products = selection;
  products.regressor_degree = std::max(products.regressor_degree, 2);
  return select_cutoff_held_out(record, signal, build, "wrench", products);
}

PreparedLoadRun prepare_sensor_run(const Model& model, const SensorMount& mount,
                                   const JointRecord& record,
                                   const Eigen::Ref<const Eigen::MatrixXd>& wrench,
                                   const SignalOptions& signal,
                                   const LoadEquationOptions& equations,
                                   std::vector<std::pair<std::string, std::string>>& choices) {
  const CutoffSelection cutoff =
      select_load_cutoff(model, mount, record, wrench, signal, equations);
  PreparedLoadRun run = prepare_load_run(record, wrench, cutoff.signal, choices);
  echo_cutoff_selection(cutoff, choices);
  return run;
}

LoadIdentificationResult identify_load(const EquationBlock& block,
                                       const LoadIdentificationOptions& options) {
  LoadIdentificationResult out;
  out.names = block.columns;
  // A subset of the six equations (seed 1 §VI-B) may leave m (moments only) or the inertias
  // (forces only) undetermined by design: that is the user's choice, reported, not an error.
  const bool subset = block.group_names.size() < 6;
  out.estimate = estimate_block(
      block, options, &out.history,
      subset ? "the chosen --components do not determine them (forces determine m and mc, "
               "moments mc and the inertias); they are listed under not_excited"
             : "the run does not excite them: record one that turns the sensor through more "
               "orientations with larger angular velocities and accelerations, or give --static "
               "to identify m and mc only; they are listed under not_excited");
  const Estimate& e = out.estimate;
  const auto undetermined = [&](Eigen::Index first, Eigen::Index last) {
    return std::any_of(e.unidentifiable.begin(), e.unidentifiable.end(),
                       [&](Eigen::Index j) { return j >= first && j < last; });
  };
  if (!subset && undetermined(0, 4)) {
    std::string names;
    for (const Eigen::Index j : e.unidentifiable) {
      names += (names.empty() ? "" : ", ") + out.names[static_cast<std::size_t>(j)];
    }
    throw Error("the data do not determine " + names +
                ": gravity keeps one direction in the sensor frame (the poses are all the same); "
                "record poses or a motion with several sensor orientations");
  }
  if (!undetermined(0, 1)) check_mass(e);
  std::vector<bool> flagged(out.names.size(), false);
  for (const Eigen::Index j : e.unidentifiable) flagged[j] = true;
  const auto first_inertia = std::find(out.names.begin(), out.names.end(), "Ixx");
  if (first_inertia != out.names.end()) {
    // Slow motions determine m and mc through gravity but not the inertias (seed 1 §VI-B). An
    // inertia whose σ exceeds 30 % of the load's rotational scale says nothing. The scale is the
    // larger of m|c|² (trace(I_P)/2 ≥ m|c|²) and the largest principal moment the data bound away
    // from zero (|I_ii| − 3σ_ii): poorly determined diagonal estimates must not inflate it.
    const auto i0 = static_cast<Eigen::Index>(first_inertia - out.names.begin());
    double scale = e.x(0) > 0.0 ? e.x.segment<3>(1).squaredNorm() / e.x(0) : 0.0;
    for (const Eigen::Index i : {i0, i0 + 3, i0 + 5}) {
      if (std::isfinite(e.std_dev(i))) {
        scale = std::max(scale, std::abs(e.x(i)) - 3.0 * e.std_dev(i));
      }
    }
    for (Eigen::Index i = i0; i < i0 + 6; ++i) {
      if (!(e.std_dev(i) <= 0.3 * scale)) flagged[static_cast<std::size_t>(i)] = true;
    }
  }
  for (std::size_t j = 0; j < out.names.size(); ++j) {
    if (flagged[j]) out.not_excited.push_back(out.names[j]);
  }
  const bool with_inertia = std::find(out.names.begin(), out.names.end(), "Ixx") != out.names.end();
  // Standing poses (the static model) carry no inertia column: the six inertias are not excited,
  // and are named so, as identify names what its data leave undetermined (issue 25 item 8).
  if (!with_inertia) {
    for (const char* name : {"Ixx", "Ixy", "Ixz", "Iyy", "Iyz", "Izz"})
      out.not_excited.emplace_back(name);
  }
  // An inertia the runs cannot reach (a planar motion leaves Ixx, Ixy, Iyy in W's null space) has
  // the minimum-norm value 0, and judging I_C ≻ 0 on it reports a violation the data never made:
  // as with the static model, only what the data determine is checked; not_excited names the rest.
  out.physics = load_physics(e.x, with_inertia && !undetermined(4, kLinkParams));
  if (undetermined(0, 4)) {
    out.physics.consistent = false;
    out.physics.violated = "the mass or centre of mass is not determined by the chosen components";
  }
  return out;
}

namespace {

// The ten load columns of the joint-torque equations of `record` (sample-major, (m·n)×10 in load
// order m mcx … Izz): the load enters like link `link`'s own standard parameters, Y_link·T, where
// T maps the load's parameters about F to those about the link origin (transform_link_params).
Eigen::MatrixXd load_link_columns(const Model& model, int link, const LoadFrame& frame,
                                  const JointRecord& record) {
  const int n = model.dof();
  if (link < 0 || link >= n) {
    throw Error("load link index " + std::to_string(link) + " is outside 0.." +
                std::to_string(n - 1));
  }
  const Eigen::MatrixXd Y = stacked_regressor(model, ParameterLayout::rigid(), false, record);
  Eigen::Matrix<double, kLinkParams, kLinkParams> T;
  for (int k = 0; k < kLinkParams; ++k) {
    T.col(k) = transform_link_params(LinkParams::Unit(k), frame.R_LF, frame.p_LF);
  }
  // Load order m mcx mcy mcz Ixx … Izz = link order indices M MX MY MZ XX … ZZ.
  const int kFromLinkOrder[kLinkParams] = {9, 6, 7, 8, 0, 1, 2, 3, 4, 5};
  const Eigen::MatrixXd link_columns = Y.middleCols(kLinkParams * link, kLinkParams) * T;
  Eigen::MatrixXd out(Y.rows(), kLinkParams);
  for (int k = 0; k < kLinkParams; ++k) out.col(k) = link_columns.col(kFromLinkOrder[k]);
  return out;
}

// The load's part of an estimate whose last ten columns are the load's (first = their index):
// parameters the joint torques do not determine get infinite σ and are listed; the mass checks
// and the physical reading apply to what is determined.
LoadIdentificationResult load_result_from_torques(const Estimate& full, Eigen::Index first) {
  LoadIdentificationResult out;
  out.names = load_parameter_names({});
  out.estimate = slice(full, first, kLinkParams);
  std::vector<bool> undetermined(kLinkParams, false);
  for (const Eigen::Index j : out.estimate.unidentifiable) {
    undetermined[static_cast<std::size_t>(j)] = true;
    out.estimate.std_dev(j) = std::numeric_limits<double>::infinity();
    out.estimate.ci_lower(j) = -std::numeric_limits<double>::infinity();
    out.estimate.ci_upper(j) = std::numeric_limits<double>::infinity();
  }
  for (int k = 0; k < kLinkParams; ++k) {
    if (undetermined[static_cast<std::size_t>(k)]) out.not_excited.push_back(out.names[k]);
  }
  if (!undetermined[0]) check_mass(out.estimate);
  if (out.not_excited.empty()) {
    out.physics = load_physics(out.estimate.x, true);
  } else {
    out.physics.violated = "not every parameter is determined by the joint torques";
  }
  return out;
}

}  // namespace

LoadIdentificationResult identify_load_from_torques(const Model& model, int link,
                                                    const LoadFrame& frame,
                                                    const ParameterLayout& layout,
                                                    const JointRecord& loaded,
                                                    const JointRecord& unloaded,
                                                    const LoadIdentificationOptions& options) {
  const int n = model.dof();
  const Eigen::MatrixXd load = load_link_columns(model, link, frame, loaded);
  const Eigen::MatrixXd Y_loaded = stacked_regressor(model, layout, false, loaded);
  const Eigen::MatrixXd Y_unloaded = stacked_regressor(model, layout, false, unloaded);
  const Eigen::Index p = Y_loaded.cols(), rows_l = Y_loaded.rows(), rows_u = Y_unloaded.rows();
  EquationBlock block;
  block.W.setZero(rows_l + rows_u, p + kLinkParams);
  block.W.topLeftCorner(rows_l, p) = Y_loaded;
  block.W.bottomLeftCorner(rows_u, p) = Y_unloaded;
  block.W.topRightCorner(rows_l, kLinkParams) = load;
  block.y.resize(rows_l + rows_u);
  for (Eigen::Index k = 0; k < loaded.tau.rows(); ++k) {
    block.y.segment(k * n, n) = loaded.tau.row(k).transpose();
  }
  for (Eigen::Index k = 0; k < unloaded.tau.rows(); ++k) {
    block.y.segment(rows_l + k * n, n) = unloaded.tau.row(k).transpose();
  }
  block.group = joint_row_groups(rows_l + rows_u, n);
  block.sample.resize(rows_l + rows_u);
  for (Eigen::Index i = 0; i < rows_l + rows_u; ++i) {
    block.sample(i) = static_cast<int>(i < rows_l ? i / n : loaded.tau.rows() + (i - rows_l) / n);
  }
  block.columns = layout.names(n);
  for (const auto& name : load_parameter_names({})) block.columns.push_back("load_" + name);
  LoadIdentificationOptions batch = options;
  batch.record_history = false;
  return load_result_from_torques(estimate_block(block, batch, nullptr, kTorqueRemedy), p);
}

LoadIdentificationResult identify_load_from_unexplained_torques(
    const Model& model, int link, const LoadFrame& frame, const JointRecord& loaded,
    const Eigen::Ref<const Eigen::MatrixXd>& predicted,
    const Eigen::Ref<const Eigen::VectorXd>& zero_velocity_threshold,
    const LoadIdentificationOptions& options) {
  const int n = model.dof();
  const Eigen::Index m = loaded.t.size();
  check_rows(loaded.q, m, n, "q");
  check_rows(loaded.dq, m, n, "dq");
  check_rows(loaded.ddq, m, n, "ddq");
  check_rows(loaded.tau, m, n, "tau");
  check_rows(predicted, m, n, "the predicted torque");
  if (zero_velocity_threshold.size() != 0 && zero_velocity_threshold.size() != n) {
    throw Error("the zero-velocity thresholds have " +
                std::to_string(zero_velocity_threshold.size()) + " values for " +
                std::to_string(n) + " joints; give one per joint or none");
  }
  const Eigen::MatrixXd load = load_link_columns(model, link, frame, loaded);
  // The rows identify() fits: near-still rows of a Coulomb model carry sign(dq) noise in the
  // prediction, so they are left out here as they were there.
  std::vector<Eigen::Index> rows;
  for (Eigen::Index k = 0; k < m; ++k) {
    for (int j = 0; j < n; ++j) {
      if (zero_velocity_threshold.size() == 0 ||
          std::abs(loaded.dq(k, j)) >= zero_velocity_threshold(j)) {
        rows.push_back(k * n + j);
      }
    }
  }
  EquationBlock block;
  const auto used = static_cast<Eigen::Index>(rows.size());
  block.W.resize(used, kLinkParams);
  block.y.resize(used);
  block.group.resize(used);
  block.sample.resize(used);
  for (Eigen::Index i = 0; i < used; ++i) {
    const Eigen::Index row = rows[static_cast<std::size_t>(i)], k = row / n;
    const int j = static_cast<int>(row % n);
    block.W.row(i) = load.row(row);
    block.y(i) = loaded.tau(k, j) - predicted(k, j);
    block.group(i) = j;
    block.sample(i) = static_cast<int>(k);
  }
  block.columns = load_parameter_names({});
  for (int j = 0; j < n; ++j) block.group_names.push_back(model.joints[j].name);
  if (!block.y.allFinite() || !block.W.allFinite()) {
    throw Error(
        "the loaded run or the predicted torques are not finite; check the run's torque "
        "columns and the reference result's parameter values");
  }
  LoadIdentificationOptions batch = options;
  batch.record_history = false;
  return load_result_from_torques(estimate_block(block, batch, nullptr, kTorqueRemedy), 0);
}

}  // namespace dynid
