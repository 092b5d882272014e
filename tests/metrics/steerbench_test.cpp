// SteerBench's metrics against values worked by hand.
#include "metrics/steerbench.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "crowddb/simulation.hpp"

namespace crowddb::metrics {
namespace {

TEST(SteerBench, ConstantWalkGivesTimePathAndEnergyByHand) {
  World w(Bounds{0, 0, 100, 10});
  w.add_goal({"g", 90, 5, 0.5, 1, {}});
  AgentSpec a;
  a.x = 10;
  a.y = 5;
  a.vx = 1;
  a.pref_speed = 1;
  a.max_speed = 1;
  a.goal = 0;
  w.insert(a);
  w.apply_pending();
  SteerBench sb(0.1, true);
  sb.start(w);
  // Move the agent by hand: 1 m/s along x for 20 ticks, then 2 m/s for 10.
  AgentTable& t = w.agents_for_tick();
  TickMetrics m;
  for (int k = 0; k < 30; ++k) {
    t.x[0] += k < 20 ? 0.1 : 0.2;
    sb.tick(w, m);
  }
  const AgentScore& s = sb.scores()[0];
  EXPECT_NEAR(s.time, 3.0, 1e-9);
  EXPECT_NEAR(s.path_length, 4.0, 1e-9);
  EXPECT_NEAR(s.energy, 20 * 0.5 * 1 + 10 * 0.5 * 4, 1e-6);
  // One change of velocity by 1 m/s in one tick of 0.1 s: 10 m/s^2.
  EXPECT_NEAR(s.acceleration, 10, 1e-6);
  EXPECT_EQ(s.collisions, 0u);
  const SteerBenchTotals tot = sb.totals();
  EXPECT_NEAR(tot.composite01, s.time + s.energy, 1e-9);
  EXPECT_NEAR(tot.composite02, s.time + s.energy + s.acceleration, 1e-9);
}

TEST(SteerBench, CollisionEpisodesCountOncePerAgentAndEpisode) {
  World w(Bounds{0, 0, 100, 100});
  w.add_goal({"g", 90, 50, 0.5, 1, {}});
  for (double x : {10.0, 11.0, 30.0}) {
    AgentSpec a;
    a.x = x;
    a.y = 50;
    a.radius = 0.5;
    a.goal = 0;
    w.insert(a);
  }
  w.apply_pending();
  SteerBench sb(0.1, true);
  sb.start(w);
  AgentTable& t = w.agents_for_tick();
  TickMetrics m;
  m.overlapping_pairs = 1;  // tells the collector to look
  // Overlap agents 0 and 1 by 0.2 m for three ticks, apart for one, overlap again; agent 2
  // touches the wall at x = 100 - 0.4 (penetration 0.1 m) once.
  const double gaps[] = {0.8, 0.8, 0.8, 1.2, 0.8, 1.0005};
  for (double g : gaps) {
    t.x[1] = t.x[0] + g;
    t.x[2] = g == 1.2 ? 99.6 : 30;
    sb.tick(w, m);
  }
  EXPECT_EQ(sb.scores()[0].collisions, 2u);  // two episodes
  EXPECT_EQ(sb.scores()[1].collisions, 2u);
  EXPECT_EQ(sb.scores()[2].collisions, 1u);  // the wall
  EXPECT_EQ(sb.totals().collisions, 5u);
}

}  // namespace
}  // namespace crowddb::metrics
