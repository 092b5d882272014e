// Throughput of self-timed execution: hand-worked graphs, then the two methods (state space,
// maximum cycle ratio of the HSDF expansion) against each other on random graphs, with the
// critical cycle checked to be a real cycle of the expansion with the reported ratio.
#include "sdf/throughput.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <map>
#include <numeric>

#include "helpers.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/repetitions.hpp"

namespace sdf {
namespace {

using test::make;
using test::timed;

// Both methods, which must agree; returns the value.
std::string both(const Graph& g) {
  const Throughput ss = throughput_state_space(g);
  const Throughput mcm = throughput_mcm(g);
  EXPECT_EQ(ss.str(), mcm.str());
  return ss.str();
}

TEST(Throughput, HandWorkedCycles) {
  // A (2) -> B (3) -> A with one token: one iteration every 5.
  EXPECT_EQ(both(timed(make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 1}}), {2, 3})),
            "1/5");
  // Two tokens: two iterations in flight (unbounded auto-concurrency).
  EXPECT_EQ(both(timed(make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 2}}), {2, 3})),
            "2/5");
  // A one-token self-loop makes an actor sequential: one firing every 3.
  EXPECT_EQ(both(timed(make({"A"}, {{"A", "A", 1, 1, 1}}), {3})), "1/3");
  // The tokens of one firing: a self-loop that gives back 2 of the 3 it takes still serialises.
  EXPECT_EQ(both(timed(make({"A"}, {{"A", "A", 2, 2, 3}}), {4})), "1/4");
}

TEST(Throughput, MinimumOverComponentsInIterations) {
  // q = (A 2, B 1). A alone fires once per time unit: half an iteration; B once per 1.
  const Graph g = timed(
      make({"A", "B"}, {{"A", "A", 1, 1, 1}, {"A", "B", 1, 2, 0}, {"B", "B", 1, 1, 1}}), {1, 1});
  EXPECT_EQ(both(g), "1/2");
  // The slower component downstream decides: C (7) after A (1).
  const Graph h = timed(
      make({"A", "C"}, {{"A", "A", 1, 1, 1}, {"A", "C", 1, 1, 0}, {"C", "C", 1, 1, 1}}), {1, 7});
  EXPECT_EQ(both(h), "1/7");
}

TEST(Throughput, UnboundedAndDeadlocked) {
  // No cycle: a chain with unbounded auto-concurrency.
  EXPECT_EQ(both(timed(make({"A", "B"}, {{"A", "B", 2, 1, 0}}), {5, 5})), "unbounded");
  // A live cycle without execution time.
  EXPECT_EQ(both(timed(make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 1}}), {0, 0})),
            "unbounded");
  // A cycle without tokens deadlocks: 0, and the cycle-ratio analysis names it.
  const Graph d =
      timed(make({"A", "B", "C"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 0}, {"C", "A", 1, 1, 0}}),
            {1, 1, 1});
  EXPECT_EQ(both(d), "0");
  const Throughput m = throughput_mcm(d);
  EXPECT_EQ(m.deadlock_cycle.size(), 2u);
  // A zero-time cycle that deadlocks is 0 too, not unbounded.
  EXPECT_EQ(both(timed(make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 0}}), {0, 0})), "0");
}

TEST(Throughput, MultiRateCycleWorkedByHand) {
  // q = (A 3, B 2); 4 tokens on B -> A. t=0: A fires twice (2 tokens each); t=2: 4 tokens on
  // A -> B, B fires once; t=5: 3 tokens back, A fires once (with 1 left); t=7: B fires
  // (2 + 2 = 4 ≥ 3) ... the expansion's critical cycle A0 B0 A2 B1 takes 2+3+2+3 = 10 with
  // one token: one iteration every 10.
  const Graph g = timed(make({"A", "B"}, {{"A", "B", 2, 3, 0}, {"B", "A", 3, 2, 4}}), {2, 3});
  EXPECT_EQ(both(g), "1/10");
  const Throughput m = throughput_mcm(g);
  EXPECT_EQ(m.cycle_time, 10u);
  EXPECT_EQ(m.cycle_tokens, 1u);
}

TEST(Throughput, TimedModemFile) {
  // filt runs twice per iteration on a one-token self-loop: 2·2 = 4 per iteration; the loop
  // src (3) -> filt, filt (4) -> sink (1) -> src carries 4 tokens of 2 = two iterations: 8 / 2.
  const Graph g = read_graph_file(test::data("timed_modem.xml"));
  EXPECT_EQ(both(g), "1/4");
}

TEST(Throughput, MissingTimesAreNamed) {
  Graph g = make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 1}});
  g.set_actor_time(0, 4);
  try {
    throughput_state_space(g);
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("actor 'B' has no execution time"), std::string::npos);
  }
  EXPECT_EQ(throughput_mcm(g, 6).str(), "1/10");
  EXPECT_THROW(throughput_mcm(make({"A", "B"}, {{"A", "B", 2, 1, 0}, {"B", "A", 1, 1, 0}}), 1),
               Error);  // inconsistent
}

// The critical cycle is a cycle of the expansion: consecutive firings joined by edges, its
// tokens the edges' tokens, its time the firings' times, and time / tokens = 1 / throughput.
void check_critical_cycle(const Graph& g, const Throughput& m) {
  if (m.unbounded || m.num == 0) return;
  const Graph h = to_hsdf(g);
  ASSERT_FALSE(m.critical_cycle.empty());
  std::map<std::pair<ActorId, ActorId>, uint64_t> edge;
  for (const Channel& c : h.channels()) edge[{c.src, c.dst}] = c.delay;
  uint64_t time = 0, tokens = 0;
  for (size_t i = 0; i < m.critical_cycle.size(); ++i) {
    const auto a = h.find_actor(m.critical_cycle[i]);
    const auto b = h.find_actor(m.critical_cycle[(i + 1) % m.critical_cycle.size()]);
    ASSERT_TRUE(a && b);
    const auto e = edge.find({*a, *b});
    ASSERT_NE(e, edge.end()) << m.critical_cycle[i] << " -> " << *b;
    tokens += e->second;
    time += *h.actor_time(*a);
  }
  EXPECT_EQ(time, m.cycle_time);
  EXPECT_EQ(tokens, m.cycle_tokens);
  const uint64_t gcd = std::gcd(time, tokens);
  EXPECT_EQ(tokens / gcd, m.num);
  EXPECT_EQ(time / gcd, m.den);
}

// Random graphs with random execution times (0 included, small and large) and random
// self-loops, until 10^4 of them are live with a finite throughput: the two methods agree on
// every graph, deadlocked and unbounded ones included.
TEST(Throughput, StateSpaceAgreesWithCycleRatioOnRandomGraphs) {
  crowddb::Rng rng(20261125);
  const gen::Shape shapes[] = {gen::Shape::cyclic, gen::Shape::cyclic_random, gen::Shape::dag,
                               gen::Shape::chain};
  int live = 0, deadlocked = 0, unbounded = 0, i = 0;
  for (; live < 10000 && i < 40000; ++i) {
    gen::Spec spec;
    spec.shape = shapes[i % 4 == 3 ? rng.below(4) : i % 2];
    spec.actors = static_cast<uint32_t>(1 + rng.below(10));
    spec.multirate = i % 3 != 0;
    spec.self_loops = i % 5 == 0;
    gen::Generated gd = gen::generate(spec, rng);
    Graph& g = gd.graph;
    const uint64_t span = i % 7 == 0 ? 1000 : 10;
    for (ActorId a = 0; a < g.actor_count(); ++a) g.set_actor_time(a, rng.below(span));
    const Throughput ss = throughput_state_space(g);
    const Throughput mcm = throughput_mcm(g);
    ASSERT_EQ(ss.str(), mcm.str()) << "graph " << i << ":\n" << write_json(g);
    check_critical_cycle(g, mcm);
    if (ss.unbounded)
      ++unbounded;
    else if (ss.num == 0)
      ++deadlocked;
    else
      ++live;
  }
  EXPECT_EQ(live, 10000) << "after " << i << " graphs";
  EXPECT_GT(deadlocked, 100);
  EXPECT_GT(unbounded, 100);
  std::cout << "graphs " << i << ": live " << live << ", deadlocked " << deadlocked
            << ", unbounded " << unbounded << "\n";
}

TEST(Hsdf, ExpansionOfAMultiRateChannel) {
  // A (q 3) -> B (q 2), prd 2, cns 3, 1 initial token. B0 takes tokens 0..2: the initial one
  // (from A2 of the previous iteration) and A0's two; B1 takes 3..5: A1's two and A2's first.
  Graph g = make({"A", "B"}, {{"A", "B", 2, 3, 1}, {"B", "A", 3, 2, 5}});
  const Graph h = to_hsdf(g);
  EXPECT_EQ(h.actor_count(), 5u);
  std::map<std::pair<std::string, std::string>, uint64_t> e;
  for (const Channel& c : h.channels()) e[{h.actor_name(c.src), h.actor_name(c.dst)}] = c.delay;
  EXPECT_EQ((e[{"A_2", "B_0"}]), 1u);
  EXPECT_EQ((e[{"A_0", "B_0"}]), 0u);
  EXPECT_EQ((e[{"A_1", "B_1"}]), 0u);
  EXPECT_EQ((e[{"A_2", "B_1"}]), 0u);
  EXPECT_EQ(e.count({"A_1", "B_0"}), 0u);
  for (const Channel& c : h.channels()) EXPECT_TRUE(c.prd == 1 && c.cns == 1);
  // The expansion is itself consistent with every entry 1.
  const Repetitions r = compute_repetitions(h);
  ASSERT_TRUE(r.consistent);
  for (uint64_t q : r.q) EXPECT_EQ(q, 1u);
}

}  // namespace
}  // namespace sdf
