// Hand-worked values of the naive access paths: the oracles must themselves be right.
#include "query/naive_paths.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <vector>

#include "query/ftc_geometry.hpp"
#include "scenario/builders.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

DiscTable two(double x1, double y1, double vx1, double vy1, double r1, double x2, double y2,
              double vx2, double vy2, double r2) {
  DiscTable t;
  t.push_back(1, x1, y1, vx1, vy1, r1);
  t.push_back(2, x2, y2, vx2, vy2, r2);
  return t;
}

TEST(RayDiscTime, HeadOnAndTangentAndReceding) {
  // gap 8 between rims, closing speed 2: t = 4
  EXPECT_DOUBLE_EQ(ray_disc_time(10, 0, -2, 0, 2, 30), 4.0);
  // already overlapping: 0
  EXPECT_EQ(ray_disc_time(1, 0, 5, 0, 2, 30), 0.0);
  // touching now and approaching: 0; touching now and receding: never
  EXPECT_EQ(ray_disc_time(2, 0, -1, 0, 2, 30), 0.0);
  EXPECT_EQ(ray_disc_time(2, 0, 1, 0, 2, 30), INFINITY);
  // grazing: closest approach exactly R is not a collision
  EXPECT_EQ(ray_disc_time(10, 2, -1, 0, 2, 30), INFINITY);
  // beyond the horizon
  EXPECT_EQ(ray_disc_time(100, 0, -1, 0, 2, 30), INFINITY);
  EXPECT_DOUBLE_EQ(ray_disc_time(100, 0, -1, 0, 2, 98), 98.0);
  // no relative motion
  EXPECT_EQ(ray_disc_time(10, 0, 0, 0, 2, 30), INFINITY);
}

TEST(RayPolygonTime, EntersThroughAnEdgeAndACorner) {
  const std::vector<Vec2> square{{0, 0}, {10, 0}, {10, 10}, {0, 10}};
  // centre at x = -5 moving +x with radius 1: touches the edge x = 0 when the centre reaches -1
  EXPECT_DOUBLE_EQ(ray_polygon_time(square, -5, 5, 1, 0, 1, 30), 4.0);
  // diagonal approach to the corner (0, 0) from (-3, -3): the disc meets the corner first
  const double t = ray_polygon_time(square, -3, -3, 1, 1, 1, 30);
  EXPECT_NEAR(t, 3 - 1 / std::sqrt(2.0), 1e-12);
  // inside: 0; moving away: never
  EXPECT_EQ(ray_polygon_time(square, 5, 5, 0, 0, 1, 30), 0.0);
  EXPECT_EQ(ray_polygon_time(square, -5, 5, -1, 0, 1, 30), INFINITY);
}

TEST(FtcNaive, AgentsBeatObstaclesAtEqualTimes) {
  // Agent 5 moves right; agent 9 stands where a circle obstacle stands: both are met at t = 8.
  DiscTable t;
  t.push_back(5, 0, 0, 1, 0, 1);
  t.push_back(9, 10, 0, 0, 0, 1);
  StaticScene scene({{10, 0, 1, 1}}, {}, 1);
  Executor ex(1);
  QueryStats st;
  std::vector<FtcHit> out(2);
  FtcNaive().run(t.view(), scene, 30, out, ex, st);
  EXPECT_EQ(out[0].with.kind, Collider::Kind::agent);
  EXPECT_EQ(out[0].with.row, 1u);
  EXPECT_DOUBLE_EQ(out[0].time, 8.0);
  // Agent 9 overlaps the obstacle now (t = 0) and is met by agent 5 only later.
  EXPECT_EQ(out[1].with.kind, Collider::Kind::circle);
  EXPECT_EQ(out[1].time, 0.0);
}

TEST(FtcNaive, EqualTimesPickTheSmallerId) {
  DiscTable t;
  t.push_back(50, 0, 0, 0, 0, 1);
  t.push_back(40, 10, 0, -1, 0, 1);  // reaches agent 50 at t = 8
  t.push_back(30, -10, 0, 1, 0, 1);  // reaches agent 50 at t = 8 too
  Executor ex(1);
  QueryStats st;
  std::vector<FtcHit> out(3);
  FtcNaive().run(t.view(), StaticScene(), 30, out, ex, st);
  EXPECT_EQ(t.id[out[0].with.row], 30u);
  EXPECT_DOUBLE_EQ(out[0].time, 8.0);
}

TEST(FieldNaive, SixFunctionsOnTwoPoints) {
  const DiscTable t = two(0, 0, 0, 0, 1, 3, 4, 0, 0, 1);
  Executor ex(1);
  QueryStats st;
  struct Case {
    Kernel k;
    Metric m;
    double d;         // distance
    double ddx, ddy;  // gradient of d w.r.t. p at agent 1 (dx = -3, dy = -4)
  };
  const double l2x = -3.0 / 5, l2y = -4.0 / 5;
  // radial, m = 2: frames 0 and pi/4. Frame 0: |dx| + |dy| = 7; frame 1: u = (dx+dy)/sqrt2,
  // w = (dy-dx)/sqrt2 -> |u| + |w| = (7 + 1)/sqrt2.
  const double s2 = std::sqrt(2.0);
  const double radial = std::numbers::pi / 8 * (7 + 8 / s2);
  // d/dx: frame 0: sign(dx) = -1; frame 1: sign(u) cos - sign(w) sin = (-1)(1/s2) - (-1)(1/s2) = 0
  // d/dy: frame 0: -1; frame 1: sign(u) sin + sign(w) cos = (-1)(1/s2) + (-1)(1/s2) = -s2
  const double rdx = std::numbers::pi / 8 * (-1 + 0), rdy = std::numbers::pi / 8 * (-1 - s2);
  const Case cases[] = {{Kernel::exp, Metric::l1, 7, -1, -1},
                        {Kernel::exp, Metric::l2, 5, l2x, l2y},
                        {Kernel::exp, Metric::radial, radial, rdx, rdy},
                        {Kernel::inv, Metric::l1, 7, -1, -1},
                        {Kernel::inv, Metric::l2, 5, l2x, l2y},
                        {Kernel::inv, Metric::radial, radial, rdx, rdy}};
  for (const Case& c : cases) {
    PotentialSpec spec;
    spec.kernel = c.k;
    spec.metric = c.m;
    spec.A = 2;
    spec.k = 0.5;
    FieldColumns f;
    FieldNaive().run(t.view(), StaticScene(), spec, f, ex, st);
    const double K = c.k == Kernel::exp ? std::exp(-0.5 * c.d) : 1 / c.d;
    const double dK = c.k == Kernel::exp ? -0.5 * K : -1 / (c.d * c.d);
    EXPECT_NEAR(f.potential[0], 2 * K, 1e-12);
    EXPECT_NEAR(f.grad_x[0], 2 * dK * c.ddx, 1e-12);
    EXPECT_NEAR(f.grad_y[0], 2 * dK * c.ddy, 1e-12);
    // symmetric partner
    EXPECT_NEAR(f.potential[1], f.potential[0], 1e-12);
    EXPECT_NEAR(f.grad_x[1], -f.grad_x[0], 1e-12);
  }
}

TEST(FieldNaive, CoincidentPointsContributeWithZeroGradientAndInvIsFloored) {
  const DiscTable t = two(1, 1, 0, 0, 1, 1, 1, 0, 0, 1);
  Executor ex(1);
  QueryStats st;
  PotentialSpec spec;
  spec.A = 1;
  FieldColumns f;
  FieldNaive().run(t.view(), StaticScene(), spec, f, ex, st);
  EXPECT_EQ(f.potential[0], 1.0);  // e^0
  EXPECT_EQ(f.grad_x[0], 0.0);
  EXPECT_EQ(f.grad_y[0], 0.0);
  spec.kernel = Kernel::inv;
  spec.metric = Metric::l2;
  spec.inv_floor = 0.25;
  FieldNaive().run(t.view(), StaticScene(), spec, f, ex, st);
  EXPECT_EQ(f.potential[0], 4.0);
  EXPECT_TRUE(std::isfinite(f.grad_x[0]));
}

TEST(FieldNaive, ChargedPointsOfObstaclesCount) {
  DiscTable t;
  t.push_back(1, 0, 0, 0, 0, 1, 2.0);  // charge 2
  StaticScene scene({{3, 0, 0.5, 3.0}}, {}, 1.0,
                    ObstacleCharges::centres);  // one point of charge 3
  PotentialSpec spec;
  spec.A = 1;
  spec.k = 1;
  FieldColumns f;
  Executor ex(1);
  QueryStats st;
  FieldNaive().run(t.view(), scene, spec, f, ex, st);
  EXPECT_NEAR(f.potential[0], 6 * std::exp(-3.0), 1e-15);
  EXPECT_NEAR(f.grad_x[0], 6 * std::exp(-3.0), 1e-15);  // -k * sign(0 - 3) * F
}

TEST(CollisionNaive, TouchingIsNotOverlappingAndObstaclesCount) {
  DiscTable t;
  t.push_back(1, 0, 0, 0, 0, 1);
  t.push_back(2, 1.5, 0, 0, 0, 1);
  t.push_back(3, 10, 0, 0, 0, 1);
  t.push_back(4, 12, 0, 0, 0, 1);   // touches 3 exactly
  t.push_back(5, 30, 0, 0, 0, 1);   // overlaps the polygon
  t.push_back(6, 50, 50, 0, 0, 1);  // overlaps the circle
  const std::vector<PolygonObstacle> polys{{{{30.5, -1}, {35, -1}, {35, 1}, {30.5, 1}}, 1}};
  StaticScene scene({{52, 50, 1.5, 1}}, polys, 1);
  CollisionPairs pairs;
  Executor ex(1);
  QueryStats st;
  CollisionNaive().run(t.view(), scene, pairs, ex, st);
  ASSERT_EQ(pairs.agents.size(), 1u);
  EXPECT_EQ(pairs.agents[0], (std::pair<uint32_t, uint32_t>{0, 1}));
  ASSERT_EQ(pairs.obstacles.size(), 2u);
  EXPECT_EQ(pairs.obstacles[0].first, 4u);
  EXPECT_EQ(pairs.obstacles[0].second.kind, Collider::Kind::polygon);
  EXPECT_EQ(pairs.obstacles[1].first, 5u);
  EXPECT_EQ(pairs.obstacles[1].second.kind, Collider::Kind::circle);
}

TEST(NaivePaths, OutputDoesNotDependOnThreadCount) {
  const DiscTable t = build::uniform(700, {}, 50, 1, 3, 17);
  StaticScene scene({{100, 100, 20, 1}, {300, 200, 10, 2}}, {}, 1);
  Executor one(1), two_threads(2);
  QueryStats st;
  std::vector<FtcHit> h1(t.size()), h2(t.size());
  FtcNaive().run(t.view(), scene, 30, h1, one, st);
  FtcNaive().run(t.view(), scene, 30, h2, two_threads, st);
  EXPECT_EQ(h1, h2);
  FieldColumns f1, f2;
  FieldNaive().run(t.view(), scene, PotentialSpec{}, f1, one, st);
  FieldNaive().run(t.view(), scene, PotentialSpec{}, f2, two_threads, st);
  EXPECT_EQ(f1.potential, f2.potential);
  EXPECT_EQ(f1.grad_x, f2.grad_x);
  CollisionPairs c1, c2;
  CollisionNaive().run(t.view(), scene, c1, one, st);
  CollisionNaive().run(t.view(), scene, c2, two_threads, st);
  EXPECT_EQ(c1.agents, c2.agents);
  EXPECT_EQ(c1.obstacles.size(), c2.obstacles.size());
}

// An unbounded list (k = 0) comes out in (dist2, id) order: up to kRankSort entries it is
// sorted by counting ranks, beyond by std::sort; both against std::sort of the same candidates.
// Distances drawn from a few values tie often (the ids settle them), and equal (dist2, id) keys
// (which the rank count cannot place) fall back to std::sort.
TEST(NearestK, UnboundedListsComeOutSortedByDistanceThenId) {
  Rng rng(42);
  // The sizes at the rank sort's edges first (one, two, odd, 63-65), then random ones.
  const std::size_t edges[] = {1, 2, 3, 63, 64, 65, 1, 2, 3, 63, 64, 65};
  for (int round = 0; round < 412; ++round) {
    const std::size_t m = round < 12 ? edges[round] : 1 + rng.below(round % 4 == 0 ? 100 : 66);
    const bool ties = round % 3 == 0 || (round >= 6 && round < 12), twins = round % 17 == 0;
    // Zeros of both signs and infinite distances now and then (they tie as std::sort ties them).
    const auto special = [&](double d2) {
      switch (rng.below(16)) {
        case 0:
          return 0.0;
        case 1:
          return -0.0;
        case 2:
          return static_cast<double>(INFINITY);
        default:
          return d2;
      }
    };
    std::vector<std::tuple<double, uint64_t, uint32_t>> want;
    NearestK best;
    best.reset(0);
    for (std::size_t a = 0; a < m; ++a) {
      const double d2 = special(ties ? static_cast<double>(rng.below(4)) : rng.uniform(0, 9));
      uint64_t id = rng.below(1u << 30);
      if (twins && a > 0 && a % 5 == 0) id = std::get<1>(want[a - 1]);
      const double key = twins && a > 0 && a % 5 == 0 ? std::get<0>(want[a - 1]) : d2;
      want.emplace_back(key, id, static_cast<uint32_t>(a));
      best.offer(static_cast<uint32_t>(a), id, key);
    }
    best.finish();
    std::sort(want.begin(), want.end(), [](const auto& p, const auto& q) {
      return std::get<0>(p) < std::get<0>(q) ||
             (std::get<0>(p) == std::get<0>(q) && std::get<1>(p) < std::get<1>(q));
    });
    ASSERT_EQ(best.size(), m);
    for (std::size_t a = 0; a < m; ++a) {
      EXPECT_EQ(best.dist2()[a], std::get<0>(want[a])) << "round " << round << " entry " << a;
      // Equal keys may come in either order (std::sort is not stable): then only the key counts.
      const auto same = [&](std::size_t b) {
        return std::get<0>(want[b]) == std::get<0>(want[a]) &&
               std::get<1>(want[b]) == std::get<1>(want[a]);
      };
      const bool twin = (a > 0 && same(a - 1)) || (a + 1 < m && same(a + 1));
      if (!twin) {
        EXPECT_EQ(best.rows()[a], std::get<2>(want[a])) << "round " << round << " entry " << a;
      }
    }
  }
}

TEST(Registry, UnknownMethodIsAUsageErrorListingTheChoices) {
  try {
    find_ftc_method("bogus");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.exit_code(), 2);
    EXPECT_NE(std::string(e.what()).find("naive"), std::string::npos);
  }
  EXPECT_EQ(choose_ftc_method(0).info.name, "naive");
}

}  // namespace
}  // namespace crowddb
