#include "crowddb/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "crowddb/simulation.hpp"
#include "support/configs.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"

namespace crowddb {
namespace {

World world_with_goals(int goals = 2) {
  World w(Bounds{0, 0, 100, 100});
  for (int g = 0; g < goals; ++g)
    w.add_goal({std::string("g").append(std::to_string(g)), 10.0 * g, 5, 1, 1, {}});
  return w;
}

AgentSpec spec_at(double x, double y, uint32_t goal = 0) {
  AgentSpec s;
  s.x = x;
  s.y = y;
  s.goal = goal;
  return s;
}

TEST(World, InsertsAreBufferedUntilApplied) {
  World w = world_with_goals();
  const AgentId a = w.insert(spec_at(1, 2));
  EXPECT_EQ(w.agents().size(), 0u);
  EXPECT_FALSE(w.contains(a));
  EXPECT_EQ(w.apply_pending(), 1u);
  ASSERT_TRUE(w.contains(a));
  EXPECT_EQ(w.agents().x[*w.row_of(a)], 1);
  EXPECT_EQ(w.agents().target_x[*w.row_of(a)], 0);  // goal 0 at (0, 5)
  w.validate();
}

// reserve() is room and nothing else: the same inserts, erases and batches give the same table
// and ids with it as without, also when called with changes pending or below the size; an
// impossible count is refused and changes nothing.
TEST(World, ReserveGivesRoomAndChangesNothingElse) {
  auto run = [](bool reserve) {
    World w = world_with_goals();
    if (reserve) w.reserve(1000);
    std::vector<AgentId> ids;
    for (int i = 0; i < 300; ++i) ids.push_back(w.insert(spec_at(1 + i % 90, 1 + i / 90)));
    if (reserve) {
      EXPECT_GE(w.agents().x.capacity(), 1000u);
      w.reserve(2000);  // with 300 inserts pending
      EXPECT_EQ(w.pending_changes(), 300u);
    }
    w.apply_pending();
    for (int i = 0; i < 300; i += 7) w.erase(ids[static_cast<std::size_t>(i)]);
    if (reserve) w.reserve(10);  // below the size: nothing
    w.apply_pending();
    for (int i = 0; i < 50; ++i) w.insert(spec_at(50, 1 + i, 1));
    w.apply_pending();
    w.validate();
    return w;
  };
  const World plain = run(false), roomy = run(true);
  EXPECT_EQ(plain.agents().id, roomy.agents().id);
  EXPECT_EQ(plain.agents().x, roomy.agents().x);
  EXPECT_EQ(plain.agents().y, roomy.agents().y);
  EXPECT_EQ(plain.agents().goal, roomy.agents().goal);
  World w = world_with_goals();
  w.insert(spec_at(1, 1));
  EXPECT_THROW(w.reserve(std::size_t{1} << 40), Error);
  EXPECT_EQ(w.pending_changes(), 1u);
  EXPECT_EQ(w.apply_pending(), 1u);
}

// A reorder keeps the room reserved: a loader reserves for the agents sources will let in, and
// the reorder of the first tick (Simulation, every few seconds from 4,096 rows) rebuilt each
// column with room for exactly its rows, so the next agent moved them all again.
TEST(World, PermutingRowsKeepsTheRoomReserved) {
  World w = world_with_goals();
  w.reserve(500);
  for (int i = 0; i < 300; ++i) w.insert(spec_at(1 + i % 90, 1 + i / 90, i % 2));
  w.apply_pending();
  std::vector<uint32_t> order(300);
  for (uint32_t r = 0; r < 300; ++r) order[r] = 299 - r;
  w.permute_rows(order);
  EXPECT_GE(w.agents().x.capacity(), 500u);  // a column that differs from row to row
  EXPECT_GE(w.agents().id.capacity(), 500u);
  EXPECT_GE(w.agents().goal.capacity(), 500u);
  EXPECT_EQ(w.agents().x[0], 1 + 299 % 90);
  const double* x = w.agents().x.data();
  for (int i = 0; i < 200; ++i) w.insert(spec_at(50, 1 + i % 90));
  w.apply_pending();
  EXPECT_EQ(w.agents().x.data(), x);
  w.validate();
}

TEST(World, EraseSwapsLastRowInAndKeepsHandlesValid) {
  World w = world_with_goals();
  const AgentId a = w.insert(spec_at(1, 0)), b = w.insert(spec_at(2, 0)),
                c = w.insert(spec_at(3, 0));
  w.apply_pending();
  w.erase(a);
  EXPECT_TRUE(w.contains(a));  // still there until the batch is applied
  w.apply_pending();
  EXPECT_FALSE(w.contains(a));
  ASSERT_TRUE(w.contains(b) && w.contains(c));
  EXPECT_EQ(w.agents().x[*w.row_of(c)], 3);
  EXPECT_EQ(w.agents().x[*w.row_of(b)], 2);
  w.validate();
}

TEST(World, ReusedSlotsGetNewGenerationsSoIdsAreNeverReused) {
  World w = world_with_goals();
  const AgentId a = w.insert(spec_at(1, 0));
  w.apply_pending();
  w.erase(a);
  w.apply_pending();
  const AgentId b = w.insert(spec_at(2, 0));
  w.apply_pending();
  EXPECT_EQ(a.index, b.index);
  EXPECT_NE(a.value(), b.value());
  EXPECT_FALSE(w.contains(a));
  EXPECT_THROW(w.erase(a), Error);
  EXPECT_THROW(w.retarget(a, 1), Error);
  w.validate();
}

TEST(World, InsertThenEraseInOneBatchLeavesNothing) {
  World w = world_with_goals();
  const AgentId a = w.insert(spec_at(1, 0));
  w.erase(a);
  w.apply_pending();
  EXPECT_EQ(w.agents().size(), 0u);
  EXPECT_FALSE(w.contains(a));
  EXPECT_THROW(w.erase(a), Error);
  w.validate();
}

TEST(World, DoubleEraseInOneBatchIsRejectedAtTheCall) {
  World w = world_with_goals();
  const AgentId a = w.insert(spec_at(1, 0));
  w.apply_pending();
  w.erase(a);
  EXPECT_THROW(w.erase(a), Error);
  w.apply_pending();
  w.validate();
}

TEST(World, RetargetChangesGoalAndTargetAtNextBatch) {
  World w = world_with_goals();
  const AgentId a = w.insert(spec_at(1, 0));
  w.apply_pending();
  w.retarget(a, 1);
  EXPECT_EQ(w.agents().goal[0], 0u);
  w.apply_pending();
  EXPECT_EQ(w.agents().goal[0], 1u);
  EXPECT_EQ(w.agents().target_x[0], 10);
  EXPECT_THROW(w.retarget(a, 7), InvalidRow);
}

struct BadField {
  const char* field;
  void (*mutate)(AgentSpec&);
};

void PrintTo(const BadField& b, std::ostream* os) {
  *os << b.field;
}

class InvalidAgentRow : public ::testing::TestWithParam<BadField> {};

TEST_P(InvalidAgentRow, IsRejectedNamingTheFieldAndNothingIsLost) {
  World w = world_with_goals();
  const AgentId keep = w.insert(spec_at(5, 5));
  w.apply_pending();
  AgentSpec s = spec_at(1, 1);
  GetParam().mutate(s);
  try {
    w.insert(s);
    FAIL() << "accepted an invalid " << GetParam().field;
  } catch (const InvalidRow& e) {
    EXPECT_EQ(e.field(), GetParam().field);
    EXPECT_NE(std::string(e.what()).find(GetParam().field), std::string::npos) << e.what();
  }
  EXPECT_EQ(w.pending_changes(), 0u);
  w.apply_pending();
  EXPECT_EQ(w.agents().size(), 1u);
  EXPECT_TRUE(w.contains(keep));
  w.validate();
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

INSTANTIATE_TEST_SUITE_P(
    World, InvalidAgentRow,
    ::testing::Values(BadField{"x", [](AgentSpec& s) { s.x = kNaN; }},
                      BadField{"y", [](AgentSpec& s) { s.y = kInf; }},
                      BadField{"vx", [](AgentSpec& s) { s.vx = kNaN; }},
                      BadField{"radius", [](AgentSpec& s) { s.radius = 0; }},
                      BadField{"radius", [](AgentSpec& s) { s.radius = -1; }},
                      BadField{"max_speed", [](AgentSpec& s) { s.max_speed = -2; }},
                      BadField{"max_accel", [](AgentSpec& s) { s.max_accel = kNaN; }},
                      BadField{"charge", [](AgentSpec& s) { s.charge = kInf; }},
                      BadField{"goal", [](AgentSpec& s) { s.goal = 9; }}),
    // Named by index and field: the default printer would name each case by pointer bytes,
    // which change from run to run and so never match ctest's stored filter.
    [](const ::testing::TestParamInfo<BadField>& param_info) {
      return std::to_string(param_info.index) + "_" + param_info.param.field;
    });

TEST(World, InvalidStaticRowsAreRejected) {
  World w = world_with_goals();
  EXPECT_THROW(w.add_goal({"bad", kNaN, 0, 1, 1, {}}), InvalidRow);
  EXPECT_THROW(w.add_goal({"bad", 0, 0, 1, 0, {}}), InvalidRow);
  EXPECT_THROW(w.add_obstacle(CircleObstacle{0, 0, -1, 1}), InvalidRow);
  EXPECT_THROW(w.add_obstacle(PolygonObstacle{{{0, 0}, {1, 1}}, 1}), InvalidRow);
  // A bow tie is not a simple polygon.
  EXPECT_THROW(w.add_obstacle(PolygonObstacle{{{0, 0}, {2, 2}, {2, 0}, {0, 2}}, 1}), InvalidRow);
  EXPECT_THROW(w.add_obstacle(PolygonObstacle{{{0, 0}, {1, 0}, {2, 0}}, 1}),
               InvalidRow);  // zero area
  EXPECT_EQ(w.goals().size(), 2u);
  EXPECT_TRUE(w.circles().empty());
  EXPECT_TRUE(w.polygons().empty());
}

// The API refuses what the scenario reader refuses: bounds that are inverted or not finite (in
// the constructor too), a duplicate goal name, and agents whose centre is outside the walkable
// area: outside the walls, or strictly inside an obstacle (its boundary is walkable).
TEST(World, ApiRefusesBadBoundsDuplicateGoalsAndAgentsOutsideTheWalkableArea) {
  const auto field_of = [](auto&& f) -> std::string {
    try {
      f();
    } catch (const InvalidRow& e) {
      return e.field() + ": " + e.what();
    }
    return "accepted";
  };
  EXPECT_EQ(field_of([] { World w(Bounds{10, 0, 0, 10}); }).rfind("bounds: ", 0), 0u);
  EXPECT_EQ(field_of([] { World w(Bounds{0, 0, kNaN, 10}); }).rfind("bounds: ", 0), 0u);
  EXPECT_EQ(field_of([] { World w(Bounds{0, 0, 1e300, 10}); }).rfind("bounds: ", 0), 0u);
  World w = world_with_goals();
  EXPECT_EQ(field_of([&] {
              w.add_goal({"g0", 1, 1, 1, 1, {}});
            }),
            "name: duplicate goal name 'g0'");

  w.add_obstacle(CircleObstacle{50, 50, 5, 1});
  w.add_obstacle(PolygonObstacle{{{20, 20}, {30, 20}, {30, 30}, {20, 30}}, 1});
  EXPECT_EQ(field_of([&] { w.insert(spec_at(-1, 50)); }),
            "x: the agent at (-1, 50) lies outside the bounds [0, 100] x [0, 100] (the walls)");
  EXPECT_EQ(field_of([&] { w.insert(spec_at(50, 100.5)); }).rfind("x: ", 0), 0u);
  EXPECT_EQ(field_of([&] { w.insert(spec_at(52, 51)); }),
            "x: the agent at (52, 51) lies inside circle obstacle 0");
  EXPECT_EQ(field_of([&] { w.insert(spec_at(25, 29.9)); }),
            "x: the agent at (25, 29.899999999999999) lies inside polygon obstacle 0");
  EXPECT_EQ(w.pending_changes(), 0u);  // nothing was stored
  // The boundary is walkable (an agent may stand against a wall or obstacle), and so is every
  // point of the bounds.
  for (const auto& p : std::vector<std::pair<double, double>>{
           {55, 50}, {20, 25}, {30, 30}, {0, 0}, {100, 100}, {31, 25}, {10, 90}})
    EXPECT_EQ(field_of([&] { w.insert(spec_at(p.first, p.second)); }), "accepted")
        << p.first << ", " << p.second;

  // Without walls the bounds do not bound agents; turning walls on checks the agents there.
  World open = world_with_goals();
  open.set_walls(false);
  open.insert(spec_at(150, 50));
  EXPECT_EQ(field_of([&] { open.set_walls(true); }).rfind("x: the agent at (150, 50)", 0), 0u);
  EXPECT_FALSE(open.walls());
  // A world without bounds has no outside.
  World unbounded;
  unbounded.add_goal({"g", 0, 0, 1, 1, {}});
  EXPECT_EQ(field_of([&] { unbounded.insert(spec_at(1e6, -1e6)); }), "accepted");
}

// Simulation takes SimConfig::walls: an agent outside the bounds is fine without walls and an
// error with them.
TEST(World, SimulationChecksTheWorldAgainstItsWalls) {
  World w = world_with_goals();
  w.set_walls(false);
  w.insert(spec_at(120, 5));
  SimConfig walled;
  EXPECT_THROW(Simulation(World(w), walled), InvalidRow);
  SimConfig open = walled;
  open.walls = false;
  Simulation sim(std::move(w), open);
  EXPECT_EQ(sim.world().agents().size(), 1u);
}

TEST(World, PolygonsAreStoredCounterClockwiseAndClosingVertexDropped) {
  World w = world_with_goals();
  w.add_obstacle(PolygonObstacle{{{0, 0}, {0, 1}, {1, 1}, {1, 0}, {0, 0}}, 1});
  ASSERT_EQ(w.polygons().size(), 1u);
  const auto& v = w.polygons()[0].vertices;
  ASSERT_EQ(v.size(), 4u);
  double area2 = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    area2 += v[i].x * v[(i + 1) % v.size()].y - v[(i + 1) % v.size()].x * v[i].y;
  EXPECT_GT(area2, 0);
}

// add_goal stores a convex area's inward edge normals so that goal_target need not take square
// roots per call; a goal built by hand (none stored) must get the very same targets, and a
// polygon that is not convex stores none (its target is the nearest boundary point).
TEST(World, GoalTargetsFromStoredNormalsEqualThoseComputedPerCall) {
  World w(Bounds{-50, -50, 50, 50});
  Rng rng(7);
  for (int k = 0; k < 40; ++k) {
    // A convex polygon: corners at increasing angles round a centre (counter-clockwise).
    const std::size_t n = 3 + rng.below(10);
    std::vector<double> angles(n);
    for (double& a : angles) a = rng.uniform(0, 2 * std::numbers::pi);
    std::sort(angles.begin(), angles.end());
    Goal g{"c" + std::to_string(k), rng.uniform(-5, 5), rng.uniform(-5, 5), 1, 1, {}};
    const double rx = rng.uniform(0.3, 6), ry = rng.uniform(0.3, 6);
    for (double a : angles) g.area.push_back({g.x + rx * std::cos(a), g.y + ry * std::sin(a)});
    if (!point_in_polygon(g.area, g.x, g.y)) continue;  // a sliver not round its centre
    const uint32_t row = w.add_goal(g);  // (before goals(): adding may move the table)
    const Goal& stored = w.goals()[row];
    ASSERT_EQ(stored.inward_normals.size(), stored.area.size());
    Goal by_hand = stored;
    by_hand.inward_normals.clear();
    for (int q = 0; q < 200; ++q) {
      const double px = rng.uniform(-20, 20), py = rng.uniform(-20, 20);
      const double r = q % 4 == 0 ? 0 : rng.uniform(0.05, 1.5);
      const Vec2 a = goal_target(stored, px, py, r), b = goal_target(by_hand, px, py, r);
      ASSERT_EQ(a.x, b.x) << k << " " << px << " " << py << " " << r;
      ASSERT_EQ(a.y, b.y);
      // Arrival: inside or within a micrometre of the boundary (the box test is only a shortcut).
      const Vec2& corner = stored.area[q % stored.area.size()];
      const double cx = corner.x + rng.uniform(-3e-3, 3e-3),
                   cy = corner.y + rng.uniform(-3e-3, 3e-3);
      for (const auto& [x, y] : {std::pair{px, py}, std::pair{cx, cy}, std::pair{a.x, a.y}}) {
        ASSERT_EQ(inside_goal(stored, x, y), point_in_polygon(stored.area, x, y) ||
                                                 dist2_to_boundary(stored.area, x, y) <= 1e-12);
      }
      // Outside the area, the target keeps the disc inside wherever the area is wide enough.
      if (r > 0 && !point_in_polygon(stored.area, px, py) &&
          !(dist2_to_boundary(stored.area, a.x, a.y) < 0.99 * r * r)) {
        EXPECT_TRUE(point_in_polygon(stored.area, a.x, a.y));
      }
    }
  }
  const uint32_t row =
      w.add_goal({"L", 1, 1, 1, 1, {{0, 0}, {4, 0}, {4, 2}, {2, 2}, {2, 4}, {0, 4}}});
  const Goal& l = w.goals()[row];
  EXPECT_TRUE(l.inward_normals.empty());
  const Vec2 c = goal_target(l, 3, 2.5, 0.5);  // the nearest boundary point, not eroded
  EXPECT_EQ(c.x, 3);
  EXPECT_EQ(c.y, 2);
}

}  // namespace
}  // namespace crowddb
