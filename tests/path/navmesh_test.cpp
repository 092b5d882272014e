// The navigation mesh against an independent oracle: shortest paths of a disc over a visibility
// graph (tests/path/visibility_graph.hpp) on fixed and random worlds, the clearance of every
// returned path, line of sight, tiling and determinism. The search with polygon costs against its
// naive twin: Dijkstra over every portal of the mesh.
#include "path/navmesh.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <cstdio>
#include <set>
#include <utility>

#include "path/visibility_graph.hpp"
#include "util/executor.hpp"
#include "util/rng.hpp"

namespace crowddb::path {
namespace {

PolygonObstacle rect(double x0, double y0, double x1, double y1) {
  return {{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, 1};
}

path::DiscWorld disc_world(const NavGeometry& g) {
  path::DiscWorld d;
  d.bounds = g.bounds;
  d.circles = g.circles;
  for (const auto& p : g.polygons) d.polygons.push_back(p.vertices);
  return d;
}

// Every point of the path (sampled every 0.02) keeps at least `need` from obstacles and walls.
double min_clearance(const path::DiscWorld& w, const PathResult& r) {
  std::vector<Vec2> pts{r.start};
  pts.insert(pts.end(), r.corners.begin(), r.corners.end());
  pts.push_back(r.end);
  double worst = INFINITY;
  for (std::size_t i = 0; i + 1 < pts.size(); ++i) {
    const double len = std::hypot(pts[i + 1].x - pts[i].x, pts[i + 1].y - pts[i].y);
    const int n = std::max(1, static_cast<int>(len / 0.02));
    for (int k = 0; k <= n; ++k) {
      const double t = static_cast<double>(k) / n;
      worst = std::min(worst, path::clearance_at(w, {pts[i].x + t * (pts[i + 1].x - pts[i].x),
                                                     pts[i].y + t * (pts[i + 1].y - pts[i].y)}));
    }
  }
  return worst;
}

double polyline_length(const PathResult& r) {
  double len = 0;
  Vec2 prev = r.start;
  for (const Vec2& c : r.corners) {
    len += std::hypot(c.x - prev.x, c.y - prev.y);
    prev = c;
  }
  return len + std::hypot(r.end.x - prev.x, r.end.y - prev.y);
}

Vec2 midpoint(const MeshPortal& p) {
  return {0.5 * (p.left.x + p.right.x), 0.5 * (p.left.y + p.right.y)};
}

double dist(Vec2 a, Vec2 b) {
  return std::hypot(b.x - a.x, b.y - a.y);
}

// The naive twin of PathFinder's search with polygon costs: Dijkstra, scanning every node for
// the next one, over the start, the goal and every portal's midpoint (one node per direction),
// with the same steps: to a portal out of the polygon one stands in, its length plus the cost
// of the polygon entered; to the goal from anywhere in the goal's polygon, its length.
// Door cuts crossed by the step from p to q, the naive way: the step's ends on strictly opposite
// sides of the cut's line, or one on it and the other right of it (a point on the line counts
// as left of it), and the cut's ends not on the same side of the step's line.
double naive_cut_costs(const PolygonCosts& costs, Vec2 p, Vec2 q) {
  double sum = 0;
  for (const DoorCut& c : costs.cuts) {
    const double sp = (c.b.x - c.a.x) * (p.y - c.a.y) - (c.b.y - c.a.y) * (p.x - c.a.x);
    const double sq = (c.b.x - c.a.x) * (q.y - c.a.y) - (c.b.y - c.a.y) * (q.x - c.a.x);
    const bool opposite = (sp >= 0 && sq < 0) || (sp < 0 && sq >= 0);
    const double ta = (q.x - p.x) * (c.a.y - p.y) - (q.y - p.y) * (c.a.x - p.x);
    const double tb = (q.x - p.x) * (c.b.y - p.y) - (q.y - p.y) * (c.b.x - p.x);
    if (opposite && !(ta > 0 && tb > 0) && !(ta < 0 && tb < 0)) sum += c.cost;
  }
  return sum;
}

double naive_costed(const NavMesh& mesh, uint32_t sref, Vec2 s, uint32_t gref, Vec2 g,
                    const PolygonCosts& costs) {
  const std::vector<MeshPortal> portals = mesh.portals();
  const std::size_t start = portals.size(), goal = start + 1;
  std::vector<double> best(goal + 1, INFINITY);
  std::vector<bool> done(goal + 1, false);
  best[start] = 0;
  for (;;) {
    std::size_t u = goal + 1;
    for (std::size_t k = 0; k <= goal; ++k)
      if (!done[k] && std::isfinite(best[k]) && (u > goal || best[k] < best[u])) u = k;
    if (u > goal || u == goal) break;
    done[u] = true;
    const Vec2 at = u == start ? s : midpoint(portals[u]);
    const uint32_t poly = u == start ? sref : portals[u].to;
    if (poly == gref)
      best[goal] = std::min(best[goal], best[u] + dist(at, g) + naive_cut_costs(costs, at, g));
    for (std::size_t k = 0; k < portals.size(); ++k)
      if (portals[k].from == poly)
        best[k] =
            std::min(best[k], best[u] + dist(at, midpoint(portals[k])) + costs.of(portals[k].to) +
                                  naive_cut_costs(costs, at, midpoint(portals[k])));
  }
  return best[goal];
}

TEST(NavMesh, OpenFloorGivesTheStraightLine) {
  NavGeometry g{{0, 0, 50, 30}, {}, {}};
  auto mesh = NavMesh::build(g, {1.0, 0.25});
  PathFinder f(*mesh);
  const PathResult r = f.find({5, 5}, {45, 25});
  ASSERT_EQ(r.status, PathStatus::ok);
  EXPECT_TRUE(r.corners.empty());
  EXPECT_NEAR(r.length, std::hypot(40, 20), 1e-3);
  EXPECT_NEAR(polyline_length(r), r.length, 1e-9);
  EXPECT_TRUE(mesh->visible({5, 5}, {45, 25}));
}

TEST(NavMesh, WallWithAGapMatchesTheVisibilityGraph) {
  // A wall across the world with a gap near its north end.
  NavGeometry g{{0, 0, 60, 40}, {}, {rect(29, 0, 31, 30)}};
  const NavMeshParams p{1.0, 0.25};
  auto mesh = NavMesh::build(g, p);
  PathFinder f(*mesh);
  const PathResult r = f.find({10, 10}, {50, 10});
  ASSERT_EQ(r.status, PathStatus::ok);
  EXPECT_GE(r.corners.size(), 1u);
  for (const Vec2& c : r.corners) EXPECT_GT(c.y, 30);  // around the wall's end
  const auto dw = disc_world(g);
  const double exact = path::shortest_path(dw, p.radius, {10, 10}, {50, 10});
  const double inflated =
      path::shortest_path(dw, mesh->clearance() + 2 * p.cell_size, {10, 10}, {50, 10});
  // Never shorter than the true shortest path of the disc, about that of a disc as wide as the
  // mesh's clearance (plus two cells: the grid rounds the eroded boundary outwards).
  EXPECT_GE(r.length, exact * (1 - 1e-4));
  EXPECT_LE(r.length, inflated * 1.02);
  EXPECT_GE(min_clearance(dw, r), p.radius);
  EXPECT_FALSE(mesh->visible({10, 10}, {50, 10}));
  EXPECT_TRUE(mesh->visible({10, 10}, {10, 35}));
}

TEST(NavMesh, UnreachableGoalGivesAPartialPathTowardsIt) {
  NavGeometry g{{0, 0, 60, 40}, {}, {rect(29, 0, 31, 40)}};  // the wall closes the world
  auto mesh = NavMesh::build(g, {1.0, 0.25});
  PathFinder f(*mesh);
  const PathResult r = f.find({10, 10}, {50, 10});
  EXPECT_EQ(r.status, PathStatus::partial);
  EXPECT_LT(r.end.x, 29);  // as close as the start's side gets
  EXPECT_GT(r.end.x, 26);
}

TEST(NavMesh, NarrowDoorPassesSmallDiscsOnly) {
  // A door 3 wide: open for a disc of radius 0.5 (clearance 1.0), closed for radius 1.5.
  NavGeometry g{{0, 0, 40, 30}, {}, {rect(19, 0, 21, 13.5), rect(19, 16.5, 21, 30)}};
  auto small = NavMesh::build(g, {0.5, 0.125});
  auto large = NavMesh::build(g, {1.5, 0.25});
  PathFinder fs(*small), fl(*large);
  EXPECT_EQ(fs.find({5, 15}, {35, 15}).status, PathStatus::ok);
  EXPECT_EQ(fl.find({5, 15}, {35, 15}).status, PathStatus::partial);
}

// Doors only a little wider than the disc: with the class mesh's cell (a quarter of the radius)
// a door five cells wider than the disc is open, one narrower than the disc is closed. The
// narrow meshes of src/path/navigation.cpp (cells of r / 8, eroded by r less two cells, cells
// marked within half a cell of an obstacle) open a door 2.3 r wide (from 1.9-2.26 r, as the
// cells fall), keep one of 1.8 r closed, and their paths keep three quarters of r from the
// door's posts.
TEST(NavMesh, DoorsALittleWiderThanTheDiscAreOpen) {
  for (double R : {0.195, 0.2, 0.21, 0.25, 0.3, 0.4, 0.5}) {
    auto door = [&](const NavMeshParams& p, double w) {
      NavGeometry g{
          {0, 0, 20, 10}, {}, {rect(9.5, 0, 10.5, 5 - w / 2), rect(9.5, 5 + w / 2, 10.5, 10)}};
      auto mesh = NavMesh::build(g, p);
      PathFinder f(*mesh);
      PathResult r = f.find({3, 3}, {17, 7});
      if (r.status == PathStatus::ok) {
        EXPECT_GE(min_clearance(disc_world(g), r), 0.75 * R) << R;
      }
      return r.status;
    };
    const NavMeshParams cls{R, R / 4}, narrow{R - R / 4, R / 8, 256, 1.0, 0.5};
    EXPECT_EQ(door(cls, 2 * R + 5 * R / 4), PathStatus::ok) << "radius " << R;
    EXPECT_EQ(door(cls, 2 * R - 0.02), PathStatus::partial) << "radius " << R;
    EXPECT_EQ(door(narrow, 2.3 * R), PathStatus::ok) << "radius " << R;
    EXPECT_EQ(door(narrow, 1.8 * R), PathStatus::partial) << "radius " << R;
  }
}

// Corner pushing: through a 1.4 m door for a disc of radius 0.5 on its narrow mesh, the path
// from off the door's axis turns at the door's posts; with corners kept up to the radius inside
// the mesh's edges it runs through the middle of the door instead of with the disc's edge on a
// post.
TEST(NavMesh, CornersArePushedIntoTheMiddleOfANarrowDoor) {
  NavGeometry g{{0, 0, 30, 20}, {}, {rect(14.5, 0, 15.5, 9.3), rect(14.5, 10.7, 15.5, 20)}};
  for (double push : {0.0, 0.5}) {
    NavMeshParams p{0.375, 0.0625, 256, 1.0, 0.5};
    p.corner_push = push;
    auto mesh = NavMesh::build(g, p);
    PathFinder f(*mesh);
    const PathResult r = f.find({5, 3}, {25, 17});
    ASSERT_EQ(r.status, PathStatus::ok);
    double off_middle = 0;  // of the corners in the door
    int in_door = 0;
    for (const Vec2& c : r.corners)
      if (c.x >= 14.4 && c.x <= 15.6) {
        off_middle = std::max(off_middle, std::abs(c.y - 10));
        ++in_door;
      }
    EXPECT_GE(in_door, 1) << "push " << push;
    if (push == 0) {
      EXPECT_GT(off_middle, 0.2);  // on the mesh's edge, 0.45 from a post
    } else {
      EXPECT_LE(off_middle, 0.1);
    }
    EXPECT_NEAR(r.length, polyline_length(r), 1e-9);
    EXPECT_GE(min_clearance(disc_world(g), r), 0.8 * p.radius);
  }
}

// On a class mesh (eroded by the radius), corners pushed in keep the path that much farther
// from a 2 m door's posts, a little longer than the straight path; without, the corners lie on
// the mesh's edge, the disc's edge next to a post.
TEST(NavMesh, PushedCornersKeepOffTheDoorPostsOnAClassMesh) {
  NavGeometry g{{0, 0, 30, 20}, {}, {rect(14.5, 0, 15.5, 9), rect(14.5, 11, 15.5, 20)}};
  double clear0[2] = {}, len0[2] = {};
  for (double push : {0.0, 0.25}) {
    NavMeshParams p{0.5, 0.125};
    p.corner_push = push;
    auto mesh = NavMesh::build(g, p);
    PathFinder f(*mesh);
    const std::pair<Vec2, Vec2> ends[2] = {{{5, 3}, {25, 17}}, {{5, 17}, {25, 3}}};
    for (int k = 0; k < 2; ++k) {
      const PathResult r = f.find(ends[k].first, ends[k].second);
      ASSERT_EQ(r.status, PathStatus::ok);
      ASSERT_GE(r.corners.size(), 1u);
      const double clear = min_clearance(disc_world(g), r);
      EXPECT_NEAR(r.length, polyline_length(r), 1e-9);
      if (push == 0) {
        clear0[k] = clear;
        len0[k] = r.length;
        EXPECT_LT(clear, mesh->clearance() + 2 * p.cell_size + 0.05);  // on the edge
      } else {
        EXPECT_GE(clear, clear0[k] + 0.7 * push) << "path " << k;
        EXPECT_GT(r.length, len0[k] - 1e-9);
        EXPECT_LT(r.length, len0[k] * 1.01);
      }
    }
  }
}

// A push larger than a quarter of a narrow exit: with push_share 0.5 every path crosses the
// exit at its middle; at 0.25 the corners keep to the strip a quarter in from either end, so
// paths from either side cross on their own side of the middle.
TEST(NavMesh, PushShareKeepsAStripOfANarrowExitInUse) {
  NavGeometry g{{0, 0, 30, 20}, {}, {rect(14.5, 0, 15.5, 9.5), rect(14.5, 10.5, 15.5, 20)}};
  for (double share : {0.5, 0.25}) {
    NavMeshParams p{0.25, 0.0625};
    p.corner_push = 0.25;
    p.push_share = share;
    auto mesh = NavMesh::build(g, p);
    PathFinder f(*mesh);
    const std::pair<Vec2, Vec2> ends[2] = {{{5, 3}, {25, 17}}, {{5, 17}, {25, 3}}};
    double ys[2] = {0, 0};  // the corner nearest the exit's middle, per path
    for (int k = 0; k < 2; ++k) {
      const PathResult r = f.find(ends[k].first, ends[k].second);
      ASSERT_EQ(r.status, PathStatus::ok);
      ASSERT_GE(r.corners.size(), 1u);
      double best = INFINITY;
      for (const Vec2& c : r.corners)
        if (std::abs(c.y - 10) < std::abs(best - 10)) best = c.y;
      ys[k] = best;
      EXPECT_GE(min_clearance(disc_world(g), r), 0.8 * p.radius);
    }
    if (share == 0.5) {
      EXPECT_NEAR(ys[0], 10, 0.02);
      EXPECT_NEAR(ys[1], 10, 0.02);
    } else {
      EXPECT_LT(ys[0], 9.97);  // from below: the lower post's side of the middle
      EXPECT_GT(ys[1], 10.03);
    }
  }
}

TEST(NavMesh, NonConvexPolygonsAndCirclesAreRespected) {
  // A U opening west with the goal behind its closed side, and a pillar.
  PolygonObstacle u{
      {{40, 18}, {64, 18}, {64, 62}, {40, 62}, {40, 60}, {62, 60}, {62, 20}, {40, 20}}, 1};
  NavGeometry g{{0, 0, 100, 80}, {{80, 55, 3, 1}}, {u}};
  const NavMeshParams p{0.8, 0.2};
  auto mesh = NavMesh::build(g, p);
  PathFinder f(*mesh);
  const PathResult r = f.find({20, 40}, {86, 40});
  ASSERT_EQ(r.status, PathStatus::ok);
  const auto dw = disc_world(g);
  EXPECT_GE(min_clearance(dw, r), p.radius);
  EXPECT_GE(r.length, path::shortest_path(dw, p.radius, {20, 40}, {86, 40}) * (1 - 1e-4));
  EXPECT_LE(
      r.length,
      path::shortest_path(dw, mesh->clearance() + 2 * p.cell_size, {20, 40}, {86, 40}) * 1.02);
  EXPECT_FALSE(mesh->visible({50, 40}, {86, 40}));  // from inside the U
}

// Random worlds: rectangles, triangles and circles; random start/goal pairs. Against the exact
// oracle, the mesh's path (plus any snap from the query points onto the mesh) is never shorter
// than the shortest path of its disc; it keeps the disc's radius from every obstacle; it exists
// whenever a disc as wide as the mesh's clearance plus two cells (the grid's rounding) can pass,
// and it is then at most 10% longer than that disc's shortest path: Detour's A* runs over
// polygons (costs between edge midpoints), so the corridor it picks is not always the one of
// the shortest path; the funnel then straightens within that corridor only.
TEST(NavMesh, RandomWorldsAgreeWithTheVisibilityGraphOracle) {
  Rng rng(20240611);
  int compared = 0;
  double worst_clearance = INFINITY, worst_excess = 0;
  for (int world = 0; world < 6; ++world) {
    NavGeometry g{{0, 0, 60, 45}, {}, {}};
    for (int k = 0; k < 7; ++k) {
      const double x = rng.uniform(5, 55), y = rng.uniform(5, 40), w = rng.uniform(1, 8),
                   h = rng.uniform(1, 8);
      if (rng.below(3) == 0) {
        g.circles.push_back({x, y, rng.uniform(0.5, 3), 1});
      } else if (rng.below(2) == 0) {
        g.polygons.push_back(rect(x, y, x + w, y + h));
      } else {
        g.polygons.push_back(
            {{{x, y}, {x + w, y + rng.uniform(-2, 2)}, {x + rng.uniform(0, w), y + h}}, 1});
      }
    }
    // Triangles may come out clockwise: store them as World does (counter-clockwise).
    for (auto& p : g.polygons) {
      double a = 0;
      for (std::size_t i = 0; i < p.vertices.size(); ++i) {
        const Vec2 &u = p.vertices[i], &v = p.vertices[(i + 1) % p.vertices.size()];
        a += u.x * v.y - v.x * u.y;
      }
      if (a < 0) std::reverse(p.vertices.begin(), p.vertices.end());
    }
    const double radius = world % 2 ? 0.5 : 1.0;
    // Every third world with the narrow meshes' marking (cells within half a cell).
    const NavMeshParams params{radius, radius / 4, 64, 1.0,
                               world % 3 == 2 ? 0.5 : 0.7071067811865476};
    auto mesh = NavMesh::build(g, params);
    PathFinder f(*mesh);
    const auto dw = disc_world(g);
    const double wide_radius = mesh->clearance() + 2 * params.cell_size;
    for (int q = 0; q < 8; ++q) {
      const Vec2 a{rng.uniform(2, 58), rng.uniform(2, 43)},
          b{rng.uniform(2, 58), rng.uniform(2, 43)};
      const double wide = path::shortest_path(dw, wide_radius, a, b);
      if (!std::isfinite(wide)) continue;  // start or goal too close to an obstacle, or no passage
      const PathResult r = f.find(a, b);
      ASSERT_EQ(r.status, PathStatus::ok) << "world " << world << " query " << q;
      const double total = r.length + std::hypot(r.start.x - a.x, r.start.y - a.y) +
                           std::hypot(r.end.x - b.x, r.end.y - b.y);
      const double exact = path::shortest_path(dw, radius, a, b);
      EXPECT_GE(total, exact * (1 - 1e-4)) << "world " << world << " query " << q;
      EXPECT_LE(total, wide * 1.10) << "world " << world << " query " << q;
      const double c = min_clearance(dw, r);
      EXPECT_GE(c, radius) << "world " << world << " query " << q;
      worst_clearance = std::min(worst_clearance, c / radius);
      worst_excess = std::max(worst_excess, total / wide);
      ++compared;
    }
  }
  EXPECT_GE(compared, 20);
  std::printf(
      "[ navmesh  ] %d random paths compared; smallest clearance %.3f x radius; longest %.3f x the "
      "wider disc's\n",
      compared, worst_clearance, worst_excess);
}

// A step crosses a cut once when its ends lie on either side and the cut's ends on either side
// of it; a point on the cut's line counts as left of it, so a path through a point of the cut
// (a portal's midpoint on a door's cut) crosses it once.
TEST(NavMesh, CutCrossing) {
  const Vec2 a{0, 0}, b{2, 0};
  EXPECT_TRUE(cut_crossed(a, b, {1, -1}, {1, 1}));
  EXPECT_TRUE(cut_crossed(a, b, {1, 1}, {1, -1}));
  EXPECT_FALSE(cut_crossed(a, b, {3, -1}, {3, 1}));  // beyond the cut's end
  EXPECT_FALSE(cut_crossed(a, b, {0.5, 1}, {1.5, 2}));
  EXPECT_FALSE(cut_crossed(a, b, {0.5, 0}, {1.5, 0}));  // along it
  // Through a point of the cut in two steps: once.
  EXPECT_NE(cut_crossed(a, b, {1, -1}, {1, 0}), cut_crossed(a, b, {1, 0}, {1, 1}));
  EXPECT_NE(cut_crossed(a, b, {1, 1}, {1, 0}), cut_crossed(a, b, {1, 0}, {1, -1}));
}

// The first narrow place along a path: a wall across a room with a 1.2 m door; walking down
// through it, the cut runs across the door from post to post; along the open floor, none.
TEST(NavMesh, FirstNarrowsIsTheDoorOnTheWay) {
  NavGeometry g{{0, 0, 30, 16}, {}, {}};
  g.polygons = {rect(0, 8, 10, 9), rect(11.2, 8, 30, 9)};
  for (int tile : {32, 256}) {
    auto mesh = NavMesh::build(g, {0.3, 0.1, tile});
    const auto cut = mesh->first_narrows({{10.6, 14}, {10.6, 2}}, 15, 2.5);
    ASSERT_TRUE(cut) << "tile " << tile;
    for (const Vec2& e : {cut->a, cut->b}) {
      EXPECT_GT(e.x, 10) << "tile " << tile;
      EXPECT_LT(e.x, 11.2) << "tile " << tile;
      EXPECT_GE(e.y, 7.5) << "tile " << tile;
      EXPECT_LE(e.y, 9.5) << "tile " << tile;
    }
    const double w = std::hypot(cut->b.x - cut->a.x, cut->b.y - cut->a.y) + 2 * mesh->clearance();
    EXPECT_NEAR(w, 1.2, 0.25) << "tile " << tile;
    EXPECT_EQ(cut->cost, 0);
    // Not within the look, and not along the open floor.
    EXPECT_FALSE(mesh->first_narrows({{10.6, 14}, {10.6, 2}}, 4, 2.5));
    EXPECT_FALSE(mesh->first_narrows({{2, 14}, {28, 12}}, 30, 2.5));
    // A place is narrow when no wider than asked: the 1.2 m door is not narrower than 1 m.
    EXPECT_FALSE(mesh->first_narrows({{10.6, 14}, {10.6, 2}}, 15, 1.0));
  }
}

// Skipping the samples near an open one changes no answer: random rooms split by walls with
// doors 0.6-3 m wide and pillars, on fine and coarse meshes, searched along found paths and
// along straight lines in every direction, as far as random looks, against the twin that
// searches every sample.
TEST(NavMesh, FirstNarrowsSkipsOnlySamplesThatCannotBeNarrow) {
  Rng rng(5150);
  int compared = 0, doors = 0;
  std::size_t samples = 0, skips = 0;
  for (int world = 0; world < 12; ++world) {
    NavGeometry g{{0, 0, 40, 30}, {}, {}};
    for (int wall = 0; wall < 2; ++wall) {  // a vertical wall with a door, then a horizontal one
      const double at = rng.uniform(8, 22), door = rng.uniform(0.6, 3), from = rng.uniform(3, 24);
      if (wall == 0) {
        g.polygons.push_back(rect(at, 0, at + 0.3, from));
        g.polygons.push_back(rect(at, from + door, at + 0.3, 30));
      } else {
        g.polygons.push_back(rect(at + 12, 0, at + 12.3, from));
        g.polygons.push_back(rect(at + 12, from + door, at + 12.3, 30));
      }
    }
    for (int k = 0; k < 3; ++k)
      g.circles.push_back({rng.uniform(2, 38), rng.uniform(2, 28), rng.uniform(0.3, 1.5), 1});
    const double radius = world % 2 ? 0.25 : 0.2;
    auto mesh = NavMesh::build(g, {radius, world % 4 < 2 ? 0.0625 : 0.125, 32 << (world % 3)});
    PathFinder f(*mesh);
    for (int q = 0; q < 60; ++q) {
      const Vec2 a{rng.uniform(1, 39), rng.uniform(1, 29)},
          b{rng.uniform(1, 39), rng.uniform(1, 29)};
      std::vector<Vec2> way;
      if (q % 2 == 0) {
        const PathResult r = f.find(a, b);
        if (r.status != PathStatus::ok) continue;
        way.push_back(r.start);
        way.insert(way.end(), r.corners.begin(), r.corners.end());
        way.push_back(r.end);
      } else {
        way = {a, b};
      }
      for (const double width : {1.0, 2.5, 4.0}) {
        // A look ending at random also ends narrow runs just begun: their first samples, those
        // nearest an open one, decide.
        const double look = q % 3 == 0 ? 40 : rng.uniform(0.5, 20);
        std::vector<NavMesh::Sample> fast_trace, naive_trace;
        const auto fast = mesh->first_narrows(way, look, width, nullptr, false, &fast_trace);
        const auto naive = mesh->first_narrows(way, look, width, nullptr, true, &naive_trace);
        ASSERT_EQ(fast.has_value(), naive.has_value()) << "world " << world << " query " << q;
        // A sample skipped is one its own search finds open; the others are searched alike.
        ASSERT_EQ(fast_trace.size(), naive_trace.size());
        for (std::size_t k = 0; k < fast_trace.size(); ++k) {
          const bool skipped = fast_trace[k] == NavMesh::Sample::skipped;
          ASSERT_EQ(skipped ? NavMesh::Sample::open : fast_trace[k], naive_trace[k])
              << "world " << world << " query " << q << " sample " << k;
          samples += 1;
          skips += skipped;
        }
        ++compared;
        if (!naive) continue;
        ++doors;
        for (const auto& [u, v] : {std::pair{fast->a, naive->a}, std::pair{fast->b, naive->b}}) {
          ASSERT_EQ(std::bit_cast<uint64_t>(u.x), std::bit_cast<uint64_t>(v.x))
              << "world " << world;
          ASSERT_EQ(std::bit_cast<uint64_t>(u.y), std::bit_cast<uint64_t>(v.y))
              << "world " << world;
        }
      }
    }
  }
  EXPECT_GT(compared, 500);
  EXPECT_GT(doors, compared / 10);
  EXPECT_GT(skips, samples / 10);
  std::printf(
      "[ navmesh  ] %d door searches compared, %d finding a narrow place; %zu of %zu samples "
      "skipped\n",
      compared, doors, skips, samples);
}

// Random worlds over small tiles (links across tile borders), random costs on a third of the
// polygons: where Detour's corridor enters one, the search finds the least cost the naive twin
// finds, along a corridor of adjacent polygons from the start's to the goal's, whose cost it
// reports; otherwise Detour's corridor stays.
TEST(PathFinder, CostedSearchAgreesWithDijkstraOverEveryPortal) {
  Rng rng(20261129);
  int compared = 0, detours = 0, kept = 0;
  for (int world = 0; world < 8; ++world) {
    NavGeometry g{{0, 0, 40, 30}, {}, {}};
    for (int k = 0; k < 6; ++k) {
      const double x = rng.uniform(4, 34), y = rng.uniform(4, 24);
      if (rng.below(3) == 0)
        g.circles.push_back({x, y, rng.uniform(0.5, 2.5), 1});
      else
        g.polygons.push_back(rect(x, y, x + rng.uniform(1, 6), y + rng.uniform(1, 6)));
    }
    auto mesh = NavMesh::build(g, {0.5, 0.25, 32});
    const std::vector<MeshPortal> portals = mesh->portals();
    std::set<std::pair<uint32_t, uint32_t>> adjacent;
    std::set<uint32_t> refs;
    for (const MeshPortal& p : portals) {
      adjacent.insert({p.from, p.to});
      refs.insert(p.from);
    }
    ASSERT_GT(refs.size(), 20u);
    PolygonCosts costs;
    for (uint32_t ref : refs)
      if (rng.below(3) == 0) costs.entries.emplace_back(ref, rng.uniform(0, 25));
    // and, in every other world, three random cuts (any segments: the search only asks which
    // of its steps cross them)
    if (world % 2 == 1)
      for (int k = 0; k < 3; ++k)
        costs.cuts.push_back({{rng.uniform(0, 40), rng.uniform(0, 30)},
                              {rng.uniform(0, 40), rng.uniform(0, 30)},
                              rng.uniform(0, 25)});
    PathFinder f(*mesh);
    for (int q = 0; q < 6; ++q) {
      const Vec2 a{rng.uniform(1, 39), rng.uniform(1, 29)},
          b{rng.uniform(1, 39), rng.uniform(1, 29)};
      const PathResult plain = f.find(a, b);
      if (plain.status != PathStatus::ok) continue;  // in an obstacle, or cut off
      const PathResult r = f.find(a, b, &costs);
      ASSERT_EQ(r.status, PathStatus::ok);
      ASSERT_FALSE(r.corridor.empty());
      if (costs.cuts.empty() && std::none_of(plain.corridor.begin() + 1, plain.corridor.end(),
                                             [&](uint32_t p) { return costs.of(p) > 0; })) {
        EXPECT_EQ(r.corridor, plain.corridor);
        EXPECT_EQ(r.cost, 0);
        ++kept;
        continue;
      }
      EXPECT_EQ(r.corridor.front(), plain.corridor.front());
      EXPECT_EQ(r.corridor.back(), plain.corridor.back());
      for (std::size_t k = 0; k + 1 < r.corridor.size(); ++k)
        EXPECT_TRUE(adjacent.count({r.corridor[k], r.corridor[k + 1]})) << "world " << world;
      const double naive =
          naive_costed(*mesh, r.corridor.front(), r.start, r.corridor.back(), r.end, costs);
      EXPECT_NEAR(r.cost, naive, 1e-6 * naive) << "world " << world << " query " << q;
      // The corridor's own cost through its portals' midpoints is the reported one.
      double along = 0;
      Vec2 at = r.start;
      for (std::size_t k = 0; k + 1 < r.corridor.size(); ++k)
        for (const MeshPortal& p : portals)
          if (p.from == r.corridor[k] && p.to == r.corridor[k + 1]) {
            along +=
                dist(at, midpoint(p)) + costs.of(p.to) + naive_cut_costs(costs, at, midpoint(p));
            at = midpoint(p);
            break;
          }
      along += dist(at, r.end) + naive_cut_costs(costs, at, r.end);
      EXPECT_NEAR(along, r.cost, 1e-6 * r.cost);
      detours += r.corridor != plain.corridor;
      ++compared;
    }
  }
  EXPECT_GE(compared, 15);
  EXPECT_GE(detours, 3);  // the costs do change routes
  std::printf("[ costed   ] %d searches against the naive twin, %d detours; %d kept Detour's\n",
              compared, detours, kept);
}

// Two stands 12 m long with a 1.2 m passage between them and 3 m aisles round them: the route
// goes through the passage unless entering it costs more than the way round.
TEST(PathFinder, APassageThatCostsMoreThanTheWayRoundIsWalkedRound) {
  NavGeometry g{{0, 0, 40, 30}, {}, {rect(14, 3, 26, 14.4), rect(14, 15.6, 26, 27)}};
  auto mesh = NavMesh::build(g, {0.25, 0.0625});
  PathFinder f(*mesh);
  const Vec2 a{5, 15}, b{35, 15};
  const PathResult plain = f.find(a, b);
  ASSERT_EQ(plain.status, PathStatus::ok);
  EXPECT_LT(plain.length, 30.5);
  EXPECT_EQ(plain.cost, 0);  // Detour's search
  const uint32_t passage = mesh->polygon_at({20, 15}, 0.1);
  ASSERT_NE(passage, 0u);
  ASSERT_TRUE(mesh->valid_polygon(passage));
  EXPECT_FALSE(mesh->valid_polygon(0));
  // The way round is 42.7 m against 30 (the search's midpoint measure puts them closer).
  PolygonCosts cheap{{{passage, 1}}, {}}, dear{{{passage, 40}}, {}};
  const PathResult through = f.find(a, b, &cheap), round = f.find(a, b, &dear);
  ASSERT_EQ(through.status, PathStatus::ok);
  ASSERT_EQ(round.status, PathStatus::ok);
  EXPECT_NEAR(through.length, plain.length, 0.05);
  EXPECT_GT(round.length, 42);
  EXPECT_LT(round.length, 44);
  for (const Vec2& c : round.corners) EXPECT_TRUE(c.y < 3 || c.y > 27) << c.x << " " << c.y;
  // With no way round (both aisles closed), the passage is the route whatever it costs.
  NavGeometry closed = g;
  closed.polygons.push_back(rect(14, 0, 26, 3));
  closed.polygons.push_back(rect(14, 27, 26, 30));
  auto cm = NavMesh::build(closed, {0.25, 0.0625});
  PathFinder fc(*cm);
  const PolygonCosts blocked{{{cm->polygon_at({20, 15}, 0.1), 1000}}, {}};
  const PathResult only = fc.find(a, b, &blocked);
  ASSERT_EQ(only.status, PathStatus::ok);
  EXPECT_NEAR(only.length, fc.find(a, b).length, 0.05);
  EXPECT_GT(only.cost, 1000);
}

TEST(NavMesh, TilesJoinSeamlessly) {
  NavGeometry g{{0, 0, 80, 60}, {{40, 30, 6, 1}}, {rect(20, 10, 24, 50), rect(56, 10, 60, 50)}};
  auto one = NavMesh::build(g, {1.0, 0.25, 512});
  auto many = NavMesh::build(g, {1.0, 0.25, 32});
  EXPECT_EQ(one->stats().tiles, 1);
  EXPECT_GT(many->stats().tiles, 50);
  PathFinder f1(*one), fm(*many);
  for (const auto& [a, b] : std::vector<std::pair<Vec2, Vec2>>{
           {{5, 30}, {75, 30}}, {{5, 5}, {75, 55}}, {{30, 55}, {50, 5}}}) {
    const PathResult r1 = f1.find(a, b), rm = fm.find(a, b);
    ASSERT_EQ(r1.status, PathStatus::ok);
    ASSERT_EQ(rm.status, PathStatus::ok);
    EXPECT_NEAR(rm.length, r1.length, 0.02 * r1.length);
    EXPECT_TRUE(many->visible(a, {a.x + 3, a.y}));  // a ray across a tile edge
  }
}

// Point location's grid against its twin, Detour's findNearestPoly: the same polygon and the same
// snapped point, bit for bit, on one-tile and many-tile meshes with obstacles, for random points
// (on and off the mesh, beyond the bounds), every polygon's corners and edge midpoints and points
// a hair either side of them, and square reaches from 0 to 4 m. The grid alone (locate_inside)
// must answer only where it is certain, and must answer well inside polygons: at their centroids.
TEST(NavMesh, PointLocationAgreesWithDetoursSearch) {
  Rng rng(77031);
  const NavGeometry g{
      {0, 0, 80, 60},
      {{40, 30, 6, 1}, {12.3, 47.1, 2.2, 1}},
      {rect(20, 10, 24, 50), rect(56, 10, 60, 50), {{{30, 5}, {36, 7}, {31, 12}}, 1}}};
  std::size_t compared = 0, located = 0, by_grid = 0, centroids = 0, centroid_hits = 0;
  for (const NavMeshParams params : {NavMeshParams{1.0, 0.25, 512}, NavMeshParams{0.25, 0.1, 32},
                                     NavMeshParams{0.5, 0.25, 16}}) {
    auto mesh = NavMesh::build(g, params);
    std::vector<Vec2> points;
    for (int k = 0; k < 4000; ++k) points.push_back({rng.uniform(-2, 82), rng.uniform(-2, 62)});
    for (const auto& ring : mesh->polygons()) {
      Vec2 c{0, 0};
      for (std::size_t v = 0; v < ring.size(); ++v) {
        const Vec2 a = ring[v], b = ring[(v + 1) % ring.size()];
        c.x += a.x / static_cast<double>(ring.size());
        c.y += a.y / static_cast<double>(ring.size());
        for (const Vec2 q : {a, Vec2{0.5 * (a.x + b.x), 0.5 * (a.y + b.y)}})
          for (const double h : {0.0, 1e-7, 1e-5, 1e-3, 2e-3})
            for (const Vec2 d : {Vec2{h, 0}, Vec2{-h, 0}, Vec2{0, h}, Vec2{0, -h}, Vec2{h, h}})
              points.push_back({q.x + d.x, q.y + d.y});
      }
      // Well inside a convex polygon: the grid must answer (a polygon thinner than the margin
      // cannot hold its centroid that far from its edges; none here is).
      ++centroids;
      const NavMesh::Located in = mesh->locate_inside(c);
      centroid_hits += in.ref != 0;
      points.push_back(c);
    }
    for (const Vec2 p : points) {
      const NavMesh::Located in = mesh->locate_inside(p);
      by_grid += in.ref != 0;
      ++located;
      for (const double reach : {0.0, 0.05, 0.5, 4.0}) {
        const NavMesh::Located fast = mesh->locate_point(p, reach);
        const NavMesh::Located naive = mesh->locate_point(p, reach, true);
        ASSERT_EQ(fast.ref, naive.ref) << p.x << " " << p.y << " reach " << reach;
        ASSERT_EQ(std::bit_cast<uint64_t>(fast.at.x), std::bit_cast<uint64_t>(naive.at.x));
        ASSERT_EQ(std::bit_cast<uint64_t>(fast.at.y), std::bit_cast<uint64_t>(naive.at.y));
        if (in.ref != 0) {
          ASSERT_EQ(in.ref, naive.ref) << p.x << " " << p.y;
          ASSERT_EQ(std::bit_cast<uint64_t>(in.at.x), std::bit_cast<uint64_t>(naive.at.x));
        }
        ++compared;
      }
    }
  }
  EXPECT_EQ(centroid_hits, centroids);
  EXPECT_GT(by_grid, located / 20);  // most points are the adversarial ones near edges
  std::printf("[ navmesh  ] %zu point locations compared; %zu of %zu points answered by the grid\n",
              compared, by_grid, located);
}

TEST(NavMesh, BuildAndQueriesAreDeterministicOnAnyThreadCount) {
  NavGeometry g{{0, 0, 80, 60}, {{40, 30, 6, 1}}, {rect(20, 10, 24, 50), rect(56, 10, 60, 50)}};
  Executor two(2);
  auto a = NavMesh::build(g, {1.0, 0.25, 32});
  auto b = NavMesh::build(g, {1.0, 0.25, 32}, &two);
  const auto pa = a->polygons(), pb = b->polygons();
  ASSERT_EQ(pa.size(), pb.size());
  for (std::size_t i = 0; i < pa.size(); ++i) {
    ASSERT_EQ(pa[i].size(), pb[i].size());
    for (std::size_t k = 0; k < pa[i].size(); ++k) {
      EXPECT_EQ(pa[i][k].x, pb[i][k].x);
      EXPECT_EQ(pa[i][k].y, pb[i][k].y);
    }
  }
  PathFinder fa(*a), fb(*b);
  const PathResult ra = fa.find({5, 5}, {75, 55});
  fa.find({70, 5}, {5, 50});  // the search state must not leak into the next query
  const PathResult ra2 = fa.find({5, 5}, {75, 55}), rb = fb.find({5, 5}, {75, 55});
  ASSERT_EQ(ra.corners.size(), rb.corners.size());
  for (std::size_t i = 0; i < ra.corners.size(); ++i) {
    EXPECT_EQ(ra.corners[i].x, rb.corners[i].x);
    EXPECT_EQ(ra.corners[i].y, ra2.corners[i].y);
  }
  EXPECT_EQ(ra.length, rb.length);
  EXPECT_EQ(ra.length, ra2.length);
}

TEST(NavMesh, StartOffTheMeshSnapsOrFails) {
  NavGeometry g{{0, 0, 40, 30}, {}, {rect(10, 10, 30, 20)}};
  auto mesh = NavMesh::build(g, {1.0, 0.25});
  PathFinder f(*mesh);
  // Inside the obstacle, near its edge: snapped to the mesh just outside.
  const PathResult near = f.find({20, 10.5}, {35, 25});
  EXPECT_NE(near.status, PathStatus::no_start);
  EXPECT_LT(near.start.y, 10);
  // Deep inside a large obstacle: nothing within reach.
  NavGeometry big{{0, 0, 200, 200}, {}, {rect(10, 10, 190, 190)}};
  auto bm = NavMesh::build(big, {1.0, 0.25, 128});
  PathFinder fb(*bm);
  EXPECT_EQ(fb.find({100, 100}, {5, 5}).status, PathStatus::no_start);
  EXPECT_FALSE(bm->visible({100, 100}, {5, 5}));
}

TEST(NavMesh, RejectsBadParameters) {
  NavGeometry g{{0, 0, 40, 30}, {}, {}};
  EXPECT_THROW(NavMesh::build(g, {0, 0.25}), Error);
  EXPECT_THROW(NavMesh::build(g, {1, 0}), Error);
  EXPECT_THROW(NavMesh::build(g, {1, 0.25, 8}), Error);
  EXPECT_THROW(NavMesh::build(g, {100, 0.25}), Error);  // erosion beyond Recast's limit
  NavGeometry huge{{0, 0, 1e6, 1e6}, {}, {}};
  EXPECT_THROW(NavMesh::build(huge, {1, 0.25}), Error);  // too many tiles
}

}  // namespace
}  // namespace crowddb::path
