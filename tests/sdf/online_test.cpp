#include "sdf/online.hpp"

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "sdf/checker.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/naive.hpp"
#include "sdf/repetitions.hpp"

namespace sdf {
namespace {

OnlineRunOptions options(FiringRule rule, bool bounded) {
  OnlineRunOptions o;
  o.scheduler.firings = rule;
  o.scheduler.bounded = bounded;
  o.max_decisions = 200'000;
  return o;
}

// Every window a run reports passes the checker: a `returns` period from the start state, a
// periodic cycle from the state where it starts (after an admissible transient).
void expect_checked(const Graph& g, const std::vector<uint64_t>& q, const OnlineRun& run) {
  ASSERT_TRUE(run.runs_listed);
  EXPECT_TRUE(run.metrics.followed_model);
  const std::span<const sdf::Run> runs(run.runs);
  const CheckResult pre = check_admissible(g, runs.first(run.transient_decisions));
  ASSERT_TRUE(pre.valid) << pre.reason;
  if (run.outcome == Outcome::returns || run.outcome == Outcome::periodic) {
    const CheckResult c = check_period(g, q, runs.subspan(run.transient_decisions), pre.tokens);
    EXPECT_TRUE(c.valid) << c.reason;
  }
}

TEST(Online, TwoActorChainsAndTheThesisAcyclicClaim) {
  // Thesis 5.3.2, figure 5.1(a), claims both a < b and a > b converge. With the verbatim tie
  // rule, a < b does not: A (key 1, lower id) wins every tie with B at key 1, so the tokens on
  // A->B cycle through 2, 4, 1, 3, 5, 2, ... and never come back to 0. The smallest
  // counter-example to "online returns on acyclic graphs" is this two-actor chain 2:3.
  struct Case {
    uint64_t a, b;
    Outcome expect;
  };
  for (const Case& c :
       {Case{3, 2, Outcome::returns}, Case{1, 1, Outcome::returns}, Case{6, 4, Outcome::returns},
        Case{2, 3, Outcome::periodic}, Case{4, 6, Outcome::periodic}}) {
    const Graph g = test::make({"A", "B"}, {{"A", "B", c.a, c.b, 0}});
    const auto q = compute_repetitions(g).q;
    const OnlineRun r = run_online(g, q, options(FiringRule::floor_key, false));
    EXPECT_EQ(r.outcome, c.expect) << c.a << ":" << c.b;
    expect_checked(g, q, r);
  }
  const Graph g = test::make({"A", "B"}, {{"A", "B", 2, 3, 0}});
  const OnlineRun r =
      run_online(g, std::vector<uint64_t>{3, 2}, options(FiringRule::floor_key, false));
  // Transient: A (2 tokens); cycle: A (4) B (1) A (3) A (5, A wins the tie at key 1) B (2).
  EXPECT_EQ(r.transient_decisions, 1u);
  EXPECT_EQ(run_length_form(g, std::span<const sdf::Run>(r.runs).subspan(1)),
            "(1 A)(1 B)(1 A)(1 A)(1 B)");
  // Declared the other way round, B wins those ties and the run returns.
  const Graph h = test::make({"B", "A"}, {{"A", "B", 2, 3, 0}});
  EXPECT_EQ(
      run_online(h, std::vector<uint64_t>{2, 3}, options(FiringRule::floor_key, false)).outcome,
      Outcome::returns);
}

TEST(Online, FanOutOfTheThesisCounterExampleIsServed) {
  // Thesis 5.3.1: A -> B, A -> C; an arbitrary choice may starve C, the key rule does not.
  // After A fires, A, B and C are all newly eligible with key 1: A wins by id, then B and C
  // hold two tokens each and fire twice.
  const Graph g = test::make({"A", "B", "C"}, {{"A", "B", 1, 1, 0}, {"A", "C", 1, 1, 0}});
  const auto q = compute_repetitions(g).q;
  const OnlineRun r = run_online(g, q, options(FiringRule::floor_key, false));
  EXPECT_EQ(r.outcome, Outcome::returns);
  EXPECT_EQ(run_length_form(g, r.runs), "(1 A)(1 A)(2 B)(2 C)");
  expect_checked(g, q, r);
}

TEST(Online, ASourceFeedingAStarvedCycleGrowsWithoutBound) {
  const Graph g = read_graph_file(test::data("starved_cycle.json"));
  const auto q = compute_repetitions(g).q;
  const OnlineRun r = run_online(g, q, options(FiringRule::floor_key, false));
  ASSERT_EQ(r.outcome, Outcome::unbounded);
  EXPECT_EQ(std::string(g.channel_name(*r.channel)), "S->X#0");
  expect_checked(g, q, r);
}

TEST(Online, CdToDatBecomesPeriodicWithoutReturning) {
  const Graph g = read_graph_file(test::data("cd2dat.json"));
  const auto q = compute_repetitions(g).q;
  const OnlineRun r = run_online(g, q, options(FiringRule::floor_key, false));
  ASSERT_EQ(r.outcome, Outcome::periodic);
  EXPECT_EQ(r.transient_decisions, 1u);
  EXPECT_EQ(r.cycle_firings, 2 * 612u);  // two periods' worth, a multiple of q
  for (ActorId a = 0; a < g.actor_count(); ++a) EXPECT_EQ(r.cycle_fired[a], 2 * q[a]);
  expect_checked(g, q, r);
}

TEST(Online, DecisionLimitIsAnOutcome) {
  const Graph g = read_graph_file(test::data("cd2dat.json"));
  const auto q = compute_repetitions(g).q;
  OnlineRunOptions o = options(FiringRule::floor_key, false);
  o.max_decisions = 50;
  const OnlineRun r = run_online(g, q, o);
  EXPECT_EQ(r.outcome, Outcome::limit);
  EXPECT_EQ(r.transient_decisions, 50u);
}

TEST(Online, FloorKeyFiresManyTimesPerDecisionAndOneFiresOnce) {
  const Graph g = test::make({"A", "B"}, {{"A", "B", 1, 1, 5}});
  const std::vector<uint64_t> q = {1, 1};
  OnlineScheduler s(g, q, {FiringRule::floor_key, false});
  EXPECT_EQ(s.step(), (sdf::Run{1, 5}));  // key(B) = 5 beats key(A) = 1
  OnlineScheduler one(g, q, {FiringRule::one, false});
  EXPECT_EQ(one.step(), (sdf::Run{1, 1}));
  OnlineScheduler capped(g, q, {FiringRule::floor_key, false});
  EXPECT_EQ(capped.step(3), (sdf::Run{1, 3}));
}

TEST(Online, TiesGoToTheEarlierEligibleThenTheLowerId) {
  // Two independent sources, key 1 for ever. T (id 0) wins the first tie by id; it is then
  // newly eligible (stamp 1) while S has waited since 0: S wins, and so on alternately.
  const Graph g = test::make({"T", "S"}, {});
  OnlineScheduler s(g, {}, {FiringRule::floor_key, false});
  EXPECT_EQ(s.step()->actor, 0u);
  EXPECT_EQ(s.eligibility_order(), (std::vector<ActorId>{1, 0}));
  EXPECT_EQ(s.step()->actor, 1u);
  EXPECT_EQ(s.step()->actor, 0u);
  EXPECT_EQ(s.step()->actor, 1u);
}

TEST(Online, KeysAreComparedExactly) {
  // B: 10^18 / 666666666666666667 = 1.4999999999999999992..., A: 3/2. In doubles both are 1.5
  // and B would win the tie by id; exactly, A's key is larger.
  const Graph g = test::make(
      {"S1", "S2", "B", "A"},
      {{"S1", "A", 1, 2, 3}, {"S2", "B", 1, 666666666666666667ull, 1000000000000000000ull}});
  OnlineScheduler s(g, {}, {FiringRule::one, false});
  EXPECT_EQ(s.step()->actor, 3u);
}

// The fast scheduler against the naive one that recomputes everything each decision and keeps
// every state in a map: same decisions, same outcome, same transient and cycle, same fairness.
TEST(Online, MatchesTheNaiveSchedulerOnRandomGraphs) {
  crowddb::Rng rng(2024);
  int counts[5] = {};
  for (int i = 0; i < 480; ++i) {
    gen::Spec spec;
    spec.shape = static_cast<gen::Shape>(i % 5);
    spec.actors = 2 + static_cast<uint32_t>(rng.below(8));
    spec.multirate = i % 4 != 3;
    spec.self_loops = (i / 5) % 3 == 0;
    const gen::Generated gg = gen::generate(spec, rng);
    const FiringRule rule = (i / 2) % 2 ? FiringRule::one : FiringRule::floor_key;
    const bool bounded = i % 3 == 0;
    OnlineRunOptions o = options(rule, bounded);
    o.max_decisions = 20'000;
    o.growth_periods = 4;
    const OnlineRun fast = run_online(gg.graph, gg.q, o);
    const naive::NaiveOnline slow = naive::online(gg.graph, gg.q, o);
    ++counts[static_cast<int>(fast.outcome)];
    ASSERT_EQ(fast.outcome, slow.outcome) << i;
    EXPECT_EQ(fast.channel, slow.channel) << i;
    if (fast.outcome == Outcome::returns || fast.outcome == Outcome::periodic) {
      EXPECT_EQ(fast.transient_decisions, slow.transient) << i;
      EXPECT_EQ(fast.cycle_decisions, slow.cycle) << i;
    }
    const size_t n = std::min(fast.runs.size(), slow.runs.size());
    ASSERT_GT(n, 0u);
    EXPECT_TRUE(std::equal(fast.runs.begin(), fast.runs.begin() + static_cast<ptrdiff_t>(n),
                           slow.runs.begin()))
        << i;
    uint64_t max_wait = 0, sum = 0;
    for (size_t k = 0; k < fast.runs.size() && k < slow.waits.size(); ++k) {
      max_wait = std::max(max_wait, slow.waits[k]);
      sum += slow.waits[k];
    }
    if (fast.runs.size() <= slow.waits.size()) {
      EXPECT_EQ(fast.metrics.fairness.max, max_wait) << i;
      EXPECT_DOUBLE_EQ(fast.metrics.fairness.mean,
                       static_cast<double>(sum) / static_cast<double>(fast.runs.size()))
          << i;
    }
    if (bounded) {
      EXPECT_EQ(fast.outcome, Outcome::returns) << i;
    }
    expect_checked(gg.graph, gg.q, fast);
  }
  // The sample must exercise the interesting outcomes, not just `returns`.
  EXPECT_GT(counts[static_cast<int>(Outcome::returns)], 100);
  EXPECT_GT(counts[static_cast<int>(Outcome::periodic)], 20);
  EXPECT_GT(counts[static_cast<int>(Outcome::unbounded)], 5);
}

TEST(Online, SameInputSameRun) {
  crowddb::Rng rng(99);
  gen::Spec spec;
  spec.shape = gen::Shape::cyclic;
  spec.actors = 30;
  const gen::Generated gg = gen::generate(spec, rng);
  const OnlineRun a = run_online(gg.graph, gg.q, options(FiringRule::floor_key, false));
  const OnlineRun b = run_online(gg.graph, gg.q, options(FiringRule::floor_key, false));
  EXPECT_EQ(a.outcome, b.outcome);
  EXPECT_EQ(a.runs, b.runs);
}

TEST(OnlineBounded, CompletesAValidPeriodOnLiveRandomGraphs) {
  crowddb::Rng rng(77);
  for (int i = 0; i < 300; ++i) {
    gen::Spec spec;
    spec.shape = static_cast<gen::Shape>(i % 5);
    spec.actors = 2 + static_cast<uint32_t>(rng.below(30));
    spec.self_loops = i % 2 == 0;
    spec.multirate = i % 7 != 0;
    const gen::Generated gg = gen::generate(spec, rng);
    const OnlineRun r =
        run_online(gg.graph, gg.q, options(i % 3 ? FiringRule::floor_key : FiringRule::one, true));
    ASSERT_EQ(r.outcome, Outcome::returns) << i;
    ASSERT_EQ(r.transient_decisions, 0u);
    for (ActorId a = 0; a < gg.graph.actor_count(); ++a) EXPECT_EQ(r.cycle_fired[a], gg.q[a]) << i;
    expect_checked(gg.graph, gg.q, r);
  }
}

TEST(OnlineScheduler, StateComparisonSeesTheEligibilityOrder) {
  const Graph g = test::make({"A", "B", "C"}, {{"A", "B", 1, 1, 0}, {"A", "C", 1, 1, 0}});
  OnlineScheduler s(g, {}, {FiringRule::floor_key, false});
  OnlineScheduler t = s;
  EXPECT_TRUE(s.same_state(t));
  s.step();
  EXPECT_FALSE(s.same_state(t));
  t.step();
  EXPECT_TRUE(s.same_state(t));
  EXPECT_EQ(s.state_hash(), t.state_hash());
}

}  // namespace
}  // namespace sdf
