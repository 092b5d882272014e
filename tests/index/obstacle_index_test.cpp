#include "index/obstacle_index.hpp"

#include <gtest/gtest.h>

#include "index/collision_check.hpp"
#include "util/rng.hpp"

namespace crowddb::index {
namespace {

TEST(ObstacleIndex, EqualsTheOracleObstacleLoop) {
  for (const auto& c : test::collision_cases(3)) {
    for (const auto& [scene_name, scene] : test::collision_scenes(test::box_of(c.discs))) {
      SCOPED_TRACE(c.name + " / " + scene_name);
      const DiscView d = c.discs.view();
      std::vector<std::pair<uint32_t, Collider>> want, got;
      disc_obstacle_overlaps(d, scene, 0, d.n, want);
      QueryStats st;
      obstacle_overlaps(d, scene, Frame::of(d), got, st);
      EXPECT_TRUE(got == want) << got.size() << " vs " << want.size();
    }
  }
}

TEST(ObstacleIndex, ManySmallObstaclesAndDiscsOnTheirBoundaries) {
  Rng rng(4);
  std::vector<CircleObstacle> circles;
  std::vector<PolygonObstacle> polys;
  for (int i = 0; i < 300; ++i)
    circles.push_back({rng.uniform(0, 500), rng.uniform(0, 500), rng.uniform(0.5, 6), 1});
  for (int i = 0; i < 100; ++i) {
    const double x = rng.uniform(0, 500), y = rng.uniform(0, 500), s = rng.uniform(1, 10);
    polys.push_back({{{x, y}, {x + s, y}, {x + s, y + s}, {x, y + s}}, 1});
  }
  const Bounds bounds{0, 0, 500, 500};
  const StaticScene scene(circles, polys, 1, ObstacleCharges::centres, &bounds);
  DiscTable t = build::uniform(3000, build::Box{-5, -5, 505, 505}, 1, 0.5, 3, 9);
  // Discs exactly touching circle obstacles from outside (not a hit) and one ulp inside (a hit).
  for (int i = 0; i < 300; ++i) {
    const CircleObstacle& c = circles[i];
    const double r = 2;
    double x = c.x + c.radius + r;
    if (i % 2) x = std::nextafter(x, c.x);
    t.push_back(10000 + i, x, c.y, 0, 0, r);
  }
  const DiscView d = t.view();
  std::vector<std::pair<uint32_t, Collider>> want, got;
  disc_obstacle_overlaps(d, scene, 0, d.n, want);
  QueryStats st;
  obstacle_overlaps(d, scene, Frame::of(d), got, st);
  EXPECT_GT(want.size(), 500u);
  EXPECT_TRUE(got == want) << got.size() << " vs " << want.size();
  EXPECT_LT(st.pair_tests, d.n * 20);  // a handful of candidates per disc, not all 404 obstacles
}

// Discs of subnormal radii spread over less than 2^-1020: the grid's cell (an eighth of that) is
// then so small that 1 / cell overflows, and the queries must bin by the division (a product with
// +inf put every disc past 0 in the last cell: the middle disc, inside a small square, missed it).
TEST(ObstacleIndex, CellsTooSmallForAnInverseAnswerAsTheOracle) {
  const double a = 4e-309, b = 6e-309;
  const std::vector<PolygonObstacle> polys = {{{{a, a}, {b, a}, {b, b}, {a, b}}, 1}};
  const StaticScene scene({}, polys, 1, ObstacleCharges::none, nullptr);
  DiscTable t;
  t.push_back(1, 0, 5e-309, 0, 0, 1e-310);
  t.push_back(2, 5e-309, 5e-309, 0, 0, 1e-310);
  t.push_back(3, 1e-308, 5e-309, 0, 0, 1e-310);
  const DiscView d = t.view();
  std::vector<std::pair<uint32_t, Collider>> want, got;
  disc_obstacle_overlaps(d, scene, 0, d.n, want);
  QueryStats st;
  obstacle_overlaps(d, scene, Frame::of(d), got, st);
  ASSERT_EQ(want.size(), 1u);  // the middle disc, inside the square
  EXPECT_TRUE(got == want) << got.size() << " vs " << want.size();
}

}  // namespace
}  // namespace crowddb::index
