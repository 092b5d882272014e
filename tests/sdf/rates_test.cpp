#include "sdf/rates.hpp"

#include <gtest/gtest.h>

#include "helpers.hpp"
#include "sdf/generate.hpp"

namespace sdf {
namespace {

OnlineRunOptions opts() {
  OnlineRunOptions o;
  o.max_decisions = 1'000'000;
  return o;
}

TEST(RateChange, MidPeriodChangeOnAChainForEveryPolicy) {
  const Graph g = test::make({"A", "B", "C"}, {{"A", "B", 1, 1, 0}, {"B", "C", 1, 1, 0}});
  const RateChange rc = RateChange::uniform(g, 1, 2, 1, 1);  // B produces 2 after A's firing
  for (Policy p : {Policy::static_order, Policy::online, Policy::online_bounded}) {
    const RateChangeResult r = simulate_rate_change(g, p, rc, opts());
    ASSERT_TRUE(r.after.consistent);
    EXPECT_EQ(r.q_before, (std::vector<uint64_t>{1, 1, 1}));
    EXPECT_EQ(r.q_after, (std::vector<uint64_t>{1, 1, 2}));
    EXPECT_EQ(r.tokens_at_change, (std::vector<uint64_t>{1, 0})) << policy_name(p);
    ASSERT_TRUE(r.outcome == Outcome::returns || r.outcome == Outcome::periodic) << policy_name(p);
    EXPECT_TRUE(r.period_checked);
    EXPECT_TRUE(r.period_valid) << policy_name(p);
    EXPECT_EQ(r.period_firings % 4, 0u);  // a multiple of q' = (1, 1, 2)
    // Static runs A B C one at a time; online lets A run ahead once (A wins the tie with B).
    EXPECT_EQ(r.buffers_before, (std::vector<uint64_t>(2, p == Policy::online ? 2 : 1)))
        << policy_name(p);
    ASSERT_EQ(r.buffers_after.size(), 2u);
    EXPECT_GE(r.buffers_after[1], 2u);
  }
  EXPECT_EQ(simulate_rate_change(g, Policy::static_order, rc, opts()).firings_until_periodic, 0u);
}

TEST(RateChange, InconsistentAndDeadlockedResults) {
  const Graph loop = test::make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 1}});
  // A:2/1 -> A produces 2, consumes 1: q_A·2 = q_B and q_B = q_A cannot both hold.
  const RateChangeResult bad =
      simulate_rate_change(loop, Policy::online, RateChange::uniform(loop, 0, 2, 1, 1), opts());
  EXPECT_FALSE(bad.after.consistent);
  EXPECT_TRUE(bad.q_after.empty());
  // A:2/2 is consistent (q' = (1, 2)) but A now needs 2 tokens on B->A, which holds 1, and B
  // waits for A: stuck.
  const RateChangeResult dead = simulate_rate_change(loop, Policy::static_order,
                                                     RateChange::uniform(loop, 0, 2, 2, 0), opts());
  ASSERT_TRUE(dead.after.consistent);
  EXPECT_EQ(dead.outcome, Outcome::deadlock);
  EXPECT_EQ(dead.stuck, (std::vector<ActorId>{0, 1}));
  EXPECT_EQ(
      simulate_rate_change(loop, Policy::online, RateChange::uniform(loop, 0, 2, 2, 0), opts())
          .outcome,
      Outcome::deadlock);
}

TEST(RateChange, RandomTreesAndFiringsEveryPeriodPassesTheChecker) {
  crowddb::Rng rng(3);
  int checked = 0;
  for (int i = 0; i < 150; ++i) {
    gen::Spec spec;
    spec.shape = i % 2 ? gen::Shape::fan_out : gen::Shape::chain;
    spec.actors = 2 + static_cast<uint32_t>(rng.below(6));
    const gen::Generated gg = gen::generate(spec, rng);
    const auto actor = static_cast<ActorId>(rng.below(spec.actors));
    const uint64_t prd = 1 + rng.below(4);
    const uint64_t cns = 1 + rng.below(4);
    uint64_t per = 0;
    for (uint64_t v : gg.q) per += v;
    const RateChange rc = RateChange::uniform(gg.graph, actor, prd, cns, rng.below(2 * per));
    const auto policy = static_cast<Policy>(i % 3);
    const RateChangeResult r = simulate_rate_change(gg.graph, policy, rc, opts());
    ASSERT_TRUE(r.after.consistent) << i;  // trees stay consistent under any rates
    if (policy != Policy::online) {
      // Static and bounded always complete a period after the change, unless the tokens at the
      // change deadlock the new graph, which a tree without delays cannot do.
      EXPECT_EQ(r.outcome, Outcome::returns) << i;
    }
    if (r.period_checked) {
      ++checked;
      EXPECT_TRUE(r.period_valid) << i << " " << policy_name(policy);
    }
  }
  EXPECT_GT(checked, 120);
}

// Scaling an actor's rates by num/den (the thesis's form) keeps any graph consistent: the new
// repetitions vector is the old one with the actor's count times den/num, made primitive.
TEST(RateChange, ScalingByAFactorKeepsTheGraphConsistent) {
  crowddb::Rng rng(4);
  int cyclic = 0;
  for (int i = 0; i < 200; ++i) {
    gen::Spec spec;
    spec.shape = i % 2 ? gen::Shape::cyclic : gen::Shape::dag;
    spec.actors = 2 + static_cast<uint32_t>(rng.below(6));
    spec.self_loops = i % 3 == 0;
    const gen::Generated gg = gen::generate(spec, rng);
    const auto a = static_cast<ActorId>(rng.below(spec.actors));
    const uint64_t num = 1 + rng.below(3), den = i % 4 == 0 ? 2 : 1;
    RateChange rc;
    try {
      rc = RateChange::scaled(gg.graph, a, num, den, rng.below(20));
    } catch (const Error&) {
      continue;  // a rate of a that is odd cannot be halved
    }
    size_t listed = 0;
    for (ChannelId c = 0; c < gg.graph.channel_count(); ++c) {
      const Channel& ch = gg.graph.channel(c);
      listed += (ch.src == a || ch.dst == a) && ch.src != ch.dst;  // self-loops keep their rates
    }
    EXPECT_EQ(rc.rates.size(), listed);
    for (const ChannelRates& r : rc.rates) {
      const Channel& ch = gg.graph.channel(r.channel);
      EXPECT_NE(ch.src, ch.dst);
      EXPECT_EQ(r.prd * den, ch.src == a ? ch.prd * num : ch.prd * den);
      EXPECT_EQ(r.cns * den, ch.dst == a ? ch.cns * num : ch.cns * den);
    }
    const RateChangeResult r =
        simulate_rate_change(gg.graph, static_cast<Policy>(i % 3), rc, opts());
    ASSERT_TRUE(r.after.consistent) << i;
    // q' ∝ q with q_a·den/num: q'_b·q_a·den = q'_a·q_b·num for every other actor b.
    for (ActorId b = 0; b < gg.q.size(); ++b) {
      if (b == a) continue;
      EXPECT_EQ(r.q_after[b] * gg.q[a] * den, r.q_after[a] * gg.q[b] * num) << i;
    }
    cyclic += spec.shape == gen::Shape::cyclic;
  }
  EXPECT_GT(cyclic, 60);
  EXPECT_THROW(RateChange::scaled(test::make({"A", "B"}, {{"A", "B", 3, 3, 0}}), 0, 1, 2, 0),
               Error);  // 3/2 is not whole
}

}  // namespace
}  // namespace sdf
