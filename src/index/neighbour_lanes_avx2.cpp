// gather_within and count_all_nearer in AVX2's four lanes (index/neighbour_lanes.hpp), compiled
// with -mavx2 and called only when the CPU has it (index/neighbour_grid.cpp makes the choice), or
// in a build for this machine when it has AVX2. Nothing inline from another header may be used
// here (std::array's operator[] either): an inline function compiled with -mavx2 could be the
// copy the linker keeps for everyone.
#ifdef __AVX2__
#include <immintrin.h>

#include <cstdint>

#include "util/lane_packs.hpp"

namespace crowddb::index {
// From a = lo on, whole vectors of four, the last one's lanes past hi read (X, Y readable to
// hi + 3) but never counted, its slots past the count written (at, dist room for hi - lo + 3).
// Returns how many were appended.
uint32_t gather_within_avx2(const double* X, const double* Y, uint32_t a, uint32_t hi, double px,
                            double py, double bound, uint32_t self_at, uint32_t* at, double* dist) {
  const __m256d vx = _mm256_set1_pd(px), vy = _mm256_set1_pd(py), vb = _mm256_set1_pd(bound);
  const __m256i step = _mm256_setr_epi32(0, 1, 2, 3, 0, 0, 0, 0);
  uint32_t m = 0;
  for (; a < hi; a += 4) {
    const __m256d dx = _mm256_sub_pd(_mm256_loadu_pd(X + a), vx);
    const __m256d dy = _mm256_sub_pd(_mm256_loadu_pd(Y + a), vy);
    const __m256d d2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
    auto mask = static_cast<uint32_t>(_mm256_movemask_pd(_mm256_cmp_pd(d2, vb, _CMP_LE_OQ)));
    if (hi - a < 4) mask &= (1u << (hi - a)) - 1;  // the lanes past the run's end
    const uint32_t self = self_at - a;             // the query's own place, when among these four
    if (self < 4) mask &= ~(1u << self);
    const __m256i halves =
        _mm256_load_si256(reinterpret_cast<const __m256i*>(kFrontPacks.halves[mask]));
    const __m256i places =
        _mm256_load_si256(reinterpret_cast<const __m256i*>(kFrontPacks.places[mask]));
    _mm256_storeu_pd(dist + m,
                     _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(d2), halves)));
    const __m256i rows = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(a)), step);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(at + m),
                     _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(rows, places)));
    m += static_cast<uint32_t>(__builtin_popcount(mask));
  }
  return m;
}

// count_all_nearer, dist[m, m + 3) INFINITY: four candidates u at a time against the others four
// at a time, each nearer one a -1 in its lane; the four counts summed across at the end.
void count_all_nearer_avx2(const double* dist, uint32_t m, uint32_t* before) {
  for (uint32_t u = 0; u < m; u += 4) {
    const __m256d d0 = _mm256_set1_pd(dist[u]), d1 = _mm256_set1_pd(dist[u + 1]);
    const __m256d d2 = _mm256_set1_pd(dist[u + 2]), d3 = _mm256_set1_pd(dist[u + 3]);
    __m256i n0 = _mm256_setzero_si256(), n1 = n0, n2 = n0, n3 = n0;
    for (uint32_t f = 0; f < m; f += 4) {
      const __m256d v = _mm256_loadu_pd(dist + f);
      n0 = _mm256_add_epi64(n0, _mm256_castpd_si256(_mm256_cmp_pd(v, d0, _CMP_LT_OQ)));
      n1 = _mm256_add_epi64(n1, _mm256_castpd_si256(_mm256_cmp_pd(v, d1, _CMP_LT_OQ)));
      n2 = _mm256_add_epi64(n2, _mm256_castpd_si256(_mm256_cmp_pd(v, d2, _CMP_LT_OQ)));
      n3 = _mm256_add_epi64(n3, _mm256_castpd_si256(_mm256_cmp_pd(v, d3, _CMP_LT_OQ)));
    }
    // Lane sums: (n0 n1) and (n2 n3) pairwise, then the halves.
    const __m256i s01 =
        _mm256_add_epi64(_mm256_unpacklo_epi64(n0, n1), _mm256_unpackhi_epi64(n0, n1));
    const __m256i s23 =
        _mm256_add_epi64(_mm256_unpacklo_epi64(n2, n3), _mm256_unpackhi_epi64(n2, n3));
    const __m256i sums = _mm256_add_epi64(_mm256_permute2x128_si256(s01, s23, 0x20),
                                          _mm256_permute2x128_si256(s01, s23, 0x31));
    alignas(32) int64_t out[4];
    _mm256_store_si256(reinterpret_cast<__m256i*>(out), sums);
    for (uint32_t l = 0; l < 4 && u + l < m; ++l) before[u + l] = static_cast<uint32_t>(-out[l]);
  }
}

}  // namespace crowddb::index
#endif  // __AVX2__
