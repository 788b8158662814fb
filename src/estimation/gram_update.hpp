#pragma once

// Internal kernel of the estimation module (not public API): the symmetric rank-k update of the
// streaming normal equations.

#include <Eigen/Core>

namespace dynid {
namespace estimation_detail {

/// Upper triangle of G += B·Bᵀ (the Gram update of k new rows, one per column of B).
/// G is q×q, column-major with leading dimension q; only its entries i ≤ j are read and written.
/// B is q×k, column-major with leading dimension ldb ≥ ceil(q/8)·8, and its rows q…ldb−1 must be
/// zero (the kernel reads them as padding). Uses an AVX2/FMA kernel when the CPU has one (checked
/// once at run time, so the default x86-64 build gets it too), else Eigen's rank update; the two
/// agree up to round-off (the sums are taken in another order).
void gram_update_upper(Eigen::Index q, Eigen::Index k, const double* B, Eigen::Index ldb,
                       double* G);

/// The padded leading dimension gram_update_upper needs for q rows.
inline Eigen::Index gram_padded_rows(Eigen::Index q) {
  return (q + 7) / 8 * 8;
}

}  // namespace estimation_detail
}  // namespace dynid
