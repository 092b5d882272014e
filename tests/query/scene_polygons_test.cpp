// A scene's polygon tests through its edge grids (query/scene_polygons.hpp) against
// world/geometry.hpp's loops, and the collision query's obstacle half (index::ObstacleIndex) that
// uses them against the oracle loop, on polygons of many edges: stars of 64-3,000 vertices and a
// walkable hall's blocked piece, with discs on, just inside and just outside their edges.
#include "query/scene_polygons.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "index/obstacle_index.hpp"
#include "query/naive_paths.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

std::vector<Vec2> star(Rng& rng, std::size_t n, double cx, double cy, double r0, double r1) {
  std::vector<Vec2> ring;
  for (std::size_t k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    const double r = rng.uniform(r0, r1);
    ring.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
  }
  return ring;
}

// A square of side 2 h around (cx, cy) less a wavy disc of n vertices inside it: the blocked
// piece of a hall drawn as a walkable area (one ring around, along the hole's border; a slit
// joins them, as the walkable areas' complement is cut).
std::vector<Vec2> hall_piece(std::size_t n, double cx, double cy, double h) {
  std::vector<Vec2> ring = {
      {cx + h, cy}, {cx + h, cy + h}, {cx - h, cy + h}, {cx - h, cy - h}, {cx + h, cy - h}};
  for (std::size_t k = 0; k <= n; ++k) {  // clockwise around the hole, back to its start
    const double a = -2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    const double r = 0.8 * h * (1 + 0.05 * std::sin(7 * a));
    ring.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
  }
  return ring;
}

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

TEST(ScenePolygons, TestsThroughTheEdgeGridsAreTheLoops) {
  Rng rng(61206);
  std::vector<PolygonObstacle> polys;
  for (const std::size_t n : {64, 200, 3000})
    polys.push_back({star(rng, n, static_cast<double>(n) * 0.1, 0, 5, 40), 1});
  polys.push_back({hall_piece(4000, 0, 300, 120), 1});
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

}  // namespace
}  // namespace crowddb
