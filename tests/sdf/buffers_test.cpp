// Buffer sizing: hand-worked lower bounds, minima and Pareto points; then the randomized checks
// of buffer_checks.hpp on a few hundred small graphs (thousands in buffers_slow_test.cpp).
#include "sdf/buffers.hpp"

#include <gtest/gtest.h>

#include <iostream>
#include <numeric>

#include "buffer_checks.hpp"
#include "helpers.hpp"
#include "sdf/checker.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/metrics.hpp"
#include "sdf/naive.hpp"
#include "sdf/repetitions.hpp"

namespace sdf {
namespace {

using test::make;
using test::timed;

TEST(Buffers, LowerBoundsByHand) {
  const Graph g = make({"A", "B"}, {{"A", "B", 2, 3, 0},
                                    {"A", "B", 2, 4, 1},
                                    {"A", "B", 2, 4, 7},
                                    {"B", "A", 6, 4, 3},
                                    {"A", "A", 1, 1, 1},
                                    {"B", "B", 2, 2, 5}});
  // 2+3−1; 2+4−2 + 1 mod 2; at least the 7 tokens; 6+4−2 + 3 mod 2; self-loops p + max(c, d).
  EXPECT_EQ(buffer_lower_bounds(g), (std::vector<uint64_t>{4, 5, 7, 9, 2, 7}));
}

TEST(Buffers, MinimalStorageByHand) {
  // A → B with 2:3: the classic p + c − gcd = 4 places (tokens 0, 2, 4→1, 3→0, 2, 4→1 ...).
  const StorageSearch s = minimal_storage(make({"A", "B"}, {{"A", "B", 2, 3, 0}}));
  EXPECT_EQ(s.size, 4u);
  EXPECT_EQ(s.distributions, (std::vector<std::vector<uint64_t>>{{4}}));
  // A cycle, q = (3, 2), whose back channel holds one period of A's tokens (6): the search and
  // enumeration agree.
  const Graph c = make({"A", "B"}, {{"A", "B", 2, 3, 0}, {"B", "A", 3, 2, 6}});
  const StorageSearch sc = minimal_storage(c);
  const StorageSearch nc = naive::minimal_storage(c, 40);
  EXPECT_EQ(sc.size, nc.size);
  EXPECT_EQ(sc.distributions, nc.distributions);
  EXPECT_THROW(minimal_storage(make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 0}})),
               Error);                                         // deadlocks whatever the capacities
  EXPECT_THROW(minimal_storage(make({"A", "B"}, {})), Error);  // not connected
}

TEST(Buffers, ParetoByHand) {
  // A (1) → B (2), each sequential (self-loops). One place on A → B: A waits for B to free it,
  // one iteration every 3; two places: B never waits, one every 2, the graph's throughput.
  const Graph g = timed(
      make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"A", "A", 1, 1, 1}, {"B", "B", 1, 1, 1}}), {1, 2});
  const ParetoSearch s = storage_throughput_pareto(g);
  ASSERT_TRUE(s.complete);
  ASSERT_EQ(s.points.size(), 2u);
  EXPECT_EQ(s.points[0].size, 5u);
  EXPECT_EQ(s.points[0].throughput.str(), "1/3");
  EXPECT_EQ(s.points[0].distributions, (std::vector<std::vector<uint64_t>>{{1, 2, 2}}));
  EXPECT_EQ(s.points[1].size, 6u);
  EXPECT_EQ(s.points[1].throughput.str(), "1/2");
  EXPECT_EQ(s.points[1].distributions, (std::vector<std::vector<uint64_t>>{{2, 2, 2}}));
}

TEST(Buffers, LimitsBindBothSearches) {
  // A → B and B → A, 1:1, with 1 and 2 tokens: at the lower bounds (the delays, 3) both
  // channels are full and nothing fires; one more place on either channel is enough.
  const Graph g = read_graph_file(test::data("full_ring.json"));
  EXPECT_EQ(minimal_storage(g).size, 4u);
  BufferLimits limits;
  limits.max_size = 3;
  try {
    minimal_storage(g, limits);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::limit);
    EXPECT_EQ(std::string(e.what()),
              "buffers: no deadlock-free distribution of size at most 3 (the size limit)");
  }
  // Firings: an iteration (A, B: 2) is the least a live run takes, so 1 is refused at once; with
  // 2 the deadlocked first distribution's run to its standstill fires nothing and the second
  // completes its iteration.
  limits = {};
  limits.max_firings_per_run = 1;
  try {
    minimal_storage(g, limits);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::limit);
    EXPECT_EQ(std::string(e.what()),
              "buffers: an iteration is 2 firings, more than the 1 one exploration may simulate "
              "(the limit of this analysis)");
  }
  limits.max_firings_per_run = 2;
  const StorageSearch two = minimal_storage(g, limits);
  EXPECT_EQ(two.size, 4u);
  EXPECT_EQ(two.firings, 2u * two.distributions.size());
  // The Pareto search stops with what it has, here nothing: the first distribution deadlocks.
  limits = {};
  limits.max_distributions = 1;
  const ParetoSearch p = storage_throughput_pareto(g, std::nullopt, limits);
  EXPECT_FALSE(p.complete);
  EXPECT_TRUE(p.points.empty());
  EXPECT_EQ(p.stopped, "buffers: more than 1 storage distributions explored (the limit)");
}

TEST(Buffers, BoundedGraphAddsReverseChannels) {
  const Graph g = make({"A", "B"}, {{"A", "B", 2, 3, 1}});
  const Graph b = bounded_graph(g, std::vector<uint64_t>{5});
  ASSERT_EQ(b.channel_count(), 2u);
  EXPECT_EQ(b.channel(1).src, 1u);
  EXPECT_EQ(b.channel(1).prd, 3u);
  EXPECT_EQ(b.channel(1).cns, 2u);
  EXPECT_EQ(b.channel(1).delay, 4u);
  EXPECT_EQ(std::string(b.channel_name(1)), "A->B#0#space");
  EXPECT_THROW(bounded_graph(g, std::vector<uint64_t>{0}), Error);  // below the delay
}

TEST(Buffers, BoundedThroughputAgreesWithBothMethods) {
  test::bounded_throughput_agrees(7001, 300);
}

TEST(Buffers, MinimalStorageMatchesEnumeration) {
  test::minimal_storage_matches(7002, 200);
}

TEST(Buffers, ParetoMatchesEnumeration) {
  test::pareto_matches(7003, 60);
}

TEST(Buffers, MinBufferScheduleIsValidAndMinimal) {
  test::min_buffer_schedule_minimal(7004, 300);
}

TEST(Buffers, ParetoOfTimedModem) {
  // The repository's small timed modem (channels a, b, back, s_src, s_filt). Each point is
  // checked by paths that share nothing with the search's bounded exploration: the throughput of
  // the explicit bounded graph by the maximum cycle ratio of its expansion, the throughput with
  // unbounded channels likewise, and the whole trade-off by enumeration of every distribution.
  const Graph g = read_graph_file(test::data("timed_modem.xml"));
  const ParetoSearch s = storage_throughput_pareto(g);
  ASSERT_TRUE(s.complete);
  EXPECT_EQ(s.max_throughput.str(), throughput_mcm(g).str());
  const std::vector<std::pair<uint64_t, std::string>> expected = {
      {12, "1/7"}, {13, "1/5"}, {15, "1/4"}};
  ASSERT_EQ(s.points.size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) {
    EXPECT_EQ(s.points[k].size, expected[k].first);
    EXPECT_EQ(s.points[k].throughput.str(), expected[k].second);
    for (const auto& d : s.points[k].distributions)
      EXPECT_EQ(throughput_mcm(bounded_graph(g, d)).str(), expected[k].second);
  }
  EXPECT_EQ(s.points.back().throughput.str(), s.max_throughput.str());
  const ParetoSearch n = naive::pareto(g, 15, buffer_lower_bounds(g));
  ASSERT_TRUE(n.complete);
  ASSERT_EQ(n.points.size(), s.points.size());
  for (size_t k = 0; k < n.points.size(); ++k)
    EXPECT_EQ(n.points[k].distributions, s.points[k].distributions);
}

}  // namespace
}  // namespace sdf
