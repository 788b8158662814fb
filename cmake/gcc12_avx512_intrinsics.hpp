// Force-included by the `native` preset under GCC 12 only (CMakeLists.txt). GCC 12's
// avx512fintrin.h initialises the "undefined" operand of _mm512_max_pd, _mm512_min_pd and friends
// from itself (`__m512d __Y = __Y;`), and -Wmaybe-uninitialized reports it wherever Eigen's
// AVX-512 packet code is inlined (GCC bug 105593). Including the intrinsics here, first, with
// that warning and its -Wuninitialized twin off silences them for the intrinsic headers' own
// lines only: the project's code keeps both warnings (Eigen's later #include is a no-op).
// The same intrinsics' 64-byte loads and stores are also reported by -Warray-bounds when Eigen's
// assignment loop, inlined for a vector GCC can see is 2 doubles (malloc(16)), keeps its packet
// branch that the run-time size never enters: off for these header lines too.
#pragma once
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#pragma GCC diagnostic ignored "-Warray-bounds"
#include <immintrin.h>
#pragma GCC diagnostic pop
