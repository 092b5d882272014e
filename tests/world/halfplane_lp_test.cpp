#include "world/halfplane_lp.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "util/rng.hpp"

namespace crowddb {
namespace {

double violation(const HalfPlane& h, double x, double y) {
  return -((x - h.px) * h.nx + (y - h.py) * h.ny);
}

HalfPlane random_plane(Rng& rng, double spread) {
  const double a = rng.uniform(0, 2 * std::numbers::pi);
  return {rng.uniform(-spread, spread), rng.uniform(-spread, spread), std::cos(a), std::sin(a)};
}

// The oracle of the 2-D program: the optimum of a convex quadratic over (disc intersect
// half-planes) is the preferred velocity itself, its projection on one line, on the circle, or a
// vertex (two lines, or a line and the circle). Enumerate every candidate, keep the feasible
// nearest.
struct Oracle {
  bool feasible = false;
  double x = 0, y = 0, d2 = INFINITY;
};
Oracle brute_force(const std::vector<HalfPlane>& p, double R, double px, double py) {
  Oracle best;
  auto consider = [&](double x, double y) {
    if (x * x + y * y > R * R * (1 + 1e-9)) return;
    for (const HalfPlane& h : p)
      if (violation(h, x, y) > 1e-9) return;
    const double d2 = (x - px) * (x - px) + (y - py) * (y - py);
    if (d2 < best.d2) best = {true, x, y, d2};
  };
  consider(px, py);
  const double l = std::hypot(px, py);
  if (l > 0) consider(px * R / l, py * R / l);
  for (std::size_t i = 0; i < p.size(); ++i) {
    const HalfPlane& a = p[i];
    const double dx = -a.ny, dy = a.nx;
    const double t = (px - a.px) * dx + (py - a.py) * dy;
    consider(a.px + t * dx, a.py + t * dy);
    const double pd = a.px * dx + a.py * dy, c = a.px * a.px + a.py * a.py - R * R;
    const double disc = pd * pd - c;
    if (disc >= 0)
      for (double s : {-1.0, 1.0}) {
        const double u = -pd + s * std::sqrt(disc);
        consider(a.px + u * dx, a.py + u * dy);
      }
    for (std::size_t j = i + 1; j < p.size(); ++j) {
      const HalfPlane& b = p[j];
      const double det = a.nx * b.ny - a.ny * b.nx;
      if (std::abs(det) < 1e-12) continue;
      const double ca = a.px * a.nx + a.py * a.ny, cb = b.px * b.nx + b.py * b.ny;
      consider((ca * b.ny - cb * a.ny) / det, (a.nx * cb - b.nx * ca) / det);
    }
  }
  return best;
}

TEST(HalfPlaneLp, FeasibleProgramsMatchTheBruteForceOptimum) {
  Rng rng(17);
  int feasible = 0;
  for (int c = 0; c < 4000; ++c) {
    const double R = rng.uniform(0.5, 3);
    std::vector<HalfPlane> p;
    const std::size_t m = rng.below(12);
    for (std::size_t i = 0; i < m; ++i) p.push_back(random_plane(rng, R));
    const double px = rng.uniform(-2 * R, 2 * R), py = rng.uniform(-2 * R, 2 * R);
    const Oracle o = brute_force(p, R, px, py);
    const LpResult r = solve_velocity_lp(p, 0, R, px, py);
    ASSERT_EQ(r.feasible, o.feasible) << "case " << c;
    EXPECT_LE(r.vx * r.vx + r.vy * r.vy, R * R * (1 + 1e-9));
    if (!o.feasible) continue;
    ++feasible;
    for (const HalfPlane& h : p) EXPECT_LE(violation(h, r.vx, r.vy), 1e-9) << "case " << c;
    EXPECT_NEAR(r.vx, o.x, 1e-7) << "case " << c;
    EXPECT_NEAR(r.vy, o.y, 1e-7) << "case " << c;
  }
  EXPECT_GT(feasible, 1000);  // both kinds are well represented
  EXPECT_LT(feasible, 3800);
}

// Normals from eight compass directions only: many lines parallel or opposite (a line lying
// outside a parallel plane has no room at all), as duplicated or mirrored planes give in a crowd.
TEST(HalfPlaneLp, ProgramsWithParallelLinesMatchTheBruteForceOptimum) {
  Rng rng(29);
  int feasible = 0, infeasible = 0;
  for (int c = 0; c < 4000; ++c) {
    const double R = rng.uniform(0.5, 3);
    std::vector<HalfPlane> p;
    const std::size_t m = 2 + rng.below(8);
    for (std::size_t i = 0; i < m; ++i) {
      const double a = static_cast<double>(rng.below(8)) * std::numbers::pi / 4;
      p.push_back({rng.uniform(-R, R), rng.uniform(-R, R), std::cos(a), std::sin(a)});
    }
    const double px = rng.uniform(-2 * R, 2 * R), py = rng.uniform(-2 * R, 2 * R);
    const Oracle o = brute_force(p, R, px, py);
    const LpResult r = solve_velocity_lp(p, 0, R, px, py);
    ASSERT_EQ(r.feasible, o.feasible) << "case " << c;
    if (!o.feasible) {
      ++infeasible;
      continue;
    }
    ++feasible;
    for (const HalfPlane& h : p) EXPECT_LE(violation(h, r.vx, r.vy), 1e-9) << "case " << c;
    EXPECT_NEAR(r.vx, o.x, 1e-7) << "case " << c;
    EXPECT_NEAR(r.vy, o.y, 1e-7) << "case " << c;
  }
  EXPECT_GT(feasible, 1000);
  EXPECT_GT(infeasible, 1000);
}

// Infeasible programs: the hard planes hold, and the largest violation of the soft ones is
// no worse than the best a fine search of the disc finds (the 3-D program's optimum).
TEST(HalfPlaneLp, InfeasibleProgramsKeepTheHardPlanesAndMinimiseTheWorstViolation) {
  Rng rng(23);
  int checked = 0;
  for (int c = 0; c < 400; ++c) {
    const double R = 1.5;
    std::vector<HalfPlane> p;
    // Hard planes zero satisfies (as the model builds them), then soft ones that conflict.
    const std::size_t hard = rng.below(4);
    for (std::size_t i = 0; i < hard; ++i) {
      HalfPlane h = random_plane(rng, 1);
      const double off = -rng.uniform(0, 1);  // v . n >= off: zero is inside
      h.px = h.nx * off;
      h.py = h.ny * off;
      p.push_back(h);
    }
    for (int i = 0; i < 3 + static_cast<int>(rng.below(6)); ++i) p.push_back(random_plane(rng, 2));
    const LpResult r = solve_velocity_lp(p, hard, R, rng.uniform(-1, 1), rng.uniform(-1, 1));
    if (r.feasible) continue;
    ++checked;
    for (std::size_t i = 0; i < hard; ++i) EXPECT_LE(violation(p[i], r.vx, r.vy), 1e-9);
    auto worst = [&](double x, double y) {
      double w = 0;
      for (std::size_t i = hard; i < p.size(); ++i) w = std::max(w, violation(p[i], x, y));
      return w;
    };
    double best = INFINITY;
    for (int a = 0; a < 300; ++a)
      for (int b = 0; b < 300; ++b) {
        const double x = -R + 2 * R * a / 299.0, y = -R + 2 * R * b / 299.0;
        if (x * x + y * y > R * R) continue;
        bool ok = true;
        for (std::size_t i = 0; i < hard && ok; ++i) ok = violation(p[i], x, y) <= 0;
        if (ok) best = std::min(best, worst(x, y));
      }
    // The grid step is 0.01: the grid's best is at most ~0.015 worse than the true optimum.
    EXPECT_LE(worst(r.vx, r.vy), best + 1e-6) << "case " << c;
  }
  EXPECT_GT(checked, 100);
}

TEST(HalfPlaneLp, NoPlanesGivesThePreferredVelocityClippedToTheSpeed) {
  const LpResult a = solve_velocity_lp({}, 0, 2, 1, 1);
  EXPECT_EQ(a.vx, 1);
  EXPECT_EQ(a.vy, 1);
  const LpResult b = solve_velocity_lp({}, 0, 1, 3, 4);
  EXPECT_NEAR(b.vx, 0.6, 1e-15);
  EXPECT_NEAR(b.vy, 0.8, 1e-15);
}

}  // namespace
}  // namespace crowddb
