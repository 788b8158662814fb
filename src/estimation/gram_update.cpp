#include "gram_update.hpp"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#include <immintrin.h>
#define DYNID_GRAM_AVX2 1
#endif

namespace dynid {
namespace estimation_detail {
namespace {

// Columns of B per pass over G's tiles. A tile's sums are added to G once per panel, so a panel as
// long as the streaming chunk (256) adds round-off to G least often; its 72-row B (147 KiB) is
// read from L2 by every tile.
constexpr Eigen::Index kPanel = 256;

void gram_update_eigen(Eigen::Index q, Eigen::Index k, const double* B, Eigen::Index ldb,
                       double* G) {
  Eigen::Map<const Eigen::MatrixXd, 0, Eigen::OuterStride<>> b(B, q, k, Eigen::OuterStride<>(ldb));
  Eigen::Map<Eigen::MatrixXd> g(G, q, q);
  g.selfadjointView<Eigen::Upper>().rankUpdate(b);
}

#ifdef DYNID_GRAM_AVX2
// 8×4 register tiles of G (rows i0…i0+7, columns j0…j0+3) over the upper triangle: per column of
// B two 4-wide loads, four broadcasts and eight fused multiply-adds. The default build targets
// plain x86-64 (SSE2, docs/design.md §1), where Eigen's rank update runs at ≈ 4 flops per cycle;
// this kernel reaches ≈ 3× that. Only raw pointers cross its boundary, so no Eigen object is built
// with other vectorisation settings than the rest of the library.
__attribute__((target("avx2,fma"))) void gram_update_avx2(Eigen::Index q, Eigen::Index k,
                                                          const double* B, Eigen::Index ldb,
                                                          double* G) {
  for (Eigen::Index s0 = 0; s0 < k; s0 += kPanel) {
    const Eigen::Index s1 = s0 + kPanel < k ? s0 + kPanel : k;
    for (Eigen::Index j0 = 0; j0 < q; j0 += 4) {
      const Eigen::Index i_end = j0 + 4 < q ? j0 + 4 : q;
      for (Eigen::Index i0 = 0; i0 < i_end; i0 += 8) {
        __m256d c00 = _mm256_setzero_pd(), c01 = _mm256_setzero_pd();
        __m256d c10 = _mm256_setzero_pd(), c11 = _mm256_setzero_pd();
        __m256d c20 = _mm256_setzero_pd(), c21 = _mm256_setzero_pd();
        __m256d c30 = _mm256_setzero_pd(), c31 = _mm256_setzero_pd();
        for (Eigen::Index s = s0; s < s1; ++s) {
          const double* b = B + s * ldb;
          const __m256d a0 = _mm256_loadu_pd(b + i0), a1 = _mm256_loadu_pd(b + i0 + 4);
          __m256d x = _mm256_broadcast_sd(b + j0);
          c00 = _mm256_fmadd_pd(a0, x, c00);
          c01 = _mm256_fmadd_pd(a1, x, c01);
          x = _mm256_broadcast_sd(b + j0 + 1);
          c10 = _mm256_fmadd_pd(a0, x, c10);
          c11 = _mm256_fmadd_pd(a1, x, c11);
          x = _mm256_broadcast_sd(b + j0 + 2);
          c20 = _mm256_fmadd_pd(a0, x, c20);
          c21 = _mm256_fmadd_pd(a1, x, c21);
          x = _mm256_broadcast_sd(b + j0 + 3);
          c30 = _mm256_fmadd_pd(a0, x, c30);
          c31 = _mm256_fmadd_pd(a1, x, c31);
        }
        const __m256d tile[4][2] = {{c00, c01}, {c10, c11}, {c20, c21}, {c30, c31}};
        for (int c = 0; c < 4; ++c) {
          const Eigen::Index j = j0 + c;
          if (j >= q) break;
          double* g = G + j * q;
          if (i0 + 8 <= j + 1) {  // the tile's column lies wholly in the upper triangle
            _mm256_storeu_pd(g + i0, _mm256_add_pd(_mm256_loadu_pd(g + i0), tile[c][0]));
            _mm256_storeu_pd(g + i0 + 4, _mm256_add_pd(_mm256_loadu_pd(g + i0 + 4), tile[c][1]));
          } else {  // diagonal tile: rows i ≤ j only
            alignas(32) double v[8];
            _mm256_store_pd(v, tile[c][0]);
            _mm256_store_pd(v + 4, tile[c][1]);
            for (Eigen::Index i = i0; i <= j && i < i0 + 8; ++i) g[i] += v[i - i0];
          }
        }
      }
    }
  }
}

bool has_avx2_fma() {
  __builtin_cpu_init();
  return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
}
#endif

}  // namespace

void gram_update_upper(Eigen::Index q, Eigen::Index k, const double* B, Eigen::Index ldb,
                       double* G) {
#ifdef DYNID_GRAM_AVX2
  static const bool avx2 = has_avx2_fma();
  if (avx2) {
    gram_update_avx2(q, k, B, ldb, G);
    return;
  }
#endif
  gram_update_eigen(q, k, B, ldb, G);
}

}  // namespace estimation_detail
}  // namespace dynid
