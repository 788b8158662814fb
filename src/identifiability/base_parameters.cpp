#include "dynid/identifiability/base_parameters.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <numeric>
#include <random>
#include <sstream>
#include <utility>

#include <Eigen/QR>
#include <Eigen/SVD>

#include "dynamics/spatial.hpp"
#include "dynid/common/error.hpp"
#include "dynid/dynamics/kinematics.hpp"
#include "dynid/model/transmission.hpp"
#include "dynid/regressor/energy_regressor.hpp"
#include "dynid/regressor/torque_regressor.hpp"
#include "regressor/joint_columns.hpp"
#include "regressor/wrench_kernel.hpp"

namespace dynid {

namespace {

// Tree algorithm, scaled units (columns of unit norm): a row of the orthonormal null basis with a
// residual above kPivotTolerance starts a new pivot; echelon entries below kEntryTolerance are
// round-off.
constexpr double kPivotTolerance = 1e-6;
constexpr double kEntryTolerance = 1e-10;

// States sampled by the tree algorithm: its local systems have at most 28 columns and up to 8 rows
// per state, so 40 states over-determine them fivefold.
constexpr int kTreeSamples = 40;

// Largest sampled regressor (plus its orthonormal copy) the dense sweep may allocate [bytes].
constexpr double kMaxDenseBytes = 2e9;

using Clock = std::chrono::steady_clock;

// Wall-clock limit of one computation (BaseParameterOptions::max_seconds).
struct Deadline {
  Clock::time_point end = Clock::time_point::max();
  double seconds = 0.0;
  explicit Deadline(double s) : seconds(s) {
    if (s > 0.0)
      end = Clock::now() +
            std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(s));
  }
  void check() const {
    if (end != Clock::time_point::max() && Clock::now() > end) {
      std::ostringstream msg;
      msg << "base parameters: time limit of " << seconds
          << " s reached before the computation finished; raise the time limit (--max-time)";
      throw Error(msg.str());
    }
  }
};

// Random joint value inside the limits, or in [−π, π] (revolute) / [−0.5, 0.5] m (prismatic).
double random_position(const Joint& joint, std::mt19937& rng) {
  double lo = joint.limits.lower, hi = joint.limits.upper;
  if (!std::isfinite(lo) || !std::isfinite(hi) || hi - lo < 1e-6) {
    const double span = joint.type == JointType::kRevolute ? M_PI : 0.5;
    lo = -span;
    hi = span;
  }
  return std::uniform_real_distribution<double>(lo, hi)(rng);
}

// Joint value at fraction u ∈ [0, 1) of the limits, or of [−π, π] / [−0.5, 0.5] m.
double position_in_range(const Joint& joint, double u) {
  double lo = joint.limits.lower, hi = joint.limits.upper;
  if (!std::isfinite(lo) || !std::isfinite(hi) || hi - lo < 1e-6) {
    const double span = joint.type == JointType::kRevolute ? M_PI : 0.5;
    lo = -span;
    hi = span;
  }
  return lo + (hi - lo) * u;
}

// Uniform in [0, 1) from (seed, state, joint, which) by splitmix64 mixing: the tree algorithm's
// state of joint j does not depend on how many joints there are, so the first links of a chain
// get the same column scales (and threshold pivots) whatever the chain's length.
double hashed_unit(unsigned seed, int state, int joint, int which) {
  std::uint64_t x = (static_cast<std::uint64_t>(seed) << 32) ^
                    (static_cast<std::uint64_t>(state) * 0x9E3779B97F4A7C15ull) ^
                    (static_cast<std::uint64_t>(joint) * 0xD1B54A32D192ED03ull) ^
                    (static_cast<std::uint64_t>(which) * 0x94D049BB133111EBull);
  for (int round = 0; round < 2; ++round) {
    x += 0x9E3779B97F4A7C15ull;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
    x ^= x >> 31;
  }
  return static_cast<double>(x >> 11) * 0x1.0p-53;
}

Eigen::MatrixXd sample_regressor(const Model& model, const BaseParameterOptions& options,
                                 int samples, const Deadline& deadline) {
  const int n = model.dof();
  const int p = options.layout.columns(n);
  const std::vector<int> motors = coupled_motors(model);
  const int extra = options.coupling && options.regressor == BaseRegressor::kTorque
                        ? 3 * static_cast<int>(motors.size())
                        : 0;
  Workspace ws(model);
  std::mt19937 rng(options.seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd q(n), dq(n), ddq(n);
  auto draw = [&]() {
    for (int j = 0; j < n; ++j) {
      q[j] = random_position(model.joints[j], rng);
      dq[j] = u(rng);
      ddq[j] = u(rng);
    }
  };
  if (options.regressor == BaseRegressor::kTorque) {
    Eigen::MatrixXd W(static_cast<Eigen::Index>(samples) * n, p + extra);
    for (int k = 0; k < samples; ++k) {
      deadline.check();
      draw();
      torque_regressor(model, ws, options.layout, q, dq, ddq, W.block(k * n, 0, n, p));
      if (extra) coupling_regressor(model, motors, dq, ddq, W.block(k * n, p, n, extra));
    }
    return W;
  }
  // Seed 2 eqs. 4–8: differences of the energy row between random states (the constant part of
  // the potential energy cancels).
  Eigen::MatrixXd W(samples, p);
  Eigen::VectorXd h0(p), h(p);
  draw();
  energy_regressor(model, ws, options.layout, q, dq, h0);
  for (int k = 0; k < samples; ++k) {
    deadline.check();
    draw();
    energy_regressor(model, ws, options.layout, q, dq, h);
    W.row(k) = (h - h0).transpose();
  }
  return W;
}

// |k| with `digits` significant digits, as an ostream with that precision writes it (%g); snprintf
// because expressions of a long chain hold O(n²) coefficients.
void append_coefficient(std::string& out, double k, int digits) {
  char buffer[64];
  const int len = std::snprintf(buffer, sizeof(buffer), "%.*g", digits, std::abs(k));
  out.append(buffer, static_cast<std::size_t>(std::max(0, len)));
}

// Snaps K_d and writes the names and expressions of the base parameters.
void describe(BaseParameters& out, const std::vector<std::string>& names,
              const BaseParameterOptions& options) {
  const int r = out.rank;
  // Coefficients that are zero or integers up to round-off are snapped, so the expressions are
  // exact where the regrouping rules are exact.
  for (Eigen::Index i = 0; i < out.K_d.rows(); ++i) {
    for (Eigen::Index j = 0; j < out.K_d.cols(); ++j) {
      double& k = out.K_d(i, j);
      if (std::abs(k) < 1e-9) k = 0.0;
      if (std::abs(k - std::round(k)) < 1e-9) k = std::round(k);
    }
  }
  // Expressions list the non-zero coefficients of each row; collect them column-wise once (K_d is
  // mostly zeros for a long chain).
  std::vector<std::vector<int>> terms(static_cast<std::size_t>(r));
  for (Eigen::Index j = 0; j < out.K_d.cols(); ++j)
    for (Eigen::Index i = 0; i < out.K_d.rows(); ++i)
      if (out.K_d(i, j) != 0.0) terms[i].push_back(static_cast<int>(j));
  for (int i = 0; i < r; ++i) {
    const std::string& lead = names[out.base[i]];
    out.names.push_back(terms[i].empty() ? lead : lead + "R");
    std::string expr = out.names.back() + " = " + lead;
    for (int j : terms[i]) {
      const double k = out.K_d(i, j);
      expr += k < 0 ? " - " : " + ";
      if (std::abs(k) != 1.0) {
        append_coefficient(expr, k, static_cast<int>(options.coefficient_digits));
        expr += '*';
      }
      expr += names[out.dependent[j]];
    }
    out.expressions.push_back(std::move(expr));
  }
}

// Threshold pivoting of the regrouping (docs/methods/model.md, "Well-conditioned base columns").
// Gautier's rule makes the last column of each null vector dependent, whatever its weight there.
// When a joint axis is nearly, not exactly, along a frame axis that weight is small (about the
// tilt squared): the dependent column is a large multiple of the link's base columns (K̃ ≈ 80 on
// arm6_odd) and those base columns are nearly dependent on every trajectory (scaled condition
// number 5e7 on random states, compounding along the chain). Per link, in units of columns scaled
// by `scale`: the block K̃ = K_d restricted to the link's base rows and dependent columns (exchanges
// inside a link change no other link's block); a dependent column d with weight
// 1/√(1 + Σ_b K̃(b,d)²) below `threshold` trades places with the link's base column b of highest
// index among those with at least half the largest |K̃(·,d)|, if |K̃(b,d)| > 1: a Gauss–Jordan
// exchange, which multiplies the volume of the base columns by |K̃(b,d)| > 1, so it ends. Returns
// true when some link changes, with `label` (column → position) ordering each changed link's
// columns as [its new base columns, its new dependent columns, its zero columns], every other
// column in place: Gautier's rule in that order gives the new split (the greedy sweep keeps each
// link's base columns first; a link's dependencies involve only it and its ancestors), with an
// exact K_d. Only the link parameters are exchanged.
bool threshold_pivots(const BaseParameters& g, const Eigen::VectorXd& scale, int n,
                      double threshold, std::vector<int>& label) {
  const auto p = static_cast<int>(g.layout_names.size());
  label.resize(static_cast<std::size_t>(p));
  std::iota(label.begin(), label.end(), 0);
  if (!(threshold > 0.0) || g.dependent.empty()) return false;
  const double limit = 1.0 / (threshold * threshold) - 1.0;  // weak when Σ K̃² exceeds it
  std::vector<int> row(static_cast<std::size_t>(p), -1), col(static_cast<std::size_t>(p), -1);
  for (std::size_t i = 0; i < g.base.size(); ++i) row[g.base[i]] = static_cast<int>(i);
  for (std::size_t j = 0; j < g.dependent.size(); ++j) col[g.dependent[j]] = static_cast<int>(j);
  bool changed = false;
  for (int k = 0; k < n && kLinkParams * (k + 1) <= p; ++k) {
    std::vector<int> B, D, Z;
    for (int c = kLinkParams * k; c < kLinkParams * (k + 1); ++c) {
      (row[c] >= 0 ? B : col[c] >= 0 ? D : Z).push_back(c);
    }
    if (B.empty() || D.empty()) continue;
    bool usable = true;
    for (int c : B) usable = usable && scale[c] > 0.0 && std::isfinite(scale[c]);
    for (int c : D) usable = usable && scale[c] > 0.0 && std::isfinite(scale[c]);
    if (!usable) continue;
    const auto nb = static_cast<Eigen::Index>(B.size()), nd = static_cast<Eigen::Index>(D.size());
    Eigen::MatrixXd K(nb, nd);
    for (Eigen::Index i = 0; i < nb; ++i)
      for (Eigen::Index j = 0; j < nd; ++j)
        K(i, j) = g.K_d(row[B[i]], col[D[j]]) * scale[B[i]] / scale[D[j]];
    std::vector<char> settled(static_cast<std::size_t>(nd), 0);
    bool link_changed = false;
    for (int swaps = 0; swaps < 4 * kLinkParams * kLinkParams;) {
      Eigen::Index j = -1;
      for (Eigen::Index jj = 0; jj < nd; ++jj) {
        if (!settled[jj] && K.col(jj).squaredNorm() > limit && (j < 0 || D[jj] > D[j])) j = jj;
      }
      if (j < 0) break;
      // The exchange partner: of the base columns with nearly the largest coefficient (at least
      // half of it), the one of highest index, as Gautier's rule prefers the last column.
      const double largest = K.col(j).cwiseAbs().maxCoeff();
      Eigen::Index i = -1;
      for (Eigen::Index ii = 0; ii < nb; ++ii) {
        if (std::abs(K(ii, j)) >= 0.5 * largest && (i < 0 || B[ii] > B[i])) i = ii;
      }
      if (i < 0 || !(std::abs(K(i, j)) > 1.0)) {
        settled[j] = 1;  // no exchange inside the link would improve it
        continue;
      }
      const double pivot = K(i, j);
      for (Eigen::Index jj = 0; jj < nd; ++jj) {
        if (jj == j) continue;
        const double f = K(i, jj) / pivot;
        for (Eigen::Index ii = 0; ii < nb; ++ii)
          if (ii != i) K(ii, jj) -= f * K(ii, j);
        K(i, jj) = f;
        settled[jj] = 0;
      }
      for (Eigen::Index ii = 0; ii < nb; ++ii)
        if (ii != i) K(ii, j) = -K(ii, j) / pivot;
      K(i, j) = 1.0 / pivot;
      std::swap(B[i], D[j]);
      link_changed = true;
      ++swaps;
    }
    if (!link_changed) continue;
    changed = true;
    std::sort(B.begin(), B.end());
    std::sort(D.begin(), D.end());
    int at = kLinkParams * k;
    for (const auto* set : {&B, &D, &Z})
      for (int c : *set) label[c] = at++;
  }
  return changed;
}

// A result computed on columns relabelled by `label` (column c at position label[c]), back in
// column order: indices mapped, base and dependent sorted, K_d permuted alike.
BaseParameters unlabel(BaseParameters in, const std::vector<int>& label,
                       const std::vector<std::string>& names) {
  std::vector<int> column(label.size());
  for (std::size_t c = 0; c < label.size(); ++c) column[label[c]] = static_cast<int>(c);
  auto map = [&](std::vector<int>& v) {
    for (int& x : v) x = column[x];
  };
  map(in.base);
  map(in.dependent);
  map(in.unidentifiable);
  std::sort(in.unidentifiable.begin(), in.unidentifiable.end());
  std::vector<Eigen::Index> bo(in.base.size()), dpo(in.dependent.size());
  std::iota(bo.begin(), bo.end(), Eigen::Index{0});
  std::iota(dpo.begin(), dpo.end(), Eigen::Index{0});
  std::sort(bo.begin(), bo.end(),
            [&](Eigen::Index x, Eigen::Index y) { return in.base[x] < in.base[y]; });
  std::sort(dpo.begin(), dpo.end(),
            [&](Eigen::Index x, Eigen::Index y) { return in.dependent[x] < in.dependent[y]; });
  BaseParameters out = in;
  for (std::size_t i = 0; i < bo.size(); ++i) out.base[i] = in.base[bo[i]];
  for (std::size_t j = 0; j < dpo.size(); ++j) out.dependent[j] = in.dependent[dpo[j]];
  for (std::size_t i = 0; i < bo.size(); ++i)
    for (std::size_t j = 0; j < dpo.size(); ++j)
      out.K_d(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = in.K_d(bo[i], dpo[j]);
  out.layout_names = names;
  return out;
}

using Vector6d = Eigen::Matrix<double, 6, 1>;

// What the local systems need of one link at one sampled state: its body regressor (wrench about
// its origin, moment rows then force rows, linear in its 10 parameters: seed 1 eq. 28), the pose
// of its frame in its parent's frame, an orthonormal basis of the twists of its strict ancestors
// carried into its frame, and its joint velocity and acceleration.
struct LinkSample {
  Eigen::Matrix<double, 6, kLinkParams> Phi;
  Eigen::Matrix<double, 6, 6> C;  // first m columns: orthonormal basis of the ancestors' twists
  int m = 0;
  Eigen::Matrix3d R;  // frame j in its parent's frame at this q
  Eigen::Vector3d p;
  double dq = 0.0, ddq = 0.0;
};

// A twist (ω; v) of a parent frame, in child frame coordinates: ω' = Rᵀω, v' = Rᵀ(v + ω×p).
Vector6d to_child(const Eigen::Matrix3d& R, const Eigen::Vector3d& p, const Vector6d& t) {
  Vector6d out;
  out.head<3>() = R.transpose() * t.head<3>();
  out.tail<3>() = R.transpose() * (t.tail<3>() + t.head<3>().cross(p));
  return out;
}

// Orthonormal basis of the columns of A (6 × cols), rank decided relative to the largest pivot.
int orthonormal_basis(const Eigen::Matrix<double, 6, Eigen::Dynamic>& A,
                      Eigen::Matrix<double, 6, 6>& out) {
  if (A.cols() == 0) return 0;
  Eigen::ColPivHouseholderQR<Eigen::Matrix<double, 6, Eigen::Dynamic>> qr(A);
  qr.setThreshold(1e-12);
  const int m = static_cast<int>(qr.rank());
  const Eigen::Matrix<double, 6, 6> Q = qr.householderQ() * Eigen::Matrix<double, 6, 6>::Identity();
  out.leftCols(m) = Q.leftCols(m);
  return m;
}

// Sparse vector over layout columns, sorted by index.
using Sparse = std::vector<std::pair<int, double>>;

// a - f·b for sorted sparse vectors.
Sparse axpy(const Sparse& a, double f, const Sparse& b) {
  Sparse out;
  out.reserve(a.size() + b.size());
  std::size_t i = 0, j = 0;
  while (i < a.size() || j < b.size()) {
    if (j == b.size() || (i < a.size() && a[i].first < b[j].first)) {
      out.push_back(a[i++]);
    } else if (i == a.size() || b[j].first < a[i].first) {
      out.emplace_back(b[j].first, -f * b[j].second);
      ++j;
    } else {
      out.emplace_back(a[i].first, a[i].second - f * b[j].second);
      ++i;
      ++j;
    }
  }
  return out;
}

// Steps 1 and 2 of the tree algorithm: the sampled per-link data, the local system of each link,
// and every layout column's norm in the system where it is "at home" (all its non-zero rows).
// The norms are also the column scales of the threshold pivoting (threshold_pivots()), for
// either algorithm. With labels, every column index it hands out is label[column] (the tree
// algorithm run on relabelled columns).
class TreeSystems {
 public:
  TreeSystems(const Model& model, const BaseParameterOptions& options, int samples,
              const Deadline& deadline)
      : model_(model),
        options_(options),
        samples_(samples),
        n_(model.dof()),
        jc_(options.layout.joint_columns()) {
    sample(deadline);
    const int p = options.layout.columns(n_);
    norms_ = Eigen::VectorXd::Zero(p);
    Eigen::MatrixXd M;
    std::vector<int> cols;
    for (int k = 0; k < n_; ++k) {
      deadline.check();
      system(k, M, cols);
      for (int i = 0; i < kLinkParams; ++i) norms_[cols[i]] = M.col(i).norm();
      const int off_jk = model.joints[k].parent < 0 ? kLinkParams : 2 * kLinkParams;
      for (int c = 0; c < jc_; ++c) norms_[cols[off_jk + c]] = M.col(off_jk + c).norm();
    }
  }

  const Eigen::VectorXd& norms() const { return norms_; }

  void set_labels(const std::vector<int>& label) {
    Eigen::VectorXd relabelled(norms_.size());
    for (std::size_t c = 0; c < label.size(); ++c) relabelled[label[c]] = norms_[c];
    norms_ = std::move(relabelled);
    label_ = label;
  }

  // System k: columns [link k | link a | joint k | joint a] (a = parent of k, absent for a root
  // joint); rows per state: joint k, joint a, the ancestors' basis of a.
  void system(int k, Eigen::MatrixXd& M, std::vector<int>& cols) const {
    const int n = n_, jc = jc_, samples = samples_;
    auto relabel = [&](int c) { return label_.empty() ? c : label_[static_cast<std::size_t>(c)]; };
    auto link_col = [&](int j, int i) { return relabel(kLinkParams * j + i); };
    auto joint_col = [&](int j, int c) { return relabel(kLinkParams * n + jc * j + c); };
    const int a = model_.joints[k].parent;
    cols.clear();
    for (int i = 0; i < kLinkParams; ++i) cols.push_back(link_col(k, i));
    if (a >= 0)
      for (int i = 0; i < kLinkParams; ++i) cols.push_back(link_col(a, i));
    for (int c = 0; c < jc; ++c) cols.push_back(joint_col(k, c));
    if (a >= 0)
      for (int c = 0; c < jc; ++c) cols.push_back(joint_col(a, c));
    const int width = static_cast<int>(cols.size());
    const int rows_per = a < 0 ? 1 : 2 + 6;
    M.setZero(static_cast<Eigen::Index>(samples) * rows_per, width);
    const int off_a = kLinkParams, off_jk = a < 0 ? kLinkParams : 2 * kLinkParams,
              off_ja = off_jk + jc;
    const Vector6d s_k = detail::joint_twist(model_.joints[k]);
    const Vector6d s_a = a < 0 ? Vector6d::Zero() : detail::joint_twist(model_.joints[a]);
    Eigen::Index r = 0;
    for (int s = 0; s < samples; ++s) {
      const LinkSample& dk = data_[static_cast<std::size_t>(s) * n + k];
      M.block(r, 0, 1, kLinkParams) = s_k.transpose() * dk.Phi;
      if (jc) detail::joint_columns(options_.layout, dk.dq, dk.ddq, M.row(r).segment(off_jk, jc));
      ++r;
      if (a < 0) continue;
      const LinkSample& da = data_[static_cast<std::size_t>(s) * n + a];
      M.block(r, 0, 1, kLinkParams) = to_child(dk.R, dk.p, s_a).transpose() * dk.Phi;
      M.block(r, off_a, 1, kLinkParams) = s_a.transpose() * da.Phi;
      if (jc) detail::joint_columns(options_.layout, da.dq, da.ddq, M.row(r).segment(off_ja, jc));
      ++r;
      for (int c = 0; c < da.m; ++c, ++r) {
        M.block(r, 0, 1, kLinkParams) = to_child(dk.R, dk.p, da.C.col(c)).transpose() * dk.Phi;
        M.block(r, off_a, 1, kLinkParams) = da.C.col(c).transpose() * da.Phi;
      }
      r += 6 - da.m;  // unused rows stay zero
    }
  }

 private:
  // 1. Sampled states: per-link quantities only, O(n) per state.
  void sample(const Deadline& deadline) {
    const int n = n_;
    data_.resize(static_cast<std::size_t>(samples_) * n);
    Workspace ws(model_);
    Eigen::VectorXd q(n), dq(n), ddq(n);
    detail::WrenchBlocks b;
    Eigen::Matrix<double, 6, Eigen::Dynamic> A(6, 7);
    for (int s = 0; s < samples_; ++s) {
      deadline.check();
      for (int j = 0; j < n; ++j) {
        q[j] = position_in_range(model_.joints[j], hashed_unit(options_.seed, s, j, 0));
        dq[j] = 2.0 * hashed_unit(options_.seed, s, j, 1) - 1.0;
        ddq[j] = 2.0 * hashed_unit(options_.seed, s, j, 2) - 1.0;
      }
      forward_kinematics(model_, ws, q, dq, ddq, true);
      for (int j = 0; j < n; ++j) {
        const LinkState& st = ws.links[j];
        LinkSample& d = data_[static_cast<std::size_t>(s) * n + j];
        detail::wrench_blocks(st.w, st.dw, st.a, b);
        d.Phi.setZero();
        d.Phi.block<3, 6>(0, 0) = b.L_I;
        d.Phi.block<3, 3>(0, 6) = b.A_skew;
        d.Phi.block<3, 3>(3, 6) = b.K_mc;
        d.Phi.block<3, 1>(3, 9) = b.a;
        d.R = st.R_PJ;
        d.p = st.p_PJ;
        d.dq = dq[j];
        d.ddq = ddq[j];
        const int a = model_.joints[j].parent;
        if (a < 0) {
          d.m = 0;
          continue;
        }
        // Ancestors of j = parent a and the ancestors of a, carried into frame j.
        const LinkSample& pa = data_[static_cast<std::size_t>(s) * n + a];
        A.resize(6, pa.m + 1);
        for (int c = 0; c < pa.m; ++c) A.col(c) = to_child(d.R, d.p, pa.C.col(c));
        A.col(pa.m) = to_child(d.R, d.p, detail::joint_twist(model_.joints[a]));
        d.m = orthonormal_basis(A, d.C);
      }
    }
  }

  const Model& model_;
  const BaseParameterOptions& options_;
  int samples_, n_, jc_;
  std::vector<LinkSample> data_;
  Eigen::VectorXd norms_;
  std::vector<int> label_;
};

// Numerical base parameters exploiting the tree (docs/methods/model.md, "Base parameters of large
// trees"). A column combination x has no effect (W·x = 0) iff it moves no joint torque at any
// state. The columns of link k are non-zero only in the rows of k and its ancestors, and every
// ancestor row is the pairing of that ancestor's twist with the wrench the subtree exerts at k's
// parent a, so the rows of the strict ancestors of a can be replaced, state by state, by an
// orthonormal basis of their twists in frame a (≤ 6 rows) without changing which x have no effect.
// The null space of each such local system over (link k, link a, their joint columns) is computed
// by an SVD; their union spans the null space of W (regrouping moves parameters from a link to its
// parent; checked against the dense sweep in tests/identifiability). The dependent columns are the
// last non-zero indices of an echelon basis of that null space, exactly the columns the
// left-to-right sweep finds dependent, and back-substitution gives K_d.
BaseParameters tree_base_parameters(const Model& model, const BaseParameterOptions& options,
                                    const TreeSystems& systems,
                                    const std::vector<std::string>& names,
                                    const Deadline& deadline) {
  const int n = model.dof();
  const int p = options.layout.columns(n);
  const Eigen::VectorXd& norms = systems.norms();
  Eigen::MatrixXd M;
  std::vector<int> cols;
  const double largest = norms.size() ? norms.maxCoeff() : 0.0;
  std::vector<bool> zero(static_cast<std::size_t>(p));
  for (int c = 0; c < p; ++c) zero[c] = !(norms[c] > options.zero_tolerance * largest);

  // 3. Echelon basis of the null space by last non-zero index (= the left-to-right sweep).
  std::vector<Sparse> pivot(static_cast<std::size_t>(p));
  std::vector<bool> has_pivot(static_cast<std::size_t>(p), false);
  // Significance of an entry: its size in the units of columns scaled to unit norm.
  auto insert = [&](Sparse v) {
    double scale = 0.0;
    for (const auto& e : v) scale = std::max(scale, std::abs(e.second) * norms[e.first]);
    const double drop = 1e-9 * scale;
    while (true) {
      v.erase(std::remove_if(v.begin(), v.end(),
                             [&](const std::pair<int, double>& e) {
                               return !(std::abs(e.second) * norms[e.first] > drop);
                             }),
              v.end());
      if (v.empty()) return;
      const int c = v.back().first;
      if (!has_pivot[c]) {
        const double lead = v.back().second;
        for (auto& e : v) e.second /= lead;
        pivot[c] = std::move(v);
        has_pivot[c] = true;
        return;
      }
      v = axpy(v, v.back().second, pivot[c]);
    }
  };
  for (int c = 0; c < p; ++c) {
    if (!zero[c]) continue;
    pivot[c] = {{c, 1.0}};
    has_pivot[c] = true;
  }
  for (int link = 0; link < n; ++link) {
    deadline.check();
    systems.system(link, M, cols);
    std::vector<int> live;  // non-zero columns of the system, scaled to unit norm
    for (int i = 0; i < static_cast<int>(cols.size()); ++i)
      if (!zero[cols[i]]) live.push_back(i);
    if (live.empty()) continue;
    Eigen::MatrixXd A(M.rows(), static_cast<Eigen::Index>(live.size()));
    Eigen::VectorXd scale(static_cast<Eigen::Index>(live.size()));
    for (std::size_t i = 0; i < live.size(); ++i) {
      scale[i] = M.col(live[i]).norm();
      A.col(i) = M.col(live[i]) / scale[i];
    }
    // R of a QR first: the SVD then works on a small square matrix.
    const Eigen::HouseholderQR<Eigen::MatrixXd> qr(A);
    const Eigen::Index w = A.cols(), h = std::min(A.rows(), w);
    const Eigen::MatrixXd Rm = qr.matrixQR().topRows(h).triangularView<Eigen::Upper>();
    const Eigen::JacobiSVD<Eigen::MatrixXd> svd(Rm, Eigen::ComputeFullV);
    const Eigen::VectorXd sv = svd.singularValues();
    std::vector<Eigen::Index> null_cols;
    for (Eigen::Index i = 0; i < w; ++i)
      if (!((i < sv.size() ? sv[i] : 0.0) > options.dependence_tolerance)) null_cols.push_back(i);
    if (null_cols.empty()) continue;
    const auto m = static_cast<Eigen::Index>(null_cols.size());
    Eigen::MatrixXd N(w, m);  // orthonormal basis of the local null space, scaled columns
    for (Eigen::Index i = 0; i < m; ++i) N.col(i) = svd.matrixV().col(null_cols[i]);
    // Echelon form by last index, computed stably: scanning the columns from the highest global
    // index down, a column is a pivot when its row of N is independent of the pivot rows found so
    // far (residual > kPivotTolerance; rows of N have norm <= 1). Then X = N·N_P⁻¹ holds one null
    // vector per pivot, 1 there and 0 at the other pivots, non-zero elsewhere only below it.
    std::vector<Eigen::Index> order(static_cast<std::size_t>(w));
    std::iota(order.begin(), order.end(), Eigen::Index{0});
    std::sort(order.begin(), order.end(),
              [&](Eigen::Index x, Eigen::Index y) { return cols[live[x]] > cols[live[y]]; });
    Eigen::MatrixXd Qr(m, m);
    std::vector<Eigen::Index> piv;
    for (Eigen::Index i : order) {
      if (static_cast<Eigen::Index>(piv.size()) == m) break;
      Eigen::VectorXd r = N.row(i).transpose();
      for (int pass = 0; pass < 2; ++pass)
        for (std::size_t k = 0; k < piv.size(); ++k) r -= Qr.col(k).dot(r) * Qr.col(k);
      if (r.norm() > kPivotTolerance) {
        Qr.col(static_cast<Eigen::Index>(piv.size())) = r / r.norm();
        piv.push_back(i);
      }
    }
    Eigen::MatrixXd NP(static_cast<Eigen::Index>(piv.size()), m);
    for (std::size_t k = 0; k < piv.size(); ++k) NP.row(k) = N.row(piv[k]);
    const Eigen::MatrixXd X = N * NP.completeOrthogonalDecomposition().pseudoInverse();
    for (std::size_t t = 0; t < piv.size(); ++t) {
      const int pivot_col = cols[live[piv[t]]];
      // Null vectors of the parent alone (pivot among its parameters) come from its own system.
      if (pivot_col < kLinkParams * n && pivot_col / kLinkParams != link) continue;
      Sparse v;
      const auto tc = static_cast<Eigen::Index>(t);
      const double lead = X(piv[t], tc) / scale[piv[t]];
      for (Eigen::Index c = 0; c < w; ++c) {
        const double x = X(c, tc);
        if (std::abs(x) > kEntryTolerance) v.emplace_back(cols[live[c]], x / scale[c] / lead);
      }
      std::sort(v.begin(), v.end());
      insert(std::move(v));
    }
  }

  // 4. Base, dependent and unidentifiable columns; K_d by back-substitution.
  BaseParameters out;
  out.layout_names = names;
  std::vector<int> base_pos(static_cast<std::size_t>(p), -1);
  for (int c = 0; c < p; ++c) {
    if (zero[c]) {
      out.unidentifiable.push_back(c);
    } else if (has_pivot[c]) {
      out.dependent.push_back(c);
    } else {
      base_pos[c] = static_cast<int>(out.base.size());
      out.base.push_back(c);
    }
  }
  out.rank = static_cast<int>(out.base.size());
  if (out.rank == 0)
    throw Error("no parameter of the model has any effect on the sampled regressor");
  out.K_d = Eigen::MatrixXd::Zero(out.rank, static_cast<Eigen::Index>(out.dependent.size()));
  for (std::size_t j = 0; j < out.dependent.size(); ++j) {
    deadline.check();
    const int d = out.dependent[j];
    Sparse v = pivot[d];
    // Earlier dependent entries are replaced by their reduced vectors (base columns only, plus
    // their own), from the last one down: a replacement adds base columns only.
    int bound = d;
    while (true) {
      int at = -1;
      for (std::size_t e = v.size(); e-- > 0;) {
        const int c = v[e].first;
        if (c < bound && has_pivot[c] && v[e].second != 0.0) {
          at = static_cast<int>(e);
          break;
        }
      }
      if (at < 0) break;
      bound = v[at].first;
      v = axpy(v, v[at].second, pivot[bound]);
    }
    for (const auto& [c, x] : v)
      if (base_pos[c] >= 0) out.K_d(base_pos[c], static_cast<Eigen::Index>(j)) = -x;
    pivot[d] = std::move(v);  // reduced: later columns may refer to it
  }
  return out;
}

}  // namespace

namespace {

// The left-to-right sweep of a sampled regressor (names and expressions not yet written).
BaseParameters classify_dense(const Eigen::Ref<const Eigen::MatrixXd>& W,
                              const std::vector<std::string>& names,
                              const BaseParameterOptions& options, const Deadline& deadline) {
  const Eigen::Index p = W.cols();
  if (static_cast<Eigen::Index>(names.size()) != p) {
    throw Error("classify_columns: " + std::to_string(names.size()) + " names for " +
                std::to_string(p) + " columns");
  }
  BaseParameters out;
  out.layout_names = names;
  const Eigen::VectorXd norms = W.colwise().norm();
  const double largest = norms.size() ? norms.maxCoeff() : 0.0;
  // Left-to-right sweep with a growing orthonormal basis (modified Gram–Schmidt, twice for
  // stability): a column is dependent when its residual is tiny compared with its own norm.
  Eigen::MatrixXd Q(W.rows(), p);
  int r = 0;
  for (Eigen::Index c = 0; c < p; ++c) {
    if (c % 64 == 0) deadline.check();
    if (!(norms[c] > options.zero_tolerance * largest)) {
      out.unidentifiable.push_back(static_cast<int>(c));
      continue;
    }
    Eigen::VectorXd v = W.col(c);
    for (int pass = 0; pass < 2; ++pass) {
      for (int k = 0; k < r; ++k) v -= Q.col(k).dot(v) * Q.col(k);
    }
    if (v.norm() > options.dependence_tolerance * norms[c]) {
      Q.col(r++) = v / v.norm();
      out.base.push_back(static_cast<int>(c));
    } else {
      out.dependent.push_back(static_cast<int>(c));
    }
  }
  out.rank = r;
  if (r == 0) throw Error("no parameter of the model has any effect on the sampled regressor");
  Eigen::MatrixXd W1(W.rows(), r), W2(W.rows(), out.dependent.size());
  for (int k = 0; k < r; ++k) W1.col(k) = W.col(out.base[k]);
  for (size_t k = 0; k < out.dependent.size(); ++k) W2.col(k) = W.col(out.dependent[k]);
  out.K_d = W2.cols() ? Eigen::MatrixXd(W1.colPivHouseholderQr().solve(W2)) : Eigen::MatrixXd(r, 0);
  return out;
}

}  // namespace

BaseParameters classify_columns(const Eigen::Ref<const Eigen::MatrixXd>& W,
                                const std::vector<std::string>& names,
                                const BaseParameterOptions& options) {
  BaseParameters out = classify_dense(W, names, options, Deadline(options.max_seconds));
  describe(out, names, options);
  return out;
}

BaseParameters compute_base_parameters(const Model& model, const BaseParameterOptions& options) {
  const Deadline deadline(options.max_seconds);
  const int n = model.dof();
  const int p = options.layout.columns(n);
  std::vector<std::string> names = options.layout.names(n);
  const bool coupled = options.coupling && options.regressor == BaseRegressor::kTorque &&
                       !coupled_motors(model).empty();
  bool tree = options.algorithm == BaseAlgorithm::kTree;
  if (options.algorithm == BaseAlgorithm::kAuto)
    tree = options.regressor == BaseRegressor::kTorque && !coupled;
  if (tree && (options.regressor != BaseRegressor::kTorque || coupled)) {
    throw Error(
        "base parameters: the tree algorithm handles the torque regressor without coupled "
        "motors only; use BaseAlgorithm::kDense");
  }
  const int tree_samples = options.samples > 0 ? options.samples : kTreeSamples;
  std::vector<int> label;
  if (tree) {
    const TreeSystems systems(model, options, tree_samples, deadline);
    BaseParameters out = tree_base_parameters(model, options, systems, names, deadline);
    if (threshold_pivots(out, systems.norms(), n, options.pivot_threshold, label)) {
      TreeSystems relabelled = systems;
      relabelled.set_labels(label);
      out =
          unlabel(tree_base_parameters(model, options, relabelled, names, deadline), label, names);
    }
    describe(out, names, options);
    out.samples = tree_samples;
    out.algorithm = BaseAlgorithm::kTree;
    return out;
  }
  const int samples =
      options.samples > 0 ? options.samples : std::max(100, 4 * p / std::max(1, n) + 50);
  if (options.coupling && options.regressor == BaseRegressor::kTorque) {
    for (const auto& name : coupling_column_names(model)) names.push_back(name);
  }
  // The dense sweep holds the whole sampled regressor: refuse what would not fit rather than fail
  // inside the allocator.
  const double rows = options.regressor == BaseRegressor::kTorque ? double(samples) * n : samples;
  const double bytes = 2.0 * 8.0 * rows * static_cast<double>(names.size());
  if (bytes > kMaxDenseBytes) {
    std::ostringstream msg;
    msg << "base parameters: the dense computation for " << n << " joints needs about "
        << std::lround(bytes / 1e9) << " GB (limit " << kMaxDenseBytes / 1e9
        << " GB); use the torque regressor without coupled motors (tree algorithm)";
    throw Error(msg.str());
  }
  Eigen::MatrixXd W = sample_regressor(model, options, samples, deadline);
  BaseParameters out = classify_dense(W, names, options, deadline);
  // Column scales of the threshold pivoting: the tree's (each column's norm in its own link's
  // system), so that the dense sweep, the tree and the energy regressor pivot alike; with
  // coupled-motor columns the sampled regressor's own norms.
  Eigen::VectorXd scales;
  if (coupled) {
    scales = W.colwise().norm().transpose();
  } else if (options.pivot_threshold > 0.0) {
    BaseParameterOptions torque = options;
    torque.regressor = BaseRegressor::kTorque;
    torque.coupling = false;
    scales = TreeSystems(model, torque, tree_samples, deadline).norms();
  }
  if (threshold_pivots(out, scales, n, options.pivot_threshold, label)) {
    // The sweep again with each changed link's columns in their new order (within the link).
    std::vector<std::string> relabelled(names.size());
    for (std::size_t c = 0; c < names.size(); ++c) relabelled[label[c]] = names[c];
    for (int k = 0; k < n; ++k) {
      const int first = kLinkParams * k;
      const Eigen::MatrixXd block = W.middleCols(first, kLinkParams);
      for (int i = 0; i < kLinkParams; ++i) W.col(label[first + i]) = block.col(i);
    }
    out = unlabel(classify_dense(W, relabelled, options, deadline), label, names);
  }
  describe(out, names, options);
  out.samples = samples;
  return out;
}

Eigen::VectorXd BaseParameters::reduce(const Eigen::Ref<const Eigen::VectorXd>& theta) const {
  Eigen::VectorXd b(rank);
  for (int i = 0; i < rank; ++i) {
    b[i] = theta[base[i]];
    for (size_t j = 0; j < dependent.size(); ++j) b[i] += K_d(i, j) * theta[dependent[j]];
  }
  return b;
}

std::vector<std::optional<double>> nominal_base_values(const Model& model,
                                                       const BaseParameters& base,
                                                       const ParameterLayout& layout) {
  const int p = layout.columns(model.dof());
  const auto columns = static_cast<Eigen::Index>(base.layout_names.size());
  if (columns < p || static_cast<int>(base.base.size()) != base.rank) {
    throw Error("nominal_base_values: the base parameters have " + std::to_string(columns) +
                " columns, the layout of model '" + model.name + "' " + std::to_string(p) +
                "; compute them for this model and layout");
  }
  Eigen::VectorXd theta = Eigen::VectorXd::Zero(columns);
  theta.head(p) = layout.parameters(model);
  const Eigen::VectorXd b = base.reduce(theta);
  const int link_columns = kLinkParams * model.dof();
  std::vector<std::optional<double>> out(static_cast<size_t>(base.rank));
  for (int i = 0; i < base.rank; ++i) {
    const int lead = base.base[static_cast<size_t>(i)];
    if (lead >= link_columns && theta[lead] == 0.0) continue;
    out[static_cast<size_t>(i)] = b[i];
  }
  return out;
}

Eigen::MatrixXd BaseParameters::select(const Eigen::Ref<const Eigen::MatrixXd>& W) const {
  Eigen::MatrixXd Wb(W.rows(), rank);
  for (int i = 0; i < rank; ++i) Wb.col(i) = W.col(base[i]);
  return Wb;
}

std::vector<std::string> BaseParameters::unidentifiable_names() const {
  std::vector<std::string> out;
  for (int c : unidentifiable) out.push_back(layout_names[c]);
  return out;
}

}  // namespace dynid
