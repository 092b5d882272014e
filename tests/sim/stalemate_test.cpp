// The stalemate stage on hand-made states: which stalled agent gets which action.
#include "sim/stalemate.hpp"

#include <gtest/gtest.h>

namespace crowddb::sim {
namespace {

// One agent 10 m east of its goal, heading west with velocity (vx, 0); its best distance so far
// was 5 m (a counter-stream carried it 5 m back), and it has not beaten that for 6 s. With
// `blocker`, a second agent, heading east, stands 0.55 m west of it.
struct PushedBack {
  World w{Bounds{0, 0, 40, 10}};
  SimConfig cfg;
  Executor ex{1};
  std::unique_ptr<NeighbourPath> path = neighbour_method("naive", 2).make();
  QueryStats stats;

  PushedBack(double vx, bool blocker) {
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
      b.goal = 1;
      w.insert(b);
    }
    w.apply_pending();
    AgentTable& t = w.agents_for_tick();
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

}  // namespace
}  // namespace crowddb::sim
