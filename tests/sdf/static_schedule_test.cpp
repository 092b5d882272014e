#include <gtest/gtest.h>

#include "helpers.hpp"
#include "sdf/checker.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/naive.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"

namespace sdf {
namespace {

TEST(StaticSchedule, CdToDatIsTheReadyQueueOrder) {
  const Graph g = read_graph_file(test::data("cd2dat.json"));
  const auto q = compute_repetitions(g).q;
  const StaticSchedule s = static_schedule(g, q);
  ASSERT_TRUE(s.complete);
  EXPECT_EQ(run_length_form(g, s.runs), "(147 A)(147 B)(98 C)(28 D)(32 E)(160 F)");
  EXPECT_TRUE(check_period(g, q, s.runs).valid);
}

TEST(StaticSchedule, BillionsOfFiringsStayRunLength) {
  const Graph g = read_graph_file(test::data("chain65537.json"));
  const auto q = compute_repetitions(g).q;
  const StaticSchedule s = static_schedule(g, q);
  ASSERT_TRUE(s.complete);
  EXPECT_EQ(run_length_form(g, s.runs), "(1 A)(65537 B)(4295098369 C)");
  EXPECT_EQ(total_firings(s.runs), 1u + 65537u + 4295098369ull);
  EXPECT_TRUE(check_period(g, q, s.runs).valid);
}

TEST(StaticSchedule, LiveCycleWithDelays) {
  const Graph g = read_graph_file(test::data("crlf_loop.xml"));
  const auto q = compute_repetitions(g).q;
  const StaticSchedule s = static_schedule(g, q);
  ASSERT_TRUE(s.complete);
  EXPECT_TRUE(check_period(g, q, s.runs).valid);
}

TEST(StaticSchedule, DeadlockNamesTheStuckActorsAndAStarvedCycle) {
  const Graph g = read_graph_file(test::data("deadlock.json"));
  const auto q = compute_repetitions(g).q;
  const StaticSchedule s = static_schedule(g, q);
  ASSERT_FALSE(s.complete);
  // S fires (it needs nothing); P needs a token from Q, Q two from P: P and Q are stuck, and R
  // downstream of them too.
  EXPECT_EQ(s.stuck, (std::vector<ActorId>{1, 2, 3}));
  ASSERT_EQ(s.starved_cycle.size(), 2u);
  EXPECT_EQ(std::string(g.channel_name(s.starved_cycle[0])), "P->Q#0");
  EXPECT_EQ(std::string(g.channel_name(s.starved_cycle[1])), "Q->P#0");
}

TEST(StaticSchedule, SelfLoopsThatGainOrLoseTokens) {
  // A self-loop with prd > cns in an inconsistent graph still fires correctly: the schedule
  // functions do not assume consistency.
  const Graph g = test::make({"A", "B"}, {{"A", "A", 3, 2, 2}, {"A", "B", 1, 1, 0}});
  const std::vector<uint64_t> q = {5, 5};
  const StaticSchedule s = static_schedule(g, q);
  EXPECT_TRUE(s.complete);
  EXPECT_TRUE(check_admissible(g, s.runs).valid);
  const Graph lose = test::make({"A"}, {{"A", "A", 1, 3, 7}});
  const StaticSchedule l = static_schedule(lose, std::vector<uint64_t>{10});
  EXPECT_EQ(l.fired[0], 3u);  // 7 -> 5 -> 3 -> 1
  EXPECT_EQ(l.starved_cycle, std::vector<ChannelId>{0});
}

// Every live random graph gets a valid period; on graphs with random back-edge delays the stuck
// set equals the naive maximal run's (fired in random single steps) exactly.
TEST(StaticSchedule, RandomGraphsAgainstTheNaiveMaximalRun) {
  crowddb::Rng rng(11);
  int deadlocks = 0, live = 0;
  for (int i = 0; i < 400; ++i) {
    gen::Spec spec;
    spec.shape = i % 2 ? gen::Shape::cyclic_random : static_cast<gen::Shape>(i % 5);
    spec.actors = 2 + static_cast<uint32_t>(rng.below(12));
    spec.self_loops = i % 7 == 0;
    const gen::Generated gg = gen::generate(spec, rng);
    const StaticSchedule s = static_schedule(gg.graph, gg.q);
    const std::vector<uint64_t> counts = naive::max_run(gg.graph, gg.q, rng);
    EXPECT_EQ(s.fired, counts) << i;
    if (s.complete) {
      ++live;
      EXPECT_TRUE(check_period(gg.graph, gg.q, s.runs).valid) << i;
    } else {
      ++deadlocks;
      std::vector<ActorId> expect;
      for (ActorId a = 0; a < gg.graph.actor_count(); ++a)
        if (counts[a] < gg.q[a]) expect.push_back(a);
      EXPECT_EQ(s.stuck, expect) << i;
      // The starved cycle: consecutive channels, closing, each short of its consumer's cns.
      const CheckResult after = check_admissible(gg.graph, s.runs);
      ASSERT_FALSE(s.starved_cycle.empty()) << i;
      for (size_t k = 0; k < s.starved_cycle.size(); ++k) {
        const Channel& c = gg.graph.channel(s.starved_cycle[k]);
        const Channel& next = gg.graph.channel(s.starved_cycle[(k + 1) % s.starved_cycle.size()]);
        EXPECT_EQ(c.dst, next.src) << i;
        EXPECT_LT(after.tokens[s.starved_cycle[k]], c.cns) << i;
      }
    }
  }
  EXPECT_GT(deadlocks, 40);
  EXPECT_GT(live, 200);
}

}  // namespace
}  // namespace sdf
