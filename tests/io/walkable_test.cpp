// Walkable areas given as WKT (src/io/walkable_wkt.cpp) and the scenario geometry checks
// (src/io/scenario_json.cpp): valid areas become obstacles that cover exactly the complement;
// invalid geometry gives a one-line error naming the file and the JSON pointer.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <numbers>
#include <sstream>

#include "crowddb/scenario.hpp"
#include "io/walkable_wkt.hpp"
#include "support/cli.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"

namespace crowddb {
namespace {

constexpr const char* kRoomWithPillar =
    "POLYGON((0 0, 40 0, 40 40, 0 40, 0 0), (10 10, 10 14, 14 14, 14 10, 10 10))";

// JSON written with single quotes (WKT is full of parentheses, which raw strings dislike).
std::string q(std::string s) {
  std::replace(s.begin(), s.end(), '\'', '"');
  return s;
}

std::string error_of(const std::function<void()>& f) {
  try {
    f();
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

TEST(WalkableArea, PolygonWithHoles) {
  const io::WalkableArea a = io::WalkableArea::parse(kRoomWithPillar);
  EXPECT_DOUBLE_EQ(a.area(), 1600 - 16);
  const Bounds e = a.envelope();
  EXPECT_EQ(e.xmin, 0);
  EXPECT_EQ(e.ymax, 40);
  EXPECT_TRUE(a.covers(5, 5));
  EXPECT_TRUE(a.covers(0, 20));  // the boundary counts
  EXPECT_FALSE(a.covers(12, 12));
  EXPECT_FALSE(a.covers(41, 5));
}

// covers() decides points away from the boundary by the rings' edge grids and leaves the rest
// to Boost.Geometry: the same answers as covered_by alone, on areas of many vertices with holes
// (one of them holding an island, one touching its outer ring at a vertex), squares sharing a
// vertex, at coordinates near 0, 10^6 and 5 * 10^8, for vertices, points on the lines through
// them, and points off an edge's middle by 0.5 to 10 times the distance under which covers()
// asks Boost (10^-9 of the coordinates), on either side.
TEST(WalkableArea, CoversIsBoostsCoveredBy) {
  Rng rng(5);
  std::size_t inside = 0, total = 0;
  const auto num = [](double v) {
    std::ostringstream os;
    os.precision(17);
    os << v;
    return os.str();
  };
  for (const double offset : {0.0, 1e6, 5e8}) {
    std::vector<std::vector<Vec2>> rings;  // every ring's vertices, for the probes
    const auto text = [&](std::vector<Vec2> v) {
      for (Vec2& p : v) p = {p.x + offset, p.y + offset};
      rings.push_back(v);
      v.push_back(v.front());
      std::string w = "(";
      for (std::size_t k = 0; k < v.size(); ++k)
        w += (k ? ", " : "") + num(v[k].x) + " " + num(v[k].y);
      return w + ")";
    };
    const auto star = [&](double cx, double cy, double r0, double r1, int n, bool cw) {
      std::vector<Vec2> v;
      for (int k = 0; k < n; ++k) {
        const double a = 2 * std::numbers::pi * k / n * (cw ? -1 : 1);
        const double r = rng.uniform(r0, r1);
        v.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
      }
      return text(v);
    };
    const auto box = [&](double x0, double y0, double x1, double y1, bool cw) {
      return cw ? text({{x0, y0}, {x0, y1}, {x1, y1}, {x1, y0}})
                : text({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}});
    };
    // A hall of 3,000 vertices with a hole of 400 holding an island of 200, and a pillar; a
    // square with a triangular hole touching its corner; two squares sharing a vertex.
    const std::string hall = "(" + star(0, 0, 90, 100, 3000, false) + ", " +
                             star(0, 0, 30, 40, 400, true) + ", " + star(60, 0, 3, 4, 6, true) +
                             ")";
    const std::string island = "(" + star(0, 0, 10, 20, 200, false) + ")";
    const std::string notch =
        "(" + box(130, -10, 150, 10, false) + ", " + text({{130, -10}, {135, 5}, {140, 0}}) + ")";
    const std::string pair =
        "(" + box(105, 105, 115, 115, false) + "), (" + box(115, 115, 125, 125, false) + ")";
    const io::WalkableArea a = io::WalkableArea::parse("MULTIPOLYGON(" + hall + ", " + island +
                                                       ", " + notch + ", " + pair + ")");
    const double near = 1e-9 * (offset + 150);  // covers()'s margin, about
    for (int k = 0; k < 20000; ++k) {
      double x = offset + rng.uniform(-120, 160), y = offset + rng.uniform(-120, 130);
      const std::vector<Vec2>& ring = rings[rng.below(rings.size())];
      const std::size_t e = rng.below(ring.size());
      const Vec2& v = ring[e];
      const Vec2& w = ring[(e + 1) % ring.size()];
      switch (k % 4) {
        case 1:  // a vertex, or a point on the horizontal line through one
          x = k % 8 == 1 ? v.x : v.x + rng.uniform(-5, 5);
          y = v.y;
          break;
        case 2:
        case 3: {  // off an edge's middle along its normal, either side
          const double l = std::hypot(w.x - v.x, w.y - v.y);
          if (l == 0) break;
          static constexpr double kOff[] = {0.5, 1, 1.01, 2, 10};
          const double d = kOff[rng.below(5)] * near * (rng.below(2) ? 1 : -1);
          x = (v.x + w.x) / 2 - d * (w.y - v.y) / l;
          y = (v.y + w.y) / 2 + d * (w.x - v.x) / l;
          break;
        }
        default:
          break;
      }
      const bool got = a.covers(x, y);
      ASSERT_EQ(got, a.covers_by_boost(x, y))
          << "offset " << offset << " (" << num(x) << ", " << num(y) << ")";
      inside += got;
      ++total;
    }
  }
  EXPECT_GT(inside, total / 5);
  EXPECT_LT(inside, total - total / 5);
}

TEST(WalkableArea, EitherRingOrientationIsAccepted) {
  const io::WalkableArea ccw = io::WalkableArea::parse("POLYGON((0 0, 10 0, 10 10, 0 10, 0 0))");
  const io::WalkableArea cw = io::WalkableArea::parse("POLYGON((0 0, 0 10, 10 10, 10 0, 0 0))");
  EXPECT_DOUBLE_EQ(ccw.area(), 100);
  EXPECT_DOUBLE_EQ(cw.area(), 100);
}

// The blocked pieces are simple polygons (World accepts them) that exactly fill the bounds
// outside the walkable area, including a frame around it (a ring: split through its hole) and
// the holes themselves; every sample point is in exactly one of walkable / some piece.
TEST(WalkableArea, BlockedPiecesAreTheExactComplement) {
  const char* cases[] = {
      kRoomWithPillar,
      "POLYGON((0 0, 40 0, 40 28, 42 28, 42 0, 82 0, 82 40, 42 40, 42 36, 40 36, 40 40, 0 40, 0 "
      "0), "
      "(58 14, 58 18, 62 18, 62 14, 58 14))",
      "MULTIPOLYGON(((0 0, 10 0, 10 10, 0 10, 0 0)), ((20 0, 30 0, 30 10, 20 10, 20 0), (24 4, 26 "
      "4, 26 6, 24 6, 24 4)))",
      "POLYGON((0 0, 30 0, 15 5, 30 10, 0 10, 0 0), (3 3, 5 3, 5 5, 3 5, 3 3), (7 3, 9 3, 9 5, 7 "
      "5, 7 3))",
  };
  for (const char* wkt : cases) {
    const io::WalkableArea a = io::WalkableArea::parse(wkt);
    const Bounds env = a.envelope();
    for (const Bounds& b : {env, Bounds{env.xmin - 3, env.ymin - 2, env.xmax + 1, env.ymax + 4}}) {
      World w(b);
      double blocked = 0;
      const auto pieces = a.blocked_pieces(b);
      for (const auto& ring : pieces) {
        ASSERT_NO_THROW(w.add_obstacle(PolygonObstacle{ring, 1})) << wkt;
        blocked += signed_area(ring);
        EXPECT_GT(signed_area(ring), 0) << "counter-clockwise";
      }
      EXPECT_NEAR(blocked + a.area(), b.width() * b.height(), 1e-9 * b.width() * b.height()) << wkt;
      for (double x = b.xmin + 0.37; x < b.xmax; x += 1.13)
        for (double y = b.ymin + 0.29; y < b.ymax; y += 0.91) {
          int in = a.covers(x, y);
          for (const PolygonObstacle& p : w.polygons()) in += point_in_polygon(p.vertices, x, y);
          EXPECT_EQ(in, 1) << wkt << " at " << x << "," << y;
        }
    }
  }
}

// The output's walkable area (the `geometry` table) is the bounds less every obstacle: point
// by point, among 150 obstacles that overlap, nest, touch and cross the bounds (circles as the
// 64-gons the WKT draws), and it parses as valid geometry.
TEST(WalkableArea, TheOutputsAreaIsTheBoundsLessEveryObstacle) {
  for (const uint64_t seed : {1u, 2u, 3u}) {
    SCOPED_TRACE(seed);
    Rng rng(seed);
    World w(Bounds{0, 0, 50, 50});
    std::vector<std::vector<Vec2>> shapes;  // each obstacle's outline as the WKT draws it
    for (int o = 0; o < 150; ++o) {
      const double x = rng.uniform(-2, 52), y = rng.uniform(-2, 52), s = rng.uniform(0.3, 4);
      std::vector<Vec2> ring;
      if (o % 3 == 0) {
        w.add_obstacle(CircleObstacle{x, y, s / 2, 1});
        for (int k = 0; k < 64; ++k) {
          const double a = 2 * std::numbers::pi * k / 64;
          ring.push_back({x + s / 2 * std::cos(a), y + s / 2 * std::sin(a)});
        }
      } else {
        ring = o % 3 == 1
                   ? std::vector<Vec2>{{x, y}, {x + s, y}, {x, y + s}}
                   : std::vector<Vec2>{{x, y}, {x + s, y}, {x + s, y + s / 3}, {x, y + s / 3}};
        w.add_obstacle(PolygonObstacle{ring, 1});
      }
      shapes.push_back(ring);
    }
    const io::WalkableArea a = io::WalkableArea::parse(io::walkable_area_wkt(w));
    std::size_t in = 0, out = 0;
    for (int k = 0; k < 4000; ++k) {
      const double x = rng.uniform(0, 50), y = rng.uniform(0, 50);
      bool blocked = false, near_an_edge = false;
      for (const auto& ring : shapes) {
        near_an_edge |= dist2_to_boundary(ring, x, y) < 1e-12;
        blocked |= point_in_polygon(ring, x, y);
      }
      if (near_an_edge) continue;  // on an edge: either answer is the area's
      EXPECT_EQ(a.covers(x, y), !blocked) << "(" << x << ", " << y << ")";
      (blocked ? out : in) += 1;
    }
    EXPECT_GT(in, 1000u);
    EXPECT_GT(out, 200u);
  }
}

TEST(WalkableArea, InvalidGeometryIsNamed) {
  const std::pair<const char*, const char*> cases[] = {
      {"POLYGON((0 0, 10 10, 10 0, 0 10, 0 0))", "self-intersecting"},
      {"POLYGON((0 0, 10 0, 10 10, 0 10))", "is not closed: it starts at (0 0) but ends at (0 10)"},
      {"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (2 2, 4 2, 4 4, 2 4))", "hole 1 is not closed"},
      {"POLYGON((0 0, 10 0, 0 0))", "has 3 points"},
      {"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (20 20, 22 20, 22 22, 20 22, 20 20))",
       "hole lies outside"},
      {"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (1 1, 9 1, 9 9, 1 9, 1 1), (2 2, 3 2, 3 3, 2 3, 2 "
       "2))",
       "nested"},
      {"MULTIPOLYGON(((0 0, 10 0, 10 10, 0 10, 0 0)), ((5 5, 15 5, 15 15, 5 15, 5 5)))", "overlap"},
      {"POLYGON((0 0, 10 10, 10 0, 0 10, 0 0))",
       "the edge from (0 0) to (10 10) meets the edge from (10 0) to (0 10)"},
      {"POLYGON((0 0, 10 0, 20 0, 0 0))", "self-intersecting"},  // folds back onto itself
      {"POLYGON((0 0, 10 0, 10 10, 0 10, 0 0), (2 2, 4 4, 4 2, 2 4, 2 2))",
       "self-intersecting: in hole 1"},
      {"POLYGON((0 0, 10 0, 10", "malformed WKT"},
      {"LINESTRING(0 0, 1 1)", "expected a WKT POLYGON or MULTIPOLYGON, got 'LINESTRING'"},
      {"", "expected a WKT POLYGON or MULTIPOLYGON"},
  };
  for (const auto& [wkt, needle] : cases) {
    const std::string msg = error_of([&, &wkt = wkt] { io::WalkableArea::parse(wkt); });
    EXPECT_NE(msg.find(needle), std::string::npos) << wkt << " -> " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << "one line: " << msg;
  }
}

// ------------------------------------------------------------------ scenario files

const std::string kRoom = std::string("'walkable': '") + kRoomWithPillar + "'";

// A scenario with one goal and one agent unless given; JSON in single quotes.
std::string scenario(const std::string& extra,
                     const std::string& agents = "[{'x': 5, 'y': 5, 'goal': 'g'}]",
                     const std::string& goals = "[{'name': 'g', 'x': 30, 'y': 30}]") {
  return q("{'goals': " + goals + ", 'agents': " + agents + ", " + extra + "}");
}

TEST(ScenarioGeometry, WalkableAreaBecomesBoundsAndObstacles) {
  const Scenario sc = parse_scenario(scenario(kRoom), "t.json");
  EXPECT_EQ(sc.world.bounds().xmax, 40);
  EXPECT_EQ(sc.world.polygons().size(), 1u);  // the pillar; the room fills its bounds
  const Scenario framed = parse_scenario(
      scenario(std::string("'bounds': [-2, -2, 42, 42], 'walls': false, 'walkable': {'wkt': '") +
               kRoomWithPillar + "', 'charge': 0.25}"),
      "t.json");
  EXPECT_GE(framed.world.polygons().size(), 3u);  // the pillar and the frame (split in two)
  for (const PolygonObstacle& p : framed.world.polygons()) EXPECT_EQ(p.charge, 0.25);
}

TEST(ScenarioGeometry, ErrorsNameTheFileAndField) {
  const std::string box = "'bounds': [0, 0, 40, 40]";
  const std::pair<std::string, std::string> cases[] = {
      {scenario("'walkable': 'POLYGON((0 0, 10 10, 10 0, 0 10, 0 0))'"),
       "t.json: /walkable: invalid walkable area: it is self-intersecting"},
      {scenario("'walkable': 'POLYGON((0 0, 10 0, 10 10, 0 10))'"),
       "t.json: /walkable: the outer ring is not closed"},
      {scenario("'walkable': {'wkt': 'POLYGON((0 0, 10 0, 10 10, 0 10))'}"),
       "t.json: /walkable/wkt: the outer ring is not closed"},
      {scenario("'walkable': 3"), "t.json: /walkable: expected a string"},
      {scenario(kRoom, "[{'x': 12, 'y': 12, 'goal': 'g'}]"),
       "t.json: /agents/0: agent at (12, 12) lies outside the walkable area"},
      {scenario(kRoom, "[{'x': 5, 'y': 5, 'goal': 'g'}]", "[{'name': 'g', 'x': 50, 'y': 5}]"),
       "t.json: /goals/0: goal 'g' at (50, 5) lies outside the walkable area"},
      {scenario(
           kRoom, "[]",
           "[{'name': 'g', 'x': 30, 'y': 30}], 'groups': [{'count': 9, 'goal': 'g', 'placement': "
           "{'type': 'grid', 'region': [8, 8, 16, 16], 'spacing': 4}}]"),
       "t.json: /groups/0: agent 5 of 9 at (12, 12) lies outside the walkable area"},
      {scenario("'bounds': [0, 0, 30, 30], " + kRoom),
       "t.json: /walkable: the walkable area extends outside the bounds"},
      {scenario(
           box +
           ", 'obstacles': [{'type': 'circle', 'x': 1, 'y': 1, 'radius': 0.5}, {'type': 'polygon', "
           "'vertices': [[20, 20], [40, 20], [40, 40], [20, 40]]}]"),
       "t.json: /goals/0: goal 'g' at (30, 30) lies inside obstacle /obstacles/1, outside the "
       "walkable area"},
      {scenario(box + ", 'obstacles': [{'type': 'circle', 'x': 5, 'y': 6, 'radius': 2}]"),
       "t.json: /agents/0: agent at (5, 5) lies inside obstacle /obstacles/0"},
      {scenario("'bounds': [0, 0, 20, 20]"),
       "t.json: /goals/0: goal 'g' at (30, 30) lies outside the bounds (the walls)"},
      {scenario("'dt': 1"), "t.json: /bounds: missing"},
      {scenario(box + ", 'navigation': {'latency': -1}"),
       "t.json: /navigation/latency: must be >= 0"},
      {scenario(box + ", 'navigation': {'budget': 0}"), "t.json: /navigation/budget: must be >= 1"},
      {scenario(box + ", 'navigation': {'corner_push': -0.1}"),
       "t.json: /navigation/corner_push: must be >= 0"},
      {scenario(box + ", 'navigation': {'cell': 1}"), "t.json: /navigation/cell: unknown key"},
      {scenario(box + ", 'navigation': {'tile_size': 8}"),
       "t.json: /navigation/tile_size: must be in 16..4096"},
      {scenario(box + ", 'navigation': {}", "[{'x': 5, 'y': 5, 'goal': 'g', 'via': [[10, 10]]}]"),
       "t.json: /navigation: cannot be combined with \"via\" waypoints"},
  };
  for (const auto& [text, needle] : cases) {
    const std::string msg = error_of([&, &text = text] { parse_scenario(text, "t.json"); });
    EXPECT_NE(msg.find(needle), std::string::npos) << text << "\n -> " << msg;
    EXPECT_EQ(msg.find('\n'), std::string::npos) << msg;
  }
}

TEST(ScenarioGeometry, NavigationBlockSwitchesTheServiceOn) {
  EXPECT_FALSE(
      parse_scenario(scenario("'bounds': [0, 0, 40, 40]"), "t.json").config.navigation.enabled);
  const Scenario on = parse_scenario(
      scenario(
          "'bounds': [0, 0, 40, 40], 'navigation': {'latency': 4, 'budget': 9, 'replan_after': 0, "
          "'radius_step': 0.5, 'cell_size': 0.2, 'clearance': 0.1, 'tile_size': 64, "
          "'skip_visible': false, 'sight_interval': 3, 'corner_push': 0.5}"),
      "t.json");
  const NavigationParams& n = on.config.navigation;
  EXPECT_TRUE(n.enabled);
  EXPECT_EQ(n.latency, 4u);
  EXPECT_EQ(n.budget, 9u);
  EXPECT_EQ(n.replan_after, 0u);
  EXPECT_EQ(n.radius_step, 0.5);
  EXPECT_EQ(n.cell_size, 0.2);
  EXPECT_EQ(n.clearance, 0.1);
  EXPECT_EQ(n.corner_push, 0.5);
  EXPECT_EQ(n.tile_size, 64u);
  EXPECT_FALSE(n.skip_visible);
  EXPECT_EQ(n.sight_interval, 3u);
  EXPECT_FALSE(parse_scenario(
                   scenario("'bounds': [0, 0, 40, 40], 'navigation': {'enabled': false}"), "t.json")
                   .config.navigation.enabled);
}

TEST(ScenarioGeometry, EveryShippedScenarioLoads) {
  std::size_t n = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(CROWDDB_SOURCE_DIR) + "/scenarios")) {
    if (entry.path().extension() != ".json") continue;
    EXPECT_NO_THROW(load_scenario(entry.path())) << entry.path();
    ++n;
  }
  EXPECT_GE(n, 7u);
}

// The CLI turns a geometry error into one line on stderr and a non-zero exit status.
TEST(ScenarioGeometry, CliReportsBadGeometryOnOneLine) {
  test::TempDir dir;
  dir.write("bowtie.json", scenario("'walkable': 'POLYGON((0 0, 10 10, 10 0, 0 10, 0 0))'"));
  const test::CliResult r = test::run_cli("validate " + (dir / "bowtie.json").string(), dir);
  EXPECT_EQ(r.status, 1);
  EXPECT_TRUE(r.out.empty()) << r.out;
  EXPECT_NE(r.err.find("bowtie.json: /walkable: invalid walkable area: it is self-intersecting"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
}

// `crowddb run --explain` shows the path service; `--no-navigation` switches it off.
TEST(ScenarioGeometry, CliExplainShowsThePathService) {
  test::TempDir dir;
  const std::string file = std::string(CROWDDB_SOURCE_DIR) + "/scenarios/two_rooms.json";
  const test::CliResult on = test::run_cli("run " + file + " --explain", dir);
  EXPECT_EQ(on.status, 0) << on.err;
  EXPECT_NE(on.out.find("path service: Recast/Detour"), std::string::npos) << on.out;
  EXPECT_NE(on.out.find("path requests      new goal, or no progress for 4 s"), std::string::npos)
      << on.out;
  const test::CliResult off = test::run_cli("run " + file + " --explain --no-navigation", dir);
  EXPECT_EQ(off.status, 0) << off.err;
  EXPECT_EQ(off.out.find("path service"), std::string::npos) << off.out;
}

}  // namespace
}  // namespace crowddb
