#include "sdf/metrics.hpp"

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"

namespace sdf {
namespace {

TEST(Metrics, StaticScheduleHandWorked) {
  const Graph g = test::make({"A", "B"}, {{"A", "B", 2, 3, 0}});
  const Metrics m = measure(g, std::vector<uint64_t>{3, 2}, Eligibility::owing,
                            std::vector<sdf::Run>{{0, 3}, {1, 2}});
  EXPECT_TRUE(m.followed_model);
  EXPECT_EQ(m.buffers, std::vector<uint64_t>{6});
  EXPECT_EQ(m.fairness.max, 0u);
  EXPECT_EQ(m.fairness.decisions, 2u);
  // Interleaved: A A B A B holds at most 4 tokens.
  const Metrics i = measure(g, std::vector<uint64_t>{3, 2}, Eligibility::owing,
                            std::vector<sdf::Run>{{0, 2}, {1, 1}, {0, 1}, {1, 1}});
  EXPECT_EQ(i.buffers, std::vector<uint64_t>{4});
  // After decision 0 (A A) both A (fired, still owing: newly eligible) and B are stamped 1.
  // Decision 1 is B (wait 0), decision 2 is A (stamped 1: wait 1), decision 3 is B (eligible
  // again after decision 2: wait 0). Waits 0, 0, 1, 0.
  EXPECT_EQ(i.fairness.max, 1u);
  EXPECT_DOUBLE_EQ(i.fairness.mean, 0.25);
}

TEST(Metrics, TheThesisFanOutExampleWaitsNMinusOne) {
  // A -> B, A -> C with the online rule: (1 A)(1 A)(2 B)(2 C). C becomes eligible at decision
  // 1 and fires at decision 3: it waits 2 = n - 1 decisions, against the claimed "< n - 1".
  const Graph g = test::make({"A", "B", "C"}, {{"A", "B", 1, 1, 0}, {"A", "C", 1, 1, 0}});
  OnlineRunOptions o;
  const OnlineRun r = run_online(g, std::vector<uint64_t>{1, 1, 1}, o);
  ASSERT_EQ(r.outcome, Outcome::returns);
  EXPECT_EQ(r.metrics.fairness.max, 2u);
  EXPECT_DOUBLE_EQ(r.metrics.fairness.mean, 0.75);
  EXPECT_EQ(r.metrics.buffers, (std::vector<uint64_t>{2, 2}));
}

TEST(Metrics, ASchedulePickingAnIneligibleActorIsFlagged) {
  const Graph g = test::make({"A", "B"}, {{"A", "B", 1, 1, 0}});
  EXPECT_FALSE(
      measure(g, std::vector<uint64_t>{1, 1}, Eligibility::fireable, std::vector<sdf::Run>{{1, 1}})
          .followed_model);
  // Owing: A may not fire a second time in the iteration.
  EXPECT_FALSE(measure(g, std::vector<uint64_t>{1, 1}, Eligibility::owing,
                       std::vector<sdf::Run>{{0, 1}, {0, 1}})
                   .followed_model);
  EXPECT_TRUE(measure(g, std::vector<uint64_t>{1, 1}, Eligibility::fireable,
                      std::vector<sdf::Run>{{0, 1}, {0, 1}})
                  .followed_model);
}

}  // namespace
}  // namespace sdf
