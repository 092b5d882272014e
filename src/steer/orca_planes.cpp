#include "steer/orca_planes.hpp"

#include <cmath>
#include <xsimd/xsimd.hpp>

namespace crowddb::steer {

HalfPlane agent_plane(double px, double py, double vx, double vy, double r, double tau, double dt,
                      double vix, double viy, double share) {
  const double d2 = px * px + py * py, r2 = r * r;
  double ux, uy, nx, ny;
  if (d2 > r2) {
    // Truncated cone: apex 0, legs tangent to the disc of radius r around p, cut off by the disc
    // of radius r / tau around p / tau. w: from the cut-off disc's centre to v.
    const double wx = vx - px / tau, wy = vy - py / tau;
    const double w2 = wx * wx + wy * wy;
    const double wp = wx * px + wy * py;
    if (wp < 0 && wp * wp > r2 * w2) {
      // Nearest boundary point on the cut-off arc.
      const double wl = std::sqrt(w2);
      nx = wx / wl;
      ny = wy / wl;
      const double s = r / tau - wl;
      ux = s * nx;
      uy = s * ny;
    } else {
      // Nearest boundary point on a leg: the legs make the angle asin(r / |p|) with p.
      const double leg = std::sqrt(d2 - r2);
      double lx, ly;
      if (px * wy - py * wx > 0) {  // w is counter-clockwise of p: the left leg
        lx = (px * leg - py * r) / d2;
        ly = (px * r + py * leg) / d2;
        nx = -ly;  // outward: counter-clockwise of the left leg
        ny = lx;
      } else {  // the right leg
        lx = (px * leg + py * r) / d2;
        ly = (-px * r + py * leg) / d2;
        nx = ly;  // outward: clockwise of the right leg
        ny = -lx;
      }
      const double along = vx * lx + vy * ly;
      ux = along * lx - vx;
      uy = along * ly - vy;
    }
  } else {
    // Already overlapping: leave the disc of radius r / dt around p / dt (separate in one tick).
    const double wx = vx - px / dt, wy = vy - py / dt;
    const double wl = std::sqrt(wx * wx + wy * wy);
    if (wl > 0) {
      nx = wx / wl;
      ny = wy / wl;
    } else {  // coincident centres and velocities: any direction, deterministic
      nx = 1;
      ny = 0;
    }
    const double s = r / dt - wl;
    ux = s * nx;
    uy = s * ny;
  }
  return {vix + share * ux, viy + share * uy, nx, ny};
}

void agent_planes(const PlaneInputs& in, std::size_t m, double dt, double vix, double viy,
                  HalfPlane* out) {
  using B = xsimd::batch<double>;
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
    for (std::size_t l = 0; l < L; ++l) out[a + l] = {opx[l], opy[l], onx[l], ony[l]};
  }
  for (; a < m; ++a)  // the tail, one at a time
    out[a] = agent_plane(in.px[a], in.py[a], in.vx[a], in.vy[a], in.r[a], in.tau[a], dt, vix, viy,
                         in.share[a]);
}

}  // namespace crowddb::steer
