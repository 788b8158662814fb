#include "dynid/estimation/gravity_experiment.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "dynid/common/error.hpp"
#include "dynid/estimation/least_squares.hpp"
#include "dynid/estimation/statistics.hpp"
#include "estimation/experiment_columns.hpp"

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
  if (!(options.confidence_level > 0.0 && options.confidence_level < 1.0)) {
    throw UsageError("confidence level must be in (0, 1)");
  }
  if (!(options.cruise_tolerance > 0.0 && options.cruise_tolerance < 1.0)) {
    throw UsageError("cruise tolerance must be in (0, 1); use e.g. 0.05");
  }
  if (runs.empty()) throw UsageError("a gravity experiment needs at least one slope run");
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
  std::vector<Slope> slopes;
  for (size_t r = 0; r < runs.size(); ++r) {
    for (int direction : {1, -1}) {
      Slope s = find_slope(runs[r], static_cast<int>(r), joint, direction, options);
      if (!s.samples.empty()) slopes.push_back(std::move(s));
    }
  }
  if (slopes.empty()) {
    throw Error("no run moves joint " + std::to_string(joint + 1) +
                " above its velocity noise; record slope runs of that joint");
  }
  const auto S = static_cast<Eigen::Index>(slopes.size());
  Eigen::Index rows = 0;
  for (const Slope& s : slopes) rows += static_cast<Eigen::Index>(s.samples.size());
  // Rows sorted by (run, time) so that the HAC lags follow time; runs are kept apart in the
  // sample index by a gap longer than any run.
  std::vector<std::pair<Eigen::Index, Eigen::Index>> order;  // (slope, sample)
  for (Eigen::Index s = 0; s < S; ++s)
    for (Eigen::Index k : slopes[s].samples) order.emplace_back(s, k);
  std::sort(order.begin(), order.end(), [&](const auto& x, const auto& y) {
    const int rx = slopes[x.first].run, ry = slopes[y.first].run;
    return rx != ry ? rx < ry : x.second < y.second;
  });
  Eigen::Index gap = 0;
  for (const auto& p : runs) gap = std::max(gap, p.record.t.size());
  Eigen::MatrixXd W = Eigen::MatrixXd::Zero(rows, 2 + S);
  Eigen::VectorXd y(rows);
  Eigen::VectorXi sample(rows);
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
    sample[i] = static_cast<int>(s.run * (gap + 1) + k);
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

}  // namespace dynid
