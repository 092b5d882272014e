// Graph statistics: a hand-counted graph, the limits, then graph_stats against brute force
// (reachability for the components, every path for the cycles) on random graphs.
#include "sdf/stats.hpp"

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/naive.hpp"

namespace sdf {
namespace {

using test::make;

void expect_same(const GraphStats& a, const GraphStats& b, const Graph& g) {
  EXPECT_EQ(a.actors, b.actors);
  EXPECT_EQ(a.channels, b.channels);
  EXPECT_EQ(a.self_loops, b.self_loops);
  EXPECT_EQ(a.initial_tokens, b.initial_tokens);
  EXPECT_EQ(a.consistent, b.consistent);
  EXPECT_EQ(a.repetitions_overflow, b.repetitions_overflow);
  EXPECT_EQ(a.repetitions_sum, b.repetitions_sum);
  EXPECT_EQ(a.repetitions_max, b.repetitions_max);
  EXPECT_EQ(a.components, b.components);
  EXPECT_EQ(a.sccs, b.sccs);
  EXPECT_EQ(a.largest_scc, b.largest_scc);
  EXPECT_EQ(a.cyclic_sccs, b.cyclic_sccs);
  EXPECT_EQ(a.simple_cycles, b.simple_cycles) << write_json(g);
  EXPECT_TRUE(a.cycles_complete);
}

TEST(Stats, HandCounted) {
  // A ⇄ B twice forward, B → C → A, a self-loop on C, and D alone.
  const Graph g = make({"A", "B", "C", "D"}, {{"A", "B", 1, 1, 0},
                                              {"A", "B", 1, 1, 0},
                                              {"B", "A", 1, 1, 1},
                                              {"B", "C", 1, 1, 0},
                                              {"C", "A", 1, 1, 2},
                                              {"C", "C", 1, 1, 1}});
  const GraphStats s = graph_stats(g);
  EXPECT_EQ(s.self_loops, 1u);
  EXPECT_EQ(s.initial_tokens, 4u);
  EXPECT_TRUE(s.consistent);
  EXPECT_EQ(s.repetitions_sum, 4u);
  EXPECT_EQ(s.components, 2u);
  EXPECT_EQ(s.sccs, 2u);
  EXPECT_EQ(s.largest_scc, 3u);
  EXPECT_EQ(s.cyclic_sccs, 1u);
  // A→B→A twice, A→B→C→A twice, C→C.
  EXPECT_EQ(s.simple_cycles, 5u);
  expect_same(s, naive::stats(g), g);
}

TEST(Stats, CycleCountStopsAtItsLimits) {
  // A complete digraph on 8 actors has Σ_k C(8, k)·(k − 1)! = 16,064 simple cycles.
  std::vector<const char*> names = {"a", "b", "c", "d", "e", "f", "g", "h"};
  std::vector<test::Edge> edges;
  for (const char* u : names)
    for (const char* v : names)
      if (u != v) edges.push_back({u, v, 1, 1, 1});
  const Graph g = make(names, edges);
  EXPECT_EQ(graph_stats(g).simple_cycles, 16064u);
  StatsLimits few;
  few.max_cycles = 1000;
  const GraphStats s = graph_stats(g, few);
  EXPECT_FALSE(s.cycles_complete);
  EXPECT_EQ(s.simple_cycles, 1000u);
  // A limit of exactly the count is enough: incomplete means a cycle beyond the limit exists.
  few.max_cycles = 16064;
  EXPECT_TRUE(graph_stats(g, few).cycles_complete);
  EXPECT_EQ(graph_stats(g, few).simple_cycles, 16064u);
  few.max_cycles = 16063;
  EXPECT_FALSE(graph_stats(g, few).cycles_complete);
  EXPECT_EQ(graph_stats(g, few).simple_cycles, 16063u);
  StatsLimits short_walk;
  short_walk.max_steps = 500;
  const GraphStats t = graph_stats(g, short_walk);
  EXPECT_FALSE(t.cycles_complete);
  EXPECT_LT(t.simple_cycles, 16064u);
}

// The generator's cyclic shapes hold a cycle on every graph of two actors or more: each back
// channel goes to an ancestor in the spanning tree (to any earlier position it closed none on a
// quarter of 8-actor graphs). Without self-loops, so that only the back channels can count.
TEST(Stats, GeneratedCyclicGraphsHoldACycle) {
  crowddb::Rng rng(77);
  for (int i = 0; i < 600; ++i) {
    gen::Spec spec;
    spec.shape = i % 2 ? gen::Shape::cyclic : gen::Shape::cyclic_random;
    spec.actors = static_cast<uint32_t>(2 + rng.below(11));
    spec.back_percent = static_cast<uint32_t>(rng.below(40));  // one back channel at least
    spec.multirate = i % 3 != 0;
    const Graph g = gen::generate(spec, rng).graph;
    EXPECT_GE(graph_stats(g).cyclic_sccs, 1u) << i;
  }
}

TEST(Stats, AgreesWithBruteForceOnRandomGraphs) {
  crowddb::Rng rng(9101);
  const gen::Shape shapes[] = {gen::Shape::chain, gen::Shape::fan_in, gen::Shape::dag,
                               gen::Shape::cyclic, gen::Shape::cyclic_random};
  uint64_t cycles = 0;
  for (int i = 0; i < 800; ++i) {
    gen::Spec spec;
    spec.shape = shapes[rng.below(std::size(shapes))];
    spec.actors = static_cast<uint32_t>(1 + rng.below(9));
    spec.self_loops = i % 3 == 0;
    spec.back_percent = 30 + 20 * static_cast<uint32_t>(rng.below(3));
    gen::Generated gd = gen::generate(spec, rng);
    Graph& g = gd.graph;
    if (i % 4 == 1) {  // disconnected: a second graph beside it
      const ActorId base = static_cast<ActorId>(g.actor_count());
      g.add_actor("x0");
      g.add_actor("x1");
      g.add_channel(base, base + 1, 2, 3, 0);
      if (i % 8 == 1) g.add_channel(base + 1, base, 3, 2, 1);
    }
    if (i % 10 == 3) {  // inconsistent
      g.add_actor("y");
      g.add_channel(0, static_cast<ActorId>(g.actor_count() - 1), 1, 1, 0);
      g.add_channel(static_cast<ActorId>(g.actor_count() - 1), 0, 2, 1, 0);
    }
    const GraphStats s = graph_stats(g);
    expect_same(s, naive::stats(g), g);
    cycles += s.simple_cycles;
    if (HasFailure()) return;
  }
  EXPECT_GT(cycles, 2000u);
}

}  // namespace
}  // namespace sdf
