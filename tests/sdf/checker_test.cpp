#include "sdf/checker.hpp"

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "sdf/generate.hpp"
#include "sdf/schedule.hpp"

namespace sdf {
namespace {

TEST(Checker, RejectsEachKindOfMistake) {
  const Graph g = test::make({"A", "B"}, {{"A", "B", 2, 3, 0}});
  const std::vector<uint64_t> q = {3, 2};
  EXPECT_TRUE(check_period(g, q, std::vector<sdf::Run>{{0, 3}, {1, 2}}).valid);
  EXPECT_TRUE(check_period(g, q, std::vector<sdf::Run>{{0, 2}, {1, 1}, {0, 1}, {1, 1}}).valid);
  const CheckResult early =
      check_period(g, q, std::vector<sdf::Run>{{0, 1}, {1, 1}, {0, 2}, {1, 1}});
  EXPECT_FALSE(early.valid);
  EXPECT_EQ(early.failed_firing, 2u);
  const CheckResult mid = check_period(g, q, std::vector<sdf::Run>{{0, 2}, {1, 2}});
  EXPECT_EQ(mid.failed_firing, 4u);  // the second B of the run lacks tokens
  const CheckResult counts = check_period(g, q, std::vector<sdf::Run>{{0, 3}, {1, 1}});
  EXPECT_FALSE(counts.valid);
  EXPECT_NE(counts.reason.find("'B' fired 1 times"), std::string::npos);
  const CheckResult unknown = check_period(g, q, std::vector<sdf::Run>{{7, 1}});
  EXPECT_FALSE(unknown.valid);
  // Counts right but tokens not back: start from a different state.
  const std::vector<uint64_t> start = {1};
  EXPECT_TRUE(check_period(g, q, std::vector<sdf::Run>{{0, 3}, {1, 2}}, start).valid);
  const Graph h = test::make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 1}});
  EXPECT_FALSE(check_period(h, std::vector<uint64_t>{1, 1}, std::vector<sdf::Run>{{1, 1}}).valid);
}

// A run of k firings is checked in one step; the answer must equal k single firings'.
TEST(Checker, RunsAgreeWithSingleFirings) {
  crowddb::Rng rng(5);
  for (int i = 0; i < 300; ++i) {
    gen::Spec spec;
    spec.shape = static_cast<gen::Shape>(i % 6);
    spec.actors = 2 + static_cast<uint32_t>(rng.below(6));
    spec.self_loops = i % 3 == 0;
    Graph g = gen::generate(spec, rng).graph;
    if (i % 4 == 0) g.add_channel(0, 0, 1 + rng.below(3), 1 + rng.below(3), rng.below(6));
    std::vector<sdf::Run> runs, singles;
    for (int r = 0; r < 8; ++r) {
      const sdf::Run run{static_cast<ActorId>(rng.below(g.actor_count())), 1 + rng.below(4)};
      runs.push_back(run);
      for (uint64_t k = 0; k < run.count; ++k) singles.push_back({run.actor, 1});
    }
    const CheckResult a = check_admissible(g, runs), b = check_admissible(g, singles);
    EXPECT_EQ(a.valid, b.valid) << i;
    EXPECT_EQ(a.failed_firing, b.failed_firing) << i;
    if (a.valid) {
      EXPECT_EQ(a.tokens, b.tokens) << i;
    }
  }
}

}  // namespace
}  // namespace sdf
