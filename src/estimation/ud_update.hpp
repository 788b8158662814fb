#pragma once

#include <Eigen/Core>

namespace dynid::estimation_detail {

/// Bierman's U-D measurement update (the Agee–Turner rank-one update of P = U·D·Uᵀ; Bierman 1977
/// ch. V) for one scalar observation y = dᵀx + e with Var(e) = r: afterwards
/// U·D·Uᵀ = P − P·d·dᵀ·P/α with α = r + dᵀP·d, and k = P·d, so the gain is k/α. U (p×p, unit upper
/// triangular, only the strict upper triangle is read and written), D (p) are updated in place;
/// f, v, k (p) are scratch, k holds P·d on return. Returns α. No allocation, O(p²).
inline double ud_update(Eigen::Ref<Eigen::MatrixXd> U, Eigen::Ref<Eigen::VectorXd> D,
                        const Eigen::Ref<const Eigen::VectorXd>& d, double r,
                        Eigen::Ref<Eigen::VectorXd> f, Eigen::Ref<Eigen::VectorXd> v,
                        Eigen::Ref<Eigen::VectorXd> k) {
  const Eigen::Index p = d.size();
  // f = Uᵀd, v = D f, α_j = r + Σ_{i≤j} v_i f_i.
  f.noalias() = U.triangularView<Eigen::UnitUpper>().transpose() * d;
  v = D.cwiseProduct(f);
  double alpha = r + v(0) * f(0);
  D(0) *= r / alpha;
  k.setZero();
  k(0) = v(0);
  for (Eigen::Index j = 1; j < p; ++j) {
    const double beta = alpha;
    alpha += v(j) * f(j);
    const double pj = -f(j) / beta;
    D(j) *= beta / alpha;
    double* u = &U(0, j);
    for (Eigen::Index i = 0; i < j; ++i) {
      const double uij = u[i];
      u[i] = uij + k(i) * pj;
      k(i) += uij * v(j);
    }
    k(j) = v(j);
  }
  return alpha;
}

}  // namespace dynid::estimation_detail
