// RingGrid (world/ring_grid.hpp) against geometry.hpp's loops over every edge, answer for answer:
// point in polygon, the boundary distance up to a reach, disc overlap; also through
// ObstacleLookup's polygon tests.
#include "world/ring_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "support/polygons.hpp"
#include "util/rng.hpp"
#include "world/obstacle_lookup.hpp"

namespace crowddb {
namespace {

using test::star;

// Points that stress the edge cases: on vertices, on edges' midpoints, on a vertex's horizontal
// line just left and right of it, a hair off an edge, far outside, and anywhere.
std::vector<Vec2> probes(Rng& rng, const std::vector<Vec2>& ring, double cx, double cy,
                         double span) {
  std::vector<Vec2> out;
  for (int q = 0; q < 400; ++q) {
    const Vec2& a = ring[rng.below(ring.size())];
    const Vec2& b = ring[rng.below(ring.size())];
    switch (q % 8) {
      case 0:
        out.push_back(a);
        break;
      case 1:
        out.push_back({(a.x + b.x) / 2, (a.y + b.y) / 2});
        break;
      case 2:
        out.push_back({a.x - rng.uniform(0, span), a.y});
        break;
      case 3:
        out.push_back({std::nextafter(a.x, -INFINITY), a.y});
        break;
      case 4: {
        const std::size_t k = rng.below(ring.size());
        const Vec2 &p = ring[k], &s = ring[(k + 1) % ring.size()];
        const double t = rng.uniform();
        out.push_back({std::nextafter(p.x + t * (s.x - p.x), INFINITY), p.y + t * (s.y - p.y)});
        break;
      }
      case 5:
        out.push_back({cx + rng.uniform(-20, 20) * span, cy + rng.uniform(-20, 20) * span});
        break;
      default:
        out.push_back({cx + rng.uniform(-1.2, 1.2) * span, cy + rng.uniform(-1.2, 1.2) * span});
    }
  }
  return out;
}

TEST(RingGrid, AnswersAreTheLoopsOverEveryEdge) {
  std::size_t inside = 0, near = 0, total = 0, by_strip = 0;
  for (const uint64_t seed : {1u, 2u, 3u, 4u}) {
    Rng rng(seed);
    for (const std::size_t n : {64u, 300u, 3000u}) {
      const double cx = rng.uniform(-1e3, 1e3), cy = rng.uniform(-1e3, 1e3);
      const double span = rng.uniform(1, 200);
      const std::vector<Vec2> ring = star(rng, n, cx, cy, span * 0.3, span);
      const RingGrid grid(ring);
      EXPECT_LE(grid.strip_entries(), 8 * n);
      for (const Vec2& p : probes(rng, ring, cx, cy, span)) {
        const bool in = point_in_polygon(ring, p.x, p.y);
        ASSERT_EQ(grid.inside(ring, p.x, p.y), in)
            << "seed " << seed << " n " << n << " at (" << p.x << ", " << p.y << ")";
        const double d2 = dist2_to_boundary(ring, p.x, p.y);
        for (const double reach : {0.0, 1e-9, span / 100, span / 3, 2 * span, 1e9}) {
          const double got = grid.dist2(ring, p.x, p.y, reach);
          if (d2 <= reach * reach)
            ASSERT_EQ(got, d2) << "seed " << seed << " n " << n << " reach " << reach;
          else
            ASSERT_GT(got, reach * reach) << "seed " << seed << " n " << n << " reach " << reach;
          ASSERT_EQ(grid.disc_overlaps(ring, p.x, p.y, reach),
                    disc_overlaps_polygon(ring, p.x, p.y, reach));
        }
        ++total;
        inside += in;
        by_strip += grid.strip_answers(p.y);
        near += d2 <= (span / 100) * (span / 100);
      }
    }
  }
  // The probes hit both sides and the boundary's neighbourhood.
  EXPECT_GT(inside, total / 5);
  EXPECT_LT(inside, total - total / 5);
  EXPECT_GT(near, total / 5);
  EXPECT_GT(by_strip, total / 2);  // stars: short strips answer most points
}

// A thin zigzag closed by one edge along its whole length: that edge spans more cells than an
// edge may be registered in and goes to the list every question scans, beside the grid.
TEST(RingGrid, LongEdgesAndHugeCoordinatesAreTheLoops) {
  Rng rng(7);
  std::vector<Vec2> ring;
  for (int k = 0; k <= 1000; ++k) ring.push_back({k * 0.1, k % 2 ? 1.0 : 0.5});
  ring.push_back({100, 0});
  ring.push_back({0, 0});
  const RingGrid grid(ring);
  EXPECT_EQ(grid.scanned_edges(), 1u);  // the long one; the others in cells
  std::size_t inside = 0;
  for (int q = 0; q < 20000; ++q) {
    const double x = rng.uniform(-5, 105);
    const double y = q % 4 == 0 ? 0 : (q % 4 == 1 ? 0.5 : rng.uniform(-1, 2));
    const bool in = point_in_polygon(ring, x, y);
    ASSERT_EQ(grid.inside(ring, x, y), in) << x << ", " << y;
    inside += in;
    const double d2 = dist2_to_boundary(ring, x, y);
    for (const double reach : {0.0, 0.05, 1.0}) {
      const double got = grid.dist2(ring, x, y, reach);
      if (d2 <= reach * reach)
        ASSERT_EQ(got, d2) << x << ", " << y;
      else
        ASSERT_GT(got, reach * reach) << x << ", " << y;
    }
  }
  EXPECT_GT(inside, 2000u);
  // The zigzag's strips between its teeth's heights list hundreds of edges: the row of cells
  // answers there.
  EXPECT_FALSE(grid.strip_answers(0.75));
  EXPECT_LE(grid.strip_entries(), 8 * ring.size());  // fewer strips where the edges climb far
  // A ring of another size than the grid's gets the loops.
  const std::vector<Vec2> other(ring.begin(), ring.begin() + 500);
  EXPECT_EQ(grid.inside(other, 20, 0.6), point_in_polygon(other, 20, 0.6));
  EXPECT_EQ(grid.dist2(other, 20, 0.6, 0), dist2_to_boundary(other, 20, 0.6));
  std::vector<Vec2> huge;
  for (int k = 0; k < 100; ++k)
    huge.push_back({k % 2 ? 1e308 : -1e308, static_cast<double>(k) * (k % 3 ? 1 : -1)});
  const RingGrid wide(huge);
  for (const double x : {-1e308, 0.0, 1e300})
    for (const double y : {-50.0, 0.5, 99.0})
      EXPECT_EQ(wide.inside(huge, x, y), point_in_polygon(huge, x, y));
}

// ObstacleLookup's polygon tests: the grid for rings with many edges, the loops for the rest.
TEST(RingGrid, ObstacleLookupsPolygonTestsAreTheLoops) {
  Rng rng(11);
  std::vector<PolygonObstacle> polys;
  polys.push_back({star(rng, 2000, 0, 0, 40, 60), 1});
  polys.push_back({{{70, 0}, {80, 0}, {80, 10}, {70, 10}}, 1});
  polys.push_back({star(rng, 500, 100, 100, 10, 30), 1});
  const std::vector<CircleObstacle> circles{{0, 100, 5, 1}};
  const ObstacleLookup lookup(circles, polys);
  // Without edge grids (a caller asking only for candidates): the same candidates, and the
  // polygon tests by the loops.
  const ObstacleLookup bare(circles, polys, ObstacleLookup::EdgeGrids::skip);
  std::vector<uint32_t> got, bare_got;
  for (int q = 0; q < 20000; ++q) {
    const double x = rng.uniform(-70, 140), y = rng.uniform(-70, 140), r = rng.uniform(0, 3);
    lookup.candidates(x, y, r, got);
    bare.candidates(x, y, r, bare_got);
    ASSERT_EQ(got, bare_got);
    for (std::size_t p = 0; p < polys.size(); ++p) {
      const auto& v = polys[p].vertices;
      ASSERT_EQ(bare.polygon_holds(p, v, x, y), point_in_polygon(v, x, y));
      ASSERT_EQ(lookup.polygon_holds(p, v, x, y), point_in_polygon(v, x, y));
      ASSERT_EQ(lookup.disc_overlaps_polygon(p, v, x, y, r), disc_overlaps_polygon(v, x, y, r));
      ASSERT_EQ(lookup.polygon_dist2(p, v, x, y, 0) > 0, dist2_to_boundary(v, x, y) > 0);
    }
  }
}

}  // namespace
}  // namespace crowddb
