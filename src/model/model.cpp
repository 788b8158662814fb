#include "dynid/model/model.hpp"

#include <cmath>
#include <numeric>
#include <sstream>
#include <unordered_map>

#include <Eigen/Eigenvalues>
#include <Eigen/QR>

#include "dynid/common/error.hpp"
#include "dynid/common/message.hpp"

namespace dynid {

bool Transmission::is_identity() const {
  return N.isIdentity(0.0) && (q_offset.size() == 0 || q_offset.isZero(0.0));
}

const std::vector<std::string>& link_parameter_labels() {
  static const std::vector<std::string> labels = {"XX", "XY", "XZ", "YY", "YZ",
                                                  "ZZ", "MX", "MY", "MZ", "M"};
  return labels;
}

Eigen::Matrix3d inertia_about_origin(const LinkParams& p) {
  Eigen::Matrix3d I;
  I << p(0), p(1), p(2), p(1), p(3), p(4), p(2), p(4), p(5);
  return I;
}

LinkParams link_params_from_com(double m, const Eigen::Vector3d& c, const Eigen::Matrix3d& I_C) {
  // Seed 1 eq. 24 (Steiner): I_O = I_C + m((cᵀc)·1 − c·cᵀ).
  const Eigen::Matrix3d I_O =
      I_C + m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  LinkParams p;
  p << I_O(0, 0), I_O(0, 1), I_O(0, 2), I_O(1, 1), I_O(1, 2), I_O(2, 2), m * c.x(), m * c.y(),
      m * c.z(), m;
  return p;
}

LinkParams transform_link_params(const LinkParams& p, const Eigen::Matrix3d& R_AB,
                                 const Eigen::Vector3d& p_AB) {
  const double m = p(9);
  const Eigen::Vector3d h = R_AB * p.segment<3>(6);  // first moment in A's axes, about B's origin
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d I_A = R_AB * inertia_about_origin(p) * R_AB.transpose() +
                              2.0 * p_AB.dot(h) * I3 -
                              (p_AB * h.transpose() + h * p_AB.transpose()) +
                              m * (p_AB.squaredNorm() * I3 - p_AB * p_AB.transpose());
  const Eigen::Vector3d h_A = h + m * p_AB;
  LinkParams out;
  out << I_A(0, 0), I_A(0, 1), I_A(0, 2), I_A(1, 1), I_A(1, 2), I_A(2, 2), h_A.x(), h_A.y(),
      h_A.z(), m;
  return out;
}

namespace {

bool all_finite(const Eigen::Ref<const Eigen::MatrixXd>& m) {
  return m.allFinite();
}

void check_physical(const LinkParams& p, const std::string& link,
                    std::vector<std::string>* warnings) {
  const double m = p(9);
  if (!(m >= 0.0)) {
    throw Error("link '" + link + "' has negative mass " + short_number(m) +
                " kg; give a mass >= 0 in its <inertial> block");
  }
  Eigen::Matrix3d I_C = inertia_about_origin(p);
  if (m > 0.0) {
    const Eigen::Vector3d c = p.segment<3>(6) / m;
    I_C -= m * (c.squaredNorm() * Eigen::Matrix3d::Identity() - c * c.transpose());
  } else if (p.segment<3>(6).norm() > 1e-12) {
    throw Error("link '" + link +
                "' has a first moment with zero mass; set its mass or zero MX, MY, MZ");
  }
  const Eigen::Vector3d ev = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(I_C).eigenvalues();
  const double scale = std::max(1.0, ev.cwiseAbs().maxCoeff());
  const double tol = 1e-9 * scale;
  // ev is sorted ascending: the triangle inequality binds on the largest moment only.
  const double triangle_excess = ev(2) - ev(0) - ev(1);
  if (ev.minCoeff() >= -tol && triangle_excess <= tol) return;
  std::ostringstream what;
  what << "link '" << link << "' has a non-physical inertia: principal moments about the centre "
       << "of mass " << short_number(ev(0)) << ", " << short_number(ev(1)) << ", "
       << short_number(ev(2)) << " kg m^2";
  const double largest = std::max(ev.cwiseAbs().maxCoeff(), 1e-300);
  if (ev.minCoeff() < -tol) {
    what << " (one is negative: " << short_number(100.0 * -ev.minCoeff() / largest)
         << " % of the largest)";
  } else {
    what << " break the triangle inequality (" << short_number(ev(2)) << " > "
         << short_number(ev(0)) << " + " << short_number(ev(1)) << " by "
         << short_number(100.0 * triangle_excess / ev(2)) << " %)";
  }
  if (!warnings) {
    throw Error(what.str() +
                "; they must be >= 0 and satisfy the triangle inequality: fix its inertia tensor");
  }
  warnings->push_back(what.str() + "; loaded as it is (--strict refuses it)");
}

// Relative threshold of the invertibility test: smallest / largest pivot magnitude.
constexpr double kSingularRatio = 1e-12;

// True when N is invertible by a scale-invariant test: N = 0.001·I passes, a matrix with a row
// that is a multiple of another fails whatever its scale. A diagonal N (the common case: gear
// ratios or the identity) is checked in O(n²) without any factorisation; otherwise the coupled
// joints form independent blocks (connected components of the non-zero pattern), each tested by a
// rank-revealing column-pivoted QR, |R_kk| > kSingularRatio·|R_11|.
bool transmission_invertible(const Eigen::MatrixXd& N) {
  const Eigen::Index n = N.rows();
  std::vector<Eigen::Index> root(static_cast<std::size_t>(n));
  std::iota(root.begin(), root.end(), Eigen::Index{0});
  auto find = [&](Eigen::Index i) {
    while (root[i] != i) i = root[i] = root[root[i]];
    return i;
  };
  bool diagonal = true;
  for (Eigen::Index c = 0; c < n; ++c) {
    for (Eigen::Index r = 0; r < n; ++r) {
      if (r == c || N(r, c) == 0.0) continue;
      diagonal = false;
      root[find(r)] = find(c);
    }
  }
  if (diagonal) {
    const Eigen::ArrayXd d = N.diagonal().cwiseAbs();
    return d.minCoeff() > kSingularRatio * d.maxCoeff();
  }
  std::unordered_map<Eigen::Index, std::vector<Eigen::Index>> blocks;
  for (Eigen::Index i = 0; i < n; ++i) blocks[find(i)].push_back(i);
  for (const auto& [id, members] : blocks) {
    const auto m = static_cast<Eigen::Index>(members.size());
    Eigen::MatrixXd B(m, m);
    for (Eigen::Index r = 0; r < m; ++r)
      for (Eigen::Index c = 0; c < m; ++c) B(r, c) = N(members[r], members[c]);
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(B);
    const Eigen::VectorXd pivots = qr.matrixR().diagonal().cwiseAbs();
    if (!(pivots.minCoeff() > kSingularRatio * pivots.maxCoeff())) return false;
  }
  return true;
}

}  // namespace

void Model::finalize(std::vector<std::string>* inertia_warnings) {
  const int n = dof();
  if (n == 0)
    throw Error("model '" + name + "' has no moving joints; add a revolute or prismatic joint");
  if (n > kMaxJoints) {
    throw Error("model '" + name + "' has " + std::to_string(n) +
                " moving joints; dynid handles at most " + std::to_string(kMaxJoints) +
                " (split the model or merge joints into fixed ones)");
  }
  if (static_cast<int>(links.size()) != n) {
    throw Error("model '" + name + "' has " + std::to_string(links.size()) +
                " link parameter sets for " + std::to_string(n) + " joints");
  }
  if (!gravity.allFinite()) throw Error("model '" + name + "' has a non-finite gravity vector");
  std::unordered_map<std::string, int> first_use;
  first_use.reserve(static_cast<std::size_t>(n));
  for (int j = 0; j < n; ++j) {
    const auto [it, fresh] = first_use.emplace(joints[j].name, j);
    if (!fresh) {
      throw Error("model '" + name + "' has two joints named '" + joints[j].name + "' (joints " +
                  std::to_string(it->second + 1) + " and " + std::to_string(j + 1) +
                  "); give every joint a unique name");
    }
  }
  for (int j = 0; j < n; ++j) {
    Joint& jt = joints[j];
    const std::string who = "joint '" + jt.name + "'";
    if (jt.parent < -1 || jt.parent >= j) {
      throw Error(who + " has parent index " + std::to_string(jt.parent) +
                  "; parents must precede their children");
    }
    if (!all_finite(jt.R_PJ) || !all_finite(jt.p_PJ) || !all_finite(jt.axis)) {
      throw Error(who + " has a non-finite origin or axis");
    }
    const double axis_norm = jt.axis.norm();
    if (axis_norm < 1e-9) throw Error(who + " has a zero axis; give a non-zero <axis xyz>");
    jt.axis /= axis_norm;
    if (!(jt.R_PJ.transpose() * jt.R_PJ).isIdentity(1e-9) || jt.R_PJ.determinant() < 0.0) {
      throw Error(who + " has an origin rotation that is not a proper rotation matrix");
    }
    if (!(jt.limits.lower <= jt.limits.upper)) {
      throw Error(who + " has lower limit above upper limit; swap them");
    }
    if (!links[j].allFinite())
      throw Error("link '" + jt.link_name + "' has non-finite inertial values");
    check_physical(links[j], jt.link_name.empty() ? jt.name : jt.link_name, inertia_warnings);
  }
  if (transmission.N.size() == 0) transmission.N = Eigen::MatrixXd::Identity(n, n);
  if (transmission.q_offset.size() == 0) transmission.q_offset = Eigen::VectorXd::Zero(n);
  if (transmission.N.rows() != n || transmission.N.cols() != n ||
      transmission.q_offset.size() != n) {
    throw Error("model '" + name + "' has a transmission of the wrong size; it must be " +
                std::to_string(n) + "x" + std::to_string(n));
  }
  if (!transmission.N.allFinite() || !transmission.q_offset.allFinite()) {
    throw Error("model '" + name +
                "' has a non-finite transmission N or q_offset; give finite values");
  }
  if (!transmission_invertible(transmission.N)) {
    throw Error("model '" + name +
                "' has a singular transmission matrix N (rank-deficient relative to its largest "
                "entry); every motor must drive an independent combination of joints");
  }
}

Eigen::VectorXd Model::standard_parameters() const {
  Eigen::VectorXd theta(kLinkParams * dof());
  for (int j = 0; j < dof(); ++j) theta.segment<kLinkParams>(kLinkParams * j) = links[j];
  return theta;
}

std::vector<std::string> Model::standard_parameter_names() const {
  std::vector<std::string> names;
  names.reserve(kLinkParams * dof());
  for (int j = 0; j < dof(); ++j) {
    for (const auto& label : link_parameter_labels())
      names.push_back(label + std::to_string(j + 1));
  }
  return names;
}

}  // namespace dynid
