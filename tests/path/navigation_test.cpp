// The path service inside the tick (src/path/navigation.cpp through Simulation): results applied
// exactly `latency` ticks after dispatch, straight steering until then, the per-tick budget,
// re-planning on a new goal and on lack of progress, and waypoint skipping by line of sight.
#include "path/navigation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <utility>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "support/cli.hpp"
#include "support/configs.hpp"

namespace crowddb {
namespace {

// A 60 x 40 room split by a wall with a gap at its north end; goal 0 behind the wall, goal 1
// on the start side.
World walled_world() {
  World w(Bounds{0, 0, 60, 40});
  w.add_goal({"east", 50, 10, 1, 2, {}});
  w.add_goal({"west", 5, 35, 1, 2, {}});
  w.add_obstacle(PolygonObstacle{{{29, 0}, {31, 0}, {31, 30}, {29, 30}}, 0.1});
  return w;
}

// The thesis's rule with one tick per second, so latencies in seconds count ticks.
SimConfig nav_config(uint32_t latency, uint32_t budget = 64) {
  SimConfig c = test::thesis_config();
  c.navigation.enabled = true;
  c.navigation.latency = latency;
  c.navigation.budget = budget;
  c.steering.thesis.w_apf = 1;
  c.steering.thesis.w_ftc = 2;
  return c;
}

AgentSpec walker(double x, double y, uint32_t goal = 0) {
  AgentSpec s;
  s.x = x;
  s.y = y;
  s.radius = 0.8;
  s.max_speed = 1;
  s.pref_speed = s.max_speed;
  s.max_accel = 0.5;
  s.goal = goal;
  return s;
}

TEST(Navigation, ResultIsAppliedExactlyLatencyTicksAfterTheRequest) {
  for (uint32_t latency : {1u, 3u, 7u}) {
    World w = walled_world();
    w.insert(walker(10, 10));
    Simulation sim(std::move(w), nav_config(latency));
    const AgentTable& t = sim.world().agents();
    EXPECT_NE(t.path_ticket[0], 0u);  // requested at tick 0
    for (uint32_t k = 1; k < latency; ++k) {
      sim.step();
      EXPECT_NE(t.path_ticket[0], 0u) << "latency " << latency << " tick " << k;
      EXPECT_TRUE(t.route[0].empty());
      EXPECT_EQ(t.target_x[0], 50);  // steering straight at the goal meanwhile
      EXPECT_EQ(t.target_y[0], 10);
    }
    sim.step();  // tick `latency`: the result is applied before the steering queries
    EXPECT_EQ(t.path_ticket[0], 0u) << "latency " << latency;
    EXPECT_GT(t.target_y[0], 30) << "the waypoint at the wall's open end";
  }
}

TEST(Navigation, BudgetLimitsDispatchesPerTickInRequestOrder) {
  World w = walled_world();
  for (int i = 0; i < 10; ++i) w.insert(walker(3 + 2.5 * i, 5));
  Simulation sim(std::move(w), nav_config(2, 3));
  // Ticket order is row order; dispatches: 3 at tick 0, 3 at 1, 3 at 2, 1 at 3.
  auto applied = [&] {
    std::size_t n = 0;
    for (uint64_t tk : sim.world().agents().path_ticket) n += tk == 0;
    return n;
  };
  EXPECT_EQ(applied(), 0u);
  sim.step();  // tick 1: nothing due yet
  EXPECT_EQ(applied(), 0u);
  for (std::size_t expect : {3u, 6u, 9u, 10u, 10u}) {
    sim.step();
    EXPECT_EQ(applied(), expect);
  }
  for (std::size_t i = 0; i < 10; ++i) EXPECT_EQ(sim.world().agents().path_ticket[i], 0u);
}

TEST(Navigation, ANewGoalIsReplanned) {
  World w = walled_world();
  const AgentId a = w.insert(walker(10, 10));
  Simulation sim(std::move(w), nav_config(2));
  for (int k = 0; k < 5; ++k) sim.step();
  const AgentTable& t = sim.world().agents();
  ASSERT_EQ(t.path_goal[0], 0u);
  ASSERT_FALSE(t.route[0].empty());
  sim.world().retarget(a, 1);
  sim.step();  // the re-target clears the route; a new request goes out at the end of the tick
  EXPECT_TRUE(t.route[0].empty());
  EXPECT_EQ(t.path_goal[0], 1u);
  EXPECT_NE(t.path_ticket[0], 0u);
  EXPECT_EQ(t.target_x[0], 5);  // straight at the new goal until its path arrives
  sim.step();
  sim.step();
  EXPECT_EQ(t.path_ticket[0], 0u);
}

TEST(Navigation, NoProgressTriggersReplanning) {
  // The goal sits in a closed box: the path is partial and the agent stalls at the box.
  World w(Bounds{0, 0, 60, 40});
  w.add_goal({"boxed", 45, 20, 1, 1, {}});
  w.add_obstacle(PolygonObstacle{{{38, 13}, {52, 13}, {52, 15}, {38, 15}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{38, 25}, {52, 25}, {52, 27}, {38, 27}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{38, 15}, {40, 15}, {40, 25}, {38, 25}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{50, 15}, {52, 15}, {52, 25}, {50, 25}}, 0.1});
  w.insert(walker(10, 20));
  SimConfig c = nav_config(1);
  c.navigation.replan_after = 10;
  Simulation sim(std::move(w), c);
  for (int k = 0; k < 300; ++k) sim.step();
  // EXPLAIN ANALYZE: "path service: N requests (M re-plans), ..."
  const std::string ea = sim.explain_analyze();
  const auto pos = ea.find("path service: ");
  ASSERT_NE(pos, std::string::npos) << ea;
  const unsigned long requests = std::stoul(ea.substr(pos + 14));
  const unsigned long replans = std::stoul(ea.substr(ea.find('(', pos) + 1));
  EXPECT_EQ(requests, replans + 1) << ea;  // the goal never changes
  // The agent walks ~100 ticks to the far side of the box, then stands: one re-plan per 10
  // ticks, never more often.
  EXPECT_GE(replans, 10u) << ea;
  EXPECT_LE(replans, 30u) << ea;
  EXPECT_NE(ea.find("partial"), std::string::npos);
}

// A walker on its last leg (its goal in sight, no route left) pushed behind a pillar (put there
// with no speed) looks towards its goal, sees the pillar and is re-planned at once, long before
// the progress watch (30 s here) would; one walking at speed is left alone, as is one with
// nothing in its way.
TEST(Navigation, AWalkerPushedBehindAnObstacleIsReplanned) {
  const auto pushed = [](double x, double y, double speed) {
    World w(Bounds{0, 0, 60, 40});
    w.add_goal({"east", 55, 20, 1, 1, {}});
    w.add_obstacle(CircleObstacle{30, 20, 3});
    w.insert(walker(10, 30));
    SimConfig c = nav_config(1);
    c.navigation.replan_after = 30;
    Simulation sim(std::move(w), c);
    AgentTable& t = sim.world().agents_for_tick();
    for (int k = 0; k < 3; ++k) sim.step();
    EXPECT_TRUE(t.route[0].empty()) << "the goal is in sight from the start";
    EXPECT_EQ(t.path_ticket[0], 0u);
    t.x[0] = x;
    t.y[0] = y;
    t.vx[0] = speed;
    t.vy[0] = 0;
    sim.step();
    return t.path_ticket[0] != 0 || !t.route[0].empty();
  };
  EXPECT_TRUE(pushed(25.5, 20.5, 0));     // pressed against the pillar's west face
  EXPECT_FALSE(pushed(25.5, 20.5, 0.9));  // walking (it will slide round or slow down)
  EXPECT_FALSE(pushed(25.5, 30, 0));      // standing, with the way free
  // Standing 2.7 m before the pillar: held up by the people in front, not by the pillar (in a
  // queue beside a door, re-planning those behind the post drew them at the post).
  EXPECT_FALSE(pushed(23.5, 20.5, 0));
}

TEST(Navigation, WaypointsAreSkippedWhenTheNextOneIsInSight) {
  for (bool skip : {false, true}) {
    World w = walled_world();
    w.insert(walker(10, 10));
    SimConfig c = nav_config(1);
    c.navigation.skip_visible = skip;
    Simulation sim(std::move(w), c);
    const AgentTable& t = sim.world().agents();
    double farthest_pop = 0;
    std::size_t arrived = 0;
    for (int k = 0; k < 300 && !t.empty(); ++k) {
      const std::vector<Vec2> before = t.route[0];
      arrived += sim.step().arrived;
      if (t.empty()) break;
      if (!before.empty() && t.route[0].size() < before.size())
        farthest_pop = std::max(farthest_pop,
                                std::hypot(before.front().x - t.x[0], before.front().y - t.y[0]));
    }
    EXPECT_EQ(arrived, 1u) << "skip " << skip;
    if (skip) {
      EXPECT_GT(farthest_pop, 0.8) << "a corner was passed by sight, before the agent reached it";
    } else {
      EXPECT_LE(farthest_pop, 0.8 + 1e-9) << "without sight, only reaching a corner advances";
    }
  }
}

TEST(Navigation, ExplainShowsThePathService) {
  World w = walled_world();
  w.insert(walker(10, 10));
  Simulation sim(std::move(w), nav_config(2));
  const std::string plan = sim.explain();
  EXPECT_NE(plan.find("path results"), std::string::npos) << plan;
  EXPECT_NE(plan.find("Recast/Detour"), std::string::npos) << plan;
  EXPECT_NE(plan.find("path requests"), std::string::npos) << plan;
  EXPECT_NE(plan.find("in sight"), std::string::npos) << plan;
  World plain = walled_world();
  plain.insert(walker(10, 10));
  Simulation off(std::move(plain), test::thesis_config());
  EXPECT_EQ(off.explain().find("path results"), std::string::npos);
  EXPECT_EQ(off.explain().find("path requests"), std::string::npos);
}

// One person of radius `radius` from (x, y) to goal 0 of `w`, with the default model and
// navigation on, for at most `ticks` ticks: the arrivals and EXPLAIN ANALYZE at the end.
struct NavWalk {
  std::size_t arrived;
  std::string analyze;
};
NavWalk walk_alone(World w, double x, double y, double radius, int ticks) {
  AgentSpec s;
  s.x = x;
  s.y = y;
  s.radius = radius;
  s.goal = 0;
  w.insert(s);
  SimConfig c;
  c.navigation.enabled = true;
  Simulation sim(std::move(w), c);
  for (int k = 0; k < ticks && sim.arrived_total() == 0; ++k) sim.step();
  return {sim.arrived_total(), sim.explain_analyze()};
}

// A person of radius 0.3 m (the 0.5 class: its mesh has no passage narrower than about 1.5 m)
// goes round a wall through its 0.9 m door, found on the agent's narrow mesh.
TEST(Navigation, AWidePersonFindsANarrowDoorWithTheDefaults) {
  World w(Bounds{0, 0, 20, 10});
  w.add_goal({"behind", 16, 2, 1, 0.5, {}});
  w.add_obstacle(PolygonObstacle{{{9.5, 0}, {10.5, 0}, {10.5, 8.1}, {9.5, 8.1}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{9.5, 9.0}, {10.5, 9.0}, {10.5, 10}, {9.5, 10}}, 0.1});
  const NavWalk walk = walk_alone(std::move(w), 4, 2, 0.3, 400);  // 40 s
  EXPECT_EQ(walk.arrived, 1u);
  // "... N searches on a narrow mesh, M of them reaching the goal": M >= 1.
  const std::string key = "on a narrow mesh, ";
  const std::size_t at = walk.analyze.find(key);
  ASSERT_NE(at, std::string::npos) << walk.analyze;
  EXPECT_GE(std::stoul(walk.analyze.substr(at + key.size())), 1u) << walk.analyze;
}

// An aircraft's aisle: a seat at the end of a 0.46 m corridor of thin walls, for a person of
// radius 0.21 who starts beside it. The class mesh has no polygon in the aisle and moves the
// goal onto the floor outside, across the wall; the narrow mesh has the aisle.
TEST(Navigation, AGoalDownANarrowAisleIsReachedThroughItsEntrance) {
  World w(Bounds{0, 0, 20, 6});
  w.add_goal({"seat", 14.5, 3.1, 1, 0.1, {}});
  w.add_obstacle(PolygonObstacle{{{5, 2.77}, {15.1, 2.77}, {15.1, 2.87}, {5, 2.87}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{5, 3.33}, {15.1, 3.33}, {15.1, 3.43}, {5, 3.43}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{15, 2.87}, {15.1, 2.87}, {15.1, 3.33}, {15, 3.33}}, 0.1});
  EXPECT_EQ(walk_alone(std::move(w), 10, 1, 0.21, 600).arrived, 1u);  // 60 s
}

// The number N of "N<key>" in EXPLAIN ANALYZE (0 when the key is not there).
uint64_t explain_count(const Simulation& sim, const std::string& key) {
  const std::string a = sim.explain_analyze();
  const std::size_t at = a.find(key);
  if (at == std::string::npos) return 0;
  const std::size_t from = a.rfind(' ', at - 1) + 1;
  return std::stoull(a.substr(from, at - from));
}

uint64_t costed_searches(const Simulation& sim) {
  return explain_count(sim, " searched round congestion");
}

// tests/data/passage.json: two groups of 30 meet in a 1.2 m passage between two stands, with
// aisles round them. Planning round the people stalled head-on, everyone is across within 100 s
// on seeds 1-3 (the last at 81, 90 and 71 s); without (congestion_cost 0) the last arrive at
// 111 s, after 147 s, and at 95 s.
TEST(Navigation, PeopleStalledInAPassageAreWalkedRound) {
  for (const char* cost : {"5", "0"})
    for (int seed = 1; seed <= 3; ++seed) {
      // (Queues at doors off: this is about the people stalled head-on alone.)
      Scenario sc = load_scenario(test::source_path("tests/data/passage.json"),
                                  LoadOptions{{},
                                              {"seed=" + std::to_string(seed),
                                               std::string("navigation.congestion_cost=") + cost,
                                               "navigation.queue_flow=0"}});
      Simulation sim(std::move(sc.world), sc.config);
      while (sim.arrived_total() < 60 && sim.ticks() < 1000) sim.step();
      if (std::string(cost) == "5") {
        EXPECT_EQ(sim.arrived_total(), 60u) << "seed " << seed;
        EXPECT_GT(costed_searches(sim), 0u);
      } else {
        EXPECT_EQ(costed_searches(sim), 0u);
      }
    }
}

// Queues at doors: a wall across a room with two 1.2 m doors 10 m apart and the goal below the
// west one; 40 people stand queued above the west door. One more coming from above plans through
// the east door (a detour of about 11 m against 40 people ahead at a 1.2 m door: about 33 m);
// with queue_flow 0, or with the queue gone, through the west one.
TEST(Navigation, AQueueAtTheNearDoorSendsTheNextOneToTheOther) {
  const auto route_x = [](double queue_flow, bool queue) {
    World w(Bounds{0, 0, 30, 20});
    w.add_goal({"out", 10.6, 2, 0.5, 1, {}});
    for (auto [x0, x1] : {std::pair{0.0, 10.0}, {11.2, 20.0}, {21.2, 30.0}})
      w.add_obstacle(PolygonObstacle{{{x0, 8}, {x1, 8}, {x1, 9}, {x0, 9}}, 1});
    const auto person = [](double x, double y) {
      AgentSpec s;
      s.x = x;
      s.y = y;
      s.radius = 0.25;
      s.pref_speed = 1.3;
      s.max_speed = 1.3;
      s.goal = 0;
      return s;
    };
    // The one to plan comes first: at most 8 searches a tick get costs, in id order, and here
    // everyone asks at the start.
    const AgentId first = w.insert(person(10.6, 15));
    std::size_t queued = 0;
    if (queue) {
      for (double y = 9.6; y < 13; y += 0.55)
        for (double x = 7.5; x < 14; x += 0.55)
          if (std::hypot(x - 10.6, y - 9) < 3.6) {
            w.insert(person(x, y));
            ++queued;
          }
      EXPECT_GE(queued, 35u);
    }
    SimConfig c;  // orca, the defaults
    c.navigation.enabled = true;
    c.navigation.latency = c.dt;
    c.navigation.queue_flow = queue_flow;
    Simulation sim(std::move(w), c);
    sim.step();  // the routes requested at the start arrive
    const AgentTable& t = sim.world().agents();
    const auto row = sim.world().row_of(first);
    double east = 0;
    for (const Vec2& p : t.route[*row]) east = std::max(east, p.x);
    return east;
  };
  EXPECT_GT(route_x(1.3, true), 19) << "through the east door";
  EXPECT_LT(route_x(0, true), 12) << "queues off: the west door";
  EXPECT_LT(route_x(1.3, false), 12) << "no queue: the west door";
}

uint64_t door_costed_searches(const Simulation& sim) {
  return explain_count(sim, " of them with a queue at a door");
}

// The door searches of one tick run on every thread (request_paths): a room of 240 emptying
// through a 1.2 m door, where most searches are costed with the queue ahead, gives the same state
// every tick on 1, 2 and 3 threads.
TEST(Navigation, QueuesAtDoorsAreCostedAlikeOnAnyThreadCount) {
  const std::string doc = R"({"bounds": [0, 0, 26, 20], "dt": 0.1, "seed": 5,
    "navigation": {}, "arrival": "remove",
    "obstacles": [{"type": "polygon", "vertices": [[20, 0], [20.3, 0], [20.3, 9.4], [20, 9.4]]},
                  {"type": "polygon", "vertices": [[20, 10.6], [20.3, 10.6], [20.3, 20], [20, 20]]}],
    "goals": [{"name": "out", "area": [[24, 0], [26, 0], [26, 20], [24, 20]]}],
    "groups": [{"count": 240, "placement": {"type": "uniform", "region": [0.3, 0.3, 19.7, 19.7],
                "gap": 0.05}, "radius": [0.2, 0.25], "pref_speed": [1.1, 1.5], "goal": "out"}]})";
  std::vector<std::vector<uint64_t>> hashes;
  uint64_t door_costed = 0;
  for (int threads : {1, 2, 3}) {
    Scenario sc = parse_scenario(doc, "door.json");
    sc.config.threads = threads;
    Simulation sim(std::move(sc.world), sc.config);
    std::vector<uint64_t> h;
    for (int k = 0; k < 300; ++k) h.push_back(sim.step().state_hash);
    hashes.push_back(std::move(h));
    if (threads == 1) door_costed = door_costed_searches(sim);
  }
  EXPECT_EQ(hashes[1], hashes[0]);
  EXPECT_EQ(hashes[2], hashes[0]);
  EXPECT_GT(door_costed, 100u);  // several door searches a tick, so they ran side by side
  std::printf("[ navigation ] %llu searches costed with a queue at a door\n",
              static_cast<unsigned long long>(door_costed));
}

// Agents that left keep no entry in the sets of routes that fall short: with a source letting
// people in for hours, they grew with everyone who ever walked (and so did every checkpoint).
TEST(Navigation, AgentsThatLeftAreForgotten) {
  World w = walled_world();
  // Goal 0 walled in on every side: every route to it ends short.
  w.add_obstacle(PolygonObstacle{{{44, 4}, {56, 4}, {56, 5}, {44, 5}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{44, 15}, {56, 15}, {56, 16}, {44, 16}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{44, 5}, {45, 5}, {45, 15}, {44, 15}}, 0.1});
  w.add_obstacle(PolygonObstacle{{{55, 5}, {56, 5}, {56, 15}, {55, 15}}, 0.1});
  std::vector<AgentId> ids;
  for (int k = 0; k < 100; ++k) ids.push_back(w.insert(walker(5 + (k % 10) * 2, 5 + (k / 10) * 2)));
  w.apply_pending();
  const SimConfig c = nav_config(1, 100);
  Executor ex(1);
  path::Navigation nav(w, c, ex);
  EXPECT_EQ(nav.request_paths(w, 0), 100u);
  EXPECT_EQ(nav.apply_results(w, 1), 100u);
  EXPECT_EQ(nav.without_path(w), 100u);
  EXPECT_EQ(nav.flagged_routes(), 100u);
  for (int k = 0; k < 60; ++k) w.erase(ids[k]);
  w.apply_pending();
  nav.apply_results(w, 2);  // 100 entries for 40 agents: within twice as many and 64
  EXPECT_EQ(nav.flagged_routes(), 100u);
  for (int k = 60; k < 99; ++k) w.erase(ids[k]);
  w.apply_pending();
  nav.apply_results(w, 3);  // 100 entries for one agent: swept
  EXPECT_EQ(nav.flagged_routes(), 1u);
  EXPECT_EQ(nav.without_path(w), 1u);
}

TEST(Navigation, RadiusClassesRoundUp) {
  World w = walled_world();
  w.insert(walker(10, 10));
  SimConfig c = nav_config(1);
  c.navigation.radius_step = 0.25;
  Executor ex(1);
  path::Navigation nav(w, c, ex);  // the pending insert is not applied yet: no agents, no mesh
  EXPECT_EQ(nav.mesh_count(), 0u);
  EXPECT_DOUBLE_EQ(nav.class_radius(0.8), 1.0);
  EXPECT_DOUBLE_EQ(nav.class_radius(1.0), 1.0);
  EXPECT_DOUBLE_EQ(nav.class_radius(1.01), 1.25);
  EXPECT_DOUBLE_EQ(nav.class_radius(0.01), 0.25);
}

}  // namespace
}  // namespace crowddb
