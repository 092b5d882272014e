// pair_lanes' four lanes (steer/orca_pairs.hpp), compiled with -mavx2 and called only when the CPU
// has it (steer/orca_pairs.cpp). Every expression is pair_one's, first_or_ask's and pair_rest's,
// lane by lane, with the same operands in the same order; the comments name the line each
// restates. Nothing inline from another header may be called here: an inline function compiled
// with -mavx2 could be the copy the linker keeps for everyone (the header is included for its
// types only; the object must define nothing but pair_lanes_avx2_impl).
#include "steer/orca_pairs.hpp"

// (Compiled in a build with AVX2 only: -mavx2 for the run-time choice, or -march=native.)
#ifdef __AVX2__
#include <immintrin.h>

namespace crowddb::steer {
namespace {

// The eight 8-byte fields of four 64-byte records, as eight vectors (field f of record l in lane
// l): two loads per record and a 4 x 4 transpose of each half.
struct Fields {
  __m256d f[8];
};

inline __attribute__((always_inline)) Fields transpose(const double* r0, const double* r1,
                                                       const double* r2, const double* r3) {
  Fields out;
  for (int half = 0; half < 2; ++half) {
    const __m256d a0 = _mm256_load_pd(r0 + 4 * half), a1 = _mm256_load_pd(r1 + 4 * half);
    const __m256d a2 = _mm256_load_pd(r2 + 4 * half), a3 = _mm256_load_pd(r3 + 4 * half);
    const __m256d t0 = _mm256_unpacklo_pd(a0, a1), t1 = _mm256_unpackhi_pd(a0, a1);
    const __m256d t2 = _mm256_unpacklo_pd(a2, a3), t3 = _mm256_unpackhi_pd(a2, a3);
    out.f[4 * half + 0] = _mm256_permute2f128_pd(t0, t2, 0x20);
    out.f[4 * half + 1] = _mm256_permute2f128_pd(t1, t3, 0x20);
    out.f[4 * half + 2] = _mm256_permute2f128_pd(t0, t2, 0x31);
    out.f[4 * half + 3] = _mm256_permute2f128_pd(t1, t3, 0x31);
  }
  return out;
}

inline __attribute__((always_inline)) __m256d select(__m256d mask, __m256d a, __m256d b) {
  return _mm256_blendv_pd(b, a, mask);  // mask ? a : b, lane by lane
}

inline __attribute__((always_inline)) __m256d as_mask(__m256i m) {
  return _mm256_castsi256_pd(m);
}

}  // namespace

void pair_lanes_avx2_impl(const PairRow& row, const PairColumns& c, const uint32_t* rows,
                          std::size_t m, const PairOut& out) {
  const auto* hi = reinterpret_cast<const double*>(row.heading);
  const Peer& pi = *row.peer;
  const __m256d zero = _mm256_setzero_pd(), one = _mm256_set1_pd(1.0);
  const __m256d sign = _mm256_set1_pd(-0.0), inf = _mm256_set1_pd(INFINITY);
  const __m256d xi = _mm256_set1_pd(row.x), yi = _mm256_set1_pd(row.y);
  const __m256d ri = _mm256_set1_pd(row.r), beyond = _mm256_set1_pd(row.beyond);
  const __m256d reach = _mm256_set1_pd(row.reach), skin = _mm256_set1_pd(kSkin);
  const __m256d dt = _mm256_set1_pd(row.dt), tau = _mm256_set1_pd(row.tau);
  const __m256d lo_share = _mm256_set1_pd(row.lo_share), hi_share = _mm256_set1_pd(row.hi_share);
  const __m256d vix = _mm256_set1_pd(row.vx), viy = _mm256_set1_pd(row.vy);
  const __m256d arrive_i = _mm256_set1_pd(pi.arrive), rem_i = _mm256_set1_pd(pi.remaining);
  const __m256i rank_i = _mm256_set1_epi64x(static_cast<int64_t>(pi.rank ^ (uint64_t{1} << 63)));
  const __m256i rank_flip = _mm256_set1_epi64x(static_cast<int64_t>(uint64_t{1} << 63));
  const bool finite_i = __builtin_isfinite(pi.remaining);  // (not std::isfinite: see the top)
  // i's heading record (sim::ahead's a)
  const __m256d ax = _mm256_set1_pd(hi[0]), ay = _mm256_set1_pd(hi[1]);
  const __m256d awx = _mm256_set1_pd(hi[2]), awy = _mm256_set1_pd(hi[3]);
  const __m256d agx = _mm256_set1_pd(hi[4]), agy = _mm256_set1_pd(hi[5]);
  const __m256d ag2 = _mm256_set1_pd(hi[6]);
  const __m256i goal_i = _mm256_set1_epi64x(row.heading->goal);
  const __m256i left_i = _mm256_set1_epi64x(row.heading->left_goal);
  const __m256i low32 = _mm256_set1_epi64x(0xFFFFFFFFll);
  const __m256d same2 = _mm256_set1_pd(kSameWay * kSameWay);
  const __m256i yielding_i = _mm256_set1_epi64x(row.yielding);
  const bool capping = row.headway | row.gap;
  const __m256d ux = _mm256_set1_pd(row.ux), uy = _mm256_set1_pd(row.uy);
  const __m256d cap_reach = _mm256_set1_pd(row.cap_reach);
  const int headway = row.headway, gap_cap = row.gap;
  const auto* H = reinterpret_cast<const double*>(c.heading);
  const auto* P = reinterpret_cast<const double*>(c.peer);
  for (std::size_t a = 0; a < m; a += 4) {
    const uint32_t j0 = rows[a], j1 = rows[a + 1], j2 = rows[a + 2], j3 = rows[a + 3];
    const Fields h = transpose(H + 8 * std::size_t{j0}, H + 8 * std::size_t{j1},
                               H + 8 * std::size_t{j2}, H + 8 * std::size_t{j3});
    const Fields p = transpose(P + 8 * std::size_t{j0}, P + 8 * std::size_t{j1},
                               P + 8 * std::size_t{j2}, P + 8 * std::size_t{j3});
    const __m256d bx = h.f[0], by = h.f[1], bwx = h.f[2], bwy = h.f[3];
    const __m256d bgx = h.f[4], bgy = h.f[5], bg2 = h.f[6];
    const __m256i goals = _mm256_castpd_si256(h.f[7]);  // goal | left_goal << 32
    const __m256i goal_j = _mm256_and_si256(goals, low32), left_j = _mm256_srli_epi64(goals, 32);
    const __m256d pvx = p.f[0], pvy = p.f[1], pax = p.f[2], pay = p.f[3];
    const __m256d rj = p.f[4], arrive_j = p.f[5], rem_j = p.f[6];
    const __m256i rank_j = _mm256_castpd_si256(p.f[7]);

    // first_or_ask: yielding first; out before in may decide (ask); else pair_rest.
    const __m256i yielding_j =
        _mm256_setr_epi64x(c.yielding[j0], c.yielding[j1], c.yielding[j2], c.yielding[j3]);
    const __m256i yield_differs =
        _mm256_xor_si256(_mm256_cmpeq_epi64(yielding_i, yielding_j), _mm256_set1_epi64x(-1));
    const __m256i ask = _mm256_andnot_si256(
        yield_differs,
        _mm256_or_si256(_mm256_cmpeq_epi64(left_i, goal_j), _mm256_cmpeq_epi64(left_j, goal_i)));
    // pair_rest: by_path = rem_i < rem_j | (rem_i == rem_j & rank_i > rank_j) (ranks unsigned)
    const __m256d by_path = _mm256_or_pd(
        _mm256_cmp_pd(rem_i, rem_j, _CMP_LT_OQ),
        _mm256_and_pd(_mm256_cmp_pd(rem_i, rem_j, _CMP_EQ_OQ),
                      as_mask(_mm256_cmpgt_epi64(rank_i, _mm256_xor_si256(rank_j, rank_flip)))));
    // sim::ahead(a = i, b = j)
    const __m256d sx = _mm256_add_pd(awx, bwx), sy = _mm256_add_pd(awy, bwy);
    const __m256d dd = _mm256_add_pd(_mm256_mul_pd(sx, _mm256_sub_pd(ax, bx)),
                                     _mm256_mul_pd(sy, _mm256_sub_pd(ay, by)));
    const __m256d by_place = _mm256_cmp_pd(dd, zero, _CMP_GT_OQ);
    const __m256d dot = _mm256_add_pd(_mm256_mul_pd(agx, bgx), _mm256_mul_pd(agy, bgy));
    __m256d decides = _mm256_andnot_pd(as_mask(_mm256_cmpeq_epi64(goal_i, goal_j)),
                                       _mm256_cmp_pd(dot, zero, _CMP_GT_OQ));
    decides = _mm256_and_pd(
        decides, _mm256_cmp_pd(_mm256_mul_pd(dot, dot),
                               _mm256_mul_pd(same2, _mm256_mul_pd(ag2, bg2)), _CMP_GE_OQ));
    decides = _mm256_and_pd(
        decides, _mm256_cmp_pd(_mm256_add_pd(_mm256_mul_pd(sx, sx), _mm256_mul_pd(sy, sy)), one,
                               _CMP_GE_OQ));
    decides = _mm256_and_pd(decides, _mm256_cmp_pd(dd, zero, _CMP_NEQ_UQ));
    // std::isfinite(rem_i) & std::isfinite(rem_j): |x| < inf (false for NaN)
    decides = _mm256_and_pd(decides, _mm256_cmp_pd(_mm256_andnot_pd(sign, rem_j), inf, _CMP_LT_OQ));
    if (!finite_i) decides = zero;
    // Where the two differ in yielding, i goes first exactly when it yields (all ones or zeros).
    const __m256d yields = row.yielding ? as_mask(_mm256_set1_epi64x(-1)) : zero;
    const __m256d i_first =
        select(as_mask(yield_differs), yields, select(decides, by_place, by_path));

    // pair_one: the contact plane
    const __m256d dx = _mm256_sub_pd(bx, xi), dy = _mm256_sub_pd(by, yi);
    const __m256d d2 = _mm256_add_pd(_mm256_mul_pd(dx, dx), _mm256_mul_pd(dy, dy));
    const __m256d far = _mm256_add_pd(beyond, rj);
    const __m256d clear = _mm256_cmp_pd(
        d2, _mm256_mul_pd(_mm256_mul_pd(far, far), _mm256_set1_pd(1 + 1e-9)), _CMP_GT_OQ);
    const int clear_bits = _mm256_movemask_pd(clear);
    uint32_t contact_bits = 0;
    if (clear_bits != 0xF) {
      const __m256d d = _mm256_andnot_pd(clear, _mm256_sqrt_pd(d2));  // clear ? 0 : sqrt(d2)
      const __m256d gap = _mm256_sub_pd(_mm256_sub_pd(_mm256_sub_pd(d, ri), rj), skin);
      const __m256d none = _mm256_or_pd(clear, _mm256_or_pd(_mm256_cmp_pd(gap, reach, _CMP_GE_OQ),
                                                            _mm256_cmp_pd(d, zero, _CMP_EQ_OQ)));
      contact_bits = static_cast<uint32_t>(~_mm256_movemask_pd(none)) & 0xF;
      if (contact_bits) {
        const __m256d nx = _mm256_div_pd(dx, d), ny = _mm256_div_pd(dy, d);
        const __m256d share = select(i_first, lo_share, hi_share);
        const __m256d g = _mm256_div_pd(_mm256_mul_pd(_mm256_max_pd(gap, zero), share), dt);
        _mm256_storeu_pd(out.cpx + a, _mm256_mul_pd(nx, g));
        _mm256_storeu_pd(out.cpy + a, _mm256_mul_pd(ny, g));
        _mm256_storeu_pd(out.cnx + a, _mm256_xor_pd(nx, sign));
        _mm256_storeu_pd(out.cny + a, _mm256_xor_pd(ny, sign));
      }
    }
    // the agent plane's inputs
    _mm256_storeu_pd(out.px + a, dx);
    _mm256_storeu_pd(out.py + a, dy);
    _mm256_storeu_pd(out.vx + a, _mm256_sub_pd(vix, select(i_first, pvx, pax)));
    _mm256_storeu_pd(out.vy + a, _mm256_sub_pd(viy, select(i_first, pvy, pay)));
    _mm256_storeu_pd(out.r + a, _mm256_add_pd(ri, rj));
    // std::min(arrive_i, arrive_j) = arrive_j < arrive_i ? arrive_j : arrive_i; std::clamp(v,
    // dt, tau) = std::min(std::max(v, dt), tau) in libstdc++: x = v < dt ? dt : v, then
    // tau < x ? tau : x
    const __m256d v = _mm256_min_pd(arrive_j, arrive_i);
    const __m256d x = select(_mm256_cmp_pd(v, dt, _CMP_LT_OQ), dt, v);
    const __m256d clamped = select(_mm256_cmp_pd(tau, x, _CMP_LT_OQ), tau, x);
    _mm256_storeu_pd(out.tau + a, clamped);
    _mm256_storeu_pd(out.share + a, select(i_first, hi_share, lo_share));
    // the caps (streams.hpp follows_at)
    uint32_t h_bits = 0, g_bits = 0;
    if (capping) {
      const __m256d wx = _mm256_setr_pd(c.wish_x[j0], c.wish_x[j1], c.wish_x[j2], c.wish_x[j3]);
      const __m256d wy = _mm256_setr_pd(c.wish_y[j0], c.wish_y[j1], c.wish_y[j2], c.wish_y[j3]);
      const __m256d w2 = _mm256_add_pd(_mm256_mul_pd(wx, wx), _mm256_mul_pd(wy, wy));
      const __m256d wdot = _mm256_add_pd(_mm256_mul_pd(wx, ux), _mm256_mul_pd(wy, uy));
      const __m256d along = _mm256_add_pd(_mm256_mul_pd(dx, ux), _mm256_mul_pd(dy, uy));
      const __m256d side =
          _mm256_andnot_pd(sign, _mm256_sub_pd(_mm256_mul_pd(dy, ux), _mm256_mul_pd(dx, uy)));
      __m256d behind = _mm256_cmp_pd(along, zero, _CMP_NLE_UQ);
      behind = _mm256_and_pd(behind, _mm256_cmp_pd(side, _mm256_add_pd(ri, rj), _CMP_NGT_UQ));
      const __m256d way = _mm256_or_pd(
          _mm256_cmp_pd(w2, zero, _CMP_EQ_OQ),
          _mm256_and_pd(
              _mm256_cmp_pd(wdot, zero, _CMP_GE_OQ),
              _mm256_cmp_pd(_mm256_mul_pd(wdot, wdot), _mm256_mul_pd(same2, w2), _CMP_GE_OQ)));
      behind = _mm256_and_pd(behind, way);
      const __m256d gap_reach = _mm256_add_pd(cap_reach, rj);
      const __m256d near = _mm256_cmp_pd(d2, _mm256_mul_pd(gap_reach, gap_reach), _CMP_LT_OQ);
      const auto behind_bits = static_cast<uint32_t>(_mm256_movemask_pd(behind));
      h_bits = headway ? behind_bits : 0;
      g_bits = gap_cap ? behind_bits & static_cast<uint32_t>(_mm256_movemask_pd(near)) : 0;
    }
    const auto ask_bits = static_cast<uint32_t>(_mm256_movemask_pd(as_mask(ask)));
    out.lanes[a / 4] =
        static_cast<uint16_t>(contact_bits | h_bits << 4 | g_bits << 8 | ask_bits << 12);
  }
}

}  // namespace crowddb::steer
#endif  // __AVX2__
