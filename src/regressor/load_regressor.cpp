#include "dynid/regressor/load_regressor.hpp"

#include "regressor/wrench_kernel.hpp"

namespace dynid {

Eigen::Matrix<double, 6, 10> load_regressor(const Eigen::Vector3d& w, const Eigen::Vector3d& dw,
                                            const Eigen::Vector3d& ddp,
                                            const Eigen::Vector3d& g_S) {
  // Seed 1 eq. 28: K = [[p̈ − g, [dω×] + [ω×][ω×], 0], [0, [(g − p̈)×], [·dω] + [ω×][·ω]]].
  detail::WrenchBlocks b;
  detail::wrench_blocks(w, dw, ddp - g_S, b);
  Eigen::Matrix<double, 6, 10> K = Eigen::Matrix<double, 6, 10>::Zero();
  K.block<3, 1>(0, 0) = b.a;
  K.block<3, 3>(0, 1) = b.K_mc;
  K.block<3, 3>(3, 1) = b.A_skew;
  K.block<3, 6>(3, 4) = b.L_I;
  return K;
}

}  // namespace dynid
