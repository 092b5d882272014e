#include "steer/orca_planes.hpp"

#include <cmath>

#include "steer/orca_planes_lanes.hpp"
#include "util/cpu.hpp"

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

#if CROWDDB_PLANES_AVX2 && !XSIMD_WITH_AVX2
#define CROWDDB_PLANES_DISPATCH 1
// orca_planes_avx2.cpp: the lanes of AVX2, for a build whose own instruction set is narrower.
std::size_t agent_planes_avx2(const PlaneInputs& in, std::size_t m, double dt, double vix,
                              double viy, HalfPlane* out);
#endif

bool wider_plane_lanes() {
#if CROWDDB_PLANES_DISPATCH
  return cpu_has_avx2();
#else
  return false;
#endif
}

void agent_planes(const PlaneInputs& in, std::size_t m, double dt, double vix, double viy,
                  HalfPlane* out, PlaneLanes lanes) {
#if CROWDDB_PLANES_DISPATCH
  std::size_t a = wider_plane_lanes() && lanes == PlaneLanes::widest
                      ? agent_planes_avx2(in, m, dt, vix, viy, out)
                      : agent_planes_lanes<xsimd::default_arch>(in, m, dt, vix, viy, out);
#else
  (void)lanes;  // the build's lanes are the widest there are
  std::size_t a = agent_planes_lanes<xsimd::default_arch>(in, m, dt, vix, viy, out);
#endif
  for (; a < m; ++a)  // the tail, one at a time
    out[a] = agent_plane(in.px[a], in.py[a], in.vx[a], in.vy[a], in.r[a], in.tau[a], dt, vix, viy,
                         in.share[a]);
}

}  // namespace crowddb::steer
