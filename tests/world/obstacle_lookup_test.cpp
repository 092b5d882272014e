#include "world/obstacle_lookup.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "world/geometry.hpp"

namespace crowddb {
namespace {

// The oracle: every obstacle a disc of radius r at (x, y) touches (r = 0: strictly holds the point
// or has it on its boundary), by a scan of the exact tests.
std::vector<uint32_t> touched(const std::vector<CircleObstacle>& circles,
                              const std::vector<PolygonObstacle>& polygons, double x, double y,
                              double r) {
  std::vector<uint32_t> out;
  for (std::size_t k = 0; k < circles.size(); ++k)
    if (std::hypot(circles[k].x - x, circles[k].y - y) <= circles[k].radius + r)
      out.push_back(static_cast<uint32_t>(k));
  for (std::size_t k = 0; k < polygons.size(); ++k) {
    const auto& ring = polygons[k].vertices;
    if (point_in_polygon(ring, x, y) || dist2_to_boundary(ring, x, y) <= r * r)
      out.push_back(static_cast<uint32_t>(circles.size() + k));
  }
  return out;
}

PolygonObstacle box(double x0, double y0, double x1, double y1) {
  return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, 1.0};
}

// Candidates come sorted, each once, and hold every obstacle the exact tests accept.
void expect_superset(const ObstacleLookup& lookup, const std::vector<CircleObstacle>& circles,
                     const std::vector<PolygonObstacle>& polygons, double x, double y, double r,
                     const std::string& where) {
  std::vector<uint32_t> got;
  lookup.candidates(x, y, r, got);
  ASSERT_TRUE(std::is_sorted(got.begin(), got.end())) << where;
  ASSERT_TRUE(std::adjacent_find(got.begin(), got.end()) == got.end()) << where;
  for (uint32_t k : touched(circles, polygons, x, y, r))
    ASSERT_TRUE(std::binary_search(got.begin(), got.end(), k))
        << where << ": obstacle " << k << " touched but not listed";
}

TEST(ObstacleLookup, ListsEveryObstacleTheExactTestsAcceptOnRandomScenes) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int scene = 0; scene < 40; ++scene) {
    const double side = scene % 4 == 0 ? 5 : 200;
    std::vector<CircleObstacle> circles;
    std::vector<PolygonObstacle> polygons;
    const int n = 1 + static_cast<int>(u(rng) * 300);
    for (int k = 0; k < n; ++k) {
      const double x = u(rng) * side, y = u(rng) * side;
      switch (static_cast<int>(u(rng) * 5)) {
        case 0:
          circles.push_back({x, y, 0.05 + u(rng) * 2, 1.0});
          break;
        case 1:  // a long wall: registered in no cell, listed for every query
          polygons.push_back(box(x - side, y, x + side, y + 0.2));
          break;
        case 2: {  // a triangle
          const double s = 0.1 + u(rng) * 4;
          polygons.push_back({{{x, y}, {x + s, y}, {x, y + s}}, 1.0});
          break;
        }
        default: {
          const double w = 0.1 + u(rng) * 3, h = 0.1 + u(rng) * 3;
          polygons.push_back(box(x, y, x + w, y + h));
        }
      }
    }
    const ObstacleLookup lookup(circles, polygons);
    for (int q = 0; q < 400; ++q) {
      // Points inside, near and far outside the obstacles' extent; reaches from 0 to huge.
      const double x = (u(rng) * 1.4 - 0.2) * side, y = (u(rng) * 1.4 - 0.2) * side;
      const double reaches[] = {0, 0.25, 1.5, side / 3, 10 * side};
      const double r = reaches[q % 5];
      expect_superset(lookup, circles, polygons, x, y, r,
                      "scene " + std::to_string(scene) + " query " + std::to_string(q));
    }
    // On the obstacles' own corners and edges (exact ties with the cell borders).
    for (const PolygonObstacle& p : polygons)
      for (const Vec2& v : p.vertices)
        expect_superset(lookup, circles, polygons, v.x, v.y, 0, "a vertex");
  }
}

TEST(ObstacleLookup, AnObstacleOnALatticeOfCellBordersIsFoundFromEverySide) {
  // Boxes edge to edge on a lattice: every box border is a likely cell border. A wall and a
  // circle across the whole lattice span more cells than an obstacle is registered in: they are
  // listed for every query.
  std::vector<CircleObstacle> circles = {{30, 30, 25, 1.0}};
  std::vector<PolygonObstacle> polygons;
  for (int i = 0; i < 60; ++i)
    for (int j = 0; j < 60; ++j) polygons.push_back(box(i, j, i + 1, j + 1));
  polygons.push_back(box(-1, 10.5, 61, 10.7));
  const ObstacleLookup lookup(circles, polygons);
  for (int i = 0; i <= 240; i += 3)
    for (int j = 0; j <= 240; j += 3)
      expect_superset(lookup, circles, polygons, i * 0.25, j * 0.25, i % 3 == 0 ? 0 : 0.25,
                      "lattice point " + std::to_string(i) + "," + std::to_string(j));
}

TEST(ObstacleLookup, EmptyScenesAndDegenerateQueriesAreAnswered) {
  const ObstacleLookup none({}, {});
  std::vector<uint32_t> got{1, 2, 3};
  none.candidates(0, 0, 1, got);
  EXPECT_TRUE(got.empty());
  // One obstacle: a zero-size extent in one axis (a point-like circle set on a line).
  const std::vector<CircleObstacle> circles = {{0, 0, 1, 1}, {5, 0, 1, 1}};
  const ObstacleLookup line(circles, {});
  line.candidates(std::nan(""), 0, 0, got);  // not finite: everything, never a crash
  EXPECT_EQ(got, (std::vector<uint32_t>{0, 1}));
  line.candidates(0, 0, INFINITY, got);
  EXPECT_EQ(got, (std::vector<uint32_t>{0, 1}));
  line.candidates(1e300, -1e300, 0, got);  // far outside: a superset of nothing is fine
  for (uint32_t k : got) EXPECT_LT(k, 2u);
}

}  // namespace
}  // namespace crowddb
