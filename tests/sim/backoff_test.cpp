// The freeze loop (DESIGN.md §3.2): the incremental loop equals the plain one; the metrics; the
// invariant on short runs of the shipped scenarios (the long runs: backoff_slow_test.cpp).
#include <gtest/gtest.h>

#include <cmath>

#include "plan/access_path.hpp"
#include "sim/invariant.hpp"
#include "sim/stages.hpp"
#include "support/configs.hpp"
#include "util/rng.hpp"

namespace crowddb::sim {
namespace {

// A tick frozen just before the backoff: start positions in `t`, tentative ones in `next`.
struct Tentative {
  AgentTable t;
  NextState next;
  StaticScene scene;
};

// n agents; start positions on a jittered lattice (overlap-free unless `spawn_overlaps`), each
// moving up to `reach` lattice spacings this tick; some idle. Circles, a polygon and walls.
Tentative make_tick(std::size_t n, uint64_t seed, bool equal_radii, bool spawn_overlaps,
                    double reach) {
  Rng rng(seed);
  Tentative k;
  AgentTable& t = k.t;
  const double rmax = 1.5, spacing = 2 * rmax + 0.2;
  const auto side = static_cast<std::size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  for (std::size_t i = 0; i < n; ++i) {
    const double r = equal_radii ? rmax : rng.uniform(0.6, rmax);
    double x = static_cast<double>(i % side) * spacing + rng.uniform(-0.1, 0.1);
    double y = static_cast<double>(i / side) * spacing + rng.uniform(-0.1, 0.1);
    if (spawn_overlaps && i % 7 == 0) x += spacing * 0.6;  // overlaps its east neighbour
    t.x.push_back(x);
    t.y.push_back(y);
    t.vx.push_back(0);
    t.vy.push_back(0);
    t.radius.push_back(r);
    t.charge.push_back(1);
    t.id.push_back(1000 + i);
  }
  k.next.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    double vx = 0, vy = 0;
    if (i % 11 != 0) {  // every 11th agent stays put (as idle agents do)
      vx = rng.uniform(-1, 1) * reach * spacing;
      vy = rng.uniform(-1, 1) * reach * spacing;
    }
    k.next.vx[i] = vx;
    k.next.vy[i] = vy;
    k.next.x[i] = t.x[i] + vx;
    k.next.y[i] = t.y[i] + vy;
  }
  const double w = static_cast<double>(side) * spacing;
  std::vector<CircleObstacle> circles = {{w * 0.3, w * 0.3, 4, 1}, {w * 0.7, w * 0.6, 6, 1}};
  std::vector<PolygonObstacle> polys = {
      {{{w * 0.5, w * 0.1}, {w * 0.6, w * 0.1}, {w * 0.55, w * 0.25}}, 1}};
  if (n >= 600)  // enough obstacles for the final count's obstacle index, many on agents
    for (int o = 0; o < 40; ++o) {
      const double ox = rng.uniform(0, w), oy = rng.uniform(0, w), s = rng.uniform(0.5, 3);
      if (o % 2)
        circles.push_back({ox, oy, s, 1});
      else
        polys.push_back({{{ox, oy}, {ox + s, oy}, {ox, oy + s}}, 1});
    }
  const Bounds walls{-1, -1, w, w};
  k.scene = StaticScene(circles, polys, 1, ObstacleCharges::centres, &walls);
  return k;
}

std::unique_ptr<CollisionPath> make_path(const std::string& name) {
  CollisionQueryShape any;
  any.equal_radii = true;
  return find_collision_method(name, any).make();
}

// On one thread and on two (a round's probes run in chunks on every thread), with enough agents
// frozen for the moved rows to get a grid of their own.
TEST(Backoff, IncrementalLoopEqualsThePlainLoop) {
  Executor ex(1), ex2(2);
  std::size_t cascades = 0, grid_probes = 0, moved_grid_rounds = 0, obstacle_hits = 0;
  const std::pair<std::size_t, uint64_t> sizes[] = {{40, 1},  {40, 2},  {40, 3},  {600, 1},
                                                    {600, 2}, {600, 3}, {4000, 1}};
  for (const auto& [n, seed] : sizes)
    for (bool equal : {false, true})
      for (bool spawn : {false, true})
        for (double reach : {0.3, 1.0}) {
          SCOPED_TRACE("n " + std::to_string(n) + " seed " + std::to_string(seed) +
                       (equal ? " equal" : "") + (spawn ? " spawned overlaps" : "") + " reach " +
                       std::to_string(reach));
          const Tentative k = make_tick(n, seed, equal, spawn, reach);
          NextState plain = k.next;
          std::size_t plain_iter = 0;
          QueryStats st;
          const OverlapReport want =
              backoff_reference(k.t, plain, k.scene, *make_path("naive"), ex, st, plain_iter);
          ASSERT_TRUE(want.violators.empty());
          cascades += plain_iter >= 3;
          grid_probes += n * 50 > (1 << 16) && plain_iter >= 2;
          std::vector<std::string> methods = {"naive", "grid", "sweep"};
          if (equal && !spawn) methods.push_back("nn");  // nn is exact for the backoff only then
          for (const std::string& m : methods)
            for (Executor* on : {&ex, &ex2}) {
              SCOPED_TRACE(m + (on == &ex2 ? " on two threads" : ""));
              NextState got = k.next;
              std::size_t iter = 0;
              const OverlapReport r = backoff(k.t, got, k.scene, *make_path(m), *on, st, iter);
              moved_grid_rounds += r.moved_grid_rounds;
              EXPECT_EQ(iter, plain_iter);
              EXPECT_EQ(r.agent_pairs, want.agent_pairs);
              EXPECT_EQ(r.obstacle_hits, want.obstacle_hits);
              obstacle_hits += r.obstacle_hits * (n >= 600);
              EXPECT_TRUE(r.violators.empty());
              EXPECT_EQ(got.frozen, plain.frozen);
              EXPECT_EQ(got.x, plain.x);
              EXPECT_EQ(got.y, plain.y);
              EXPECT_EQ(got.vx, plain.vx);
              EXPECT_EQ(got.vy, plain.vy);
            }
        }
  EXPECT_GT(cascades, 20u);          // freezes that cause further freezes
  EXPECT_GE(grid_probes, 6u);        // large enough for the probes to use the grid
  EXPECT_GT(moved_grid_rounds, 0u);  // and for the moved rows to get a grid of their own
  EXPECT_GT(obstacle_hits, 0u);      // hits left among many obstacles (counted through an index)
}

TEST(Backoff, ChainOfFreezesTakesOneIterationPerLink) {
  // Four discs of radius 1 in a row, 2.5 apart. The last stays; each other one steps right,
  // clear of its neighbour's tentative position but not of its start position: 2 and 3 clash,
  // then freezing 2 traps 1, then freezing 1 traps 0. Four rounds, all four frozen.
  Tentative k;
  for (int i = 0; i < 4; ++i) {
    k.t.x.push_back(2.5 * i);
    k.t.y.push_back(0);
    k.t.vx.push_back(0);
    k.t.vy.push_back(0);
    k.t.radius.push_back(1);
    k.t.charge.push_back(1);
    k.t.id.push_back(i);
  }
  k.next.resize(4);
  const double to[4] = {0.9, 3.3, 5.6, 7.5};
  for (int i = 0; i < 4; ++i) {
    k.next.x[i] = to[i];
    k.next.y[i] = 0;
    k.next.vx[i] = to[i] - k.t.x[i];
    k.next.vy[i] = 0;
  }
  Executor ex(1);
  QueryStats st;
  for (const std::string m : {"naive", "grid", "sweep", "nn"}) {
    NextState s = k.next;
    std::size_t iter = 0;
    const OverlapReport r = backoff(k.t, s, k.scene, *make_path(m), ex, st, iter);
    EXPECT_EQ(iter, 4u) << m;
    EXPECT_EQ(s.frozen, (std::vector<uint8_t>{1, 1, 1, 1})) << m;
    EXPECT_EQ(s.x, k.t.x) << m;
    EXPECT_EQ(r.agent_pairs, 0u) << m;
  }
}

// Agents at (x, y) of radius r, stepping dx along the x axis this tick.
struct Step {
  double x, y, r, dx;
};
Tentative steps(const std::vector<Step>& all) {
  Tentative k;
  uint64_t id = 0;
  for (const Step& a : all) {
    k.t.x.push_back(a.x);
    k.t.y.push_back(a.y);
    k.t.vx.push_back(0);
    k.t.vy.push_back(0);
    k.t.radius.push_back(a.r);
    k.t.charge.push_back(1);
    k.t.id.push_back(id++);
    k.next.x.push_back(a.x + a.dx);
    k.next.y.push_back(a.y);
    k.next.vx.push_back(a.dx);
    k.next.vy.push_back(0);
    k.next.frozen.push_back(0);
  }
  return k;
}
// The same on a line, radius 0.25.
Tentative line_tick(std::initializer_list<std::pair<double, double>> x_dx) {
  std::vector<Step> all;
  for (auto [x, dx] : x_dx) all.push_back({x, 0, 0.25, dx});
  return steps(all);
}

bool by_lists(const Tentative& k, double range, uint32_t k_nearest) {
  Executor ex(1);
  const NeighbourLists lists = neighbours(DiscView::of(k.t), range, k_nearest, {}, "naive");
  return lists_rule_out_overlaps(k.t, k.next, {&lists, range, k_nearest}, ex);
}

TEST(Backoff, NeighbourListsMustReachAsFarAsBothAgentsMove) {
  // A and B (1 m apart) step 0.3 m towards each other and overlap. Each one's single nearest
  // neighbour is someone else 0.9 m off (C, D), who stays: neither list holds the pair. A bound
  // of r + r_max + one's own move (0.8 m) would pass both lists; the other's move must count.
  const Tentative k = line_tick({{0, 0.3}, {1, -0.3}, {-0.9, 0}, {1.9, 0}});
  Executor ex(1);
  QueryStats st;
  EXPECT_GT(find_overlaps(k.t, k.next, k.scene, *make_path("naive"), ex, st).agent_pairs, 0u);
  EXPECT_FALSE(by_lists(k, 5, 1));
  EXPECT_FALSE(by_lists(k, 5, 0));  // every row within 5 m listed: the pair is, and overlaps
  // Stepping apart by 0.1 m: nobody within 0.7 m (r + r_max + both moves) of anyone, so the
  // single nearest (0.9 m) is enough, and so are empty lists complete to 0.75 m; those complete
  // to 0.65 m fall short, and the four rows' pairs are tested one by one.
  const Tentative apart = line_tick({{0, -0.1}, {1, 0.1}, {-0.9, -0.1}, {1.9, 0.1}});
  EXPECT_TRUE(by_lists(apart, 5, 1));
  EXPECT_TRUE(by_lists(apart, 0.75, 0));
  EXPECT_TRUE(by_lists(apart, 0.65, 0));
  // Radii count at their largest. A (0.25 m) and B (0.5 m), 0.9 m apart, step 0.1 m towards
  // each other and overlap. B's two nearest are A and D (1.3 m): its list holds the pair. A's are
  // C and E (0.8, 0.85 m), short of 0.25 + 0.5 + 0.1 + 0.1 (though not of 0.25 + 0.25 + 0.2): the
  // pair is in one list only, and a check of each pair from one side would miss it.
  const Tentative mixed = steps({{0, 0, 0.25, 0.1},
                                 {0.9, 0, 0.5, -0.1},
                                 {-0.8, 0, 0.25, 0},
                                 {2.2, 0, 0.25, 0},
                                 {0, 0.85, 0.25, 0}});
  EXPECT_GT(
      find_overlaps(mixed.t, mixed.next, mixed.scene, *make_path("naive"), ex, st).agent_pairs, 0u);
  EXPECT_FALSE(by_lists(mixed, 5, 2));
}

TEST(Backoff, NeighbourListsFallingShortAreTestedOneByOneUpToACap) {
  // A row of agents 0.6 m apart, all stepping 0.05 m to the right: every single-nearest list
  // (0.6 m) falls short of 0.25 + 0.25 + 2 * 0.05. Up to 256 such rows
  // their pairs are tested one by one; beyond, the lists show nothing.
  for (std::size_t n : {200u, 256u, 257u, 300u}) {
    std::vector<Step> row;
    for (std::size_t i = 0; i < n; ++i)
      row.push_back({0.6 * static_cast<double>(i), 0, 0.25, 0.05});
    Tentative k = steps(row);
    EXPECT_EQ(by_lists(k, 5, 1), n <= 256) << n;
    // One pair stepping into each other (rows 10 and 11) is found among them.
    k.next.x[10] = k.t.x[10] + 0.06;
    k.next.x[11] = k.t.x[11] - 0.06;
    EXPECT_FALSE(by_lists(k, 5, 1)) << n;
  }
}

TEST(Backoff, NeighbourListsRuleOutOnlyTicksWithoutOverlaps) {
  // Random ticks against the naive collision query; lists of every k and range. Whenever the
  // lists rule overlaps out, the oracle finds none, and the backoff with them (which then skips
  // the query's agent half) ends where the plain loop does.
  Executor one(1), two(2);
  std::size_t shown = 0, overlapping = 0, not_shown_clean = 0;
  for (uint64_t seed = 1; seed <= 40; ++seed) {
    Rng rng(seed);
    const std::size_t n = 20 + rng.below(400);
    const bool equal = seed % 3 == 0;
    const double reach = seed % 4 == 0 ? 0.3 : (seed % 4 == 1 ? 0.01 : 0.05);
    const Tentative k = make_tick(n, seed, equal, seed % 5 == 0, reach);
    NextState plain = k.next;
    std::size_t plain_iter = 0;
    QueryStats st;
    const OverlapReport want =
        backoff_reference(k.t, plain, k.scene, *make_path("naive"), one, st, plain_iter);
    const OverlapReport before = find_overlaps(k.t, k.next, k.scene, *make_path("naive"), one, st);
    for (uint32_t kn : {0u, 1u, 4u, 8u, 12u, 30u})
      for (double range : {2.0, 4.0, 6.5, 20.0}) {
        SCOPED_TRACE("seed " + std::to_string(seed) + " k " + std::to_string(kn) + " range " +
                     std::to_string(range));
        const NeighbourLists lists = neighbours(DiscView::of(k.t), range, kn, {}, "naive");
        const NearLists near{&lists, range, kn};
        const bool ruled_out = lists_rule_out_overlaps(k.t, k.next, near, one);
        EXPECT_EQ(lists_rule_out_overlaps(k.t, k.next, near, two), ruled_out);
        if (ruled_out) {
          ++shown;
          EXPECT_EQ(before.agent_pairs, 0u);
        } else {
          overlapping += before.agent_pairs > 0;
          not_shown_clean += before.agent_pairs == 0;
        }
        NextState got = k.next;
        std::size_t iter = 0;
        const OverlapReport r = backoff(k.t, got, k.scene, *make_path("grid"), two, st, iter, near);
        EXPECT_EQ(r.agents_by_lists, ruled_out);
        EXPECT_EQ(iter, plain_iter);
        EXPECT_EQ(r.agent_pairs, want.agent_pairs);
        EXPECT_EQ(r.obstacle_hits, want.obstacle_hits);
        EXPECT_EQ(got.frozen, plain.frozen);
        EXPECT_EQ(got.x, plain.x);
        EXPECT_EQ(got.y, plain.y);
      }
  }
  // All three kinds of tick occur: the test is not vacuous.
  EXPECT_GT(shown, 100u);
  EXPECT_GT(overlapping, 100u);
  EXPECT_GT(not_shown_clean, 20u);
}

World two_agents_head_on() {
  World w(Bounds{0, 0, 100, 100});
  w.add_goal({"east", 90, 50, 1, 1, {}});
  w.add_goal({"west", 10, 50, 1, 1, {}});
  AgentSpec a;
  a.x = 40;
  a.y = 50;
  a.radius = 1;  // the thesis's units: at 1 per tick, smaller discs would pass through each other
  a.max_speed = 1;
  a.pref_speed = a.max_speed;
  a.goal = 0;
  w.insert(a);
  a.x = 60;
  a.goal = 1;
  w.insert(a);
  return w;
}

TEST(Backoff, TickMetricsCountFrozenAgentsAndIterations) {
  SimConfig cfg = test::thesis_config();
  cfg.steering.thesis.w_apf = 0;  // no avoidance: they walk into each other
  cfg.steering.thesis.w_ftc = 0;
  cfg.nudge_after = 0;
  cfg.gridlock_time = 5;
  Simulation sim(two_agents_head_on(), cfg);
  std::size_t first_freeze = 0, streak = 0;
  for (int k = 1; k <= 40; ++k) {
    const auto before = sim.world().agents().x;
    const TickMetrics& m = sim.step();
    if (m.frozen && !first_freeze) {
      first_freeze = static_cast<std::size_t>(k);
      EXPECT_EQ(m.frozen, 2u);
      EXPECT_EQ(m.freeze_iterations, 2u);  // one round freezes both, the next finds nothing
      EXPECT_EQ(sim.world().agents().x, before);
      EXPECT_EQ(sim.world().agents().vx, (std::vector<double>{0, 0}));
    }
    if (!m.frozen) {
      EXPECT_EQ(m.freeze_iterations, 1u);
    }
    EXPECT_EQ(m.overlapping_pairs, 0u);
    // Both or neither are frozen; gridlock: 5 frozen ticks in a row.
    EXPECT_TRUE(m.frozen == 0 || m.frozen == 2);
    streak = m.frozen ? streak + 1 : 0;
    EXPECT_EQ(m.longest_frozen, streak);
    EXPECT_EQ(m.gridlocked, streak >= 5 ? 2u : 0u);
    EXPECT_EQ(m.gridlock_started, streak == 5 ? 2u : 0u);
  }
  EXPECT_GT(first_freeze, 5u);
  EXPECT_LT(first_freeze, 20u);
  EXPECT_GE(streak, 10u);  // head-on without a sidestep: they stay stuck
}

TEST(Backoff, NudgingBreaksAHeadOnDeadlock) {
  SimConfig cfg = test::thesis_config();
  cfg.steering.thesis.w_apf = 0;
  cfg.steering.thesis.w_ftc = 0;
  cfg.nudge_after = 2;
  Simulation sim(two_agents_head_on(), cfg);
  std::size_t nudged = 0;
  for (int k = 0; k < 200 && sim.world().agents().size(); ++k) nudged += sim.step().nudged;
  EXPECT_GT(nudged, 0u);
  EXPECT_EQ(sim.arrived_total(), 2u);  // both got past each other
}

// Agents spawned overlapping in clumps: the tolerated overlaps never deepen, new ones never
// appear, and the overlap metrics equal the brute-force counts.
World spawned_overlapping(bool equal_radii) {
  World w(Bounds{0, 0, 120, 120});
  w.add_goal({"a", 110, 110, 1, 3, {}});
  w.add_goal({"b", 10, 110, 1, 3, {}});
  Rng rng(9);
  for (int c = 0; c < 12; ++c) {
    const double cx = rng.uniform(20, 100), cy = rng.uniform(20, 100);
    for (int i = 0; i < 6; ++i) {
      AgentSpec s;
      s.x = cx + rng.uniform(-1.5, 1.5);
      s.y = cy + rng.uniform(-1.5, 1.5);
      s.radius = equal_radii ? 1.2 : rng.uniform(0.8, 1.6);
      s.max_speed = 1;
      s.pref_speed = s.max_speed;
      s.max_accel = 0.5;
      s.goal = static_cast<uint32_t>(c % 2);
      w.insert(s);
    }
  }
  return w;
}

TEST(Backoff, PreExistingOverlapsNeverDeepen) {
  for (bool equal : {false, true}) {
    SimConfig cfg = test::thesis_config();
    cfg.steering.thesis.w_apf = 2;
    cfg.steering.thesis.w_ftc = 2;
    cfg.arrival = ArrivalPolicy::idle;
    Simulation sim(spawned_overlapping(equal), cfg);
    ASSERT_FALSE(test::initially_overlap_free(sim.world(), cfg));
    const test::RunResult r = test::run_checked(sim, 150);
    EXPECT_EQ(r.bad, 0u);
    EXPECT_EQ(r.metric_mismatch, 0u);
    EXPECT_GT(r.overlaps_at_end,
              50u);  // the spawned overlaps persist for a while: the case is real
  }
}

TEST(Backoff, ForcedNnFallsBackWhileAgentsOverlapAndMatchesGrid) {
  SimConfig cfg = test::thesis_config();
  cfg.steering.thesis.w_apf = 2;
  cfg.steering.thesis.w_ftc = 2;
  cfg.arrival = ArrivalPolicy::idle;
  cfg.access.collisions = "nn";
  Simulation nn(spawned_overlapping(true), cfg);
  const test::RunResult a = test::run_checked(nn, 150);
  cfg.access.collisions = "grid";
  Simulation grid(spawned_overlapping(true), cfg);
  const test::RunResult b = test::run_checked(grid, 150, false);
  EXPECT_EQ(a.bad, 0u);
  EXPECT_EQ(a.hashes, b.hashes);
  const std::string plan = nn.explain_analyze();
  EXPECT_NE(plan.find("(instead of nn)"), std::string::npos) << plan;
  EXPECT_NE(plan.find("collisions=nn x"), std::string::npos) << plan;  // used once clean
}

TEST(Backoff, ForcedNnIsRejectedWhereItCanNeverServe) {
  SimConfig cfg = test::thesis_config();
  cfg.access.collisions = "nn";
  EXPECT_THROW(Simulation(spawned_overlapping(false), cfg), Error);  // unequal radii
  cfg.backoff = false;  // overlap counts need every pair
  EXPECT_THROW(Simulation(spawned_overlapping(true), cfg), Error);
}

// Short runs of the shipped scenarios; backoff_slow_test.cpp runs > 10^4 ticks of them.
struct ScenarioRun {
  std::string name;
  uint64_t ticks;
  std::function<void(nlohmann::json&)> edit;
  bool backoff_busy = true;  // the run must freeze someone (else it proves little)
};

TEST(Backoff, ShippedScenariosKeepTheInvariantAndAllExactMethodsAgree) {
  // Under the thesis's rule the backoff has work to do; under the default model (orca) it
  // should have almost none, and the invariant must hold all the same.
  // The thesis's rule with its avoidance off: the agents walk into each other.
  auto thesis = [](nlohmann::json& j) {
    j["steering"] = {{"model", "thesis"}, {"thesis", {{"w_apf", 0}, {"w_ftc", 0}}}};
  };
  const std::vector<ScenarioRun> runs = {
      {"circle", 250, thesis},
      {"bottleneck", 300, thesis},
      {"airport", 300,
       [&](nlohmann::json& j) {  // 500 travellers, no sources
         j["groups"][0]["count"] = 500;
         j.erase("sources");
         thesis(j);
       }},
      {"bottleneck", 300, [](nlohmann::json&) {}, false},
      {"crossing", 300, [](nlohmann::json&) {}, false},
  };
  for (const auto& run : runs) {
    SCOPED_TRACE(run.name);
    std::vector<uint64_t> reference;
    std::size_t frozen = 0;
    // "auto": under orca the backoff's agent half answered from orca's neighbour lists (only
    // with the method left to the planner), against the methods asked for by name.
    for (const std::string m : {"naive", "grid", "sweep", "nn", "auto"}) {
      Scenario sc = test::load_edited(run.name, [&](nlohmann::json& j) {
        run.edit(j);
        j["access"]["collisions"] = m;
      });
      const bool equal =
          std::all_of(sc.world.agents().radius.begin(), sc.world.agents().radius.end(),
                      [&](double r) { return r == sc.world.agents().radius.front(); });
      if (m == "nn" && !equal) continue;
      sc.world.apply_pending();
      ASSERT_TRUE(test::initially_overlap_free(sc.world, sc.config));
      Simulation sim(std::move(sc.world), sc.config);
      const test::RunResult r = test::run_checked(sim, run.ticks, m == "naive" || m == "grid");
      const bool by_lists =
          sim.explain_analyze().find("collisions=model's neighbour lists") != std::string::npos;
      EXPECT_EQ(by_lists, m == "auto" && !run.backoff_busy) << m;
      EXPECT_EQ(r.bad, 0u) << m;
      EXPECT_EQ(r.overlaps_at_end, 0u) << m;
      EXPECT_EQ(r.metric_mismatch, 0u) << m;
      if (reference.empty()) {
        reference = r.hashes;
        frozen = r.frozen_total;
      } else {
        EXPECT_EQ(r.hashes, reference) << m;
      }
    }
    if (run.backoff_busy) {
      EXPECT_GT(frozen, 0u) << "the backoff had no work: the run proves little";
    }
  }
}

}  // namespace
}  // namespace crowddb::sim
