// NearestPoint (world/nearest_point.hpp) against its loop over every point, answer for answer:
// random points, clusters, lattices (many points at equal distances: ties by list position),
// duplicates, queries on points, between them and far outside, and degenerate lists.
#include "world/nearest_point.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "util/rng.hpp"

namespace crowddb {
namespace {

std::vector<Vec2> scene(Rng& rng, int kind, std::size_t n) {
  std::vector<Vec2> out;
  for (std::size_t k = 0; k < n; ++k) {
    switch (kind) {
      case 0:  // uniform over a square
        out.push_back({rng.uniform(-500, 500), rng.uniform(-500, 500)});
        break;
      case 1:  // a lattice, shuffled by position in the list: ties everywhere
        out.push_back({static_cast<double>(rng.below(40)), static_cast<double>(rng.below(40))});
        break;
      case 2:  // two far clusters
        out.push_back(k % 2 ? Vec2{rng.uniform(0, 1), rng.uniform(0, 1)}
                            : Vec2{1e5 + rng.uniform(0, 10), rng.uniform(-3e4, 3e4)});
        break;
      case 3:  // a thin line, far from the origin
        out.push_back({1e7 + rng.uniform(0, 1e3), 2e6 + 1e-3 * static_cast<double>(rng.below(7))});
        break;
      default:  // rooms: dense clusters far apart, and a few points at subnormal spacing
        out.push_back(k % 50 == 0 ? Vec2{1e-310 * static_cast<double>(rng.below(5)), 0}
                                  : Vec2{1e3 * static_cast<double>(k % 7) + rng.uniform(0, 2),
                                         -4e2 * static_cast<double>(k % 3) + rng.uniform(0, 2)});
    }
  }
  return out;
}

TEST(NearestPoint, AnswersAreTheLoopsOnRandomScenes) {
  Rng rng(20261206);
  std::size_t indexed = 0, queries = 0;
  for (int s = 0; s < 60; ++s) {
    const int kind = s % 5;
    const std::size_t n =
        s % 6 == 0 ? 1 + rng.below(NearestPoint::kMinPoints) : 64 + rng.below(5000);
    const std::vector<Vec2> points = scene(rng, kind, n);
    const NearestPoint near(points);
    indexed += near.indexed();
    for (int q = 0; q < 500; ++q) {
      Vec2 at;
      const Vec2& p = points[rng.below(n)];
      switch (q % 5) {
        case 0:
          at = p;  // on a point (duplicates: the first in the list)
          break;
        case 1:
          at = {p.x + 0.5, p.y + 0.5};  // a lattice cell's centre: four at the same distance
          break;
        case 2:
          at = {p.x * (1 + rng.uniform(-1, 1) * 10), p.y * (1 + rng.uniform(-1, 1) * 10)};
          break;
        case 3:
          at = {std::nextafter(p.x, INFINITY), p.y};
          break;
        default:
          at = {rng.uniform(-2e5, 2e5), rng.uniform(-2e5, 2e5)};
      }
      ASSERT_EQ(near.nearest(at.x, at.y), near.loop(at.x, at.y))
          << "scene " << s << " query " << q << " at " << at.x << ", " << at.y;
      ++queries;
    }
  }
  EXPECT_GT(indexed, 40u);
  EXPECT_EQ(queries, 60u * 500u);
}

// A lattice with half-unit queries: ties between points in different leaves, whose boxes lie at
// exactly the best distance (a skip at "box distance >= best" would miss them).
TEST(NearestPoint, TiesBetweenLeavesOnAUnitLattice) {
  std::vector<Vec2> points;
  for (int k = 0; k <= 31; ++k) {  // the four outer lines: a 31 x 31 extent
    points.push_back({double(k), 0});
    points.push_back({double(k), 31});
    points.push_back({0, double(k)});
    points.push_back({31, double(k)});
  }
  Rng rng(31);
  while (points.size() < 961) points.push_back({double(rng.below(32)), double(rng.below(32))});
  const NearestPoint near(points);
  ASSERT_TRUE(near.indexed());
  for (int qx = -4; qx <= 70; ++qx)
    for (int qy = -4; qy <= 70; ++qy) {
      const double x = qx * 0.5, y = qy * 0.5;
      ASSERT_EQ(near.nearest(x, y), near.loop(x, y)) << x << ", " << y;
    }
}

TEST(NearestPoint, DegenerateListsAndQueries) {
  EXPECT_EQ(NearestPoint(std::vector<Vec2>{}).nearest(0, 0), NearestPoint::kNone);
  std::vector<Vec2> same(200, Vec2{3, 4});  // all at one spot: the first
  const NearestPoint one(same);
  EXPECT_EQ(one.nearest(0, 0), 0u);
  EXPECT_EQ(one.nearest(NAN, 0), NearestPoint::kNone);
  EXPECT_EQ(one.nearest(INFINITY, 0), NearestPoint::kNone);
  std::vector<Vec2> wild(100);
  for (std::size_t k = 0; k < wild.size(); ++k) wild[k] = {double(k), double(k % 7)};
  wild[50] = {INFINITY, 0};  // not finite: the loop answers every query
  const NearestPoint loop_only(wild);
  EXPECT_FALSE(loop_only.indexed());
  EXPECT_EQ(loop_only.nearest(49.9, 0), loop_only.loop(49.9, 0));
}

// Distances that overflow (some, or every one: then no answer), distances equal only after
// rounding (coordinates near 10^16, a unit apart), signed zeros, and the smallest indexed list.
TEST(NearestPoint, OverflowRoundingTiesSignedZerosAndTheSmallestTree) {
  Rng rng(41);
  std::vector<std::vector<Vec2>> scenes(4);
  for (int k = 0; k < 300; ++k) {
    const double big = 1.7e308 * (k % 2 ? 1 : -1);
    scenes[0].push_back({big * rng.uniform(0.5, 1), 1.7e308 * rng.uniform(-1, 1)});
    scenes[1].push_back({1e16 + 2 * static_cast<double>(rng.below(8)),
                         -1e16 + 2 * static_cast<double>(rng.below(8))});
    scenes[2].push_back({k % 3 == 0 ? -0.0 : 0.0, k % 5 == 0 ? -0.0 : static_cast<double>(k % 4)});
  }
  for (int k = 0; k < static_cast<int>(NearestPoint::kMinPoints); ++k)
    scenes[3].push_back({rng.uniform(0, 10), rng.uniform(0, 10)});
  const std::vector<Vec2> queries = {{0, 0},        {-0.0, -0.0},          {1.7e308, 1.7e308},
                                     {-1.7e308, 0}, {1e16 + 1, -1e16 + 3}, {1e16 - 5, -1e16},
                                     {5, 5},        {-1e300, 1e300}};
  for (std::size_t s = 0; s < scenes.size(); ++s) {
    const NearestPoint near(scenes[s]);
    ASSERT_TRUE(near.indexed()) << "scene " << s;
    for (const Vec2& q : queries)
      ASSERT_EQ(near.nearest(q.x, q.y), near.loop(q.x, q.y))
          << "scene " << s << " at " << q.x << ", " << q.y;
    for (int q = 0; q < 300; ++q) {  // on and beside the points
      const Vec2& p = scenes[s][rng.below(scenes[s].size())];
      const double x = q % 2 ? p.x : std::nextafter(p.x, -INFINITY), y = p.y;
      ASSERT_EQ(near.nearest(x, y), near.loop(x, y)) << "scene " << s << " at " << x << ", " << y;
    }
  }
  // Every distance infinite: no answer, as the loop.
  std::vector<Vec2> far(100, Vec2{1.7e308, 1.7e308});
  const NearestPoint all_far(far);
  EXPECT_EQ(all_far.nearest(-1.7e308, -1.7e308), NearestPoint::kNone);
  EXPECT_EQ(all_far.loop(-1.7e308, -1.7e308), NearestPoint::kNone);
}

// The work of a query is a walk down the tree, also where a grid sized for the mean spacing read
// every point: clusters of many points in a small part of the extent, and queries far outside it.
TEST(NearestPoint, ClustersAndFarQueriesReadFewPoints) {
  Rng rng(7);
  std::vector<Vec2> points;
  for (int room = 0; room < 4; ++room)  // 4 rooms of 5,000 in 1 m^2, 10 km apart
    for (int k = 0; k < 5000; ++k)
      points.push_back({1e4 * room + rng.uniform(0, 1), rng.uniform(0, 1)});
  const NearestPoint near(points);
  ASSERT_TRUE(near.indexed());
  std::size_t most = 0;
  for (int q = 0; q < 2000; ++q) {
    const double x = q % 2 ? rng.uniform(-1e6, 1e6)
                           : 1e4 * static_cast<double>(rng.below(4)) + rng.uniform(-1, 2);
    const double y = q % 2 ? rng.uniform(-1e6, 1e6) : rng.uniform(-1, 2);
    std::size_t read = 0;
    ASSERT_EQ(near.nearest(x, y, &read), near.loop(x, y)) << x << ", " << y;
    most = std::max(most, read);
  }
  EXPECT_LT(most, 400u);  // of 20,000
}

}  // namespace
}  // namespace crowddb
