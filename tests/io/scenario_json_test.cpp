#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "crowddb/scenario.hpp"
#include "support/cli.hpp"
#include "world/geometry.hpp"

namespace crowddb {
namespace {

const char* kMinimal = R"({
  "bounds": [0, 0, 100, 100],
  "goals": [{"name": "g", "x": 90, "y": 50}],
  "agents": [{"x": 10, "y": 50, "radius": 1, "max_speed": 1, "goal": "g"}]
})";

std::string error_of(const std::string& text) {
  try {
    parse_scenario(text, "s.json");
  } catch (const Error& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "not one line: " << e.what();
    return e.what();
  }
  return "";
}

TEST(ScenarioJson, MinimalFileHasDefaults) {
  Scenario sc = parse_scenario(kMinimal, "s.json");
  EXPECT_EQ(sc.world.agents().size(), 1u);
  EXPECT_EQ(sc.config.dt, 0.1);
  EXPECT_EQ(sc.ticks, 600u);  // 60 s
  EXPECT_EQ(sc.config.steering.model, "orca");
  EXPECT_TRUE(sc.config.backoff);
  EXPECT_EQ(sc.config.access.ftc, "auto");
  EXPECT_TRUE(std::isinf(sc.world.agents().max_accel[0]));
  // max_speed given alone: pref_speed follows it (files written for the thesis's rule).
  EXPECT_EQ(sc.world.agents().pref_speed[0], 1.0);
  EXPECT_EQ(sc.world.goals()[0].arrival_radius, 0.5);
  EXPECT_TRUE(sc.warnings.empty());
}

TEST(ScenarioJson, UnitsAreMetresAndSeconds) {
  const std::string text = R"({"bounds": [0, 0, 100, 100], "dt": 0.05, "duration": 12.5,
    "gridlock_time": 3, "nudge_after": 0.5, "stall": {"after": 3, "progress": 0.2},
    "navigation": {"latency": 0.25, "replan_after": 6},
    "steering": {"orca": {"time_horizon": 3, "time_horizon_obst": 1, "neighbor_dist": 4}},
    "goals": [{"name": "g", "x": 90, "y": 50}],
    "agents": [{"x": 10, "y": 50, "goal": "g"}, {"x": 10, "y": 60, "pref_speed": 1.1, "goal": "g"},
               {"x": 10, "y": 70, "pref_speed": 1.1, "max_speed": 2, "goal": "g"}]})";
  const Scenario sc = parse_scenario(text, "s.json");
  EXPECT_EQ(sc.ticks, 250u);  // 12.5 s at 0.05 s per tick
  EXPECT_EQ(sc.config.ticks_for(sc.config.gridlock_time), 60u);
  EXPECT_EQ(sc.config.ticks_for(sc.config.nudge_after), 10u);
  EXPECT_EQ(sc.config.ticks_for(sc.config.stall.after), 60u);  // not the default (2 s)
  EXPECT_EQ(sc.config.ticks_for(sc.config.navigation.latency), 5u);
  EXPECT_EQ(sc.config.steering.orca.time_horizon, 3.0);
  const AgentTable& t = sc.world.agents();
  EXPECT_EQ(t.pref_speed[0], 1.34);  // Weidmann's free speed
  EXPECT_EQ(t.max_speed[0], 1.34);
  EXPECT_EQ(t.pref_speed[1], 1.1);
  EXPECT_EQ(t.max_speed[1], 1.1);
  EXPECT_EQ(t.max_speed[2], 2.0);
}

TEST(ScenarioJson, GoalAreasSequencesAndTargets) {
  const std::string text = R"({"bounds": [0, 0, 100, 100],
    "goals": [{"name": "door", "area": [[90, 40], [100, 40], [100, 60], [90, 60]]},
              {"name": "L", "area": [[10, 10], [30, 10], [30, 12], [12, 12], [12, 30], [10, 30]]},
              {"name": "p", "x": 50, "y": 50, "arrival_radius": 2}],
    "agents": [{"x": 5, "y": 50, "goal": ["p", "door"]}],
    "groups": [{"count": 3, "placement": {"type": "grid", "region": [40, 80, 60, 90], "spacing": 5},
                "goals": {"assign": "targets", "points": [[45, 20], [50, 20], [55, 20]], "arrival_radius": 1},
                "then": ["door"]}]})";
  const Scenario sc = parse_scenario(text, "s.json");
  const auto goals = sc.world.goals();
  ASSERT_EQ(goals.size(), 6u);  // three named, one per target
  EXPECT_TRUE(goals[0].is_polygon());
  EXPECT_EQ(goals[0].x, 95);  // its centroid
  EXPECT_EQ(goals[0].y, 50);
  // The L's centroid lies outside it: the goal's point is moved inside.
  EXPECT_TRUE(point_in_polygon(goals[1].area, goals[1].x, goals[1].y));
  const AgentTable& t = sc.world.agents();
  EXPECT_EQ(t.goal[0], 2u);
  EXPECT_EQ(t.then[0], (std::vector<uint32_t>{0}));
  for (std::size_t i = 1; i < 4; ++i) {
    EXPECT_EQ(goals[t.goal[i]].x, 40 + 5.0 * static_cast<double>(i));
    EXPECT_EQ(goals[t.goal[i]].y, 20);
    EXPECT_EQ(t.then[i], (std::vector<uint32_t>{0}));
  }
  // An agent steers for the nearest point of a polygon goal where its disc fits: the nearest
  // point of the area eroded by its radius (in the middle across an area thinner than the disc).
  EXPECT_EQ(goal_target(goals[0], 50, 45).x, 90);
  EXPECT_EQ(goal_target(goals[0], 50, 45).y, 45);
  const Vec2 fit = goal_target(goals[0], 50, 45, 0.5);
  EXPECT_NEAR(fit.x, 90.5, 1e-12);
  EXPECT_NEAR(fit.y, 45, 1e-12);
  const Vec2 corner = goal_target(goals[0], 50, 20, 0.5);  // below the area: its eroded corner
  EXPECT_NEAR(corner.x, 90.5, 1e-12);
  EXPECT_NEAR(corner.y, 40.5, 1e-12);
  Goal slot{"slot", 22.5, 20.75, 1, 1, {{22, 20.5}, {23, 20.5}, {23, 21}, {22, 21}}};
  // 0.5 m deep, thinner than a disc of radius 0.3: eroded by the 0.25 m that fits.
  const Vec2 door = goal_target(slot, 22.8, 19.86, 0.3);
  EXPECT_NEAR(door.x, 22.75, 1e-6);  // beside the jamb: pulled in to fit
  EXPECT_NEAR(door.y, 20.75, 1e-6);  // the middle across
}

TEST(ScenarioJson, SourcesAreRead) {
  const std::string text = R"({"bounds": [0, 0, 100, 100],
    "goals": [{"name": "a", "x": 90, "y": 50}, {"name": "b", "x": 90, "y": 10}],
    "sources": [{"name": "gate", "area": [0, 40, 4, 60], "rate": 2, "count": 30, "start": 5, "end": 20,
                 "radius": [0.2, 0.3], "pref_speed": [1, 1.4], "max_speed": 1.6, "goals": ["a", "b"]},
                {"polygon": [[10, 10], [20, 10], [15, 20]], "rate": 0.5, "count": 3, "goal": ["b", "a"]}]})";
  const Scenario sc = parse_scenario(text, "s.json");
  ASSERT_EQ(sc.world.sources().size(), 2u);
  const Source& s = sc.world.sources()[0];
  EXPECT_EQ(s.rate, 2);
  EXPECT_EQ(s.count, 30u);
  EXPECT_EQ(s.start, 5);
  EXPECT_EQ(s.end, 20);
  EXPECT_EQ(s.agent.radius, 0.2);
  EXPECT_EQ(s.radius_max, 0.3);
  EXPECT_EQ(s.pref_speed_max, 1.4);
  EXPECT_EQ(s.goals, (std::vector<uint32_t>{0, 1}));
  EXPECT_EQ(sc.world.sources()[1].agent.then, (std::vector<uint32_t>{0}));
  EXPECT_TRUE(std::isinf(sc.world.sources()[1].end));
}

// The table is reserved for the sources' agents too (up to as many again as were loaded): the
// first agent a source lets in must not move every column (0.65 s at 10^6 agents).
TEST(ScenarioJson, RoomForTheSourcesAgentsIsReserved) {
  Scenario sc =
      parse_scenario(R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g", "x": 90, "y": 50}],
    "groups": [{"count": 64, "placement": {"type": "grid", "region": [10, 10, 50, 50], "spacing": 1}, "radius": 0.3,
                "goals": {"assign": "round_robin"}}],
    "sources": [{"area": [60, 0, 100, 100], "rate": 1, "count": 10, "radius": 0.3, "goals": ["g"]}]})",
                     "s.json");
  ASSERT_EQ(sc.world.agents().size(), 64u);
  const double* x = sc.world.agents().x.data();
  const uint32_t* goal = sc.world.agents().goal.data();
  AgentSpec spec = sc.world.sources()[0].agent;
  for (int k = 0; k < 10; ++k) {
    spec.x = 70 + k;
    spec.y = 50;
    sc.world.insert(spec);
  }
  sc.world.apply_pending();
  ASSERT_EQ(sc.world.agents().size(), 74u);
  EXPECT_EQ(sc.world.agents().x.data(), x);
  EXPECT_EQ(sc.world.agents().goal.data(), goal);
}

TEST(ScenarioJson, SyntaxErrorNamesLineAndColumn) {
  const std::string e = error_of("{\n  \"bounds\": [0, 0, 1, 1],\n  \"ticks\": 5,,\n}");
  EXPECT_NE(e.find("s.json:3:"), std::string::npos) << e;
  EXPECT_NE(e.find("malformed JSON"), std::string::npos) << e;
}

TEST(ScenarioJson, InvalidFieldsNameTheirPointer) {
  struct Case {
    std::string text, expect;
  };
  const std::string head =
      R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g", "x": 1, "y": 1}], )";
  const Case cases[] = {
      {head + R"("agents": [{"x": 1, "y": 1, "radius": 0, "goal": "g"}]})", "/agents/0/radius"},
      {head + R"("agents": [{"x": 1, "y": 1, "radius": -2, "goal": "g"}]})", "/agents/0/radius"},
      {head + R"("agents": [{"x": 1, "y": 1, "goal": "nowhere"}]})", "unknown goal 'nowhere'"},
      {head + R"("agents": [{"x": "NaN", "y": 1, "goal": "g"}]})",
       "/agents/0/x: expected a number"},
      {head + R"("agents": [{"x": 1e999, "y": 1, "goal": "g"}]})", "s.json"},
      {head + R"("agents": [{"x": 1, "y": 1, "goal": "g", "colour": "red"}]})",
       "/agents/0/colour: unknown key"},
      {head + R"("agents": [{"x": 1, "y": 1, "max_speed": -1, "goal": "g"}]})",
       "/agents/0/max_speed"},
      {head + R"("agents": [{"x": 1, "y": 1, "pref_speed": 2, "max_speed": 1, "goal": "g"}]})",
       "/agents/0/max_speed: must be >= pref_speed"},
      {head + R"("agents": [{"x": 1, "y": 1, "goal": ["g", "elsewhere"]}]})",
       "/agents/0/goal/1: unknown goal 'elsewhere'"},
      {head + R"("ticks": -5})", "/ticks"},
      {head + R"("ticks": 5, "duration": 3})", "/ticks: give one of"},
      {head + R"("dt": 0})", "/dt"},
      {head + R"("gridlock_ticks": 50})", "/gridlock_ticks: no longer here: gridlock_time"},
      {head + R"("steering": {"horizon": 0}})", "/steering/horizon: no longer here"},
      {head + R"("steering": {"model": "boids"}})", "/steering/model: unknown steering model"},
      {head + R"("steering": {"thesis": {"horizon": 0}}})", "/steering/thesis/horizon"},
      {head + R"("steering": {"thesis": {"potential": {"kernel": "gauss"}}}})",
       "/steering/thesis/potential/kernel"},
      {head + R"("steering": {"orca": {"first_share": 1}}})", "/steering/orca/first_share"},
      {head + R"("steering": {"orca": {"time_gap": -0.5}}})", "/steering/orca/time_gap"},
      {head + R"("steering": {"orca": {"max_retreat": -0.1}}})", "/steering/orca/max_retreat"},
      {head + R"("steering": {"orca": {"stream_gap": -1}}})", "/steering/orca/stream_gap"},
      {head + R"("steering": {"orca": {"pass_side": "middle"}}})",
       "/steering/orca/pass_side: 'middle' is not one of: right, left, none"},
      {head + R"("steering": {"orca": {"pass_look": -2}}})", "/steering/orca/pass_look"},
      {head + R"("steering": {"orca": {"pass_look": "far"}}})", "/steering/orca/pass_look"},
      {R"({"bounds": [-1e308, -1e308, 1e308, 1e308]})",
       "/bounds: coordinates must lie within +-1e9 m (got -1e+308)"},
      {head + R"("steering": {"cfsm": {"time_gap": -1}}})", "/steering/cfsm/time_gap"},
      {head + R"("stall": {"after": 0}})", "/stall/after"},
      {head + R"("stall": {"head_on_yield_time": 0}})", "/stall/head_on_yield_time"},
      {head + R"("stall": {"reverse_after": -1}})", "/stall/reverse_after"},
      {head + R"("stall": {"reverse_period": 0}})", "/stall/reverse_period"},
      {R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g", "area": [[0,0],[4,4],[4,0],[0,3]]}]})",
       "/goals/0/area: polygon is not simple"},
      {R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g", "area": [[0,0],[2,0],[2,2]], "x": 5, "y": 5}]})",
       "/goals/0/x: the goal's point (5, 5) lies outside its area"},
      {R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g", "area": [[0,0],[2,0],[2,2]], "arrival_radius": 1}]})",
       "/goals/0/arrival_radius"},
      {head + R"("sources": [{"area": [0, 0, 1, 1], "rate": 0, "count": 1, "goal": "g"}]})",
       "/sources/0/rate"},
      {head +
           R"("sources": [{"area": [0, 0, 1, 1], "rate": 1, "count": 1, "start": 5, "end": 2, "goal": "g"}]})",
       "/sources/0/end"},
      {head + R"("sources": [{"area": [0, 0, 1, 1], "rate": 1, "count": 1}]})",
       "/sources/0/goal: give exactly one"},
      {head + R"("sources": [{"area": [0, 0, 200, 1], "rate": 1, "count": 1, "goal": "g"}]})",
       "/sources/0/area: a corner lies outside the bounds"},
      {head +
           R"("groups": [{"count": 2, "placement": {"type": "grid", "region": [0,0,10,10], "spacing": 5}, "goals": {"assign": "targets", "points": [[1, 1]]}}]})",
       "/groups/0/goals/points: expected one target per agent"},
      {head + R"("arrival": "teleport"})", "/arrival"},
      {head + R"("obstacles": [{"type": "polygon", "vertices": [[0,0],[2,2],[2,0],[0,2]]}]})",
       "/obstacles/0"},
      {head + R"("obstacles": [{"type": "circle", "x": 1, "y": 1, "radius": 0}]})",
       "/obstacles/0/radius"},
      {head +
           R"("groups": [{"count": 5, "placement": {"type": "grid", "region": [0,0,1,1], "spacing": 5}, "goal": "g"}]})",
       "the grid holds 1 agents"},
      {head +
           R"("groups": [{"count": 500, "radius": 3, "placement": {"type": "uniform", "region": [0,0,10,10]}, "goal": "g"}]})",
       "too crowded"},
      // Control characters would cut names short in SQLite output and end up raw in messages.
      {R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g\u0000x", "x": 1, "y": 1}]})",
       "/goals/0/name: contains the control character U+0000 at position 1"},
      {R"({"walkable": "POLYGON((0 0,9 0,9 9,0 9,0 0))\u001bjunk"})",
       "/walkable: contains the control character U+001B at position 30"},
      {R"({"bounds": [0, 0, -1, 1]})", "/bounds"},
      {R"({"bounds": [0, 0, 1, 1], "bounds": [0, 0, 2, 2]})", "duplicate key"},
      {R"({"ticks": 3})", "/bounds: missing"},
      {R"([1, 2])", "expected an object"},
  };
  for (const Case& c : cases) {
    const std::string e = error_of(c.text);
    EXPECT_NE(e.find(c.expect), std::string::npos) << "input: " << c.text << "\nerror: " << e;
    EXPECT_EQ(e.rfind("s.json", 0), 0u) << e;
  }
}

TEST(ScenarioJson, GroupsAreReproducibleAndOverlapFree) {
  const std::string text = R"({"bounds": [0, 0, 200, 200], "seed": 9,
    "goals": [{"name": "a", "x": 0, "y": 0}, {"name": "b", "x": 200, "y": 200}, {"name": "c", "x": 0, "y": 200}],
    "groups": [{"count": 300, "radius": [1, 3], "speed": [0, 5],
                "placement": {"type": "uniform", "region": [0, 0, 200, 200]},
                "goals": {"assign": "round_robin"}}]})";
  const Scenario a = parse_scenario(text, "s.json"), b = parse_scenario(text, "s.json");
  EXPECT_EQ(a.world.agents().x, b.world.agents().x);
  EXPECT_EQ(a.world.agents().vy, b.world.agents().vy);
  EXPECT_TRUE(a.warnings.empty());
  const AgentTable& t = a.world.agents();
  for (std::size_t i = 0; i < t.size(); ++i) {
    EXPECT_EQ(t.goal[i], i % 3);
    EXPECT_GE(t.radius[i], 1.0);
    EXPECT_LE(t.radius[i], 3.0);
    EXPECT_LE(std::hypot(t.vx[i], t.vy[i]), 5.0 + 1e-12);
    for (std::size_t j = i + 1; j < t.size(); ++j)
      ASSERT_GE(std::hypot(t.x[i] - t.x[j], t.y[i] - t.y[j]), t.radius[i] + t.radius[j]);
  }
}

TEST(ScenarioJson, CircleWithAntipodalGoalsAndOverlapWarning) {
  const std::string text = R"({"bounds": [0, 0, 100, 100],
    "groups": [{"count": 40, "radius": 1, "placement": {"type": "circle", "center": [50, 50], "radius": 5},
                "goals": {"assign": "antipodal", "arrival_radius": 0.5}}]})";
  const Scenario sc = parse_scenario(text, "s.json");
  const AgentTable& t = sc.world.agents();
  ASSERT_EQ(t.size(), 40u);
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Goal& g = sc.world.goals()[t.goal[i]];
    EXPECT_NEAR(g.x, 100 - t.x[i], 1e-9);
    EXPECT_NEAR(g.y, 100 - t.y[i], 1e-9);
  }
  // 40 agents of radius 1 on a circle of circumference 31: they overlap, which is only a warning.
  ASSERT_EQ(sc.warnings.size(), 1u);
  EXPECT_NE(sc.warnings[0].find("overlapping"), std::string::npos);
}

// The overlap warning counts pairs exactly (brute force beside it) and names the first one.
TEST(ScenarioJson, OverlapWarningCountsPairsExactly) {
  const std::string text = R"({"bounds": [0, 0, 100, 100], "seed": 3,
    "groups": [{"count": 120, "radius": [0.2, 0.6], "placement": {"type": "circle", "center": [50, 50], "radius": 4},
                "goals": {"assign": "antipodal"}}]})";
  const Scenario sc = parse_scenario(text, "s.json");
  const AgentTable& t = sc.world.agents();
  std::size_t pairs = 0, fi = 0, fj = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    for (std::size_t j = i + 1; j < t.size(); ++j)
      if (std::hypot(t.x[i] - t.x[j], t.y[i] - t.y[j]) < t.radius[i] + t.radius[j] && !pairs++) {
        fi = i;
        fj = j;
      }
  ASSERT_GT(pairs, 0u);
  ASSERT_EQ(sc.warnings.size(), 1u);
  EXPECT_NE(sc.warnings[0].find("overlapping: " + std::to_string(pairs) + " pairs (first: agents " +
                                std::to_string(fi) + " and " + std::to_string(fj) + " "),
            std::string::npos)
      << sc.warnings[0];
}

// Agents that a uniform placement put clear of every agent before them are not searched for
// overlaps; agents placed after them without that check (a grid here) still are, against them
// too: explicit agents, a uniform group, a grid across it, and another uniform group, counted
// exactly as by brute force.
TEST(ScenarioJson, OverlapWarningCountsPairsAcrossPlacements) {
  const std::string text = R"({"bounds": [0, 0, 100, 100], "seed": 5,
    "goals": [{"name": "g", "x": 90, "y": 90}],
    "agents": [{"x": 40, "y": 40, "radius": 0.5, "goal": "g"}, {"x": 40.6, "y": 40, "radius": 0.5, "goal": "g"}],
    "groups": [{"count": 300, "radius": [0.3, 0.6], "goal": "g", "placement": {"type": "uniform", "region": [0, 0, 30, 30]}},
               {"count": 100, "radius": 0.6, "goal": "g", "placement": {"type": "grid", "region": [1, 1, 30, 30], "spacing": 3}},
               {"count": 200, "radius": 0.4, "goal": "g", "placement": {"type": "uniform", "region": [0, 0, 30, 30], "gap": 0.1}}]})";
  const Scenario sc = parse_scenario(text, "s.json");
  const AgentTable& t = sc.world.agents();
  ASSERT_EQ(t.size(), 602u);
  std::size_t pairs = 0, fi = 0, fj = 0, last_j = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    for (std::size_t j = i + 1; j < t.size(); ++j)
      if (std::hypot(t.x[i] - t.x[j], t.y[i] - t.y[j]) < t.radius[i] + t.radius[j]) {
        if (!pairs++) {
          fi = i;
          fj = j;
        }
        last_j = std::max(last_j, j);
      }
  ASSERT_GT(pairs, 1u);
  EXPECT_EQ(fi, 0u);        // the explicit pair
  EXPECT_GE(last_j, 302u);  // and some of the grid's
  ASSERT_EQ(sc.warnings.size(), 1u);
  EXPECT_NE(sc.warnings[0].find("overlapping: " + std::to_string(pairs) + " pairs (first: agents " +
                                std::to_string(fi) + " and " + std::to_string(fj) + " "),
            std::string::npos)
      << sc.warnings[0];
}

// Work is bounded by the input, not by its numbers: 20,000 agents on one spot (2 * 10^8 pairs)
// are counted up to a cap; a huge placement gap fails at once instead of scanning 10^18 cells.
TEST(ScenarioJson, HugePilesAndGapsStayCheap) {
  const Scenario pile = parse_scenario(R"({"bounds": [0, 0, 100, 100],
    "groups": [{"count": 20000, "radius": 0.25, "placement": {"type": "circle", "center": [50, 50], "radius": 0.01},
                "goals": {"assign": "antipodal"}}]})",
                                       "s.json");
  ASSERT_EQ(pile.warnings.size(), 1u);
  EXPECT_NE(pile.warnings[0].find("overlapping: at least 1"), std::string::npos)
      << pile.warnings[0];
  for (const char* gap : {"1e9", "1e308"}) {
    const std::string e = error_of(
        std::string(R"({"bounds": [0, 0, 100, 100], "goals": [{"name": "g", "x": 5, "y": 5}],
      "groups": [{"count": 10, "goal": "g", "placement": {"type": "uniform", "region": [0, 0, 100, 100], "gap": )") +
        gap + "}}]}");
    EXPECT_NE(e.find("/groups/0/placement: could not place agent 2 of 10"), std::string::npos) << e;
  }
  // A gap wider than the agents are many scans the agents instead of the cells: the gap holds.
  const Scenario wide = parse_scenario(
      R"({"bounds": [0, 0, 200, 200], "seed": 5, "goals": [{"name": "g", "x": 5, "y": 5}],
      "groups": [{"count": 6, "goal": "g", "radius": 0.25, "placement": {"type": "uniform", "region": [0, 0, 200, 200], "gap": 30}}]})",
      "s.json");
  const AgentTable& t = wide.world.agents();
  ASSERT_EQ(t.size(), 6u);
  for (std::size_t i = 0; i < t.size(); ++i)
    for (std::size_t j = i + 1; j < t.size(); ++j)
      EXPECT_GE(std::hypot(t.x[i] - t.x[j], t.y[i] - t.y[j]), 30.5);
}

// The documented limit on agents placed at load time is checked before any agent is placed, so
// a 200-byte file asking for 10^7 agents is refused at once instead of taking GBs and minutes.
TEST(ScenarioJson, AgentsPlacedAtLoadAreLimited) {
  const std::string head =
      R"({"bounds": [0, 0, 100000, 100000], "goals": [{"name": "g", "x": 5, "y": 5}], )";
  const std::string uniform =
      R"(, "goal": "g", "placement": {"type": "uniform", "region": [0, 0, 100000, 100000]}})";
  std::string e = error_of(head + R"("groups": [{"count": 10000000)" + uniform + "]}");
  EXPECT_NE(e.find("/groups/0/count: 10000000 agents would make 10000000; a scenario places at "
                   "most 2000000 at load time"),
            std::string::npos)
      << e;
  // Explicit agents count too: one explicit agent and a group of exactly the limit pass it.
  e = error_of(head + R"("agents": [{"x": 1, "y": 1, "goal": "g"}], "groups": [{"count": 2000000)" +
               uniform + "]}");
  EXPECT_NE(e.find("/groups/0/count: 2000000 agents would make 2000001"), std::string::npos) << e;
  EXPECT_EQ(kMaxScenarioAgents, 2'000'000u);
}

TEST(ScenarioJson, ShippedScenariosLoadWithoutWarnings) {
  for (const char* name : {"airport", "circle", "crossing", "bottleneck"}) {
    const Scenario sc =
        load_scenario(test::source_path(std::string("scenarios/") + name + ".json"));
    EXPECT_EQ(sc.name, name);
    EXPECT_GT(sc.world.agents().size(), 0u);
    EXPECT_TRUE(sc.warnings.empty()) << name << ": " << sc.warnings.front();
  }
  const Scenario airport = load_scenario(test::source_path("scenarios/airport.json"));
  EXPECT_EQ(airport.world.agents().size(), 1000u);
  EXPECT_EQ(airport.world.circles().size(), 24u);
  EXPECT_EQ(airport.world.goals().size(), 12u);
  EXPECT_EQ(airport.ticks, 3000u);  // 300 s
  EXPECT_EQ(airport.world.sources().size(), 2u);
}

TEST(ScenarioJson, MissingFileIsAnIoError) {
  try {
    load_scenario("/nonexistent/x.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::io);
    EXPECT_NE(std::string(e.what()).find("/nonexistent/x.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace crowddb

namespace crowddb {
namespace {

TEST(ScenarioJson, PolygonGoalPointIsExactFarFromTheOrigin) {
  // A 2 x 1 m exit in UTM coordinates (osm2vadere's files use such).
  const double x0 = 692152.09, y0 = 5337384.67;
  std::ostringstream os;
  os.precision(17);
  os << R"({"bounds": [)" << x0 - 10 << ", " << y0 - 10 << ", " << x0 + 10 << ", " << y0 + 10
     << R"(], "goals": [{"name": "exit", "area": [[)" << x0 << ", " << y0 << "], [" << x0 + 2
     << ", " << y0 << "], [" << x0 + 2 << ", " << y0 + 1 << "], [" << x0 << ", " << y0 + 1
     << R"(]]}], "agents": [{"x": )" << x0 - 5 << ", \"y\": " << y0 << R"(, "goal": "exit"}]})";
  Scenario sc = parse_scenario(os.str(), "utm.json");
  const Goal& g = sc.world.goals()[0];
  EXPECT_NEAR(g.x, x0 + 1, 1e-6);
  EXPECT_NEAR(g.y, y0 + 0.5, 1e-6);
}

}  // namespace
}  // namespace crowddb
