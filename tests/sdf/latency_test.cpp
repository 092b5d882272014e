// Latency: hand-worked cases, then the event simulation against longest paths in the unfolded
// HSDF expansion (naive::latency) on random graphs, with random source and destination actors
// and one to four iterations.
#include "sdf/latency.hpp"

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/naive.hpp"
#include "sdf/schedule.hpp"

namespace sdf {
namespace {

using test::make;
using test::timed;

TEST(Latency, ChainByHand) {
  // A (2) → B (3) with 1:2, q = (2, 1): both A firings run at once (0–2), B runs 2–5.
  const Graph g = timed(make({"A", "B"}, {{"A", "B", 1, 2, 0}}), {2, 3});
  const Latency l = latency(g);
  EXPECT_EQ(l.per_iteration, (std::vector<int64_t>{5}));
  EXPECT_EQ(l.makespan, 5u);
  // With A sequential (a one-token self-loop) A runs 0–2, 2–4 and B 4–7; from A to B: 7.
  const Graph s = timed(make({"A", "B"}, {{"A", "B", 1, 2, 0}, {"A", "A", 1, 1, 1}}), {2, 3});
  LatencyOptions o;
  o.from = 0;
  o.to = 1;
  o.iterations = 3;
  const Latency ls = latency(s, o);
  // Iteration i: A starts at 4i, B ends at 4i + 7 (B runs 4–7, 8–11, 12–15).
  EXPECT_EQ(ls.per_iteration, (std::vector<int64_t>{7, 7, 7}));
  EXPECT_EQ(ls.makespan, 15u);
  // From B to A: A's part of iteration i ends (4i + 4) just when B's starts: 0. A stage that
  // does not wait for the source can even end before it starts (negative; the random test
  // below meets such graphs).
  o.from = 1;
  o.to = 0;
  const Latency back = latency(s, o);
  EXPECT_EQ(back.per_iteration, (std::vector<int64_t>{0, 0, 0}));
}

TEST(Latency, DeadlockIsReported) {
  const Graph g = timed(make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 0}}), {1, 1});
  const Latency l = latency(g);
  EXPECT_TRUE(l.deadlock);
  EXPECT_EQ(l.stuck, (std::vector<ActorId>{0, 1}));
  EXPECT_TRUE(naive::latency(g, {}, std::nullopt).deadlock);
  LatencyOptions bad;
  bad.from = 0;
  EXPECT_THROW(latency(g, bad), Error);
}

// An empty <sdf/> reads as a graph without actors, which has no iteration to measure: an error,
// not a read past an empty vector.
TEST(Latency, GraphWithoutActorsIsRefused) {
  const Graph g = read_graph_file(test::data("empty.xml"));
  ASSERT_EQ(g.actor_count(), 0u);
  try {
    latency(g);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::input);
    EXPECT_EQ(std::string(e.what()), "latency: the graph has no actors (no iteration to measure)");
  }
}

TEST(Latency, SimulationAgreesWithUnfoldedExpansion) {
  crowddb::Rng rng(9001);
  const gen::Shape shapes[] = {gen::Shape::chain, gen::Shape::fan_out, gen::Shape::fan_in,
                               gen::Shape::dag,   gen::Shape::cyclic,  gen::Shape::cyclic_random};
  int live = 0, deadlocked = 0, negative = 0;
  for (int i = 0; i < 1500; ++i) {
    gen::Spec spec;
    spec.shape = shapes[rng.below(std::size(shapes))];
    spec.actors = static_cast<uint32_t>(1 + rng.below(7));
    spec.multirate = i % 3 != 0;
    spec.self_loops = i % 4 == 0;
    spec.max_q = 6;
    gen::Generated gd = gen::generate(spec, rng);
    Graph& g = gd.graph;
    for (ActorId a = 0; a < g.actor_count(); ++a)
      g.set_actor_time(a, rng.below(i % 5 == 0 ? 3 : 20));
    LatencyOptions o;
    o.iterations = 1 + rng.below(4);
    if (i % 2) {
      o.from = static_cast<ActorId>(rng.below(g.actor_count()));
      o.to = static_cast<ActorId>(rng.below(g.actor_count()));
    }
    const Latency l = latency(g, o);
    const Latency n = naive::latency(g, o, std::nullopt);
    ASSERT_EQ(l.deadlock, n.deadlock) << write_json(g);
    if (l.deadlock) {
      ++deadlocked;
      if (o.iterations == 1) {
        EXPECT_EQ(l.stuck, static_schedule(g, gd.q).stuck) << write_json(g);
      }
      continue;
    }
    ++live;
    ASSERT_EQ(l.per_iteration, n.per_iteration) << write_json(g);
    ASSERT_EQ(l.max, n.max);
    ASSERT_EQ(l.iteration, n.iteration);
    ASSERT_EQ(l.makespan, n.makespan) << write_json(g);
    negative += l.max < 0;
  }
  EXPECT_GT(live, 1000);
  EXPECT_GT(deadlocked, 30);
  EXPECT_GT(negative, 10);
}

}  // namespace
}  // namespace sdf
