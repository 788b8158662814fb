#include "dynid/excitation/move_sequence.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "dynid/common/error.hpp"
#include "excitation/move_timing.hpp"

namespace dynid {

namespace excitation_detail {

void check_positive(const Eigen::VectorXd& v, Eigen::Index n, const std::string& name) {
  if (v.size() != n)
    throw Error(name + ": needs one value per joint (" + std::to_string(n) + "), got " +
                std::to_string(v.size()));
  for (Eigen::Index j = 0; j < n; ++j)
    if (!std::isfinite(v[j]) || v[j] <= 0.0)
      throw Error(name + " of joint " + std::to_string(j + 1) + ": must be finite and > 0, got " +
                  std::to_string(v[j]));
}

void check_way_points(const Eigen::MatrixXd& way_points, const std::string& name) {
  if (way_points.rows() < 1 || way_points.cols() < 2)
    throw Error(name + ": need an n×m matrix with at least 2 way-points (columns), got " +
                std::to_string(way_points.rows()) + "×" + std::to_string(way_points.cols()));
  if (!way_points.allFinite()) throw Error(name + ": NaN or Inf; give finite joint positions");
}

namespace {

// A move from `from` to `to` with no acceleration phases yet (filled in by its profile).
Move rest_to_rest(const Eigen::VectorXd& from, const Eigen::VectorXd& to) {
  Move m;
  m.q_start = from;
  m.distance = to - from;
  m.acceleration = Eigen::VectorXd::Zero(from.size());
  m.accel_time = Eigen::VectorXd::Zero(from.size());
  return m;
}

}  // namespace

Move trapezoid_move(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                    const Eigen::VectorXd& v_max, const Eigen::VectorXd& a_max, int index) {
  const Eigen::Index n = from.size();
  Move m = rest_to_rest(from, to);
  double T = 0.0;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double D = std::abs(m.distance[j]);
    if (D == 0.0) continue;
    const double v = v_max[j], a = a_max[j];
    if (D < v * v / a)
      throw Error("trapezoidal move " + std::to_string(index + 1) + ", joint " +
                  std::to_string(j + 1) + ": distance " + std::to_string(D) +
                  " is too short to reach v_max " + std::to_string(v) + " with a_max " +
                  std::to_string(a) + "; lower v_max to at most " +
                  std::to_string(std::sqrt(D * a)) + " or use a bang-bang move");
    T = std::max(T, D / v + v / a);
  }
  if (T == 0.0)
    throw Error("trapezoidal move " + std::to_string(index + 1) +
                ": way-points are identical; remove the repeated way-point or use a dwell");
  m.duration = T;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double D = std::abs(m.distance[j]);
    if (D == 0.0) continue;
    const double a = a_max[j];
    // Cruise speed v with D = v (T − v/a): the smaller root of v²/a − vT + D = 0.
    const double disc = std::max(0.0, a * a * T * T - 4.0 * a * D);
    const double v = 0.5 * (a * T - std::sqrt(disc));
    m.acceleration[j] = a;
    m.accel_time[j] = std::min(v / a, 0.5 * T);
  }
  return m;
}

Move bang_bang_move(const Eigen::VectorXd& from, const Eigen::VectorXd& to,
                    const Eigen::VectorXd& a_max, int index) {
  const Eigen::Index n = from.size();
  Move m = rest_to_rest(from, to);
  double T = 0.0;
  for (Eigen::Index j = 0; j < n; ++j)
    T = std::max(T, 2.0 * std::sqrt(std::abs(m.distance[j]) / a_max[j]));
  if (T == 0.0)
    throw Error("bang-bang move " + std::to_string(index + 1) +
                ": way-points are identical; remove the repeated way-point or use a dwell");
  m.duration = T;
  for (Eigen::Index j = 0; j < n; ++j) {
    const double D = std::abs(m.distance[j]);
    if (D == 0.0) continue;
    m.acceleration[j] = 4.0 * D / (T * T);
    m.accel_time[j] = 0.5 * T;
  }
  return m;
}

}  // namespace excitation_detail

void MoveSequence::finish(const Eigen::VectorXd& start, double dwell) {
  if (!std::isfinite(dwell) || dwell < 0.0)
    throw Error("dwell: must be finite and >= 0 s, got " + std::to_string(dwell));
  start_ = start;
  double t = 0.0;
  for (size_t i = 0; i < moves_.size(); ++i) {
    if (i > 0) t += dwell;
    moves_[i].start_time = t;
    t += moves_[i].duration;
  }
  duration_ = t;
}

void MoveSequence::evaluate(double t, Eigen::Ref<Eigen::VectorXd> q, Eigen::Ref<Eigen::VectorXd> dq,
                            Eigen::Ref<Eigen::VectorXd> ddq) const {
  dq.setZero();
  ddq.setZero();
  if (moves_.empty() || t <= 0.0) {
    q = start_;
    return;
  }
  // Last move that starts at or before t.
  const auto it = std::upper_bound(moves_.begin(), moves_.end(), t,
                                   [](double x, const Move& m) { return x < m.start_time; });
  const Move& m = *(it - 1);
  const double tau = t - m.start_time;
  if (tau >= m.duration) {  // at rest after the move (dwell or end)
    q = m.q_start + m.distance;
    return;
  }
  const double T = m.duration;
  for (Eigen::Index j = 0; j < q.size(); ++j) {
    const double D = m.distance[j];
    const double s = D > 0.0 ? 1.0 : (D < 0.0 ? -1.0 : 0.0);
    const double a = m.acceleration[j], ta = m.accel_time[j];
    double pos, vel, acc;
    if (s == 0.0 || a == 0.0) {
      pos = vel = acc = 0.0;
    } else if (tau < ta) {
      pos = 0.5 * a * tau * tau;
      vel = a * tau;
      acc = a;
    } else if (tau <= T - ta) {
      pos = 0.5 * a * ta * ta + a * ta * (tau - ta);
      vel = a * ta;
      acc = 0.0;
    } else {
      const double r = T - tau;
      pos = std::abs(D) - 0.5 * a * r * r;
      vel = a * r;
      acc = -a;
    }
    q[j] = m.q_start[j] + s * pos;
    dq[j] = s * vel;
    ddq[j] = s * acc;
  }
}

}  // namespace dynid
