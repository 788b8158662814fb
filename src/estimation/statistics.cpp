#include "dynid/estimation/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <mutex>
#include <random>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <Eigen/SVD>
#include <boost/math/distributions/students_t.hpp>

#include "dynid/common/error.hpp"

namespace dynid {

double student_t_quantile(double level, double dof) {
  if (!(level > 0.0 && level < 1.0)) {
    throw Error("confidence level " + std::to_string(level) +
                " is outside (0, 1); pass a level such as 0.95 or 0.999");
  }
  if (!(dof > 0.0) || !std::isfinite(dof)) {
    throw Error("Student-t degrees of freedom " + std::to_string(dof) +
                " must be positive and finite; use more rows than parameters");
  }
  const boost::math::students_t dist(dof);
  return boost::math::quantile(boost::math::complement(dist, 0.5 * (1.0 - level)));
}

void fill_parameter_statistics(Estimate& e, const EstimationOptions& options) {
  const double level = options.confidence_level;
  if (!(level > 0.0 && level < 1.0)) {
    // Named as the user gives it (--confidence, confidence_level=), not by the C++ field.
    std::ostringstream shown;
    shown << level;
    throw Error("the confidence level (confidence_level) " + shown.str() +
                " is outside (0, 1); give a level such as 0.95 or 0.999 (--confidence)");
  }
  const Eigen::Index p = e.x.size();
  const double inf = std::numeric_limits<double>::infinity();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  e.confidence_level = level;
  e.std_dev = e.covariance.diagonal().cwiseMax(0.0).cwiseSqrt();
  for (Eigen::Index j : e.unidentifiable) e.std_dev(j) = inf;
  if (e.degrees_of_freedom <= 0) {
    e.std_dev.setConstant(nan);
    e.summary.warnings.push_back(
        "no degrees of freedom left (rows = rank): statistics are NaN; "
        "add rows to estimate the noise");
  }
  e.relative_std_percent.resize(p);
  for (Eigen::Index j = 0; j < p; ++j) {
    const double ax = std::abs(e.x(j));
    e.relative_std_percent(j) = ax > 0.0 ? 100.0 * e.std_dev(j) / ax : inf;
  }
  e.t_quantile =
      e.degrees_of_freedom > 0 ? student_t_quantile(level, double(e.degrees_of_freedom)) : nan;
  e.critical_value = e.t_quantile;
  e.ci_lower = e.x - e.t_quantile * e.std_dev;
  e.ci_upper = e.x + e.t_quantile * e.std_dev;
  e.poorly_excited.clear();
  for (Eigen::Index j = 0; j < p; ++j) {
    if (e.relative_std_percent(j) > options.poorly_excited_percent) e.poorly_excited.push_back(j);
  }
}

namespace {

constexpr int kFixedBSteps = 1000, kFixedBDraws = 2000;

// The simulation behind fixed_b_critical_value for a window of M of its kFixedBSteps steps.
double simulate_fixed_b_critical_value(double level, int M) {
  constexpr int kSteps = kFixedBSteps, kDraws = kFixedBDraws;
  // Own Box–Muller on mt19937_64 (whose output the standard fixes): the same values everywhere.
  std::mt19937_64 rng(20050601);
  const double two_pi = 2.0 * std::acos(-1.0), scale = 1.0 / 18446744073709551616.0;
  auto uniform = [&] { return (static_cast<double>(rng()) + 0.5) * scale; };
  std::vector<double> q(kDraws);
  Eigen::VectorXd u(kSteps), S(kSteps);
  for (int r = 0; r < kDraws; ++r) {
    for (int t = 0; t < kSteps; t += 2) {
      const double rad = std::sqrt(-2.0 * std::log(uniform())), ang = two_pi * uniform();
      u(t) = rad * std::cos(ang);
      if (t + 1 < kSteps) u(t + 1) = rad * std::sin(ang);
    }
    u.array() -= u.mean();
    double acc = 0.0;
    for (int t = 0; t < kSteps; ++t) S(t) = acc += u(t);
    // Σ_{t,s} u_t u_s (1 − |t−s|/M)₊ = (2/M)[Σ S_t² − Σ S_t S_{t+M}] with S_T = 0 (summation by
    // parts twice: the second difference of the Bartlett weights is 2/M at 0, −1/M at ±M).
    double sum = S.head(kSteps - 1).squaredNorm();
    if (M < kSteps - 1) sum -= S.head(kSteps - 1 - M).dot(S.segment(M, kSteps - 1 - M));
    q[r] = 2.0 / M * sum / kSteps;
  }
  auto coverage = [&](double c) {
    double acc = 0.0;
    for (double v : q) acc += std::erf(c * std::sqrt(std::max(v, 0.0)) / std::sqrt(2.0));
    return acc / kDraws;
  };
  double lo = 0.0, hi = 1.0;
  while (coverage(hi) < level && hi < 1e6) hi *= 2.0;
  for (int it = 0; it < 80; ++it) {
    const double mid = 0.5 * (lo + hi);
    (coverage(mid) < level ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

double fixed_b_critical_value(double level, double b) {
  if (!(level > 0.0 && level < 1.0)) {
    throw Error("confidence level " + std::to_string(level) +
                " is outside (0, 1); pass a level such as 0.95 or 0.999");
  }
  if (!(b >= 0.0 && b <= 1.0)) {
    throw Error("fixed-b fraction " + std::to_string(b) +
                " is outside [0, 1]; pass (bandwidth + 1)/samples");
  }
  const int M = std::max(1, static_cast<int>(std::lround(b * kFixedBSteps)));
  // The value depends on (level, M) only and its simulation has a fixed seed, so it is computed
  // once per process: one simulation costs 2·10⁶ normal draws (50-150 ms), which every HAC
  // estimate, every run of a Monte-Carlo test and every stage of a project file paid again.
  static std::mutex mutex;
  static std::map<std::pair<double, int>, double> known;
  {
    const std::lock_guard<std::mutex> lock(mutex);
    const auto it = known.find({level, M});
    if (it != known.end()) return it->second;
  }
  const double c = simulate_fixed_b_critical_value(level, M);
  const std::lock_guard<std::mutex> lock(mutex);
  known.emplace(std::make_pair(level, M), c);
  return c;
}

Eigen::MatrixXd bartlett_long_run_covariance(const Eigen::Ref<const Eigen::MatrixXd>& G, int lags) {
  if (lags < 0) {
    throw Error("bartlett_long_run_covariance: " + std::to_string(lags) + " lags; pass 0 or more");
  }
  const Eigen::Index T = G.rows(), p = G.cols();
  Eigen::MatrixXd S = Eigen::MatrixXd::Zero(p, p);
  if (T == 0) return S;
  const Eigen::Index M = std::min<Eigen::Index>(lags, T - 1) + 1;
  // C_t = Σ_{u<t} g_u; window j covers samples [j, j + M − 1] ∩ [0, T − 1], j = −M+1 … T−1, and
  // its sum is B_j = C_min(j+M,T) − C_max(j,0).
  Eigen::MatrixXd C(T + 1, p);
  C.row(0).setZero();
  for (Eigen::Index t = 0; t < T; ++t) C.row(t + 1) = C.row(t) + G.row(t);
  Eigen::MatrixXd B(T + M - 1, p);
  for (Eigen::Index j = -M + 1; j < T; ++j) {
    B.row(j + M - 1) = C.row(std::min(j + M, T)) - C.row(std::max<Eigen::Index>(j, 0));
  }
  S.selfadjointView<Eigen::Lower>().rankUpdate(B.transpose(), 1.0 / static_cast<double>(M));
  S.triangularView<Eigen::StrictlyUpper>() = S.transpose();
  return S;
}

namespace {

// Andrews' (1991) AR(1) plug-in bandwidth for the Bartlett kernel, L = 1.1447·(α̂·T)^(1/3), with
// each score component standardised (unit weights on the standardised series make the rule
// independent of the parameters' units). ρ is capped at 0.97: beyond, the plug-in explodes while
// the cap at T/4 decides anyway.
int andrews_bandwidth(const Eigen::MatrixXd& G, double& mean_rho) {
  const Eigen::Index T = G.rows();
  double num = 0.0, den = 0.0, rho_sum = 0.0;
  int used = 0;
  for (Eigen::Index a = 0; a < G.cols(); ++a) {
    const Eigen::VectorXd g = G.col(a);
    const double lagged = g.head(T - 1).squaredNorm();
    if (!(lagged > 0.0)) continue;
    double rho = g.tail(T - 1).dot(g.head(T - 1)) / lagged;
    rho = std::clamp(rho, -0.97, 0.97);
    rho_sum += rho;
    ++used;
    num += 4.0 * rho * rho / (std::pow(1.0 - rho, 6) * std::pow(1.0 + rho, 2));
    den += 1.0 / std::pow(1.0 - rho, 4);
  }
  mean_rho = used ? rho_sum / used : 0.0;
  if (!(den > 0.0)) return 0;
  const double L = 1.1447 * std::cbrt(num / den * static_cast<double>(T));
  return static_cast<int>(std::min(std::ceil(L), std::floor((T - 1) / 4.0)));
}

}  // namespace

HacSummary apply_hac_covariance(Estimate& e, const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const Eigen::Ref<const Eigen::VectorXd>& res,
                                const Eigen::Ref<const Eigen::VectorXi>& sample,
                                const EstimationOptions& estimation_options,
                                const HacOptions& options) {
  const Eigen::Index m = W.rows(), p = W.cols();
  if (res.size() != m || sample.size() != m || e.x.size() != p || e.covariance.rows() != p) {
    throw Error("apply_hac_covariance: W is " + std::to_string(m) + "×" + std::to_string(p) +
                ", e has " + std::to_string(res.size()) + " and sample " +
                std::to_string(sample.size()) + " entries, the estimate " +
                std::to_string(e.x.size()) + " parameters; pass the rows the estimator solved");
  }
  HacSummary out;
  if (m == 0 || !(e.residual_variance > 0.0) || e.degrees_of_freedom <= 0) return out;
  if (sample(0) < 0) throw Error("apply_hac_covariance: sample indices must be >= 0");
  for (Eigen::Index i = 1; i < m; ++i) {
    if (sample(i) < sample(i - 1)) {
      throw Error("apply_hac_covariance: sample index decreases at row " + std::to_string(i) +
                  "; pass the rows in time order");
    }
  }
  // Per-sample scores g_k = Σ W_iᵀ e_i; samples without rows keep a zero score (gaps).
  const Eigen::Index T = sample(m - 1) + 1;
  Eigen::MatrixXd G = Eigen::MatrixXd::Zero(T, p);
  for (Eigen::Index i = 0; i < m; ++i) G.row(sample(i)) += res(i) * W.row(i);
  // Andrews–Monahan pre-whitening: V = residuals of a VAR(1) fitted to the scores.
  Eigen::MatrixXd A = Eigen::MatrixXd::Zero(p, p);
  if (options.prewhiten && T > 2) {
    const Eigen::MatrixXd M = G.topRows(T - 1).transpose() * G.topRows(T - 1);
    const Eigen::MatrixXd C = G.bottomRows(T - 1).transpose() * G.topRows(T - 1);
    A = M.completeOrthogonalDecomposition().solve(C.transpose()).transpose();
    Eigen::JacobiSVD<Eigen::MatrixXd> svd(A, Eigen::ComputeFullU | Eigen::ComputeFullV);
    const Eigen::VectorXd sv = svd.singularValues().cwiseMin(0.97);
    A = svd.matrixU() * sv.asDiagonal() * svd.matrixV().transpose();
    const Eigen::MatrixXd V = G.bottomRows(T - 1) - G.topRows(T - 1) * A.transpose();
    G = V;
  }
  const Eigen::Index Tv = G.rows();
  double lag1 = 0.0;
  int L = options.bandwidth >= 0
              ? static_cast<int>(std::min<Eigen::Index>(options.bandwidth, Tv - 1))
              : andrews_bandwidth(G, lag1);
  if (options.bandwidth < 0) {
    const double floor_lags = std::ceil(options.min_bandwidth_fraction * Tv) - 1.0;
    L = std::max(L, static_cast<int>(std::min(floor_lags, std::floor((Tv - 1) / 4.0))));
  }
  out.score_lag1 = lag1;
  out.bandwidth = L;
  Eigen::MatrixXd S = bartlett_long_run_covariance(G, L);
  if (options.prewhiten && T > 2) {
    const Eigen::MatrixXd R =
        (Eigen::MatrixXd::Identity(p, p) - A).fullPivLu().solve(Eigen::MatrixXd::Identity(p, p));
    S = R * S * R.transpose();
  }
  const Eigen::MatrixXd bread = e.covariance / e.residual_variance;
  const double dof_correction = static_cast<double>(m) / static_cast<double>(e.degrees_of_freedom);
  const Eigen::VectorXd white = e.std_dev;
  e.covariance = dof_correction * bread * S * bread;
  e.covariance = 0.5 * (e.covariance + e.covariance.transpose());
  fill_parameter_statistics(e, estimation_options);
  e.std_dev_white = white;
  e.ci_lower_white = e.x - e.t_quantile * white;
  e.ci_upper_white = e.x + e.t_quantile * white;
  e.covariance_kind = "hac_bartlett";
  out.b = std::min(1.0, (L + 1.0) / static_cast<double>(Tv));
  if (options.fixed_b) {
    // The fixed-b value is the N(0,1)-based limit; never below the Student-t quantile, which
    // already allows for estimating σ² from m − r degrees of freedom.
    e.critical_value =
        std::max(e.t_quantile, fixed_b_critical_value(estimation_options.confidence_level, out.b));
    e.ci_lower = e.x - e.critical_value * e.std_dev;
    e.ci_upper = e.x + e.critical_value * e.std_dev;
  }
  out.critical_value = e.critical_value;
  std::vector<double> ratio;
  for (Eigen::Index j = 0; j < p; ++j) {
    if (white(j) > 0.0 && std::isfinite(white(j))) ratio.push_back(e.std_dev(j) / white(j));
  }
  if (!ratio.empty()) {
    std::nth_element(ratio.begin(), ratio.begin() + ratio.size() / 2, ratio.end());
    out.median_ratio = ratio[ratio.size() / 2];
  }
  return out;
}

}  // namespace dynid
