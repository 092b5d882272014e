// Goal areas, goal sequences, sources, idle arrivals and stalemates in the tick.
#include <gtest/gtest.h>

#include <climits>
#include <cmath>
#include <cstdint>
#include <map>

#include "crowddb/query.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "sim/sources.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

struct Loaded {
  Scenario sc;
  std::unique_ptr<Simulation> sim;
  explicit Loaded(const std::string& text) : sc(parse_scenario(text, "t.json")) {
    sim = std::make_unique<Simulation>(std::move(sc.world), sc.config);
  }
};

TEST(Goals, AnAgentArrivesAnywhereInAPolygonGoal) {
  // The goal is a wide strip; the agent walks straight to its nearest point, not to its centre.
  Loaded r(R"({"bounds": [0, 0, 40, 40], "duration": 30,
    "goals": [{"name": "strip", "area": [[30, 0], [31, 0], [31, 40], [30, 40]]}],
    "agents": [{"x": 5, "y": 5, "goal": "strip"}]})");
  uint64_t t = 0;
  while (r.sim->world().agents().size() && t < 300) {
    const AgentTable& a = r.sim->world().agents();
    // Straight east to the nearest point where its disc fits, not towards the strip's centre.
    ASSERT_NEAR(a.y[0], 5, 1e-3);
    r.sim->step();
    ++t;
  }
  EXPECT_EQ(r.sim->arrived_total(), 1u);
  EXPECT_NEAR(static_cast<double>(t) * 0.1, 25.0 / 1.34, 0.3);
}

TEST(Goals, SequencesVisitEveryGoalInOrderThenArrive) {
  Loaded r(R"({"bounds": [0, 0, 40, 40], "duration": 120,
    "goals": [{"name": "a", "x": 30, "y": 5}, {"name": "b", "x": 30, "y": 30}, {"name": "c", "x": 5, "y": 30}],
    "agents": [{"x": 5, "y": 5, "goal": ["a", "b", "c"]}]})");
  std::vector<uint32_t> visited;
  for (uint64_t t = 0; t < r.sc.ticks && r.sim->world().agents().size(); ++t) {
    const uint32_t g = r.sim->world().agents().goal[0];
    if (visited.empty() || visited.back() != g) visited.push_back(g);
    const std::size_t arrived = r.sim->step().arrived;  // only at the last goal
    EXPECT_EQ(arrived, r.sim->world().agents().empty() ? 1u : 0u);
  }
  EXPECT_EQ(visited, (std::vector<uint32_t>{0, 1, 2}));
  EXPECT_EQ(r.sim->arrived_total(), 1u);
}

TEST(Goals, IdleArrivalsMakeRoomAndLaterOnesJoinThem) {
  // 30 people share one small goal disc and idle there: the first ones step off the disc, the
  // later ones arrive on it or at the group gathered around it.
  Loaded r(R"({"bounds": [0, 0, 30, 30], "duration": 120, "arrival": "idle",
    "goals": [{"name": "spot", "x": 25, "y": 15, "arrival_radius": 0.5}],
    "groups": [{"count": 30, "placement": {"type": "uniform", "region": [1, 1, 10, 29], "gap": 0.1},
                "goal": "spot"}]})");
  for (uint64_t t = 0; t < r.sc.ticks; ++t) r.sim->step();
  EXPECT_EQ(r.sim->arrived_total(), 30u);
  const AgentTable& a = r.sim->world().agents();
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a.state[i], AgentState::arrived);
}

TEST(Goals, AnIdleArrivalStepsOutOfTheWayOfAnotherGoalThatSomeoneStillNeeds) {
  // A formation (Menge's formationNavigation): goals 0.3 m apart, each person's own spot. "near"
  // starts on its spot and idles there; "far"'s spot is 0.3 m away, so far (0.25 m) could not
  // stand on it beside near (0.25 m). Far is 8 m off, beyond ORCA's 5 m range, so nothing but the
  // goal stage moves near: it steps away from far's spot at once, not when far is upon it.
  Loaded r(R"({"bounds": [0, 0, 20, 10], "duration": 60, "arrival": "idle",
    "goals": [{"name": "near", "x": 10, "y": 5, "arrival_radius": 0.05},
              {"name": "far", "x": 10.3, "y": 5, "arrival_radius": 0.05}],
    "agents": [{"x": 10, "y": 5, "radius": 0.25, "goal": "near"},
               {"x": 2, "y": 5.5, "radius": 0.25, "goal": "far"}]})");
  for (int k = 0; k < 3; ++k) r.sim->step();
  {
    const AgentTable& a = r.sim->world().agents();
    ASSERT_EQ(a.state[0], AgentState::arrived);
    EXPECT_LT(a.vx[0], -0.1);  // away from far's spot, which lies east of it
    EXPECT_NEAR(a.vy[0], 0, 1e-3);
  }
  for (uint64_t t = 3; t < r.sc.ticks && r.sim->arrived_total() < 2; ++t)
    EXPECT_EQ(r.sim->step().overlapping_pairs, 0u);
  EXPECT_EQ(r.sim->arrived_total(), 2u);
  // With nobody left to come, near stands still, out of far's way and close to its own spot.
  for (int k = 0; k < 20; ++k) r.sim->step();
  const AgentTable& a = r.sim->world().agents();
  ASSERT_EQ(a.size(), 2u);
  const std::size_t n = a.goal[0] == 0 ? 0 : 1;  // rows are re-ordered every 2 s
  EXPECT_EQ(a.vx[n], 0.0);
  EXPECT_EQ(a.vy[n], 0.0);
  EXPECT_LT(std::hypot(a.x[n] - 10, a.y[n] - 5), 1.0);
}

TEST(Goals, IdleArrivalsWalkIntoAnAreaAndKeepItsEdgeFree) {
  // A box goal 1 m beyond a 1 m gap in a wall. Arrivals that stepped off the box stood in the
  // strip between the gap and the box and locked the later ones out (14 of 30 arrived when
  // measured); walking on into the box they leave its edge free and everyone gets in.
  Loaded r(R"({"bounds": [0, 0, 30, 30], "duration": 120, "arrival": "idle",
    "obstacles": [{"type": "polygon", "vertices": [[0, 8], [14.5, 8], [14.5, 10], [0, 10]]},
                  {"type": "polygon", "vertices": [[15.5, 8], [30, 8], [30, 10], [15.5, 10]]}],
    "navigation": {"enabled": true},
    "goals": [{"name": "box", "area": [[12, 11], [18, 11], [18, 16], [12, 16]]}],
    "groups": [{"count": 30, "radius": 0.25, "goal": "box",
                "placement": {"type": "uniform", "region": [1, 1, 29, 7], "gap": 0.1}}]})");
  for (uint64_t t = 0; t < r.sc.ticks; ++t) EXPECT_EQ(r.sim->step().overlapping_pairs, 0u);
  EXPECT_EQ(r.sim->arrived_total(), 30u);
  // Nobody idles in the gap itself.
  const AgentTable& a = r.sim->world().agents();
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_FALSE(a.y[i] < 10 && a.y[i] > 8);
}

TEST(Goals, AWaitHoldsTheAgentAtTheGoalForItsTimeThenItGoesOn) {
  // A counter with a 5 s wait on the way to an exit: 50 ticks standing there, then on.
  Loaded r(R"({"bounds": [0, 0, 20, 10], "duration": 40,
    "goals": [{"name": "counter", "x": 10, "y": 5, "arrival_radius": 0.5, "wait": 5},
              {"name": "exit", "area": [[19, 0], [20, 0], [20, 10], [19, 10]]}],
    "agents": [{"x": 2, "y": 5, "goal": ["counter", "exit"]}]})");
  uint64_t waited = 0, first = 0, last = 0;
  double wx = NAN, wy = NAN;
  for (uint64_t t = 1; t <= r.sc.ticks && !r.sim->world().agents().empty(); ++t) {
    r.sim->step();
    const AgentTable& a = r.sim->world().agents();
    if (a.empty() || a.state[0] != AgentState::waiting) continue;
    if (waited++ == 0) {
      first = t;
      wx = a.x[0];
      wy = a.y[0];
    }
    last = t;
    EXPECT_EQ(a.goal[0], 0u);  // still at the counter
    EXPECT_EQ(a.x[0], wx);     // standing: nobody else needs the spot
    EXPECT_EQ(a.y[0], wy);
    EXPECT_EQ(r.sim->arrived_total(), 0u);
  }
  EXPECT_EQ(waited, 50u);
  EXPECT_EQ(last - first + 1, 50u);
  EXPECT_LE(std::hypot(wx - 10, wy - 5), 0.5);
  EXPECT_EQ(r.sim->arrived_total(), 1u);
}

TEST(Goals, WaitsAreDrawnPerAgentInTheirRangeAndAlikeOnAnyThreadCount) {
  // 20 people through a booth with a 2-6 s wait to an exit; a wait at the last goal comes
  // before the arrival policy (here: leaving the table).
  const std::string text = R"({"bounds": [0, 0, 30, 20], "duration": 200, "threads": THREADS,
    "goals": [{"name": "booth", "area": [[14, 8], [16, 8], [16, 12], [14, 12]], "wait": [2, 6]},
              {"name": "exit", "x": 28, "y": 10, "arrival_radius": 0.5, "wait": 1}],
    "groups": [{"count": 20, "placement": {"type": "uniform", "region": [1, 1, 8, 19], "gap": 0.1},
                "goal": ["booth", "exit"]}]})";
  std::map<uint64_t, uint64_t> wait_ticks[2];  // id -> ticks waiting at the booth
  std::vector<uint64_t> hashes[2];
  for (int k = 0; k < 2; ++k) {
    std::string t = text;
    t.replace(t.find("THREADS"), 7, k ? "2" : "1");
    Loaded r(t);
    for (uint64_t s = 0; s < r.sc.ticks; ++s) {
      const TickMetrics& m = r.sim->step();
      EXPECT_EQ(m.overlapping_pairs, 0u);
      hashes[k].push_back(m.state_hash);
      const AgentTable& a = r.sim->world().agents();
      for (std::size_t i = 0; i < a.size(); ++i) {
        if (a.state[i] == AgentState::waiting && a.goal[i] == 0) ++wait_ticks[k][a.id[i]];
        // Nobody leaves before the exit's 1 s: a row at the exit waits there first.
        if (a.goal[i] == 1 && std::hypot(a.x[i] - 28, a.y[i] - 10) < 0.3) {
          EXPECT_EQ(a.state[i], AgentState::waiting);
        }
      }
    }
    EXPECT_EQ(r.sim->arrived_total(), 20u);
  }
  EXPECT_EQ(hashes[0], hashes[1]);
  EXPECT_EQ(wait_ticks[0], wait_ticks[1]);
  ASSERT_EQ(wait_ticks[0].size(), 20u);
  uint64_t lo = UINT64_MAX, hi = 0;
  for (const auto& [id, n] : wait_ticks[0]) {
    lo = std::min(lo, n);
    hi = std::max(hi, n);
  }
  EXPECT_GE(lo, 20u);
  EXPECT_LE(hi, 60u);
  EXPECT_GE(hi - lo, 10u);  // drawn per agent, not one wait for all
}

TEST(Goals, BadWaitsAreRefusedNamingTheGoal) {
  const auto error_of = [](const std::string& wait) {
    try {
      parse_scenario(R"({"bounds": [0, 0, 10, 10], "goals": [{"name": "g", "x": 5, "y": 5,
        "wait": )" + wait +
                         R"(}], "agents": [{"x": 1, "y": 1, "goal": "g"}]})",
                     "t.json");
    } catch (const Error& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(error_of("-1").find("/goals/0/wait"), std::string::npos) << error_of("-1");
  EXPECT_NE(error_of("[5, 2]").find("/goals/0/wait"), std::string::npos) << error_of("[5, 2]");
  EXPECT_NE(error_of("[1, 2, 3]").find("/goals/0/wait"), std::string::npos);
  EXPECT_NE(error_of("\"long\"").find("/goals/0/wait"), std::string::npos);
  EXPECT_NE(error_of("1e9").find("/goals/0/wait"), std::string::npos) << error_of("1e9");
  EXPECT_NE(error_of(R"({"exponential": -1})").find("/goals/0/wait/exponential"),
            std::string::npos);
  EXPECT_NE(error_of(R"({"exponential": 5, "mean": 5})").find("/goals/0/wait"), std::string::npos);
  EXPECT_NE(error_of(R"({"exponential": 2e7})").find("/goals/0/wait"), std::string::npos);
  EXPECT_EQ(error_of("[0, 2.5]"), "no error");
  EXPECT_EQ(error_of(R"({"exponential": 5})"), "no error");
}

TEST(Goals, ExponentialWaitsHaveTheirMean) {
  // 100 people through a counter with exponential waits of mean 3 s (a queue's service time).
  Loaded r(R"({"bounds": [0, 0, 60, 40], "duration": 300, "seed": 11,
    "goals": [{"name": "counter", "area": [[30, 0], [32, 0], [32, 40], [30, 40]],
               "wait": {"exponential": 3}},
              {"name": "exit", "area": [[59, 0], [60, 0], [60, 40], [59, 40]]}],
    "groups": [{"count": 100, "placement": {"type": "uniform", "region": [1, 1, 20, 39], "gap": 0.1},
                "goal": ["counter", "exit"]}]})");
  std::map<uint64_t, uint64_t> ticks;
  for (uint64_t s = 0; s < r.sc.ticks && !r.sim->world().agents().empty(); ++s) {
    r.sim->step();
    const AgentTable& a = r.sim->world().agents();
    for (std::size_t i = 0; i < a.size(); ++i)
      if (a.state[i] == AgentState::waiting) ++ticks[a.id[i]];
  }
  EXPECT_EQ(r.sim->arrived_total(), 100u);
  double sum = 0, longest = 0;
  for (const auto& [id, n] : ticks) {
    sum += static_cast<double>(n) * 0.1;
    longest = std::max(longest, static_cast<double>(n) * 0.1);
  }
  // Whole ticks round each draw up by < 0.1 s. The mean of 100 draws lies within 3 +- 0.9 s
  // with probability > 0.997, and the longest of 100 is above 6 s with probability > 0.999.
  EXPECT_EQ(ticks.size(), 100u);
  EXPECT_NEAR(sum / 100, 3.0, 0.9);
  EXPECT_GT(longest, 6.0);
}

TEST(Sources, LetAgentsInAtTheirRateUntilCountOrEnd) {
  Loaded r(R"({"bounds": [0, 0, 60, 20], "duration": 30,
    "goals": [{"name": "out", "area": [[59, 0], [60, 0], [60, 20], [59, 20]]}, {"name": "b", "x": 50, "y": 10}],
    "sources": [{"area": [0, 5, 5, 15], "rate": 2, "count": 100, "start": 3, "end": 8, "goals": ["out", "b"]},
                {"area": [0, 0, 2, 2], "rate": 1, "count": 3, "goal": "out"}]})");
  EXPECT_EQ(sim::source_total(r.sim->world().sources()[0]), 10u);  // 2/s for 5 s
  std::size_t entered = 0;
  for (uint64_t t = 1; t <= r.sc.ticks; ++t) {
    const TickMetrics& m = r.sim->step();
    entered += m.entered;
    const double now = static_cast<double>(t - 1) * 0.1;
    // Source 0: 1 + floor((now - 3) * 2) due from t = 3 s; source 1: one per second, 3 in all.
    const std::size_t due0 =
        now < 3 ? 0
                : std::min<std::size_t>(
                      10, 1 + static_cast<std::size_t>(std::floor((now - 3) * 2 + 1e-9)));
    const std::size_t due1 =
        std::min<std::size_t>(3, 1 + static_cast<std::size_t>(std::floor(now + 1e-9)));
    EXPECT_EQ(entered, due0 + due1) << "tick " << t;
    EXPECT_EQ(m.overlapping_pairs, 0u);
  }
  EXPECT_EQ(r.sim->entered_total(), 13u);
  EXPECT_EQ(r.sim->waiting_to_enter(), 0u);
}

TEST(Sources, AFullAreaMakesAgentsWaitNotVanish) {
  // A 1 x 1 m area, 40 agents at 20 per second: most must wait for the ones before to walk off.
  Loaded r(R"({"bounds": [0, 0, 40, 10], "duration": 60,
    "goals": [{"name": "out", "area": [[39, 0], [40, 0], [40, 10], [39, 10]]}],
    "sources": [{"area": [0.5, 4.5, 1.5, 5.5], "rate": 20, "count": 40, "goal": "out"}]})");
  bool waited = false;
  for (uint64_t t = 1; t <= r.sc.ticks; ++t) {
    r.sim->step();
    if (t == 20) waited = r.sim->waiting_to_enter() > 0;
  }
  EXPECT_TRUE(waited);
  EXPECT_EQ(r.sim->entered_total(), 40u);
  EXPECT_EQ(r.sim->arrived_total(), 40u);
}

TEST(Sources, AreDeterministicAcrossThreads) {
  const std::string text = R"({"bounds": [0, 0, 30, 30], "duration": 20, "threads": THREADS,
    "goals": [{"name": "a", "x": 28, "y": 28}, {"name": "b", "x": 28, "y": 2}],
    "sources": [{"area": [0, 0, 6, 30], "rate": 5, "count": 60, "radius": [0.2, 0.3],
                 "pref_speed": [1, 1.5], "max_speed": 1.5, "goals": ["a", "b"]}]})";
  std::vector<uint64_t> h[2];
  for (int k = 0; k < 2; ++k) {
    std::string t = text;
    t.replace(t.find("THREADS"), 7, k ? "2" : "1");
    Loaded r(t);
    for (uint64_t s = 0; s < r.sc.ticks; ++s) h[k].push_back(r.sim->step().state_hash);
  }
  EXPECT_EQ(h[0], h[1]);
}

// The sources' free spots through the placement grid are the naive loop's, spot for spot: a
// crowd of mixed radii (some piled on one spot, pairs touching exactly, one disc of 5 m), three
// sources over it (a box, a triangle with radii drawn, a small box inside the crowd), obstacles
// and walls, hundreds of agents due in a tick and areas filling up.
TEST(Sources, FreeSpotsThroughTheGridAreTheNaiveLoops) {
  for (const uint64_t seed : {1u, 2u, 3u, 4u}) {
    SCOPED_TRACE(seed);
    const bool crowd = seed != 4;  // without one, more spots are decided by the obstacles
    // 120 obstacles more, scattered: enough for the spots to be tested through a lookup.
    std::string more;
    Rng place(seed + 100);
    for (int o = 0; o < 120; ++o) {
      const double x = place.uniform(2, 55), y = place.uniform(2, 55), d = place.uniform(0.2, 2);
      more += o % 2 ? R"(, {"type": "circle", "x": )" + std::to_string(x) + R"(, "y": )" +
                          std::to_string(y) + R"(, "radius": )" + std::to_string(d) + "}"
                    : R"(, {"type": "polygon", "vertices": [[)" + std::to_string(x) + ", " +
                          std::to_string(y) + "], [" + std::to_string(x + d) + ", " +
                          std::to_string(y) + "], [" + std::to_string(x) + ", " +
                          std::to_string(y + d) + "]]}";
    }
    const auto world = [seed, crowd, &more] {
      Scenario sc = parse_scenario(R"({"bounds": [0, 0, 60, 60],
        "goals": [{"name": "g", "x": 59, "y": 30}],
        "obstacles": [{"type": "circle", "x": 20, "y": 20, "radius": 3},
                      {"type": "polygon", "vertices": [[40, 40], [45, 40], [45, 45]]})" +
                                       more + R"(],
        "sources": [{"area": [0, 0, 30, 30], "rate": 4000, "count": 1500, "goal": "g"},
                    {"polygon": [[10, 10], [50, 10], [30, 50]], "rate": 3000, "count": 900,
                     "radius": [0.1, 0.8], "goal": "g"},
                    {"area": [29, 29, 31, 31], "rate": 1000, "count": 50, "goal": "g"}]})",
                                   "sources.json");
      World w = std::move(sc.world);
      Rng rng(seed);
      for (int k = 0; k < (crowd ? 2500 : 0); ++k) {
        AgentSpec a;
        a.x = rng.uniform(0.5, 59.5);
        a.y = rng.uniform(0.5, 59.5);
        a.radius = rng.uniform(0.1, 0.6);
        a.goal = 0;
        try {
          w.insert(a);
          if (k % 100 == 0) {  // the same spot twice, and a disc touching it exactly
            w.insert(a);
            a.x += 2 * a.radius;
            w.insert(a);
          }
        } catch (const Error&) {  // in an obstacle
        }
      }
      AgentSpec big;
      big.x = 50;
      big.y = 15;
      big.radius = 5;
      big.goal = 0;
      try {
        w.insert(big);
      } catch (const Error&) {  // in an obstacle
      }
      w.apply_pending();
      return w;
    };
    World by_grid = world(), by_loop = world();
    SimConfig cfg;
    cfg.dt = 0.1;
    const StaticScene scene({by_grid.circles().begin(), by_grid.circles().end()},
                            {by_grid.polygons().begin(), by_grid.polygons().end()}, 0.1,
                            ObstacleCharges::none, &by_grid.bounds());
    sim::SourceEmitter grid(by_grid, seed),
        loop(by_loop, seed, sim::SourceEmitter::FreeSpots::naive);
    std::size_t entered = 0;
    for (uint64_t tick = 1; tick <= 6; ++tick) {
      const std::size_t made = grid.emit(by_grid, cfg, scene, tick);
      ASSERT_EQ(made, loop.emit(by_loop, cfg, scene, tick)) << "tick " << tick;
      entered += made;
      by_grid.apply_pending();
      by_loop.apply_pending();
      const AgentTable &a = by_grid.agents(), &b = by_loop.agents();
      ASSERT_EQ(a.size(), b.size());
      for (std::size_t i = 0; i < a.size(); ++i)
        ASSERT_TRUE(a.x[i] == b.x[i] && a.y[i] == b.y[i] && a.radius[i] == b.radius[i])
            << "tick " << tick << " row " << i;
    }
    EXPECT_GT(entered, 300u);              // many entered
    EXPECT_GT(grid.waiting(by_grid), 0u);  // and some found no room
    EXPECT_GT(grid.grids_built(), 0u);     // the grid answered (not only the loop)
    EXPECT_EQ(loop.grids_built(), 0u);
  }
}

// Two people meet head-on in a corridor only one body wide. Under the collision-free speed model
// they stop face to face and, without resolution, never move on (never frozen either: the
// summary must still see them); with it, the one of lower priority backs out. (orca gets through
// on its own: the agent with more path left gives way to where the other wants to go.)
std::string narrow_corridor(bool resolve) {
  return std::string(R"({"bounds": [0, 0, 20, 3], "duration": 90, "steering": {"model": "cfsm"},
    "stall": {"resolve": )") +
         (resolve ? "true" : "false") + R"(},
    "obstacles": [{"type": "polygon", "vertices": [[6, 0], [14, 0], [14, 1.15], [6, 1.15]]},
                  {"type": "polygon", "vertices": [[6, 1.85], [14, 1.85], [14, 3], [6, 3]]}],
    "goals": [{"name": "E", "area": [[19, 0], [20, 0], [20, 3], [19, 3]]},
              {"name": "W", "area": [[0, 0], [1, 0], [1, 3], [0, 3]]}],
    "agents": [{"x": 4, "y": 1.5, "radius": 0.25, "goal": "E"},
               {"x": 16, "y": 1.5, "radius": 0.25, "goal": "W"}],
    "navigation": {}})";
}

TEST(Stalemates, AHeadOnMeetingInANarrowCorridorIsSeenAndResolved) {
  {
    Loaded r(narrow_corridor(false));
    std::size_t most = 0;
    for (uint64_t t = 0; t < r.sc.ticks; ++t) most = std::max(most, r.sim->step().stalled);
    EXPECT_EQ(r.sim->arrived_total(), 0u);
    EXPECT_EQ(most, 2u);  // both seen as stalled, although never frozen
  }
  {
    Loaded r(narrow_corridor(true));
    std::size_t yields = 0;
    for (uint64_t t = 0; t < r.sc.ticks; ++t) yields += r.sim->step().yielding;
    EXPECT_EQ(r.sim->arrived_total(), 2u);
    EXPECT_GT(yields, 0u);
  }
}

}  // namespace
}  // namespace crowddb
