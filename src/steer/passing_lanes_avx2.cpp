// passing_filter in AVX2's four lanes (steer/passing_lanes.hpp), compiled with -mavx2 and called
// only when the CPU has it (steer/passing.cpp makes the choice), or in a build for this machine
// when it has AVX2. Every expression is passing_filter's, lane by lane, with the same operands in
// the same order. The header is included for its types only: an inline function compiled with
// -mavx2 could be the copy the linker keeps for everyone.
#include "steer/passing_lanes.hpp"
#include "util/lane_packs.hpp"

#ifdef __AVX2__
#include <immintrin.h>

namespace crowddb::steer {
uint32_t passing_filter_avx2(const PassingColumns& c, uint32_t a, uint32_t hi, const LaneQuery& q,
                             double same_way2, double side_reach, uint32_t* pick) {
  const __m256d px = _mm256_set1_pd(q.px), py = _mm256_set1_pd(q.py);
  const __m256d ux = _mm256_set1_pd(q.ux), uy = _mm256_set1_pd(q.uy);
  const __m256d look = _mm256_set1_pd(q.look), ri = _mm256_set1_pd(q.ri);
  const __m256d k2 = _mm256_set1_pd(same_way2), reach = _mm256_set1_pd(side_reach);
  const __m256d zero = _mm256_setzero_pd(), sign = _mm256_set1_pd(-0.0);
  const __m256i step = _mm256_setr_epi32(0, 1, 2, 3, 0, 0, 0, 0);
  uint32_t m = 0;
  for (; a < hi; a += 4) {
    // rx = x - px, ry = y - py; along = rx ux + ry uy
    const __m256d rx = _mm256_sub_pd(_mm256_loadu_pd(c.x + a), px);
    const __m256d ry = _mm256_sub_pd(_mm256_loadu_pd(c.y + a), py);
    const __m256d along = _mm256_add_pd(_mm256_mul_pd(rx, ux), _mm256_mul_pd(ry, uy));
    // w2 = wx wx + wy wy, dot = wx ux + wy uy
    const __m256d wx = _mm256_loadu_pd(c.wx + a), wy = _mm256_loadu_pd(c.wy + a);
    const __m256d w2 = _mm256_add_pd(_mm256_mul_pd(wx, wx), _mm256_mul_pd(wy, wy));
    const __m256d dot = _mm256_add_pd(_mm256_mul_pd(wx, ux), _mm256_mul_pd(wy, uy));
    // side = rx uy - ry ux; |side| <= ri + r + side_reach
    const __m256d side = _mm256_sub_pd(_mm256_mul_pd(rx, uy), _mm256_mul_pd(ry, ux));
    const __m256d width = _mm256_add_pd(_mm256_add_pd(ri, _mm256_loadu_pd(c.r + a)), reach);
    // !(along <= 0) & !(along > look) & !(|side| > width): true for NaN, as in the reference
    __m256d keep = _mm256_and_pd(_mm256_cmp_pd(along, zero, _CMP_NLE_UQ),
                                 _mm256_cmp_pd(along, look, _CMP_NGT_UQ));
    keep = _mm256_and_pd(keep, _mm256_cmp_pd(_mm256_andnot_pd(sign, side), width, _CMP_NGT_UQ));
    keep = _mm256_and_pd(keep, _mm256_cmp_pd(dot, zero, _CMP_LT_OQ));
    keep = _mm256_and_pd(keep,
                         _mm256_cmp_pd(_mm256_mul_pd(dot, dot), _mm256_mul_pd(k2, w2), _CMP_GE_OQ));
    auto mask = static_cast<uint32_t>(_mm256_movemask_pd(keep));
    if (hi - a < 4) mask &= (1u << (hi - a)) - 1;  // the lanes past the run's end
    const __m256i places =
        _mm256_load_si256(reinterpret_cast<const __m256i*>(kFrontPacks.places[mask]));
    const __m256i rows = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int32_t>(a)), step);
    _mm_storeu_si128(reinterpret_cast<__m128i*>(pick + m),
                     _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(rows, places)));
    m += static_cast<uint32_t>(__builtin_popcount(mask));
  }
  return m;
}

}  // namespace crowddb::steer
#endif  // __AVX2__
