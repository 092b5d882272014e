// The stalemate stage on hand-made states: which stalled agent gets which action.
#include "sim/stalemate.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>
#include <utility>

#include "sim/stages.hpp"
#include "util/rng.hpp"

namespace crowddb::sim {
namespace {

// One agent 10 m east of its goal, heading west with velocity (vx, 0); its best distance so far
// was 5 m (a counter-stream carried it 5 m back), and it has not beaten that for 6 s. With
// `blocker`, a second agent, bound for `blocker_goal` (east by default), stands 0.55 m west of
// it, idle there when `blocker_arrived`.
struct PushedBack {
  World w{Bounds{0, 0, 40, 10}};
  SimConfig cfg;
  Executor ex{1};
  std::unique_ptr<NeighbourPath> path = neighbour_method("naive", 2).make();
  QueryStats stats;

  PushedBack(double vx, bool blocker, bool blocker_arrived = false, uint32_t blocker_goal = 1) {
    w.add_goal({"W", 0, 5, 0.5, 1, {}});
    w.add_goal({"E", 39, 5, 0.5, 1, {}});
    AgentSpec a;
    a.x = 10;
    a.y = 5;
    a.vx = vx;
    a.pref_speed = 1.3;
    a.max_speed = 1.3;
    a.radius = 0.25;
    a.goal = 0;
    w.insert(a);
    if (blocker) {
      AgentSpec b = a;
      b.x = 9.45;
      b.vx = 0;
      b.goal = blocker_goal;
      w.insert(b);
    }
    w.apply_pending();
    AgentTable& t = w.agents_for_tick();
    if (blocker && blocker_arrived) t.state[1] = AgentState::arrived;
    t.progress_best[0] = 5;
    t.stall_ticks[0] = static_cast<uint32_t>(cfg.ticks_for(6.0));
  }

  StallCounts run() { return stalemates(w, cfg, 100, *path, ex, stats); }
  StallAction action() { return w.agents().stall_action[0]; }
};

TEST(Stalemates, AnAgentWalkingBackFreelyIsCountedButNotTurnedAside) {
  PushedBack s(-1.2, false);
  const StallCounts c = s.run();
  EXPECT_EQ(c.stalled, 1u);  // still without progress: the summary sees it
  EXPECT_EQ(c.sidestepping, 0u);
  EXPECT_EQ(s.action(), StallAction::none);
}

TEST(Stalemates, AnAgentStandingWithNobodyInFrontSidesteps) {
  PushedBack s(0.0, false);
  const StallCounts c = s.run();
  EXPECT_EQ(c.stalled, 1u);
  EXPECT_EQ(c.sidestepping, 1u);
  EXPECT_EQ(s.action(), StallAction::sidestep);
}

TEST(Stalemates, AnAgentSlowerThanHalfItsSpeedSidesteps) {
  PushedBack s(-0.6, false);  // 0.6 < 0.5 * 1.3 m/s
  EXPECT_EQ(s.run().sidestepping, 1u);
}

TEST(Stalemates, AnAgentWalkingTowardsABlockerStillSidesteps) {
  // Someone heading elsewhere stands in front of it: walking on would not get it past.
  PushedBack s(-1.2, true);
  const StallCounts c = s.run();
  EXPECT_EQ(c.stalled, 1u);
  EXPECT_EQ(c.sidestepping, 1u);
  EXPECT_EQ(s.action(), StallAction::sidestep);
}

TEST(Stalemates, StandingBehindIdleArrivalsOfAnotherGoalIsAStalemate) {
  // The other stream's arrivals idle in its way (Menge's stress example): nobody ahead moves,
  // so it is no queue; the summary counts it and an action gets it round them.
  PushedBack s(0.0, true, true, 1);
  const StallCounts c = s.run();
  EXPECT_EQ(c.stalled, 1u);
  EXPECT_EQ(c.queueing, 0u);
  EXPECT_NE(s.action(), StallAction::none);
}

TEST(Stalemates, StandingBehindIdleArrivalsAtItsOwnGoalIsQueueing) {
  PushedBack s(0.0, true, true, 0);
  const StallCounts c = s.run();
  EXPECT_EQ(c.stalled, 0u);
  EXPECT_EQ(c.queueing, 1u);
  EXPECT_EQ(s.action(), StallAction::none);
}

// Someone standing in a stalled walker's way who is not at the walker's goal (idle at another
// booth: Menge's tradeshow) is asked to make way: it steps off the walker's line, to the side it
// stands on, for yield_time; the walker still sidesteps.
TEST(Stalemates, AStandingBlockerBoundElsewhereStepsOffTheWalkersLine) {
  for (const double side : {0.1, -0.1}) {  // north, then south of the walker's line
    PushedBack s(0.0, true, true, 1);
    s.w.agents_for_tick().y[1] = 5 + side;
    const StallCounts c = s.run();
    EXPECT_EQ(c.making_way, 1u);
    EXPECT_EQ(c.sidestepping, 1u);
    const AgentTable& t = s.w.agents();
    EXPECT_EQ(t.stall_action[0], StallAction::sidestep);
    EXPECT_EQ(t.stall_action[1], StallAction::make_way);
    // The walker heads west: off its line is north or south, the blocker's side.
    EXPECT_EQ(t.stall_dir_x[1], 0.0);
    EXPECT_EQ(t.stall_dir_y[1], side > 0 ? 1.0 : -1.0);
    EXPECT_EQ(t.stall_until[1], 100 + s.cfg.ticks_for(s.cfg.stall.yield_time));
  }
}

TEST(Stalemates, AStandingBlockerAtTheWalkersOwnGoalStays) {
  PushedBack s(0.0, true, true, 0);  // a queue at its own goal (above)
  EXPECT_EQ(s.run().making_way, 0u);
  EXPECT_EQ(s.w.agents().stall_action[1], StallAction::none);
}

TEST(Stalemates, MakingWayLastsItsTimeAndMovesTheStandingAgent) {
  PushedBack s(0.0, true, true, 1);
  s.w.agents_for_tick().y[1] = 5.1;
  ASSERT_EQ(s.run().making_way, 1u);
  const uint64_t until = 100 + s.cfg.ticks_for(s.cfg.stall.yield_time);
  // The goal stage walks it north at half its preferred speed while the action lasts.
  Preferred pref;
  pref.reset(s.w.agents().size());
  goal_stage(s.w.agents(), s.w.goals(), s.cfg, until - 1, {}, pref, s.ex);
  EXPECT_EQ(pref.vx[1], 0.0);
  EXPECT_EQ(pref.vy[1], 0.5 * 1.3);
  goal_stage(s.w.agents(), s.w.goals(), s.cfg, until, {}, pref, s.ex);
  EXPECT_EQ(pref.vx[1], 0.0);
  EXPECT_EQ(pref.vy[1], 0.0);
  // The progress watch keeps a standing agent's action until then, and ends it after.
  AgentTable& t = s.w.agents_for_tick();
  t.stall_ticks[0] = 0;  // the walker out of the picture
  t.progress_best[0] = 0;
  EXPECT_EQ(stalemates(s.w, s.cfg, until - 1, *s.path, s.ex, s.stats).making_way, 0u);
  EXPECT_EQ(t.stall_action[1], StallAction::make_way);
  stalemates(s.w, s.cfg, until, *s.path, s.ex, s.stats);
  EXPECT_EQ(t.stall_action[1], StallAction::none);
}

// Two stalled agents touching (0.05 m apart): a at (ax, ay) heading for goal ga, b at (bx, by)
// heading for goal gb; goals W (0, 5) and E (39, 5) far west and east, S (5, -20) far south. Both
// have made no progress for 6 s.
struct Pair {
  World w{Bounds{-1, -25, 40, 30}};
  SimConfig cfg;
  Executor ex{1};
  std::unique_ptr<NeighbourPath> path = neighbour_method("naive", 2).make();
  QueryStats stats;

  Pair(double ax, double ay, uint32_t ga, double bx, double by, uint32_t gb) {
    w.add_goal({"W", 0, 5, 0.5, 1, {}});
    w.add_goal({"E", 39, 5, 0.5, 1, {}});
    w.add_goal({"S", 5, -20, 0.5, 1, {}});
    w.add_goal({"WS", 0, -5, 0.5, 1, {}});
    for (auto [x, y, g] : {std::tuple{ax, ay, ga}, std::tuple{bx, by, gb}}) {
      AgentSpec a;
      a.x = x;
      a.y = y;
      a.pref_speed = 1.3;
      a.max_speed = 1.3;
      a.radius = 0.25;
      a.goal = g;
      w.insert(a);
    }
    w.apply_pending();
    AgentTable& t = w.agents_for_tick();
    for (std::size_t i = 0; i < 2; ++i) {
      t.progress_best[i] = path_left(t, w.goals(), i);
      t.stall_ticks[i] = static_cast<uint32_t>(cfg.ticks_for(6.0));
    }
  }

  StallCounts run(uint64_t tick = 100) { return stalemates(w, cfg, tick, *path, ex, stats); }
  void stalled_for(double a, double b) {
    AgentTable& t = w.agents_for_tick();
    t.stall_ticks[0] = static_cast<uint32_t>(cfg.ticks_for(a));
    t.stall_ticks[1] = static_cast<uint32_t>(cfg.ticks_for(b));
  }
};

TEST(Stalemates, AHeadOnYieldLastsHeadOnYieldTime) {
  // a (10 m from W) has less path left than b (29.5 m from E): b yields, briefly.
  Pair s(10, 5, 0, 9.45, 5, 1);
  s.cfg.stall.head_on_yield_time = 0.5;
  s.cfg.stall.yield_time = 1.5;
  EXPECT_EQ(s.run().yielding, 1u);
  const AgentTable& t = s.w.agents();
  EXPECT_EQ(t.stall_action[0], StallAction::none);
  EXPECT_EQ(t.stall_action[1], StallAction::yield);
  EXPECT_EQ(t.stall_until[1], 100 + s.cfg.ticks_for(0.5));
}

TEST(Stalemates, AYieldInAJamLastsYieldTime) {
  // Side by side, both heading for S 30 m south: each is in the other's way and neither heads at
  // the other, an arch: the one that yields goes first and yields for yield_time.
  Pair s(4.7, 10, 2, 5.25, 10, 2);
  s.cfg.stall.head_on_yield_time = 0.5;
  s.cfg.stall.yield_time = 1.5;
  EXPECT_EQ(s.run().yielding, 1u);
  const AgentTable& t = s.w.agents();
  const std::size_t y = t.stall_action[0] == StallAction::yield_ahead ? 0 : 1;
  EXPECT_EQ(t.stall_action[y], StallAction::yield_ahead);
  EXPECT_EQ(t.stall_action[1 - y], StallAction::none);
  EXPECT_EQ(t.stall_until[y], 100 + s.cfg.ticks_for(1.5));
}

// Head-on, a (10 m from W) has less path left than b (29.5 m from E), so b yields. Once both
// have been stalled for reverse_after (12 s), they take turns: in every other reverse_period (3 s,
// 30 ticks: ticks 30-59, 90-119, ...) a yields instead.
TEST(Stalemates, APairStalledLongTakesTurnsToYield) {
  for (uint64_t tick : {0, 29, 60, 89, 120}) {  // even periods: the usual order
    Pair s(10, 5, 0, 9.45, 5, 1);
    s.stalled_for(13, 13);
    EXPECT_EQ(s.run(tick).yielding, 1u);
    EXPECT_EQ(s.w.agents().stall_action[1], StallAction::yield) << "tick " << tick;
  }
  for (uint64_t tick : {30, 59, 90, 119}) {  // odd periods: the other way round
    Pair s(10, 5, 0, 9.45, 5, 1);
    s.stalled_for(13, 13);
    EXPECT_EQ(s.run(tick).yielding, 1u);
    EXPECT_EQ(s.w.agents().stall_action[0], StallAction::yield) << "tick " << tick;
    EXPECT_EQ(s.w.agents().stall_action[1], StallAction::none);
  }
}

// Out before in: the pair above, but b has just been to W, where a is going, and is nearer to
// it: b goes first, and a, with less path left, yields.
TEST(Stalemates, OneComingOutOfTheOthersGoalGoesFirst) {
  Pair s(10, 5, 0, 9.45, 5, 1);
  s.w.agents_for_tick().left_goal[1] = 0;
  EXPECT_EQ(out_before_in(s.w.agents(), s.w.goals(), 0, 1), -1);
  EXPECT_EQ(out_before_in(s.w.agents(), s.w.goals(), 1, 0), 1);
  EXPECT_EQ(s.run().yielding, 1u);
  EXPECT_EQ(s.w.agents().stall_action[0], StallAction::yield);
  EXPECT_EQ(s.w.agents().stall_action[1], StallAction::none);
}

// The one ahead: a (10 m from W) has less path left than b, which stands in front of it (0.55 m
// further west) bound for WS (0, -5), 13.8 m away, the same way (45 degrees apart). By path left
// a would go on and b yield; b is ahead, so a yields.
TEST(Stalemates, OfTwoBoundTheSameWayForDifferentGoalsTheOneAheadGoesOn) {
  Pair s(10, 5, 0, 9.45, 5, 3);
  const AgentTable& t = s.w.agents();
  ASSERT_LT(path_left(t, s.w.goals(), 0), path_left(t, s.w.goals(), 1));
  bool a_first = true;
  ASSERT_TRUE(ahead(ahead_input(t, s.w.goals(), 0), ahead_input(t, s.w.goals(), 1), a_first));
  EXPECT_FALSE(a_first);
  EXPECT_GE(s.run().yielding, 1u);
  EXPECT_TRUE(t.stall_action[0] == StallAction::yield ||
              t.stall_action[0] == StallAction::yield_ahead);
  EXPECT_NE(t.stall_action[1], StallAction::yield);
  EXPECT_NE(t.stall_action[1], StallAction::yield_ahead);
}

// sim::ahead is antisymmetric bit for bit (orca's shares add up to one only then), and decides
// only for goals within 60 degrees and headings within 120 degrees, against a naive twin in
// angles on random and rounded inputs.
TEST(Stalemates, TheOneAheadIsAntisymmetricAndDecidesWhereItShould) {
  Rng rng = Rng::stream(7, 1);
  int decided = 0;
  for (int k = 0; k < 20000; ++k) {
    auto unit = [&] {
      const double a = rng.uniform(0, 2 * std::numbers::pi);
      return std::pair{std::cos(a), std::sin(a)};
    };
    // Every fourth input on a coarse grid, so that ties and exact boundaries come up.
    const bool coarse = k % 4 == 0;
    auto coord = [&](double lo, double hi) {
      const double v = rng.uniform(lo, hi);
      return coarse ? std::round(v) : v;
    };
    AheadInput a, b;
    std::tie(a.way_x, a.way_y) = unit();
    std::tie(b.way_x, b.way_y) = unit();
    a.goal_x = coord(-50, 50), a.goal_y = coord(-50, 50), b.goal_x = coord(-50, 50),
    b.goal_y = coord(-50, 50);
    a.goal2 = a.goal_x * a.goal_x + a.goal_y * a.goal_y;
    b.goal2 = b.goal_x * b.goal_x + b.goal_y * b.goal_y;
    const double ax = coord(-5, 5), ay = coord(-5, 5), bx = coord(-5, 5), by = coord(-5, 5);
    a.x = ax, a.y = ay, b.x = bx, b.y = by;
    a.goal = 0, b.goal = 1;
    bool a_first = false, b_first = false;
    const bool ab = ahead(a, b, a_first);
    const bool ba = ahead(b, a, b_first);
    ASSERT_EQ(ab, ba) << k;
    if (ab) {
      ASSERT_NE(a_first, b_first) << k;
    }
    decided += ab;
    // The naive twin: angles, away from the boundaries (1e-9 rad).
    const double goals_apart = std::abs(std::remainder(
        std::atan2(a.goal_y, a.goal_x) - std::atan2(b.goal_y, b.goal_x), 2 * std::numbers::pi));
    const double ways_apart = std::abs(std::remainder(
        std::atan2(a.way_y, a.way_x) - std::atan2(b.way_y, b.way_x), 2 * std::numbers::pi));
    const double sx = a.way_x + b.way_x, sy = a.way_y + b.way_y;
    const double along = sx * (ax - bx) + sy * (ay - by);
    const double margin = 1e-9;
    if (a.goal2 == 0 || b.goal2 == 0 || std::abs(goals_apart - std::numbers::pi / 3) < margin ||
        std::abs(ways_apart - 2 * std::numbers::pi / 3) < margin || std::abs(along) < margin)
      continue;
    const bool expected =
        goals_apart < std::numbers::pi / 3 && ways_apart < 2 * std::numbers::pi / 3;
    ASSERT_EQ(ab, expected) << k << ": goals " << goals_apart << " ways " << ways_apart;
    if (ab) {
      ASSERT_EQ(a_first, along > 0) << k;
    }
  }
  EXPECT_GT(decided, 1000);  // the random inputs reach both answers
}

TEST(Stalemates, OutBeforeInOnlyForTheOneNearerTheGoalAndBothWalking) {
  auto decides = [](Pair& s) { return out_before_in(s.w.agents(), s.w.goals(), 0, 1); };
  {  // b left W but stands farther from it than a
    Pair s(9.45, 5, 0, 10, 5, 1);
    s.w.agents_for_tick().left_goal[1] = 0;
    EXPECT_EQ(decides(s), 0);
  }
  {  // b left a goal a is not heading for
    Pair s(10, 5, 0, 9.45, 5, 1);
    s.w.agents_for_tick().left_goal[1] = 2;
    EXPECT_EQ(decides(s), 0);
  }
  {  // each left the other's goal and is nearer to it: the rule does not decide
    Pair s(10, 5, 0, 9.45, 5, 1);
    s.w.agents_for_tick().left_goal[0] = 1;
    s.w.agents_for_tick().left_goal[1] = 0;
    EXPECT_EQ(decides(s), 0);
  }
  {  // b stands idle: idle people come last whatever they left
    Pair s(10, 5, 0, 9.45, 5, 1);
    s.w.agents_for_tick().left_goal[1] = 0;
    s.w.agents_for_tick().state[1] = AgentState::arrived;
    EXPECT_EQ(decides(s), 0);
  }
}

TEST(Stalemates, TurnsStartWhenBothHaveBeenStalledReverseAfter) {
  for (auto [a, b] : {std::pair{13.0, 11.0}, std::pair{11.0, 13.0}, std::pair{6.0, 6.0}}) {
    Pair s(10, 5, 0, 9.45, 5, 1);
    s.stalled_for(a, b);
    s.run(30);  // an odd period
    EXPECT_EQ(s.w.agents().stall_action[1], StallAction::yield) << a << " s and " << b << " s";
  }
  Pair off(10, 5, 0, 9.45, 5, 1);
  off.cfg.stall.reverse_after = 0;  // switched off
  off.stalled_for(60, 60);
  off.run(30);
  EXPECT_EQ(off.w.agents().stall_action[1], StallAction::yield);
}

// The queueing test's chain walk against its twin, the repeated sweeps: random blocker graphs
// (chains, cycles, trees into cycles, heads that move, people not walking their blocker's way),
// and long chains that run against the row order (the sweeps' worst case).
TEST(QueueMembers, MatchesTheRepeatedSweeps) {
  Rng rng(7);
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t m = 1 + rng.below(trial < 300 ? 40 : 2000);
    const double p_same = rng.uniform(0.3, 1.0), p_moves = rng.uniform(0, 0.3);
    std::vector<uint8_t> same_way(m), moves(m);
    std::vector<int64_t> next(m);
    for (std::size_t q = 0; q < m; ++q) {
      same_way[q] = rng.uniform() < p_same;
      next[q] = rng.uniform() < 0.1 ? -1 : static_cast<int64_t>(rng.below(m));
      moves[q] = same_way[q] && (next[q] < 0 || rng.uniform() < p_moves);
    }
    EXPECT_EQ(queue_members(same_way, moves, next), queue_members_naive(same_way, moves, next))
        << "trial " << trial << ", " << m << " rows";
  }
  // One queue of 3,000 whose blockers sit at lower rows, its head moving; then the same closed
  // into a ring (an arch: nobody queues).
  const std::size_t m = 3000;
  std::vector<uint8_t> same_way(m, 1), moves(m, 0);
  std::vector<int64_t> next(m);
  for (std::size_t q = 0; q < m; ++q) next[q] = static_cast<int64_t>(q) - 1;
  moves[0] = 1;
  const auto line = queue_members(same_way, moves, next);
  EXPECT_EQ(line, queue_members_naive(same_way, moves, next));
  EXPECT_EQ(std::count(line.begin(), line.end(), 1), static_cast<long>(m));
  moves[0] = 0;
  next[0] = static_cast<int64_t>(m - 1);
  const auto ring = queue_members(same_way, moves, next);
  EXPECT_EQ(ring, queue_members_naive(same_way, moves, next));
  EXPECT_EQ(std::count(ring.begin(), ring.end(), 1), 0);
}

}  // namespace
}  // namespace crowddb::sim
