#include "dynid/experiments/gravity_experiment.hpp"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/dynamics/workspace.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "dynid/identifiability/base_parameters.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "experiments/experiment_columns.hpp"

namespace dynid {

namespace {

struct Slope {
  int run = 0;
  int direction = 1;
  double velocity = 0.0;
  std::vector<Eigen::Index> samples;
};

// The cruise samples of one direction of run r, or an empty slope when the run does not move that
// way; Error when it moves that way without a constant-velocity part.
Slope find_slope(const ProcessedRecord& p, int r, int joint, int direction,
                 const GravityExperimentOptions& o) {
  Slope s;
  s.run = r;
  s.direction = direction;
  const Eigen::VectorXd v = direction * p.record.dq.col(joint);
  const double peak = v.maxCoeff();
  const double noise = p.velocity_noise_std.size() > joint ? p.velocity_noise_std[joint] : 0.0;
  if (!(peak > 3.0 * noise) || !(peak > 0.0)) return s;
  // The cruise velocity is the most populated one: the centre of the densest band of relative
  // width 2·cruise_tolerance among the moving samples (robust to overshoot and noise spikes,
  // which a median of the fast samples is not).
  std::vector<double> moving_v;
  for (Eigen::Index k = 0; k < v.size(); ++k)
    if (v[k] > 0.1 * peak) moving_v.push_back(v[k]);
  std::sort(moving_v.begin(), moving_v.end());
  size_t best_i = 0, best_count = 0;
  for (size_t i = 0, j = 0; i < moving_v.size(); ++i) {
    if (j < i) j = i;
    while (j + 1 < moving_v.size() &&
           moving_v[j + 1] <= moving_v[i] * (1.0 + 2.0 * o.cruise_tolerance)) {
      ++j;
    }
    if (j - i + 1 > best_count) {
      best_count = j - i + 1;
      best_i = i;
    }
  }
  s.velocity = moving_v.empty() ? 0.0 : moving_v[best_i + best_count / 2];
  Eigen::Index moving = 0;
  for (Eigen::Index k = 0; k < v.size(); ++k) {
    if (v[k] > 0.1 * s.velocity) ++moving;
    if (std::abs(v[k] - s.velocity) <= o.cruise_tolerance * s.velocity) s.samples.push_back(k);
  }
  const double fraction = static_cast<double>(s.samples.size()) / static_cast<double>(moving);
  if (fraction < o.min_cruise_fraction ||
      static_cast<Eigen::Index>(s.samples.size()) < o.min_cruise_samples) {
    std::ostringstream m;
    m << "run " << r + 1 << " moves joint " << joint + 1 << (direction > 0 ? " up" : " down")
      << " without a constant-velocity part (" << s.samples.size() << " of " << moving
      << " moving samples within " << 100.0 * o.cruise_tolerance << " % of "
      << direction * s.velocity
      << "); a gravity experiment needs slope runs (dynid excite --family slope)";
    throw Error(m.str());
  }
  s.velocity *= direction;
  return s;
}

// The cruise samples of every slope of joint J in `runs`, as fit rows sorted by (run, time) so
// that the HAC lags follow time; runs are kept apart in the sample index by a gap longer than any
// run.
struct Cruise {
  std::vector<Slope> slopes;
  std::vector<std::pair<Eigen::Index, Eigen::Index>> order;  // (slope, sample) per fit row
  Eigen::VectorXi sample;                                    // HAC sample index per fit row
};

Cruise collect_cruise(const std::vector<ProcessedRecord>& runs, int joint,
                      const GravityExperimentOptions& options) {
  Cruise c;
  for (size_t r = 0; r < runs.size(); ++r) {
    for (int direction : {1, -1}) {
      Slope s = find_slope(runs[r], static_cast<int>(r), joint, direction, options);
      if (!s.samples.empty()) c.slopes.push_back(std::move(s));
    }
  }
  if (c.slopes.empty()) {
    throw Error("no run moves joint " + std::to_string(joint + 1) +
                " above its velocity noise; record slope runs of that joint");
  }
  const auto S = static_cast<Eigen::Index>(c.slopes.size());
  for (Eigen::Index s = 0; s < S; ++s)
    for (Eigen::Index k : c.slopes[s].samples) c.order.emplace_back(s, k);
  std::sort(c.order.begin(), c.order.end(), [&](const auto& x, const auto& y) {
    const int rx = c.slopes[x.first].run, ry = c.slopes[y.first].run;
    return rx != ry ? rx < ry : x.second < y.second;
  });
  Eigen::Index gap = 0;
  for (const auto& p : runs) gap = std::max(gap, p.record.t.size());
  c.sample.resize(static_cast<Eigen::Index>(c.order.size()));
  for (size_t i = 0; i < c.order.size(); ++i) {
    c.sample[static_cast<Eigen::Index>(i)] =
        static_cast<int>(c.slopes[c.order[i].first].run * (gap + 1) + c.order[i].second);
  }
  return c;
}

void check_options(const std::vector<ProcessedRecord>& runs, const GravityExperimentOptions& o) {
  if (!(o.confidence_level > 0.0 && o.confidence_level < 1.0)) {
    throw UsageError("confidence level must be in (0, 1)");
  }
  if (!(o.cruise_tolerance > 0.0 && o.cruise_tolerance < 1.0)) {
    throw UsageError("cruise tolerance must be in (0, 1); use e.g. 0.05");
  }
  if (runs.empty()) throw UsageError("a gravity experiment needs at least one slope run");
}

}  // namespace

namespace detail {

Sinusoid sinusoid_from_linear(double a, double b, const Eigen::Matrix2d& C) {
  constexpr double kPi = 3.14159265358979323846;
  Sinusoid s;
  const double r2 = a * a + b * b;
  s.q_off = std::atan2(b, a);
  s.k = std::sqrt(r2);
  if (s.q_off > kPi / 2) {
    s.q_off -= kPi;
    s.k = -s.k;
  } else if (s.q_off <= -kPi / 2) {
    s.q_off += kPi;
    s.k = -s.k;
  }
  if (r2 > 0.0) {
    const Eigen::Vector2d dk(a / s.k, b / s.k), dq(-b / r2, a / r2);
    s.k_std = std::sqrt(dk.dot(C * dk));
    s.q_off_std = std::sqrt(dq.dot(C * dq));
  } else {
    s.k_std = std::sqrt(C.trace());
    s.q_off_std = INFINITY;
  }
  return s;
}

}  // namespace detail

GravityExperimentResult fit_gravity_experiment(const std::vector<ProcessedRecord>& runs, int joint,
                                               const GravityExperimentOptions& options) {
  check_options(runs, options);
  for (size_t r = 0; r < runs.size(); ++r) {
    if (joint < 0 || joint >= runs[r].record.q.cols()) {
      throw UsageError("joint " + std::to_string(joint + 1) + " is not a joint of run " +
                       std::to_string(r + 1) + ", which has " +
                       std::to_string(runs[r].record.q.cols()) + " joints");
    }
  }
  GravityExperimentResult out;
  out.joint = joint;
  out.confidence_level = options.confidence_level;
  const Cruise cruise = collect_cruise(runs, joint, options);
  const std::vector<Slope>& slopes = cruise.slopes;
  const auto& order = cruise.order;
  const Eigen::VectorXi& sample = cruise.sample;
  const auto S = static_cast<Eigen::Index>(slopes.size());
  const auto rows = static_cast<Eigen::Index>(order.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(rows, 2 + S);
  Eigen::VectorXd y(rows);
  out.sample_run.resize(rows);
  out.sample_q.resize(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const Slope& s = slopes[order[i].first];
    const Eigen::Index k = order[i].second;
    const double q = runs[s.run].record.q(k, joint);
    W(i, 0) = std::sin(q);
    W(i, 1) = std::cos(q);
    W(i, 2 + order[i].first) = 1.0;
    y[i] = runs[s.run].record.tau(k, joint);
    out.sample_run[i] = s.run;
    out.sample_q[i] = q;
  }
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = {"a", "b"};
  for (const Slope& s : slopes) {
    out.slope_names.push_back("run " + std::to_string(s.run + 1) + (s.direction > 0 ? " +" : " -"));
    out.slope_velocity.push_back(s.velocity);
    out.slope_rows.push_back(static_cast<Eigen::Index>(s.samples.size()));
    eo.names.push_back("c(" + out.slope_names.back() + ")");
  }
  out.estimate = ordinary_least_squares(W, y, Eigen::VectorXi(), eo);
  if (out.estimate.summary.rank < W.cols()) {
    double lo = out.sample_q.minCoeff(), hi = out.sample_q.maxCoeff();
    std::ostringstream m;
    m << "the slopes of joint " << joint + 1 << " cover q in [" << lo << ", " << hi
      << "] rad, too little to separate the gravity amplitude k from the offsets; run the "
         "slopes over a wider range (a quarter turn or more)";
    throw Error(m.str());
  }
  const Eigen::VectorXd e = y - W * out.estimate.x;
  const HacSummary h = apply_hac_covariance(out.estimate, W, e, sample, eo);
  out.rows = rows;
  out.relative_error = e.norm() / std::max(y.norm(), 1e-300);
  out.residual_rms = e.norm() / std::sqrt(static_cast<double>(rows));
  out.sample_tau = y;
  out.sample_fitted = W * out.estimate.x;
  const detail::Sinusoid g = detail::sinusoid_from_linear(
      out.estimate.x[0], out.estimate.x[1], out.estimate.covariance.topLeftCorner<2, 2>());
  out.k = g.k;
  out.q_off = g.q_off;
  out.k_std = g.k_std;
  out.q_off_std = g.q_off_std;
  out.k_ci_half_width = h.critical_value * out.k_std;
  out.q_off_ci_half_width = h.critical_value * out.q_off_std;
  for (Eigen::Index s = 0; s < S; ++s) {
    out.offset.push_back(out.estimate.x[2 + s]);
    out.offset_std.push_back(out.estimate.std_dev[2 + s]);
  }
  std::ostringstream c;
  c << rows << " cruise samples (|dq - v| <= " << options.cruise_tolerance << " |v|) on " << S
    << " slopes";
  out.choices.emplace_back("cruise", c.str());
  out.choices.emplace_back("covariance", "Newey-West (HAC) over samples, Bartlett window of " +
                                             std::to_string(h.bandwidth) +
                                             " samples; k and q_off by the delta method");
  if (std::abs(out.k) < h.critical_value * out.k_std) {
    out.warnings.push_back("the gravity amplitude of joint " + std::to_string(joint + 1) +
                           " is not distinguishable from zero at this level: its axis may be "
                           "vertical, and q_off then means nothing");
  }
  for (const std::string& w : out.estimate.summary.warnings) out.warnings.push_back(w);
  return out;
}

namespace {

// Poses (other than joint J) farther apart than 10·distinct_pose_tolerance in some joint.
int distinct_poses(const std::vector<Eigen::VectorXd>& poses, int joint,
                   const GravityExperimentOptions& options) {
  int distinct = 0;
  for (size_t r = 0; r < poses.size(); ++r) {
    bool seen = false;
    for (size_t u = 0; u < r && !seen; ++u) {
      Eigen::VectorXd d = poses[r] - poses[u];
      d[joint] = 0.0;
      seen = d.cwiseAbs().maxCoeff() <= 10.0 * options.distinct_pose_tolerance;
    }
    distinct += !seen;
  }
  return distinct;
}

// Row J of the torque regressor at rest (q̇ = q̈ = 0): the gravity row, over the link columns.
class GravityRow {
 public:
  GravityRow(const Model& model, int joint)
      : model_(model), ws_(model), joint_(joint), Y_(model.dof(), kLinkParams * model.dof()) {}
  Eigen::RowVectorXd operator()(const Eigen::VectorXd& q) {
    const Eigen::VectorXd zero = Eigen::VectorXd::Zero(model_.dof());
    torque_regressor(model_, ws_, ParameterLayout::rigid(), q, zero, zero, Y_);
    return Y_.row(joint_);
  }

 private:
  const Model& model_;
  Workspace ws_;
  int joint_;
  Eigen::MatrixXd Y_;
};

constexpr int kGravityPoses = 200;
constexpr unsigned kGravityPoseSeed = 20261130;

// The structural gravity base parameters of row J: its link columns sampled at random poses,
// classified left to right (so MX, MY, MZ lead and masses regroup into them). Fixed seed: the
// same model and joint always give the same names.
BaseParameters gravity_row_base(const Model& model, int joint) {
  const int n = model.dof();
  GravityRow gravity_row(model, joint);
  const std::vector<std::string> link_names = ParameterLayout::rigid().names(n);
  constexpr int kPoses = kGravityPoses;
  std::mt19937 rng(kGravityPoseSeed);
  std::uniform_real_distribution<double> angle(-3.14159265358979323846, 3.14159265358979323846);
  Eigen::MatrixXd random_rows(kPoses, kLinkParams * n);
  for (int s = 0; s < kPoses; ++s) {
    Eigen::VectorXd q(n);
    for (int i = 0; i < n; ++i) q[i] = angle(rng);
    random_rows.row(s) = gravity_row(q);
  }
  BaseParameterOptions bo;
  bo.layout = ParameterLayout::rigid();
  return classify_columns(random_rows, link_names, bo);
}

}  // namespace

struct JointGravityModel::Row {
  Row(const Model& m, int joint) : model(m), gravity_row(model, joint) {}
  Row(const Row&) = delete;  // gravity_row refers to this object's model
  Row& operator=(const Row&) = delete;
  Model model;              // owned: gravity_row refers to it
  GravityRow gravity_row;   // workspace reused by every torque() call
  Eigen::VectorXd weights;  // per link column [docs/design.md §3 order]
};

JointGravityModel JointGravityModel::sinusoid(int joint, double k, double q_off) {
  if (!std::isfinite(k) || !std::isfinite(q_off)) {
    throw Error("the gravity of joint " + std::to_string(joint + 1) +
                " (k, qoff) is not finite; give a result of dynid identify --model gravity");
  }
  JointGravityModel g;
  g.joint_ = joint;
  g.k_ = k;
  g.q_off_ = q_off;
  return g;
}

JointGravityModel JointGravityModel::poses(const Model& model, int joint,
                                           const std::vector<std::string>& names,
                                           const Eigen::VectorXd& values) {
  if (joint < 0 || joint >= model.dof()) {
    throw Error("joint " + std::to_string(joint + 1) + " is not a joint of model '" + model.name +
                "'");
  }
  const BaseParameters base = gravity_row_base(model, joint);
  if (base.names != names || values.size() != static_cast<Eigen::Index>(names.size()) ||
      !values.allFinite()) {
    throw Error("the gravity parameters given are not those of joint " + std::to_string(joint + 1) +
                " of model '" + model.name +
                "' (expected the names dynid identify --model gravity writes for it)");
  }
  JointGravityModel g;
  g.joint_ = joint;
  g.row_ = std::make_shared<Row>(model, joint);
  const auto columns = static_cast<Eigen::Index>(kLinkParams * model.dof());
  // base.select() maps rows over the link columns to the base columns (base + K_d·dependent), so
  // τ_g,J = Y_g,J(q)·select(I)·θ_g: one weight per link column, formed once.
  g.row_->weights = base.select(Eigen::MatrixXd::Identity(columns, columns)) * values;
  return g;
}

double JointGravityModel::torque(const Eigen::VectorXd& q) const {
  if (!row_) return k_ * std::sin(q[joint_] + q_off_);
  return row_->gravity_row(q).dot(row_->weights);
}

GravityPosesResult fit_gravity_poses(const Model& model, const std::vector<ProcessedRecord>& runs,
                                     int joint, const GravityExperimentOptions& options) {
  const int n = model.dof();
  check_options(runs, options);
  if (joint < 0 || joint >= n) {
    throw UsageError("joint " + std::to_string(joint + 1) + " is not a joint of model '" +
                     model.name + "', which has " + std::to_string(n));
  }
  for (size_t r = 0; r < runs.size(); ++r) {
    if (runs[r].record.q.cols() != n) {
      throw Error("run " + std::to_string(r + 1) + " has " +
                  std::to_string(runs[r].record.q.cols()) + " joints but model '" + model.name +
                  "' has " + std::to_string(n));
    }
  }
  const std::string jn = std::to_string(joint + 1);
  GravityRow gravity_row(model, joint);
  const BaseParameters base = gravity_row_base(model, joint);
  // The random poses of the diagnosis below continue the stream gravity_row_base() drew from.
  std::mt19937 rng(kGravityPoseSeed);
  std::uniform_real_distribution<double> angle(-3.14159265358979323846, 3.14159265358979323846);
  for (int s = 0; s < kGravityPoses * n; ++s) angle(rng);
  const int rg = base.rank;
  if (rg == 0) {
    throw Error("gravity exerts no torque on joint " + jn + " of '" + model.name +
                "' at any pose (its axis is vertical, or it carries no mass); there is nothing to "
                "fit");
  }
  GravityPosesResult out;
  out.joint = joint;
  out.confidence_level = options.confidence_level;
  out.names = base.names;
  out.expressions = base.expressions;
  const Cruise cruise = collect_cruise(runs, joint, options);
  const auto S = static_cast<Eigen::Index>(cruise.slopes.size());
  const auto rows = static_cast<Eigen::Index>(cruise.order.size());
  // The pose of each run: the mean of its cruise samples (the held joints, with their noise
  // averaged out).
  out.pose.assign(runs.size(), Eigen::VectorXd::Zero(n));
  std::vector<Eigen::Index> per_run(runs.size(), 0);
  for (const auto& [s, k] : cruise.order) {
    const int r = cruise.slopes[s].run;
    out.pose[r] += runs[r].record.q.row(k).transpose();
    ++per_run[r];
  }
  for (size_t r = 0; r < runs.size(); ++r)
    if (per_run[r] > 0) out.pose[r] /= static_cast<double>(per_run[r]);
  // Which gravity parameters the poses determine: the gravity columns at each run's mean pose
  // (q_J as measured) after the slope constants, classified with a tolerance that treats poses
  // closer than distinct_pose_tolerance as one. Measured held joints would make every column
  // look independent through their noise alone.
  // The cruise is closed-loop: the controller's ripple leaves q̈_J ≠ 0, and it follows the
  // gravity load, so left out it would bias θ_g. One equivalent inertia per run (M_JJ depends on
  // the held joints only, which are fixed in a run) takes it: τ_J += M_r·q̈_J.
  const auto R = static_cast<Eigen::Index>(runs.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(rows, rg + S + R);
  Eigen::MatrixXd at_pose = Eigen::MatrixXd::Zero(rows, S + rg);
  Eigen::VectorXd y(rows);
  for (Eigen::Index i = 0; i < rows; ++i) {
    const auto [s, k] = cruise.order[static_cast<size_t>(i)];
    const int r = cruise.slopes[s].run;
    const Eigen::VectorXd q = runs[r].record.q.row(k).transpose();
    W.row(i).head(rg) = base.select(gravity_row(q));
    W(i, rg + s) = 1.0;
    W(i, rg + S + r) = runs[r].record.ddq(k, joint);
    Eigen::VectorXd held = out.pose[r];
    held[joint] = q[joint];
    at_pose.row(i).tail(rg) = base.select(gravity_row(held));
    at_pose(i, s) = 1.0;
    y[i] = runs[r].record.tau(k, joint);
  }
  std::vector<std::string> check_names;
  for (Eigen::Index s = 0; s < S; ++s) check_names.push_back("c" + std::to_string(s));
  check_names.insert(check_names.end(), base.names.begin(), base.names.end());
  BaseParameterOptions check;
  check.dependence_tolerance = options.distinct_pose_tolerance;
  const BaseParameters determined = classify_columns(at_pose, check_names, check);
  std::vector<std::string> missing;
  for (int c : determined.dependent)
    if (c >= S) missing.push_back(check_names[static_cast<size_t>(c)]);
  for (int c : determined.unidentifiable)
    if (c >= S) missing.push_back(check_names[static_cast<size_t>(c)]);
  if (!missing.empty()) {
    // Count the distinct poses and name the joints the gravity of J depends on.
    std::vector<Eigen::VectorXd> fitted;
    for (size_t r = 0; r < runs.size(); ++r)
      if (per_run[r] > 0) fitted.push_back(out.pose[r]);
    const int distinct = distinct_poses(fitted, joint, options);
    std::string depends;
    for (int i = 0; i < n; ++i) {
      if (i == joint) continue;
      double change = 0.0, scale = 0.0;
      for (int s = 0; s < 20; ++s) {
        Eigen::VectorXd q(n);
        for (int m = 0; m < n; ++m) q[m] = angle(rng);
        const Eigen::RowVectorXd g0 = base.select(gravity_row(q));
        q[i] += 1.0;
        change = std::max(change, (base.select(gravity_row(q)) - g0).norm());
        scale = std::max(scale, g0.norm());
      }
      if (change > 1e-9 * scale) depends += (depends.empty() ? "" : ", ") + std::to_string(i + 1);
    }
    std::ostringstream m;
    m << "the slope runs of joint " << jn << " hold the other joints at " << distinct
      << " distinct pose" << (distinct == 1 ? "" : "s") << ", which leave";
    for (size_t i = 0; i < missing.size(); ++i) m << (i ? ", " : " ") << missing[i];
    m << " of its " << rg << " gravity base parameters undetermined (one pose determines only k "
      << "and q_off); record slope runs of joint " << jn << " with joint"
      << (depends.find(',') == std::string::npos ? " " : "s ") << depends << " held at "
      << (rg + 1) / 2 << " or more different poses, or fit one pose with fit_gravity_experiment";
    throw Error(m.str());
  }
  EstimationOptions eo;
  eo.confidence_level = options.confidence_level;
  eo.names = base.names;
  for (const Slope& s : cruise.slopes) {
    out.slope_names.push_back("run " + std::to_string(s.run + 1) + (s.direction > 0 ? " +" : " -"));
    out.slope_velocity.push_back(s.velocity);
    out.slope_rows.push_back(static_cast<Eigen::Index>(s.samples.size()));
    eo.names.push_back("c(" + out.slope_names.back() + ")");
  }
  for (Eigen::Index r = 0; r < R; ++r) eo.names.push_back("M(run " + std::to_string(r + 1) + ")");
  out.estimate = ordinary_least_squares(W, y, Eigen::VectorXi(), eo);
  const Eigen::VectorXd e = y - W * out.estimate.x;
  const HacSummary h = apply_hac_covariance(out.estimate, W, e, cruise.sample, eo);
  out.rows = rows;
  out.relative_error = e.norm() / std::max(y.norm(), 1e-300);
  out.residual_rms = e.norm() / std::sqrt(static_cast<double>(rows));
  for (Eigen::Index s = 0; s < S; ++s) {
    out.offset.push_back(out.estimate.x[rg + s]);
    out.offset_std.push_back(out.estimate.std_dev[rg + s]);
  }
  // Per pose: τ_g,J = a·sin q_J + b·cos q_J with a = Y_g,J(q_J = π/2)·θ_g and b = Y_g,J(q_J =
  // 0)·θ_g (exactly sinusoidal in q_J for a revolute joint), so (a, b) and their covariance are
  // linear in θ_g and its covariance.
  const Eigen::VectorXd theta = out.estimate.x.head(rg);
  const Eigen::MatrixXd C = out.estimate.covariance.topLeftCorner(rg, rg);
  for (size_t r = 0; r < runs.size(); ++r) {
    Eigen::VectorXd q = out.pose[r];
    Eigen::MatrixXd ab(2, rg);
    q[joint] = 3.14159265358979323846 / 2;
    ab.row(0) = base.select(gravity_row(q));
    q[joint] = 0.0;
    ab.row(1) = base.select(gravity_row(q));
    const Eigen::Vector2d v = ab * theta;
    const Eigen::Matrix2d Cab = ab * C * ab.transpose();
    const detail::Sinusoid g = detail::sinusoid_from_linear(v[0], v[1], Cab);
    out.k.push_back(g.k);
    out.q_off.push_back(g.q_off);
    out.k_std.push_back(g.k_std);
    out.q_off_std.push_back(g.q_off_std);
    out.k_ci_half_width.push_back(h.critical_value * g.k_std);
    out.q_off_ci_half_width.push_back(h.critical_value * g.q_off_std);
  }
  std::ostringstream c;
  c << rows << " cruise samples (|dq - v| <= " << options.cruise_tolerance << " |v|) on " << S
    << " slopes of " << runs.size() << " runs";
  out.choices.emplace_back("cruise", c.str());
  out.choices.emplace_back("gravity_columns",
                           "row " + jn + " of the torque regressor at rest, reduced to its " +
                               std::to_string(rg) + " base columns (200 random poses)");
  out.choices.emplace_back("covariance", "Newey-West (HAC) over samples, Bartlett window of " +
                                             std::to_string(h.bandwidth) +
                                             " samples; k and q_off per pose by the delta method");
  for (const std::string& w : out.estimate.summary.warnings) out.warnings.push_back(w);
  return out;
}

int count_distinct_poses(const std::vector<ProcessedRecord>& runs, int joint,
                         const GravityExperimentOptions& options) {
  std::vector<Eigen::VectorXd> poses;
  for (size_t r = 0; r < runs.size(); ++r) {
    const Eigen::MatrixXd& q = runs[r].record.q;
    if (joint < 0 || joint >= q.cols()) {
      throw UsageError("joint " + std::to_string(joint + 1) + " is not a joint of run " +
                       std::to_string(r + 1) + ", which has " + std::to_string(q.cols()) +
                       " joints");
    }
    if (q.rows() > 0) poses.push_back(q.colwise().mean().transpose());
  }
  return distinct_poses(poses, joint, options);
}

}  // namespace dynid
