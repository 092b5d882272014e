// Buffer-sizing checks shared by buffers_test.cpp (a few hundred graphs) and
// buffers_slow_test.cpp (thousands): the bounded exploration's throughput against the two
// throughput methods on the explicit bounded graph; both searches against enumeration of every
// distribution (which also checks that no deadlock-free distribution falls below the lower
// bounds); the buffer-minimising schedule.
#pragma once

#include <gtest/gtest.h>

#include <numeric>

#include "sdf/buffers.hpp"
#include "sdf/checker.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/metrics.hpp"
#include "sdf/naive.hpp"
#include "sdf/repetitions.hpp"

namespace sdf::test {

// Small random graphs: 2–4 actors, repetition counts up to 3, some with self-loops and cycles.
inline gen::Generated small_graph(crowddb::Rng& rng, int i, uint32_t max_actors) {
  const gen::Shape shapes[] = {gen::Shape::chain, gen::Shape::dag, gen::Shape::cyclic,
                               gen::Shape::cyclic_random, gen::Shape::fan_out};
  gen::Spec spec;
  spec.shape = shapes[rng.below(std::size(shapes))];
  spec.actors = static_cast<uint32_t>(2 + rng.below(max_actors - 1));
  spec.multirate = i % 4 != 0;
  spec.self_loops = i % 5 == 0;
  spec.max_q = 3;
  spec.max_multiplier = 1 + static_cast<uint32_t>(rng.below(2));
  spec.extra_percent = 30;
  spec.back_percent = 20;
  gen::Generated gd = gen::generate(spec, rng);
  if (i % 2 == 0) return gd;
  // Random delays on every channel: cycles short of tokens, where the lower bounds do not
  // suffice and several distributions of the smallest size can be deadlock-free.
  Graph g;
  for (ActorId a = 0; a < gd.graph.actor_count(); ++a) g.add_actor(gd.graph.actor_name(a));
  for (const Channel& c : gd.graph.channels())
    g.add_channel(c.src, c.dst, c.prd, c.cns, rng.below(2) ? c.delay : rng.below(c.prd + c.cns));
  gd.graph = std::move(g);
  return gd;
}

// A ring of 2–4 actors plus a chord or two, multi-rate, with few tokens on each channel: the
// graphs where capacities at the lower bounds deadlock and the smallest deadlock-free size has
// several distributions.
inline gen::Generated ring_graph(crowddb::Rng& rng) {
  const auto n = static_cast<uint32_t>(2 + rng.below(3));
  gen::Generated gd;
  gd.q.resize(n);
  for (auto& v : gd.q) v = 1 + rng.below(4);
  for (uint32_t a = 0; a < n; ++a) gd.graph.add_actor("a" + std::to_string(a));
  auto connect = [&](ActorId u, ActorId v) {
    const uint64_t g = std::gcd(gd.q[u], gd.q[v]);
    const uint64_t p = gd.q[v] / g, c = gd.q[u] / g;
    gd.graph.add_channel(u, v, p, c, rng.below(p + c + 1));
  };
  for (uint32_t a = 0; a < n; ++a) connect(a, (a + 1) % n);
  for (uint64_t k = rng.below(3); k > 0; --k) {
    const auto u = static_cast<ActorId>(rng.below(n)), v = static_cast<ActorId>(rng.below(n));
    if (u != v) connect(u, v);
  }
  uint64_t common = 0;
  for (uint64_t v : gd.q) common = std::gcd(common, v);
  for (auto& v : gd.q) v /= common;
  return gd;
}

inline bool live(const Graph& g, const std::vector<uint64_t>& q) {
  return static_schedule(g, q).complete;
}

// The bounded exploration's throughput equals both methods' on the explicit bounded graph, for
// random capacities from below the lower bounds (deadlocks) to well above.
inline void bounded_throughput_agrees(uint64_t seed, int count) {
  crowddb::Rng rng(seed);
  int positive = 0, zero = 0, graphs = 0;
  for (int i = 0; graphs < count && i < 10 * count; ++i) {
    gen::Generated gd = i % 2 ? ring_graph(rng) : small_graph(rng, i, 5);
    Graph& g = gd.graph;
    if (!live(g, gd.q)) continue;
    ++graphs;
    for (ActorId a = 0; a < g.actor_count(); ++a)
      g.set_actor_time(a, rng.below(i % 7 == 0 ? 2 : 9));
    const std::vector<uint64_t> lb = buffer_lower_bounds(g);
    for (int k = 0; k < 4; ++k) {
      std::vector<uint64_t> cap(g.channel_count());
      for (ChannelId c = 0; c < cap.size(); ++c) {
        const uint64_t d = g.channel(c).delay;
        cap[c] = std::max(d, lb[c] + rng.below(2 + 3 * static_cast<uint64_t>(k)) - (k == 0));
      }
      const Throughput t = bounded_throughput(g, cap);
      const Graph b = bounded_graph(g, cap);
      const Throughput ss = throughput_state_space(b), mcm = throughput_mcm(b);
      ASSERT_EQ(t.str(), ss.str()) << write_json(g);
      ASSERT_EQ(t.str(), mcm.str()) << write_json(g);
      (t.num == 0 && !t.unbounded ? zero : positive)++;
    }
  }
  EXPECT_EQ(graphs, count);
  EXPECT_GT(zero, count / 6);
  EXPECT_GT(positive, 2 * count);
}

// Minimal deadlock-free distributions: the search finds exactly the ones enumeration finds, and
// none of them is below the lower bounds. Every live graph is compared: enumeration (from the
// delays, not the bounds) up to the bounds' size + 14, and where it finds nothing that small the
// search, limited to that size, must find nothing either.
inline void minimal_storage_matches(uint64_t seed, int count) {
  crowddb::Rng rng(seed);
  int graphs = 0;
  int several = 0, above_bounds = 0, beyond = 0;
  for (int i = 0; graphs < count && i < 10 * count; ++i) {
    const gen::Generated gd = i % 2 ? ring_graph(rng) : small_graph(rng, i, 4);
    const Graph& g = gd.graph;
    if (!live(g, gd.q) || g.channel_count() > 7) continue;
    ++graphs;
    const std::vector<uint64_t> lb = buffer_lower_bounds(g);
    uint64_t lb_size = 0;
    for (uint64_t v : lb) lb_size += v;
    BufferLimits limits;
    limits.max_size = lb_size + 14;
    const StorageSearch n = naive::minimal_storage(g, limits.max_size);
    if (n.distributions.empty()) {
      ++beyond;
      EXPECT_THROW(minimal_storage(g, limits), Error) << write_json(g);
      continue;
    }
    const StorageSearch s = minimal_storage(g, limits);
    ASSERT_EQ(n.size, s.size) << write_json(g);
    ASSERT_EQ(n.distributions, s.distributions) << write_json(g);
    for (const auto& d : n.distributions)
      for (ChannelId c = 0; c < g.channel_count(); ++c) ASSERT_GE(d[c], lb[c]) << write_json(g);
    several += n.distributions.size() > 1;
    above_bounds += s.size > lb_size;
  }
  EXPECT_EQ(graphs, count);
  EXPECT_LT(beyond, count / 20 + 1);  // nearly every graph compared distribution by distribution
  // Not only the trivial case (the bounds suffice, one distribution) was compared.
  EXPECT_GT(several, count / 20);
  EXPECT_GT(above_bounds, count / 7);
}

// The storage–throughput Pareto points: the search against enumeration of every distribution
// with the throughput of each by both methods, on every live graph, both up to the bounds' size
// + 8: the same points, and complete (the throughput with unbounded channels reached) in both or
// in neither.
inline void pareto_matches(uint64_t seed, int count) {
  crowddb::Rng rng(seed);
  int graphs = 0, points = 0, complete = 0;
  for (int i = 0; graphs < count && i < 40 * count; ++i) {
    gen::Generated gd = i % 2 ? ring_graph(rng) : small_graph(rng, i, 3);
    Graph& g = gd.graph;
    if (!live(g, gd.q) || g.channel_count() > 5) continue;
    for (ActorId a = 0; a < g.actor_count(); ++a) g.set_actor_time(a, 1 + rng.below(4));
    ++graphs;
    const std::vector<uint64_t> lb = buffer_lower_bounds(g);
    BufferLimits limits;
    limits.max_size = std::accumulate(lb.begin(), lb.end(), uint64_t{0}) + 8;
    const ParetoSearch n = naive::pareto(g, limits.max_size, lb);
    const ParetoSearch s = storage_throughput_pareto(g, std::nullopt, limits);
    ASSERT_EQ(n.complete, s.complete) << s.stopped << "\n" << write_json(g);
    complete += n.complete;
    ASSERT_EQ(n.points.size(), s.points.size()) << write_json(g);
    for (size_t k = 0; k < n.points.size(); ++k) {
      ASSERT_EQ(n.points[k].size, s.points[k].size) << write_json(g);
      ASSERT_EQ(n.points[k].throughput.str(), s.points[k].throughput.str()) << write_json(g);
      ASSERT_EQ(n.points[k].distributions, s.points[k].distributions) << write_json(g);
    }
    points += static_cast<int>(s.points.size());
  }
  EXPECT_EQ(graphs, count);
  EXPECT_GT(points, 2 * count);
  EXPECT_GT(complete, count / 3);
}

// The schedule within a minimal distribution is a valid period whose buffers sum to the minimum
// (self-loops aside) and never exceed the static schedule's.
inline void min_buffer_schedule_minimal(uint64_t seed, int count) {
  crowddb::Rng rng(seed);
  int graphs = 0;
  for (int i = 0; graphs < count && i < 10 * count; ++i) {
    gen::Generated gd = i % 2 ? ring_graph(rng) : small_graph(rng, i, 6);
    const Graph& g = gd.graph;
    if (!live(g, gd.q)) continue;
    ++graphs;
    std::vector<uint64_t> cap;
    const std::vector<sdf::Run> runs = min_buffer_schedule(g, &cap);
    ASSERT_TRUE(check_period(g, gd.q, runs).valid) << write_json(g);
    const Metrics m = measure(g, gd.q, Eligibility::owing, runs);
    const Metrics st = measure(g, gd.q, Eligibility::owing, static_schedule(g, gd.q).runs);
    uint64_t sum = 0, sum_static = 0, size = 0, self = 0;
    for (ChannelId c = 0; c < g.channel_count(); ++c) {
      ASSERT_LE(m.buffers[c], cap[c]);
      sum += m.buffers[c];
      sum_static += st.buffers[c];
      size += cap[c];
      if (g.channel(c).src == g.channel(c).dst) self += g.channel(c).prd;
    }
    EXPECT_EQ(sum + self, size) << write_json(g);
    EXPECT_LE(sum, sum_static) << write_json(g);
  }
  EXPECT_EQ(graphs, count);
}

}  // namespace sdf::test
