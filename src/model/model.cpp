#include "dynid/model/model.hpp"

#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "dynid/common/error.hpp"

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

void check_physical(const LinkParams& p, const std::string& link) {
  const double m = p(9);
  if (!(m >= 0.0)) {
    throw Error("link '" + link + "' has negative mass " + std::to_string(m) +
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
  const bool triangle =
      ev(0) + ev(1) >= ev(2) - tol && ev(0) + ev(2) >= ev(1) - tol && ev(1) + ev(2) >= ev(0) - tol;
  if (ev.minCoeff() < -tol || !triangle) {
    std::ostringstream msg;
    msg << "link '" << link << "' has a non-physical inertia (principal moments about the centre "
        << "of mass " << ev.transpose()
        << " must be >= 0 and satisfy the triangle inequality); fix its inertia tensor";
    throw Error(msg.str());
  }
}

}  // namespace

void Model::finalize() {
  const int n = dof();
  if (n == 0)
    throw Error("model '" + name + "' has no moving joints; add a revolute or prismatic joint");
  if (static_cast<int>(links.size()) != n) {
    throw Error("model '" + name + "' has " + std::to_string(links.size()) +
                " link parameter sets for " + std::to_string(n) + " joints");
  }
  if (!gravity.allFinite()) throw Error("model '" + name + "' has a non-finite gravity vector");
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
    check_physical(links[j], jt.link_name.empty() ? jt.name : jt.link_name);
  }
  if (transmission.N.size() == 0) transmission.N = Eigen::MatrixXd::Identity(n, n);
  if (transmission.q_offset.size() == 0) transmission.q_offset = Eigen::VectorXd::Zero(n);
  if (transmission.N.rows() != n || transmission.N.cols() != n ||
      transmission.q_offset.size() != n) {
    throw Error("model '" + name + "' has a transmission of the wrong size; it must be " +
                std::to_string(n) + "x" + std::to_string(n));
  }
  if (std::abs(transmission.N.determinant()) < 1e-12) {
    throw Error("model '" + name + "' has a singular transmission matrix; it must be invertible");
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
