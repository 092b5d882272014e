#include "index/feature_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "query/naive_paths.hpp"
#include "scenario/builders.hpp"
#include "util/rng.hpp"

namespace crowddb::index {
namespace {

FeatureLists run(FeaturePath& p, const DiscView& d, std::span<const double> reach,
                 const StaticScene& s, int threads = 1) {
  Executor ex(threads);
  QueryStats st;
  FeatureLists out;
  p.run(d, reach, s, out, ex, st);
  return out;
}

void expect_same(const FeatureLists& a, const FeatureLists& b) {
  ASSERT_EQ(a.offset, b.offset);
  EXPECT_EQ(a.feature, b.feature);
  EXPECT_EQ(a.dist2, b.dist2);
}

// A scene of random circles, thin walls, long diagonal walls and star-shaped polygons.
StaticScene random_scene(Rng& rng, double side, bool walls) {
  std::vector<CircleObstacle> circles;
  std::vector<PolygonObstacle> polys;
  for (int i = 0; i < 12; ++i)
    circles.push_back(
        {rng.uniform(0, side), rng.uniform(0, side), rng.uniform(0.05, side / 20), 1});
  for (int i = 0; i < 6; ++i) {  // a diagonal wall, a rotated thin rectangle
    const double x = rng.uniform(0, side), y = rng.uniform(0, side);
    const double a = rng.uniform(0, 3.14), len = rng.uniform(side / 10, side), w = 0.2;
    const double c = std::cos(a), s = std::sin(a);
    polys.push_back({{{x, y},
                      {x + c * len, y + s * len},
                      {x + c * len - s * w, y + s * len + c * w},
                      {x - s * w, y + c * w}},
                     1});
  }
  for (int i = 0; i < 4; ++i) {  // a star
    const double cx = rng.uniform(0, side), cy = rng.uniform(0, side), r = rng.uniform(1, side / 8);
    std::vector<Vec2> v;
    for (int k = 0; k < 10; ++k) {
      const double a = k * 3.14159265 / 5, rr = k % 2 ? r : r / 3;
      v.push_back({cx + rr * std::cos(a), cy + rr * std::sin(a)});
    }
    polys.push_back({v, 1});
  }
  const Bounds b{0, 0, side, side};
  return StaticScene(circles, polys, 1, ObstacleCharges::none, walls ? &b : nullptr);
}

TEST(FeatureGrid, EqualsNaiveOnRandomScenes) {
  Rng rng(3);
  FeatureNaive naive;
  for (int c = 0; c < 30; ++c) {
    const double side = rng.uniform(10, 400);
    const StaticScene scene = random_scene(rng, side, c % 2 == 0);
    DiscTable pts = build::uniform(200, {-side / 4, -side / 4, side * 1.25, side * 1.25}, 0, 0.1,
                                   0.3, 50 + static_cast<uint64_t>(c));
    std::vector<double> reach(pts.size());
    for (double& r : reach) r = rng.below(10) == 0 ? 0 : side * std::pow(10, rng.uniform(-3, -0.3));
    SCOPED_TRACE("case " + std::to_string(c));
    FeatureGrid grid;  // fresh: its cell follows the first query's reach
    const FeatureLists want = run(naive, pts.view(), reach, scene);
    expect_same(run(grid, pts.view(), reach, scene), want);
    expect_same(run(grid, pts.view(), reach, scene, 3), want);
    // The same grid, other reaches: the cell size was chosen for the first ones.
    for (double& r : reach) r *= 7;
    expect_same(run(grid, pts.view(), reach, scene), run(naive, pts.view(), reach, scene));
  }
}

// Far from every feature a query ends at its cell's distance to the nearest feature cell. The
// grid's cell is set by a first query of one point (its reach); then points at every distance
// from a circle and from a diagonal wall, in steps finer than a cell, ask for a reach a hair
// above or below that distance, so the feature is just in or just out of reach and their cells
// lie at every Chebyshev distance from the features' cells; and points beyond the grid's box.
// Skipping a cell early (the bound m instead of m - 1) fails it.
TEST(FeatureGrid, SkipsOnlyWhatIsOutOfReach) {
  const std::vector<CircleObstacle> circles = {{50, 50, 0.5, 1}};
  const std::vector<PolygonObstacle> polys = {
      {{{10, 80}, {80, 10}, {80.2, 10.2}, {10.2, 80.2}}, 1}};
  const StaticScene scene(circles, polys, 1, ObstacleCharges::none, nullptr);
  FeatureNaive naive;
  for (double cell : {0.3, 1.0, 2.5}) {
    FeatureGrid grid;
    DiscTable first;
    first.push_back(1, 50, 50, 0, 0, 0.2);
    const std::vector<double> first_reach = {cell};
    run(grid, first.view(), first_reach, scene);  // the grid's cell: the first query's reach
    DiscTable pts;
    std::vector<double> reach;
    uint64_t id = 1;
    auto add = [&](double x, double y, double r) {
      pts.push_back(id++, x, y, 0, 0, 0.2);
      reach.push_back(r);
    };
    for (double dist = 0.05; dist < 12; dist += 0.0371)
      for (double hair : {-1e-9, 1e-9, 0.02}) {
        const double a = dist * 7.3;  // directions spread over the circle
        add(50 + (0.5 + dist) * std::cos(a), 50 + (0.5 + dist) * std::sin(a), dist + hair);
        // From the wall's south-west side (its normal is (-1, -1) / sqrt 2), along its length.
        const double t = std::fmod(dist * 0.137, 1.0);
        add(10 + 70 * t - dist * 0.70710678, 80 - 70 * t - dist * 0.70710678, dist + hair);
      }
    for (double r : {1.0, 30.0, 200.0}) {  // beyond the grid's box on every side
      add(-40, 50, r);
      add(50, 130, r);
      add(130, -40, r);
    }
    SCOPED_TRACE("cell " + std::to_string(cell));
    const FeatureLists want = run(naive, pts.view(), reach, scene);
    expect_same(run(grid, pts.view(), reach, scene), want);
    std::size_t found = 0;
    for (std::size_t q = 0; q + 1 < want.offset.size(); ++q)
      found += want.offset[q + 1] > want.offset[q];
    EXPECT_GT(found, pts.size() / 3);  // the reaches straddle the distances: many hit, many miss
    EXPECT_LT(found, pts.size());
  }
}

TEST(FeatureGrid, RebuildsForANewSceneAndHandlesAnEmptyOne) {
  Rng rng(8);
  FeatureNaive naive;
  FeatureGrid grid;
  const DiscTable pts = build::uniform(100, {0, 0, 50, 50}, 0, 0.1, 0.3, 4);
  const std::vector<double> reach(pts.size(), 5.0);
  for (int c = 0; c < 3; ++c) {
    const StaticScene scene = random_scene(rng, 50, c == 1);
    expect_same(run(grid, pts.view(), reach, scene), run(naive, pts.view(), reach, scene));
  }
  const StaticScene empty;
  const FeatureLists l = run(grid, pts.view(), reach, empty);
  EXPECT_EQ(l.offset.back(), 0u);
  EXPECT_EQ(l.queries(), pts.size());
}

TEST(FeatureQuery, FeatureNumbersDistancesAndClosestPoints) {
  const StaticScene s({{10, 0, 2, 1}}, {{{{0, 0}, {4, 0}, {4, 4}, {0, 4}}, 1}}, 1,
                      ObstacleCharges::none);
  ASSERT_EQ(s.feature_count(), 5u);  // a circle, four edges
  EXPECT_EQ(s.first_edge(0), 1u);
  EXPECT_EQ(s.edge_of(3), (std::pair<std::size_t, std::size_t>{0, 2}));
  EXPECT_EQ(feature_dist2(s, 0, 15, 0), 9.0);    // 5 from the centre, 3 from the circle
  EXPECT_EQ(feature_dist2(s, 0, 10.5, 0), 0.0);  // inside the circle
  EXPECT_EQ(feature_dist2(s, 1, 2, -3), 9.0);    // below the bottom edge
  const Vec2 c = feature_closest(s, 0, 15, 0);
  EXPECT_EQ(c.x, 12);
  EXPECT_EQ(c.y, 0);
  const DiscTable p = build::uniform(1, {2, -3, 2, -3}, 0, 0.1, 0.1, 1);
  const double reach[] = {3.5};
  const FeatureLists l = obstacle_features(p.view(), reach, s);
  EXPECT_EQ(l.feature, (std::vector<uint32_t>{1}));  // only the bottom edge is within 3.5
  const double bad[] = {-1};
  EXPECT_THROW(obstacle_features(p.view(), bad, s), Error);
}

}  // namespace
}  // namespace crowddb::index
