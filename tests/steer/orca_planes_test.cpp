// ORCA's agent planes built several at a time (agent_planes, xsimd) against the reference built
// one at a time (agent_plane): the same planes to the bit, on random neighbours in every case the
// construction distinguishes (the cut-off arc, either leg, overlapping, coincident), for every
// count of neighbours (so that whole batches and the tail both run), in the build's own lanes and
// in the widest the CPU has (AVX2's, chosen at run time in a default build).
#include "steer/orca_planes.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cstdint>
#include <iostream>
#include <vector>

#include "util/rng.hpp"

namespace crowddb::steer {
namespace {

bool same_bits(double a, double b) {
  return std::bit_cast<uint64_t>(a) == std::bit_cast<uint64_t>(b);
}

struct Columns {
  std::vector<double> px, py, vx, vy, r, tau, share;
  PlaneInputs view() const {
    return {px.data(), py.data(), vx.data(), vy.data(), r.data(), tau.data(), share.data()};
  }
};

// Which case of the construction a neighbour falls in (the reference's branches, restated).
enum Case { kArc, kLeftLeg, kRightLeg, kOverlap, kCoincident, kCases };
Case case_of(double px, double py, double vx, double vy, double r, double tau, double dt) {
  const double d2 = px * px + py * py, r2 = r * r;
  if (!(d2 > r2)) {
    const double wx = vx - px / dt, wy = vy - py / dt;
    return wx * wx + wy * wy > 0 ? kOverlap : kCoincident;
  }
  const double wx = vx - px / tau, wy = vy - py / tau;
  const double w2 = wx * wx + wy * wy, wp = wx * px + wy * py;
  if (wp < 0 && wp * wp > r2 * w2) return kArc;
  return px * wy - py * wx > 0 ? kLeftLeg : kRightLeg;
}

TEST(OrcaPlanes, BatchMatchesTheReferenceBitForBit) {
  Rng rng(20261201);
  int seen[kCases] = {};
  const double dt = 0.1;
  for (int trial = 0; trial < 4000; ++trial) {
    const std::size_t m = static_cast<std::size_t>(trial % 24);
    Columns c;
    for (std::size_t a = 0; a < m; ++a) {
      const double r = rng.uniform(0.3, 0.8);
      double px, py, vx, vy;
      switch (rng.below(5)) {
        case 0:  // anywhere within 6 m, any velocity
          px = rng.uniform(-6, 6), py = rng.uniform(-6, 6);
          vx = rng.uniform(-3, 3), vy = rng.uniform(-3, 3);
          break;
        case 1:  // just outside contact, closing in (the arc)
          px = r * 1.05, py = rng.uniform(-0.05, 0.05);
          vx = rng.uniform(2, 8), vy = rng.uniform(-0.5, 0.5);
          break;
        case 2:  // overlapping
          px = rng.uniform(-r, r) * 0.7, py = rng.uniform(-r, r) * 0.7;
          vx = rng.uniform(-2, 2), vy = rng.uniform(-2, 2);
          break;
        case 3:  // coincident centres, equal velocities
          px = py = vx = vy = 0;
          break;
        default:  // exact grid values: ties, zeros, axis-parallel
          px = static_cast<double>(rng.below(9)) - 4, py = static_cast<double>(rng.below(9)) - 4;
          vx = static_cast<double>(rng.below(5)) - 2, vy = static_cast<double>(rng.below(5)) - 2;
          break;
      }
      c.px.push_back(px);
      c.py.push_back(py);
      c.vx.push_back(vx);
      c.vy.push_back(vy);
      c.r.push_back(r);
      c.tau.push_back(rng.below(4) == 0 ? dt : rng.uniform(dt, 5));
      c.share.push_back(rng.below(2) ? 0.5 : rng.uniform(0, 1));
    }
    const double vix = rng.uniform(-2, 2), viy = rng.uniform(-2, 2);
    std::vector<HalfPlane> batch(m), build(m);
    agent_planes(c.view(), m, dt, vix, viy, batch.data());  // the widest lanes there are
    agent_planes(c.view(), m, dt, vix, viy, build.data(), PlaneLanes::build);
    for (std::size_t a = 0; a < m; ++a) {
      const HalfPlane& own = build[a];
      const HalfPlane& wide = batch[a];
      ASSERT_TRUE(same_bits(own.px, wide.px) && same_bits(own.py, wide.py) &&
                  same_bits(own.nx, wide.nx) && same_bits(own.ny, wide.ny))
          << "trial " << trial << " neighbour " << a << ": the build's lanes and the widest differ";
    }
    for (std::size_t a = 0; a < m; ++a) {
      ++seen[case_of(c.px[a], c.py[a], c.vx[a], c.vy[a], c.r[a], c.tau[a], dt)];
      const HalfPlane ref = agent_plane(c.px[a], c.py[a], c.vx[a], c.vy[a], c.r[a], c.tau[a], dt,
                                        vix, viy, c.share[a]);
      const HalfPlane& got = batch[a];
      ASSERT_TRUE(same_bits(got.px, ref.px) && same_bits(got.py, ref.py) &&
                  same_bits(got.nx, ref.nx) && same_bits(got.ny, ref.ny))
          << "trial " << trial << " neighbour " << a << " of " << m << ": p (" << c.px[a] << ", "
          << c.py[a] << ") v (" << c.vx[a] << ", " << c.vy[a] << ") r " << c.r[a] << " tau "
          << c.tau[a] << ": batch (" << got.px << ", " << got.py << ", " << got.nx << ", " << got.ny
          << ") reference (" << ref.px << ", " << ref.py << ", " << ref.nx << ", " << ref.ny << ")";
    }
  }
  // Every case was met often enough to mean something.
  for (int k = 0; k < kCases; ++k) EXPECT_GT(seen[k], 500) << "case " << k;
  // Without wider lanes (no AVX2 here, or a build whose own are that wide) both PlaneLanes are
  // the same code, and the comparison between them above shows nothing: said, not hidden.
  if (!wider_plane_lanes()) std::cout << "[ note ] no lanes wider than the build's on this CPU\n";
#if CROWDDB_TEST_AVX2_DISPATCH && !defined(__AVX2__)
  // The AVX2 copy is in the build (whose own lanes are narrower): it must be the one taken
  // where the CPU has AVX2.
  EXPECT_EQ(wider_plane_lanes(), __builtin_cpu_supports("avx2") != 0);
#endif
}

}  // namespace
}  // namespace crowddb::steer
