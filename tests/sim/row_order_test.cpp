// The row order is physical design, not semantics: putting the agents' rows in another order
// (World::permute_rows, the tick's Z-curve order) changes no agent's trajectory.
#include "sim/row_order.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <tuple>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "support/cli.hpp"
#include "util/executor.hpp"

namespace crowddb {
namespace {

// Every column of every agent, by id, and the handles' rows.
struct Agent {
  double x, y, vx, vy, radius, pref_speed, max_speed, max_accel, charge, target_x, target_y;
  uint32_t goal;
  AgentState state;
  uint32_t frozen_ticks;
  double progress_best;
  uint32_t stall_ticks;
  std::vector<Vec2> route;
  std::vector<uint32_t> then;
  StallAction stall_action;
  uint64_t stall_until;
  double stall_dir_x, stall_dir_y;
  uint32_t path_goal;
  uint64_t path_ticket;
  uint32_t replan_ticks;
  uint64_t wait_until;
  bool operator==(const Agent& o) const {
    auto tie = [](const Agent& a) {
      return std::tie(a.x, a.y, a.vx, a.vy, a.radius, a.pref_speed, a.max_speed, a.max_accel,
                      a.charge, a.target_x, a.target_y, a.goal, a.state, a.frozen_ticks,
                      a.progress_best, a.stall_ticks, a.then, a.stall_action, a.stall_until,
                      a.stall_dir_x, a.stall_dir_y, a.path_goal, a.path_ticket, a.replan_ticks,
                      a.wait_until);
    };
    if (route.size() != o.route.size()) return false;
    for (std::size_t k = 0; k < route.size(); ++k)
      if (route[k].x != o.route[k].x || route[k].y != o.route[k].y) return false;
    return tie(*this) == tie(o);
  }
};

std::map<uint64_t, Agent> by_id(const World& w) {
  const AgentTable& t = w.agents();
  std::map<uint64_t, Agent> out;
  for (std::size_t i = 0; i < t.size(); ++i) {
    out[t.id[i]] = {
        t.x[i],           t.y[i],           t.vx[i],        t.vy[i],           t.radius[i],
        t.pref_speed[i],  t.max_speed[i],   t.max_accel[i], t.charge[i],       t.target_x[i],
        t.target_y[i],    t.goal[i],        t.state[i],     t.frozen_ticks[i], t.progress_best[i],
        t.stall_ticks[i], t.route[i],       t.then[i],      t.stall_action[i], t.stall_until[i],
        t.stall_dir_x[i], t.stall_dir_y[i], t.path_goal[i], t.path_ticket[i],  t.replan_ticks[i],
        t.wait_until[i]};
    EXPECT_EQ(w.row_of(AgentId::from_value(t.id[i])), i);
  }
  return out;
}

// "" when equal, else the first agent (by id) that differs, or is only in one of them.
std::string first_difference(const std::map<uint64_t, Agent>& a,
                             const std::map<uint64_t, Agent>& b) {
  for (const auto& [id, agent] : a) {
    const auto it = b.find(id);
    if (it == b.end()) return "agent " + std::to_string(id) + " only in the first";
    if (!(it->second == agent)) {
      const Agent& o = it->second;
      std::string f;
#define CROWDDB_FIELD(m) \
  if (!(agent.m == o.m)) f += " " #m
      CROWDDB_FIELD(x);
      CROWDDB_FIELD(y);
      CROWDDB_FIELD(vx);
      CROWDDB_FIELD(vy);
      CROWDDB_FIELD(target_x);
      CROWDDB_FIELD(target_y);
      CROWDDB_FIELD(goal);
      CROWDDB_FIELD(state);
      CROWDDB_FIELD(frozen_ticks);
      CROWDDB_FIELD(progress_best);
      CROWDDB_FIELD(stall_ticks);
      CROWDDB_FIELD(then);
      CROWDDB_FIELD(stall_action);
      CROWDDB_FIELD(stall_until);
      CROWDDB_FIELD(path_goal);
      CROWDDB_FIELD(path_ticket);
      CROWDDB_FIELD(replan_ticks);
      CROWDDB_FIELD(wait_until);
      CROWDDB_FIELD(route.size());
#undef CROWDDB_FIELD
      return "agent " + std::to_string(id) + " differs in" + (f.empty() ? " route" : f);
    }
  }
  if (b.size() != a.size()) return "agents only in the second";
  return "";
}

// A disc of 1 cm at (x, y) bound for goal 0: many fit in a 1 m cell.
AgentSpec small_disc(double x, double y) {
  AgentSpec a;
  a.x = x;
  a.y = y;
  a.radius = 0.01;
  a.pref_speed = 1;
  a.max_speed = 1;
  a.goal = 0;
  return a;
}

Scenario shipped(const std::string& name, const std::string& model, const std::string& order) {
  Scenario sc = load_scenario(test::source_path("scenarios/" + name + ".json"));
  sc.config.steering.model = model;
  sc.config.access.row_order = order;
  return sc;
}

TEST(RowOrder, PermuteRowsMovesEveryColumnAndHandle) {
  Scenario sc = shipped("airport", "orca", "none");
  Simulation sim(std::move(sc.world), sc.config);
  for (int t = 0; t < 60; ++t) sim.step();  // routes, stalls and waits under way
  const auto before = by_id(sim.world());
  ASSERT_GT(before.size(), 100u);
  std::vector<uint32_t> order(before.size());
  std::iota(order.begin(), order.end(), 0u);
  std::shuffle(order.begin(), order.end(), std::mt19937(3));
  sim.world().permute_rows(order);
  EXPECT_EQ(by_id(sim.world()), before);
  sim.world().validate();
  // Not a permutation: refused, nothing changed.
  order[0] = order[1];
  EXPECT_THROW(sim.world().permute_rows(order), std::invalid_argument);
  order.pop_back();
  EXPECT_THROW(sim.world().permute_rows(order), std::invalid_argument);
  EXPECT_EQ(by_id(sim.world()), before);
}

// permute_rows leaves a column that holds one value in every row as it is. One that differs in
// a single row (each kind of column: numbers, a state, a list; the odd row first, last, or a
// zero of the other sign) must still move with its rows.
TEST(RowOrder, PermuteRowsMovesAColumnThatDiffersInOneRow) {
  Executor two(2);
  for (const bool last : {false, true})
    for (const bool threads : {false, true}) {
      SCOPED_TRACE(std::string(last ? "the last row" : "the first row") +
                   (threads ? ", two threads" : ""));
      World w(Bounds{0, 0, 100, 100});
      Goal g;
      g.x = g.y = 90;
      w.add_goal(g);
      for (int k = 0; k < 40; ++k) w.insert(small_disc(1 + 2 * (k % 10), 1 + 2 * (k / 10)));
      w.apply_pending();
      AgentTable& t = w.agents_for_tick();
      const std::size_t odd = last ? t.size() - 1 : 0;
      t.charge[odd] = 2;
      t.stall_dir_x[odd] = -0.0;  // the others: +0.0, equal by ==, not bit for bit
      t.stall_action[odd] = StallAction::sidestep;
      t.route[odd] = {{3, 4}};
      t.then[odd] = {0};
      t.wait_until[odd] = 7;
      const auto before = by_id(w);
      std::vector<uint32_t> order(t.size());
      std::iota(order.begin(), order.end(), 0u);
      std::shuffle(order.begin(), order.end(), std::mt19937(5));
      w.permute_rows(order, threads ? &two : nullptr);
      EXPECT_EQ(first_difference(before, by_id(w)), "");
      const auto moved_to =
          static_cast<std::size_t>(std::find(order.begin(), order.end(), odd) - order.begin());
      ASSERT_LT(moved_to, t.size());
      EXPECT_EQ(t.charge[moved_to], 2);
      EXPECT_TRUE(std::signbit(t.stall_dir_x[moved_to]));
      EXPECT_EQ(std::count_if(t.stall_dir_x.begin(), t.stall_dir_x.end(),
                              [](double v) { return std::signbit(v); }),
                1);
      EXPECT_EQ(t.route[moved_to].size(), 1u);
      EXPECT_EQ(t.then[moved_to].size(), 1u);
      EXPECT_EQ(t.wait_until[moved_to], 7u);
      EXPECT_EQ(t.stall_action[moved_to], StallAction::sidestep);
    }
}

// Every shipped scenario but the 5,000-agent airport, under orca and cfsm: the same agents in
// the same state after every tick, whether the rows are put in curve order every 2 s or shuffled
// every tick, as with the rows left in insertion order. (Found on the way and made independent
// of the row order: the path requests' order within the budget, and which freed handles new
// agents get. The thesis model's potential field sums the agents' charges in row order, so its
// rounding depends on it: "auto" leaves its rows alone, see below.)
TEST(RowOrder, RowOrderChangesNoTrajectory) {
  for (const char* name :
       {"airport", "bottleneck", "circle", "crossing", "serpentine", "two_rooms", "u_trap"})
    for (const char* model : {"orca", "cfsm"}) {
      SCOPED_TRACE(std::string(name) + " " + model);
      Scenario a = shipped(name, model, "none"), b = shipped(name, model, "curve"),
               c = shipped(name, model, "none");
      Simulation plain(std::move(a.world), a.config), curve(std::move(b.world), b.config),
          shuffled(std::move(c.world), c.config);
      std::mt19937 rng(11);
      const int ticks = std::string(name) == "airport" ? 120 : 250;
      for (int t = 0; t < ticks; ++t) {
        plain.step();
        curve.step();
        shuffled.step();
        const auto want = by_id(plain.world());
        ASSERT_EQ(first_difference(want, by_id(curve.world())), "") << "tick " << t + 1;
        ASSERT_EQ(first_difference(want, by_id(shuffled.world())), "") << "tick " << t + 1;
        std::vector<uint32_t> order(shuffled.world().agents().size());
        std::iota(order.begin(), order.end(), 0u);
        std::shuffle(order.begin(), order.end(), rng);
        shuffled.world().permute_rows(order);
      }
    }
}

TEST(RowOrder, CurveOrderFollowsTheZCurveThenTheId) {
  Scenario sc = shipped("crossing", "orca", "none");
  const AgentTable& t = sc.world.agents();
  const std::vector<uint32_t> order = sim::curve_order(t);
  ASSERT_EQ(order.size(), t.size());
  std::vector<uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  for (uint32_t r = 0; r < sorted.size(); ++r) ASSERT_EQ(sorted[r], r);
  // Consecutive rows: a 1 m cell apart at most as often as not (a curve, not a shuffle).
  std::size_t near = 0;
  for (std::size_t k = 1; k < order.size(); ++k)
    near += std::abs(t.x[order[k]] - t.x[order[k - 1]]) < 2 &&
            std::abs(t.y[order[k]] - t.y[order[k - 1]]) < 2;
  EXPECT_GT(near, order.size() / 2);
}

// On an executor's threads (the sort in pieces merged, the columns gathered side by side): the
// same order and the same table as on the calling thread alone, for a table large enough for
// the pieces (70,000 agents, many sharing their 1 m cell, so ties by id decide).
TEST(RowOrder, CurveOrderAndPermutationAreTheSameOnAnyThreadCount) {
  // An empty table (everyone arrived and removed) on the calling thread and on an executor.
  World empty(Bounds{0, 0, 10, 10});
  Executor two(2);
  EXPECT_TRUE(sim::curve_order(empty.agents()).empty());
  EXPECT_TRUE(sim::curve_order(empty.agents(), &two).empty());
  empty.permute_rows({});
  empty.permute_rows({}, &two);
  EXPECT_EQ(empty.agents().size(), 0u);
  World base(Bounds{0, 0, 120, 90});
  base.add_goal({"g", 60, 45, 1, 1, {}});
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> ux(0, 120), uy(0, 90);
  for (int k = 0; k < 70000; ++k) base.insert(small_disc(ux(rng), uy(rng)));
  base.apply_pending();
  const std::vector<uint32_t> want = sim::curve_order(base.agents());
  std::vector<uint32_t> shuffle(want.size());
  std::iota(shuffle.begin(), shuffle.end(), 0u);
  std::shuffle(shuffle.begin(), shuffle.end(), rng);
  World plain = base;
  plain.permute_rows(want);
  plain.permute_rows(shuffle);
  for (int threads : {1, 2, 3}) {
    Executor ex(threads);
    EXPECT_EQ(sim::curve_order(base.agents(), &ex), want) << threads << " threads";
    World w = base;
    w.permute_rows(want, &ex);
    w.permute_rows(shuffle, &ex);
    EXPECT_EQ(first_difference(by_id(plain), by_id(w)), "") << threads << " threads";
    EXPECT_EQ(w.agents().id, plain.agents().id) << threads << " threads";
  }
}

// The curve order against its naive twin (one comparison sort by key, then id) on tables made to
// break it: rows not in id order, many agents sharing a 1 m cell (ties by id decide), everyone on
// one point (a single run of ties), negative and huge coordinates, and a world wider than 65 km
// (keys of more than 32 bits: the comparison sort's way); on the calling thread and on
// executors of 1 to 3 threads, above and below the size at which the sorting goes parallel.
TEST(RowOrder, CurveOrderEqualsTheNaiveSortOnAdversarialTables) {
  struct Case {
    const char* name;
    std::size_t n;
    double x0, x1, y0, y1;
    double snap;  // > 0: positions rounded to multiples of this (shared cells)
  };
  const Case cases[] = {
      {"uniform", 5000, 0, 100, 0, 100, 0},
      {"shared cells", 40000, 0, 200, 0, 150, 3},
      {"one point", 3000, 7.5, 7.5, -2.25, -2.25, 0},
      {"negative", 6000, -5000, -4000, -80, 30, 0.5},
      {"one row of cells", 5000, 0, 60000, 0, 1, 0},
      {"wider than 65 km", 40000, -1e6, 1e6, 0, 50, 0},
      {"huge", 2000, -9e8, 9e8, -9e8, 9e8, 0},
  };
  for (const Case& c : cases) {
    World w(Bounds{-1e9, -1e9, 1e9, 1e9});
    w.add_goal({"g", 0, 0, 1, 1, {}});
    std::mt19937 rng(static_cast<unsigned>(c.n));
    std::uniform_real_distribution<double> ux(c.x0, c.x1), uy(c.y0, c.y1);
    for (std::size_t k = 0; k < c.n; ++k) {
      double x = ux(rng), y = uy(rng);
      if (c.snap > 0) {
        x = std::round(x / c.snap) * c.snap;
        y = std::round(y / c.snap) * c.snap;
      }
      w.insert(small_disc(x, y));
    }
    w.apply_pending();
    ASSERT_EQ(w.agents().size(), c.n) << c.name;
    // Rows out of id order, so that a tie left in row order would show.
    std::vector<uint32_t> shuffle(c.n);
    std::iota(shuffle.begin(), shuffle.end(), 0u);
    std::shuffle(shuffle.begin(), shuffle.end(), rng);
    w.permute_rows(shuffle);
    const std::vector<uint32_t> want = sim::curve_order_naive(w.agents());
    EXPECT_EQ(sim::curve_order(w.agents()), want) << c.name;
    for (int threads : {1, 2, 3}) {
      Executor ex(threads);
      EXPECT_EQ(sim::curve_order(w.agents(), &ex), want) << c.name << ", " << threads << " threads";
    }
  }
}

// "auto" reorders from 4096 agents under orca and cfsm, never under the thesis model; EXPLAIN
// says when it does.
TEST(RowOrder, AutoReordersLargeTablesOfTheOrderIndependentModels) {
  auto plan = [](std::size_t agents, const std::string& model, const std::string& order) {
    const std::string side = std::to_string(std::sqrt(static_cast<double>(agents) / 0.5));
    const std::string text =
        R"({"bounds": [0, 0, )" + side + ", " + side + R"(], "steering": {"model": ")" + model +
        R"("}, "access": {"row_order": ")" + order +
        R"("}, "goals": [{"name": "G", "x": 1, "y": 1}], "groups": [{"count": )" +
        std::to_string(agents) +
        R"(, "goal": "G", "radius": 0.2, "placement": {"type": "uniform", "region": [0, 0, )" +
        side + ", " + side + R"(]}}]})";
    Scenario sc = parse_scenario(text, "t.json");
    Simulation sim(std::move(sc.world), sc.config);
    return sim.explain().find("Z-curve order") != std::string::npos;
  };
  EXPECT_TRUE(plan(sim::kReorderMinRows, "orca", "auto"));
  EXPECT_TRUE(plan(sim::kReorderMinRows, "cfsm", "auto"));
  EXPECT_FALSE(plan(sim::kReorderMinRows - 1, "orca", "auto"));
  EXPECT_FALSE(plan(sim::kReorderMinRows, "thesis", "auto"));
  EXPECT_FALSE(plan(sim::kReorderMinRows, "orca", "none"));
  EXPECT_TRUE(plan(10, "orca", "curve"));
}

TEST(RowOrder, UnknownRowOrderIsAnError) {
  Scenario sc = shipped("circle", "orca", "zigzag");
  EXPECT_THROW(Simulation(std::move(sc.world), sc.config), InvalidRow);
  EXPECT_THROW(
      parse_scenario(R"({"bounds": [0, 0, 10, 10], "access": {"row_order": "zigzag"}})", "t.json"),
      Error);
}

}  // namespace
}  // namespace crowddb
