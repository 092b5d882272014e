// A scene's polygon tests through its edge grids (query/scene_polygons.hpp) against
// world/geometry.hpp's loops, and the collision query's obstacle half (index::ObstacleIndex) that
// uses them against the oracle loop, on polygons of many edges: stars of 64-3,000 vertices and a
// walkable hall's blocked piece, with discs on, just inside and just outside their edges.
#include "query/scene_polygons.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <numbers>
#include <vector>

#include "index/obstacle_index.hpp"
#include "query/ftc_geometry.hpp"
#include "query/naive_paths.hpp"
#include "support/polygons.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

using test::hall_piece;
using test::star;

// Discs anywhere near the polygons, and on, a hair inside and a hair outside their edges.
DiscTable discs_about(Rng& rng, const std::vector<PolygonObstacle>& polys, double lo, double hi) {
  DiscTable t;
  uint64_t id = 1;
  for (int k = 0; k < 2000; ++k)
    t.push_back(id++, rng.uniform(lo, hi), rng.uniform(lo, hi), 0, 0, rng.uniform(0.2, 3));
  for (const PolygonObstacle& p : polys)
    for (int k = 0; k < 300; ++k) {
      const std::size_t s = rng.below(p.vertices.size());
      const Vec2 &a = p.vertices[s], &b = p.vertices[(s + 1) % p.vertices.size()];
      const double u = rng.uniform(0, 1), ex = b.x - a.x, ey = b.y - a.y;
      const double len = std::hypot(ex, ey);
      if (len == 0) continue;
      const double r = rng.uniform(0.2, 3), off = r * (1 + rng.uniform(-1e-12, 1e-12));
      const double side = rng.below(2) ? 1 : -1;
      const double x = a.x + u * ex + side * off * -ey / len,
                   y = a.y + u * ey + side * off * ex / len;
      t.push_back(id++, rng.below(8) == 0 ? a.x : x, rng.below(8) == 0 ? a.y : y, 0, 0, r);
    }
  return t;
}

// Stars of the given sizes along the x axis (centres `spread` times their vertex count apart)
// and a hall's blocked piece above them.
std::vector<PolygonObstacle> stars_and_hall(Rng& rng, std::initializer_list<std::size_t> sizes,
                                            double spread) {
  std::vector<PolygonObstacle> polys;
  for (const std::size_t n : sizes)
    polys.push_back({star(rng, n, static_cast<double>(n) * spread, 0, 5, 40), 1});
  polys.push_back({hall_piece(4000, 0, 300, 120), 1});
  return polys;
}

TEST(ScenePolygons, TestsThroughTheEdgeGridsAreTheLoops) {
  Rng rng(61206);
  std::vector<PolygonObstacle> polys = stars_and_hall(rng, {64, 200, 3000}, 0.1);
  polys.push_back({{{0, -100}, {10, -100}, {10, -90}}, 1});  // few edges: the loops
  const StaticScene scene({}, polys, 1, ObstacleCharges::none, nullptr);
  for (std::size_t p = 0; p < 4; ++p) ASSERT_NE(scene.ring_grid(p), nullptr) << p;
  EXPECT_EQ(scene.ring_grid(4), nullptr);
  const DiscTable t = discs_about(rng, polys, -150, 450);
  for (std::size_t i = 0; i < t.x.size(); ++i)
    for (std::size_t p = 0; p < polys.size(); ++p) {
      const auto& ring = polys[p].vertices;
      const double x = t.x[i], y = t.y[i], r = t.radius[i];
      ASSERT_EQ(scene_polygon_holds(scene, p, x, y), point_in_polygon(ring, x, y)) << i << " " << p;
      ASSERT_EQ(scene_disc_hits_polygon(scene, p, x, y, r),
                disc_hits_polygon(polys[p], scene.polygon_boxes()[p], x, y, r))
          << i << " " << p;
      for (const double reach : {0.0, r, 50.0}) {
        Vec2 want_c{NAN, NAN}, got_c{NAN, NAN};
        const double want = dist2_to_boundary(ring, x, y, &want_c);
        const double got = scene_polygon_dist2(scene, p, x, y, reach, &got_c);
        ASSERT_EQ(got, want) << i << " " << p << " reach " << reach;
        ASSERT_EQ(got_c.x, want_c.x) << i << " " << p;
        ASSERT_EQ(got_c.y, want_c.y) << i << " " << p;
      }
    }
}

// Points as far from two parallel edges: the closest point is the first edge's in ring order,
// as the loop's (a grid keeping the last would pass the random probes, whose ties are at shared
// vertices, where both edges give the same point).
// Both ways round: the grid reads its rows bottom up, so with the bottom side first in the
// ring a grid keeping whichever tie it meets first would pass too.
TEST(ScenePolygons, TheClosestPointOfTiesIsTheFirstEdgesInRingOrder) {
  for (const bool bottom_first : {true, false}) {
    std::vector<Vec2> ring;  // a 100 x 2 strip, each long side in 50 pieces
    const double first_y = bottom_first ? 0 : 2, second_y = 2 - first_y;
    for (int k = 0; k <= 50; ++k) ring.push_back({2.0 * k, first_y});
    for (int k = 50; k >= 0; --k) ring.push_back({2.0 * k, second_y});
    const StaticScene scene({}, {{ring, 1}}, 1, ObstacleCharges::none, nullptr);
    ASSERT_NE(scene.ring_grid(0), nullptr);
    for (int k = 0; k < 97; ++k) {  // farther than 1 from the strip's ends
      const double x = 1.5 + k;
      Vec2 want_c{NAN, NAN}, got_c{NAN, NAN};
      const double want = dist2_to_boundary(ring, x, 1, &want_c);
      ASSERT_EQ(scene_polygon_dist2(scene, 0, x, 1, 1.5, &got_c), want) << x;
      ASSERT_EQ(want_c.y, first_y) << x;  // the first side's edges come first
      ASSERT_EQ(got_c.x, want_c.x) << x;
      ASSERT_EQ(got_c.y, want_c.y) << x << (bottom_first ? " bottom first" : " top first");
    }
  }
}

TEST(ScenePolygons, TheCollisionQuerysObstacleHalfIsTheOracleLoop) {
  Rng rng(1206);
  std::vector<PolygonObstacle> polys;
  for (int k = 0; k < 6; ++k)
    polys.push_back({star(rng, 64 + rng.below(2000), rng.uniform(0, 400), rng.uniform(0, 400), 3,
                          rng.uniform(10, 60)),
                     1});
  polys.push_back({hall_piece(5000, 200, 200, 150), 1});
  const Bounds bounds{-200, -200, 600, 600};
  const StaticScene scene({{50, 50, 4, 1}}, polys, 1, ObstacleCharges::none, &bounds);
  const DiscTable t = discs_about(rng, polys, -10, 410);
  const DiscView d = t.view();
  std::vector<std::pair<uint32_t, Collider>> want, got;
  disc_obstacle_overlaps(d, scene, 0, d.n, want);
  QueryStats st;
  index::obstacle_overlaps(d, scene, index::Frame::of(d), got, st);
  EXPECT_GT(want.size(), 1000u);
  EXPECT_TRUE(got == want) << got.size() << " vs " << want.size();
}

// First-to-collide's ray against a polygon (query/ftc_geometry.hpp): the grid's time is the
// loop's bit for bit where that is at most the cap, and above the cap otherwise.
TEST(ScenePolygons, RayTimesThroughTheEdgeGridsAreTheLoops) {
  Rng rng(2612);
  std::vector<PolygonObstacle> polys = stars_and_hall(rng, {64, 700, 3000}, 0.05);
  // Spikes: long edges whose boxes meet a slice of the path long before the edge is hit, while a
  // short edge just past the slice is hit first.
  std::vector<Vec2> spiky = star(rng, 600, 200, 100, 20, 22);
  for (std::size_t k = 0; k < spiky.size(); k += 23)
    spiky[k] = {200 + 4 * (spiky[k].x - 200), 100 + 4 * (spiky[k].y - 100)};
  polys.push_back({spiky, 1});
  const StaticScene scene({}, polys, 1, ObstacleCharges::none, nullptr);
  const DiscTable t = discs_about(rng, polys, -150, 450);
  std::size_t hits = 0, capped = 0;
  for (std::size_t i = 0; i < t.x.size(); ++i) {
    const double x = t.x[i], y = t.y[i];
    // Some discs wider than many cells (the slices then give up for the loop), some of negative
    // radius (the loop's answer, whatever it means).
    const double r = rng.below(20) == 0 ? 60 : rng.below(50) == 0 ? -t.radius[i] : t.radius[i];
    const double speed = rng.below(10) == 0 ? 0 : rng.below(10) == 0 ? 1e3 : rng.uniform(0.1, 5);
    const double a = rng.uniform(0, 2 * std::numbers::pi);
    double vx = speed * std::cos(a), vy = speed * std::sin(a);
    if (rng.below(4) == 0) vy = 0;  // along the lattice's horizontal edges
    for (std::size_t p = 0; p < polys.size(); ++p)
      for (const double horizon : {0.0, 2.0, 30.0, double(INFINITY)}) {
        const double want = ray_polygon_time(polys[p].vertices, x, y, vx, vy, r, horizon);
        for (const double cap :
             {double(INFINITY), horizon, rng.uniform(0, 30), 0.0, -1.0, double(NAN)}) {
          const double got = ray_polygon_time(scene, p, x, y, vx, vy, r, horizon, cap);
          if (want <= cap || std::isnan(cap)) {  // a NaN cap: no cap
            ASSERT_EQ(std::memcmp(&got, &want, sizeof got), 0)
                << i << " " << p << " horizon " << horizon << " cap " << cap << ": " << got
                << " vs " << want;
            hits += want < INFINITY && want > 0;
          } else {
            ASSERT_GT(got, cap) << i << " " << p << " horizon " << horizon << " want " << want;
            ++capped;
          }
        }
      }
  }
  EXPECT_GT(hits, 1000u);
  EXPECT_GT(capped, 1000u);
}

}  // namespace
}  // namespace crowddb
