// The first-to-collide tree's pair times several at a time (index/ftc_tree.cpp), for one
// instruction set: ray_disc_time of one query against a leaf's members in the lanes of xsimd's
// batch for Arch. Included by ftc_tree.cpp (the build's own instruction set) and
// ftc_pair_lanes_avx2.cpp (compiled with -mavx2, called only when the CPU has it): every case
// computed in every lane, then selected; the same operations on the same operands as
// ray_disc_time, lane by lane (IEEE square roots and divisions, and no fused multiply-adds:
// -ffp-contract=off everywhere, and the AVX2 file is not given -mfma), so the same bits.
// Nothing but xsimd's templates on Arch and this function may be used here: an inline function
// of another header compiled with -mavx2 could be the copy the linker keeps for everyone.
#pragma once

#include <cmath>
#include <cstdint>
#include <xsimd/xsimd.hpp>

namespace crowddb::ftc {

// A member of a tree: its columns copied from the source in tree order, so a leaf's members lie
// together in memory (scans and queries run in tree order). The values are the source's own,
// untouched, so pair times computed from them are bit-identical to the naive path's.
struct Member {
  double x, y, vx, vy, r;
  uint64_t key;
  uint32_t row;
};

// The query's own columns.
struct Query {
  double x, y, vx, vy, r;
};

// The members' values column by column, in tree order: the lanes load them as they lie (copying
// four Members' fields into columns on the stack first cost the first-to-collide stage 2-3 %).
struct Columns {
  const double *x, *y, *vx, *vy, *r;
  Columns from(uint32_t k) const { return {x + k, y + k, vx + k, vy + k, r + k}; }
};

// out[k] = ray_disc_time(m[k] - q) for k < n - n % lanes; returns that count (the caller does
// the tail), and `earliest`, the smallest of those times (+inf when none).
template <class Arch>
uint32_t pair_times_lanes(const Columns& m, uint32_t n, const Query& q, double horizon, double* out,
                          double& earliest) {
  using B = xsimd::batch<double, Arch>;
  constexpr uint32_t L = B::size;
  const B ax(q.x), ay(q.y), avx(q.vx), avy(q.vy), ar(q.r), hz(horizon), zero(0.0), inf(INFINITY);
  B soonest = inf;
  uint32_t k = 0;
  for (; k + L <= n; k += L) {
    const B dx = B::load_unaligned(m.x + k) - ax, dy = B::load_unaligned(m.y + k) - ay;
    const B wx = B::load_unaligned(m.vx + k) - avx, wy = B::load_unaligned(m.vy + k) - avy;
    const B R = ar + B::load_unaligned(m.r + k);
    const B c = dx * dx + dy * dy - R * R;
    const B b = dx * wx + dy * wy;
    const B a = wx * wx + wy * wy;
    const B cross = dx * wy - dy * wx;
    const B disc = a * (R * R) - cross * cross;
    const B t = c / (-b + xsimd::sqrt(disc));
    B time = xsimd::select(t <= hz, t, inf);
    time = xsimd::select(disc > zero, time, inf);
    time = xsimd::select(b < zero, time, inf);
    time = xsimd::select(c < zero, zero, time);
    time.store_unaligned(out + k);
    soonest = xsimd::min(soonest, time);
  }
  alignas(64) double lanes[L];
  soonest.store_aligned(lanes);
  earliest = INFINITY;
  for (uint32_t l = 0; l < L; ++l) earliest = lanes[l] < earliest ? lanes[l] : earliest;
  return k;
}

// Does this build call the AVX2 lanes (the CPU has them and the build's own set is narrower)?
bool pair_times_avx2();

// out[k] = ray_disc_time(m[k] - q) for every k < n: the widest lanes there are (AVX2 where
// pair_times_avx2()), or the build's own (tests compare both), and the tail one at a time.
// Returns the smallest of them (+inf when none, or n = 0). Defined in ftc_tree.cpp.
enum class Lanes { widest, build };
double pair_times(const Columns& m, uint32_t n, const Query& q, double horizon, double* out,
                  Lanes lanes = Lanes::widest);

}  // namespace crowddb::ftc
