// The body of agent_planes (steer/orca_planes.hpp) for one instruction set: the whole vectors of
// a row's neighbours in the lanes of xsimd's batch for Arch. Included by orca_planes.cpp (the
// build's own instruction set) and orca_planes_avx2.cpp (compiled with -mavx2, called only when
// the CPU has it): the same operations on the same operands in every lane, and no fused
// multiply-adds (-ffp-contract=off everywhere; the AVX2 file is not given -mfma either), so both
// give the reference's bits.
// Nothing but xsimd's templates on Arch and this function may be used here: an inline function
// of another header compiled with -mavx2 could be the copy the linker keeps for everyone.
#pragma once

#include <cstddef>
#include <xsimd/xsimd.hpp>

#include "steer/orca_planes.hpp"

namespace crowddb::steer {

// Computes out[a] for a < m - m % lanes and returns that count (the caller does the tail).
template <class Arch>
std::size_t agent_planes_lanes(const PlaneInputs& in, std::size_t m, double dt, double vix,
                               double viy, HalfPlane* out) {
  using B = xsimd::batch<double, Arch>;
  constexpr std::size_t L = B::size;
  const B zero(0.0), one(1.0), bdt(dt), bvix(vix), bviy(viy);
  std::size_t a = 0;
  for (; a + L <= m; a += L) {
    const B px = B::load_unaligned(in.px + a), py = B::load_unaligned(in.py + a);
    const B vx = B::load_unaligned(in.vx + a), vy = B::load_unaligned(in.vy + a);
    const B r = B::load_unaligned(in.r + a), tau = B::load_unaligned(in.tau + a);
    const B share = B::load_unaligned(in.share + a);
    const B d2 = px * px + py * py, r2 = r * r;
    const auto overlap = !(d2 > r2);
    // The cut-off arc, and the overlapping case: the same formula with horizon dt, and when the
    // relative velocity points nowhere, the normal (1, 0).
    const B te = xsimd::select(overlap, bdt, tau);
    const B wx = vx - px / te, wy = vy - py / te;
    const B w2 = wx * wx + wy * wy;
    const B wp = wx * px + wy * py;
    const auto arc = overlap | ((wp < zero) & (wp * wp > r2 * w2));
    const B wl = xsimd::sqrt(w2);
    const auto nowhere = overlap & !(wl > zero);
    const B anx = xsimd::select(nowhere, one, wx / wl);
    const B any = xsimd::select(nowhere, zero, wy / wl);
    const B s = r / te - wl;
    const B aux = s * anx, auy = s * any;
    // The legs: the right leg is the left one with -r for r (negating a product is exact).
    const B leg = xsimd::sqrt(d2 - r2);
    const auto left = px * wy - py * wx > zero;
    const B sr = xsimd::select(left, r, -r);
    const B lx = (px * leg - py * sr) / d2;
    const B ly = (px * sr + py * leg) / d2;
    const B lnx = xsimd::select(left, -ly, ly);
    const B lny = xsimd::select(left, lx, -lx);
    const B along = vx * lx + vy * ly;
    const B lux = along * lx - vx, luy = along * ly - vy;
    const B ux = xsimd::select(arc, aux, lux), uy = xsimd::select(arc, auy, luy);
    alignas(64) double opx[L], opy[L], onx[L], ony[L];
    (bvix + share * ux).store_aligned(opx);
    (bviy + share * uy).store_aligned(opy);
    xsimd::select(arc, anx, lnx).store_aligned(onx);
    xsimd::select(arc, any, lny).store_aligned(ony);
    for (std::size_t l = 0; l < L; ++l) {
      out[a + l].px = opx[l];
      out[a + l].py = opy[l];
      out[a + l].nx = onx[l];
      out[a + l].ny = ony[l];
    }
  }
  return a;
}

}  // namespace crowddb::steer
