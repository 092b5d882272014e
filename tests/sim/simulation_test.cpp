#include "crowddb/simulation.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <sstream>

#include "crowddb/scenario.hpp"
#include "sim/stages.hpp"
#include "support/cli.hpp"
#include "support/configs.hpp"
#include "util/executor.hpp"
#include "util/rng.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb {
namespace {

// A small, dense airport under the thesis's rule in its own units: 250 travellers in a 160 x 160
// hall with 6 pillars and 4 gates.
std::string small_airport(uint64_t seed, int threads = 1, const char* arrival = "retarget") {
  return std::string(R"({"bounds": [0, 0, 160, 160], "seed": )") + std::to_string(seed) +
         R"(, "threads": )" + std::to_string(threads) + R"(, "arrival": ")" + arrival + R"(", )" +
         test::thesis_json() + R"(, "ticks": 100,
    "goals": [{"name": "S", "x": 80, "y": 4, "arrival_radius": 8}, {"name": "N", "x": 80, "y": 156, "arrival_radius": 8},
              {"name": "W", "x": 4, "y": 80, "arrival_radius": 8}, {"name": "E", "x": 156, "y": 80, "arrival_radius": 8}],
    "obstacles": [{"type": "circle", "x": 40, "y": 50, "radius": 8}, {"type": "circle", "x": 80, "y": 50, "radius": 10},
                  {"type": "circle", "x": 120, "y": 50, "radius": 8}, {"type": "circle", "x": 40, "y": 110, "radius": 9},
                  {"type": "polygon", "vertices": [[70, 100], [90, 100], [90, 120], [70, 120]]},
                  {"type": "circle", "x": 120, "y": 110, "radius": 8}],
    "groups": [{"count": 250, "radius": [1, 3], "speed": [0, 5], "max_speed": 5, "max_accel": 1,
                "placement": {"type": "uniform", "region": [5, 5, 155, 155], "gap": 0.5},
                "goals": {"assign": "round_robin"}}],
    "steering": {"model": "thesis", "perturbation": 0,
                 "thesis": {"w_apf": 30, "w_ftc": 3, "obstacle_repulsion": "charges"}}})";
}

std::vector<uint64_t> hashes(const std::string& text, int ticks) {
  Scenario sc = parse_scenario(text, "t.json");
  Simulation sim(std::move(sc.world), sc.config);
  std::vector<uint64_t> h{sim.state_hash()};
  for (int t = 0; t < ticks; ++t) h.push_back(sim.step().state_hash);
  return h;
}

TEST(Determinism, SameSeedTwiceGivesTheSameHashEveryTick) {
  EXPECT_EQ(hashes(small_airport(5), 40), hashes(small_airport(5), 40));
  EXPECT_NE(hashes(small_airport(5), 2), hashes(small_airport(6), 2));
}

TEST(Determinism, OneAndTwoThreadsGiveTheSameHashEveryTick) {
  EXPECT_EQ(hashes(small_airport(5, 1), 40), hashes(small_airport(5, 2), 40));
}

// The state hash in blocks and lanes (sim::state_hash): the same on any executor, and any one
// changed word of any row (first, last, either side of a block's end, the tail) changes it, as
// do the tick, the row order and the sign of a zero.
TEST(Determinism, TheStateHashSeesEveryWordOnAnyThreadCount) {
  for (const std::size_t n : {std::size_t{0}, std::size_t{1}, std::size_t{7}, sim::kHashBlock,
                              2 * sim::kHashBlock + 13}) {
    AgentTable t;
    Rng rng(n + 1);
    for (std::size_t i = 0; i < n; ++i) {
      t.id.push_back(1000 + i);
      t.x.push_back(rng.uniform(-50, 50));
      t.y.push_back(rng.uniform(-50, 50));
      t.vx.push_back(rng.uniform(-1, 1));
      t.vy.push_back(rng.uniform(-1, 1));
      t.state.push_back(i % 5 == 0 ? AgentState::arrived : AgentState::active);
    }
    const uint64_t h = sim::state_hash(t, 9);
    for (int threads : {1, 2, 3}) {
      Executor ex(threads);
      EXPECT_EQ(sim::state_hash(t, 9, &ex), h) << n << " rows, " << threads << " threads";
    }
    EXPECT_NE(sim::state_hash(t, 10), h) << n;
    if (n == 0) continue;
    std::vector<std::size_t> rows = {0, n - 1, n / 2};
    if (n > sim::kHashBlock) rows.insert(rows.end(), {sim::kHashBlock - 1, sim::kHashBlock});
    for (const std::size_t i : rows) {
      auto changes = [&](auto& column, auto other) {
        const auto keep = column[i];
        column[i] = other;
        Executor ex(2);
        const bool seen = sim::state_hash(t, 9) != h && sim::state_hash(t, 9, &ex) != h;
        column[i] = keep;
        return seen;
      };
      EXPECT_TRUE(changes(t.id, t.id[i] + 1)) << "id of row " << i << " of " << n;
      EXPECT_TRUE(changes(t.x, std::nextafter(t.x[i], 1e9))) << "x of row " << i << " of " << n;
      EXPECT_TRUE(changes(t.y, std::nextafter(t.y[i], 1e9))) << "y of row " << i << " of " << n;
      EXPECT_TRUE(changes(t.vx, -t.vx[i])) << "vx of row " << i << " of " << n;
      EXPECT_TRUE(changes(t.vy, t.vy[i] == 0.0 ? -0.0 : 0.0)) << "vy of row " << i << " of " << n;
      EXPECT_TRUE(changes(
          t.state, t.state[i] == AgentState::arrived ? AgentState::active : AgentState::arrived))
          << "state of row " << i << " of " << n;
    }
    if (n > 1) {  // two rows swapped: the same set of agents in another order
      for (auto* c : {&t.x, &t.y, &t.vx, &t.vy}) std::swap((*c)[0], (*c)[n - 1]);
      std::swap(t.id[0], t.id[n - 1]);
      std::swap(t.state[0], t.state[n - 1]);
      EXPECT_NE(sim::state_hash(t, 9), h) << n;
    }
  }
  AgentTable zero;  // -0.0 and 0.0 differ
  zero.id = {1};
  zero.x = {0.0};
  zero.y = zero.vx = zero.vy = {0.0};
  zero.state = {AgentState::active};
  const uint64_t plus = sim::state_hash(zero, 0);
  zero.x[0] = -0.0;
  EXPECT_NE(sim::state_hash(zero, 0), plus);
}

TEST(Simulation, BackoffKeepsAnOverlapFreeWorldOverlapFree) {
  Scenario sc = parse_scenario(small_airport(3), "t.json");
  ASSERT_TRUE(sc.warnings.empty());
  Simulation sim(std::move(sc.world), sc.config);
  std::size_t frozen = 0;
  for (int t = 0; t < 150; ++t) {
    const TickMetrics& m = sim.step();
    ASSERT_EQ(m.overlapping_pairs, 0u) << "tick " << m.tick;
    ASSERT_EQ(m.obstacle_overlaps, 0u) << "tick " << m.tick;
    frozen += m.frozen;
  }
  EXPECT_GT(frozen, 0u);  // the loop had work to do: the invariant is not vacuous
  EXPECT_GT(sim.arrived_total(), 0u);
}

TEST(Simulation, WithoutBackoffOverlapsHappen) {
  std::string text = small_airport(3);
  text.insert(text.rfind('}'), R"(, "backoff": false)");
  Scenario sc = parse_scenario(text, "t.json");
  Simulation sim(std::move(sc.world), sc.config);
  std::size_t worst = 0;
  for (int t = 0; t < 60; ++t) worst = std::max(worst, sim.step().overlapping_pairs);
  EXPECT_GT(worst, 0u);
}

World corridor_world() {
  World w(Bounds{0, 0, 100, 20});
  w.add_goal({"east", 90, 10, 1, 2, {}});
  w.add_goal({"west", 10, 10, 1, 2, {}});
  return w;
}

AgentSpec walker(double x, uint32_t goal, double vx = 0) {
  AgentSpec s;
  s.x = x;
  s.y = 10;
  s.vx = vx;
  s.radius = 1;
  s.max_speed = 1;
  s.pref_speed = s.max_speed;
  s.goal = goal;
  return s;
}

TEST(Simulation, ALoneAgentWalksStraightToItsGoalAndLeaves) {
  World w = corridor_world();
  const AgentId a = w.insert(walker(10, 0));
  Simulation sim(std::move(w), test::thesis_config());
  int ticks = 0;
  while (sim.world().contains(a) && ticks < 200) {
    const double y = sim.world().agents().y[*sim.world().row_of(a)];
    ASSERT_NEAR(y, 10, 1e-9);
    sim.step();
    ++ticks;
  }
  EXPECT_FALSE(sim.world().contains(a));
  EXPECT_EQ(sim.arrived_total(), 1u);
  // 78 units to go at max speed 1 after accelerating from rest (tau = 2): a little over 78 ticks.
  EXPECT_GE(ticks, 78);
  EXPECT_LE(ticks, 90);
}

TEST(Simulation, ArrivalPoliciesIdleAndRetarget) {
  for (ArrivalPolicy policy : {ArrivalPolicy::idle, ArrivalPolicy::retarget}) {
    World w = corridor_world();
    const AgentId a = w.insert(walker(85, 0));
    SimConfig cfg = test::thesis_config();
    cfg.arrival = policy;
    Simulation sim(std::move(w), cfg);
    for (int t = 0; t < 10; ++t) sim.step();
    ASSERT_TRUE(sim.world().contains(a));
    const std::size_t row = *sim.world().row_of(a);
    EXPECT_GE(sim.arrived_total(), 1u);
    if (policy == ArrivalPolicy::idle) {
      EXPECT_EQ(sim.world().agents().state[row], AgentState::arrived);
      EXPECT_EQ(sim.world().agents().vx[row], 0.0);
    } else {
      EXPECT_EQ(sim.world().agents().goal[row], 1u);  // the only other goal
      // A wandering crowd records no goal left (out before in is for goal sequences).
      EXPECT_EQ(sim.world().agents().left_goal[row], AgentTable::kNoGoal);
    }
  }
}

TEST(Simulation, AGoalSequenceRecordsTheGoalLeft) {
  World w = corridor_world();
  AgentSpec s = walker(85, 0);
  s.then = {1};
  const AgentId a = w.insert(s);
  Simulation sim(std::move(w), test::thesis_config());
  EXPECT_EQ(sim.world().agents().left_goal[0], AgentTable::kNoGoal);
  for (int t = 0; t < 10; ++t) sim.step();
  const std::size_t row = *sim.world().row_of(a);
  EXPECT_EQ(sim.world().agents().goal[row], 1u);
  EXPECT_EQ(sim.world().agents().left_goal[row], 0u);  // east, reached on the way
}

TEST(Simulation, ChangesMadeBetweenTicksApplyAtTheNextTickAsOneBatch) {
  World w = corridor_world();
  const AgentId a = w.insert(walker(20, 0));
  Simulation sim(std::move(w), test::thesis_config());
  sim.step();
  const AgentId b = sim.world().insert(walker(60, 1));
  sim.world().retarget(a, 1);
  EXPECT_FALSE(sim.world().contains(b));
  EXPECT_EQ(sim.world().agents().goal[*sim.world().row_of(a)], 0u);
  sim.step();
  ASSERT_TRUE(sim.world().contains(b));
  EXPECT_EQ(sim.world().agents().goal[*sim.world().row_of(a)], 1u);
  sim.world().erase(a);
  sim.step();
  EXPECT_FALSE(sim.world().contains(a));
  EXPECT_TRUE(sim.world().contains(b));
  sim.world().validate();
}

TEST(Simulation, PreExistingOverlapsNeverDeepen) {
  World w = corridor_world();
  // Spawned overlapping (centres 1.5 apart, radii 1), both pulled towards each other's side.
  const AgentId a = w.insert(walker(49, 0, 1));
  const AgentId b = w.insert(walker(50.5, 1, -1));
  SimConfig cfg = test::thesis_config();
  cfg.steering.thesis.w_apf = 0;  // no repulsion: only backoff stops them
  cfg.steering.thesis.w_ftc = 0;
  Simulation sim(std::move(w), cfg);
  double gap = 1.5;
  for (int t = 0; t < 30; ++t) {
    sim.step();
    const AgentTable& tab = sim.world().agents();
    const std::size_t i = *sim.world().row_of(a), j = *sim.world().row_of(b);
    const double d = std::hypot(tab.x[i] - tab.x[j], tab.y[i] - tab.y[j]);
    ASSERT_GE(d, gap) << "tick " << t;
    gap = d;
  }
}

TEST(Simulation, WallsKeepAgentsInside) {
  World w(Bounds{0, 0, 50, 50});
  w.add_goal({"outside", 200, 25, 1, 1, {}});
  for (int i = 0; i < 5; ++i) {
    AgentSpec s = walker(30 + 3 * i, 0, 2);
    s.y = 10 + 7 * i;
    s.max_speed = 3;
    s.pref_speed = s.max_speed;
    w.insert(s);
  }
  Simulation sim(std::move(w), test::thesis_config());
  for (int t = 0; t < 50; ++t) {
    sim.step();
    const AgentTable& tab = sim.world().agents();
    for (std::size_t i = 0; i < tab.size(); ++i) {
      ASSERT_LE(tab.x[i] + tab.radius[i], 50.0);
      ASSERT_GE(tab.x[i] - tab.radius[i], 0.0);
    }
  }
}

TEST(Simulation, ExplainNamesEveryOperatorAndAccessPath) {
  Scenario sc = parse_scenario(small_airport(1), "t.json");
  Simulation sim(std::move(sc.world), sc.config);
  const std::string plan = sim.explain();
  for (const char* s : {"Q1 attraction", "Q2 inner avoidance", "Q3 outer avoidance", "backoff",
                        "commit", "exp-l1", "goal stage", "stalemates", "model=thesis"})
    EXPECT_NE(plan.find(s), std::string::npos) << s << "\n" << plan;
  // One access path per indexed query: Q2, Q3 and the backoff's collision set.
  std::size_t paths = 0;
  for (auto at = plan.find("access path: "); at != std::string::npos;
       at = plan.find("access path: ", at + 1))
    ++paths;
  EXPECT_EQ(paths, 3u) << plan;
  for (int t = 0; t < 3; ++t) sim.step();
  const std::string analyze = sim.explain_analyze();
  EXPECT_NE(analyze.find("EXPLAIN ANALYZE  3 ticks"), std::string::npos) << analyze;
  EXPECT_NE(analyze.find("pair tests"), std::string::npos) << analyze;
  // Placed apart, the crowd starts tick 1 with overlaps unknown and ticks 2 and 3 with none
  // (the backoff's word): the first-to-collide index is told so on those two, and acts on it.
  EXPECT_NE(analyze.find("ticks with no overlap pass (none at the start) 2 "), std::string::npos)
      << analyze;
}

// ORCA's and CFSM's obstacle queries (and ORCA's look ahead for people passing) run beside the
// neighbour query on the same threads, the thesis model's potential field (and its obstacles)
// beside its first-to-collide query: EXPLAIN ANALYZE says so, and its total counts the overlap
// once: it is the operators' times less the overlap it reports.
TEST(Simulation, ExplainAnalyzeCountsOperatorsSideBySideOnce) {
  for (const char* model : {"orca", "cfsm", "thesis"}) {
    std::string text = small_airport(1, 2);
    const std::string thesis = R"("model": "thesis")";
    text.replace(text.find(thesis), thesis.size(), std::string(R"("model": ")") + model + "\"");
    const bool is_thesis = model == std::string("thesis");
    if (is_thesis) {  // its obstacles by the nearest feature: a pass of their own, beside Q3 too
      const std::string charges = R"("obstacle_repulsion": "charges")";
      text.replace(text.find(charges), charges.size(), R"("obstacle_repulsion": "nearest")");
    }
    Scenario sc = parse_scenario(text, "t.json");
    Simulation sim(std::move(sc.world), sc.config);
    Stopwatch wall;
    for (int t = 0; t < 5; ++t) sim.step();
    const double wall_ms = wall.seconds() * 1e3;
    const std::string a = sim.explain_analyze();
    SCOPED_TRACE(a);
    const std::string other = model == std::string("orca")   ? "ORCA neighbours"
                              : model == std::string("cfsm") ? "CFSM neighbours"
                                                             : "Q3 outer avoidance";
    EXPECT_NE(a.find("beside " + other + ", on the same threads"), std::string::npos);
    if (is_thesis) {  // the field and the obstacle pass, both
      const std::string beside = "beside Q3 outer avoidance, on the same threads";
      const auto first = a.find(beside);
      EXPECT_NE(first, std::string::npos);
      EXPECT_NE(a.find(beside, first + 1), std::string::npos);
    }
    // Sum the operators' "total ms" column and compare with the total line.
    double sum = 0, total = -1, overlap = 0;
    std::istringstream in(a);
    for (std::string line; std::getline(in, line);) {
      unsigned long long loops = 0, rows = 0;
      double ms = 0, per = 0;
      char name[64];
      if (std::sscanf(line.c_str(), "  total %lf", &total) == 1) continue;
      if (std::sscanf(line.c_str(), "  (operators side by side overlapped by %lf", &overlap) == 1)
        continue;
      // "  name words  loops rows total ms/loop": the four numbers at the end.
      const auto at = line.find_last_not_of(" 0123456789.");
      if (at == std::string::npos || line.rfind("  ", 0) != 0) continue;
      if (std::sscanf(line.c_str() + at + 1, "%llu %llu %lf %lf", &loops, &rows, &ms, &per) == 4 &&
          std::sscanf(line.c_str(), "  %63s", name) == 1)
        sum += ms;
    }
    ASSERT_GT(total, 0);
    EXPECT_NEAR(total, sum - overlap, 0.01 + 1e-6 * sum);
    // The operators ran within the steps: their total, the overlap counted once, cannot exceed
    // the steps' wall time.
    EXPECT_LE(total, wall_ms + 0.01);
  }
}

TEST(Simulation, UnknownAccessPathIsRejectedBeforeTheRun) {
  Scenario sc = parse_scenario(small_airport(1), "t.json");
  sc.config.access.ftc = "quantum";
  EXPECT_THROW(Simulation(std::move(sc.world), sc.config), Error);
}

}  // namespace
}  // namespace crowddb
