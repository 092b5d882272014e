#include "sdf/repetitions.hpp"

#include <gtest/gtest.h>

#include <numeric>

#include "helpers.hpp"
#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/naive.hpp"

namespace sdf {
namespace {

__extension__ using u128 = unsigned __int128;
bool balanced(uint64_t q_src, uint64_t prd, uint64_t q_dst, uint64_t cns) {
  return static_cast<u128>(q_src) * prd == static_cast<u128>(q_dst) * cns;
}

// Oracle: a positive vector that balances every channel and has gcd 1 on each connected
// component is the repetitions vector (the solutions of a connected consistent graph form a
// one-dimensional lattice).
void expect_primitive_solution(const Graph& g, const std::vector<uint64_t>& q) {
  ASSERT_EQ(q.size(), g.actor_count());
  for (ChannelId id = 0; id < g.channel_count(); ++id) {
    const Channel& c = g.channel(id);
    EXPECT_TRUE(balanced(q[c.src], c.prd, q[c.dst], c.cns)) << g.channel_name(id);
  }
  const Adjacency adj(g);
  const Components comp = connected_components(g, adj);
  std::vector<uint64_t> gcd(comp.count, 0);
  for (ActorId a = 0; a < g.actor_count(); ++a) {
    EXPECT_GT(q[a], 0u);
    gcd[comp.of_actor[a]] = std::gcd(gcd[comp.of_actor[a]], q[a]);
  }
  for (uint64_t v : gcd) EXPECT_EQ(v, 1u);
}

TEST(Repetitions, CdToDatSampleRateConverterMatchesTheLiterature) {
  // Bhattacharyya, Murthy & Lee: CD (44.1 kHz) to DAT (48 kHz), rates 1:1, 2:3, 2:7, 8:7, 5:1.
  for (const char* file : {"cd2dat.json", "cd2dat.xml"}) {
    const Repetitions r = compute_repetitions(read_graph_file(test::data(file)));
    ASSERT_TRUE(r.consistent);
    EXPECT_EQ(r.q, (std::vector<uint64_t>{147, 147, 98, 28, 32, 160})) << file;
  }
}

TEST(Repetitions, CountsBeyond32BitsAreExact) {
  const Repetitions r = compute_repetitions(read_graph_file(test::data("chain65537.json")));
  ASSERT_TRUE(r.consistent);
  EXPECT_EQ(r.q, (std::vector<uint64_t>{1, 65537, 4295098369ull}));
  // Reversed rates put the big count on the source.
  const Graph rev = test::make({"A", "B", "C"}, {{"A", "B", 1, 65537, 0}, {"B", "C", 1, 65537, 0}});
  EXPECT_EQ(compute_repetitions(rev).q, (std::vector<uint64_t>{4295098369ull, 65537, 1}));
}

TEST(Repetitions, OverflowIsAnErrorNeverAWrappedNumber) {
  try {
    compute_repetitions(read_graph_file(test::data("overflow.json")));
    FAIL() << "2^64 * 3 must not fit";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::overflow);
  }
  // The largest value that fits still works: 2^63 * ... and 2^64 - 1 = 3 * 5 * 17 * 257 * 641 *
  // 65537 * 6700417.
  const Graph fits = test::make({"A", "B"}, {{"A", "B", 18446744073709551615ull, 1, 0}});
  EXPECT_EQ(compute_repetitions(fits).q, (std::vector<uint64_t>{1, 18446744073709551615ull}));
  // An overflow in the lcm of denominators, with every single fraction small enough.
  Graph lcm;
  lcm.add_actor("hub");
  const uint64_t primes[] = {4294967291ull, 4294967279ull, 4294967231ull};
  for (int i = 0; i < 3; ++i) {
    lcm.add_actor("p" + std::to_string(i));
    lcm.add_channel(0, static_cast<ActorId>(i + 1), 1, primes[i], 0);
  }
  EXPECT_THROW(compute_repetitions(lcm), Error);
}

TEST(Repetitions, InconsistentGraphNamesAFailingChannel) {
  const Graph g = read_graph_file(test::data("inconsistent.json"));
  const Repetitions r = compute_repetitions(g);
  ASSERT_FALSE(r.consistent);
  const Channel& c = g.channel(r.channel);
  EXPECT_FALSE(balanced(r.q_src, c.prd, r.q_dst, c.cns));
  // A self-loop with prd != cns can never balance.
  const Repetitions s = compute_repetitions(test::make({"A"}, {{"A", "A", 2, 1, 1}}));
  EXPECT_FALSE(s.consistent);
  EXPECT_EQ(s.channel, 0u);
}

TEST(Repetitions, ComponentsAreScaledIndependently) {
  const Graph g = test::make({"A", "B", "C", "D", "E"}, {{"A", "B", 2, 4, 0}, {"C", "D", 3, 1, 0}});
  const Repetitions r = compute_repetitions(g);
  ASSERT_TRUE(r.consistent);
  EXPECT_EQ(r.q, (std::vector<uint64_t>{2, 1, 1, 3, 1}));
}

TEST(Repetitions, RandomGraphsBuiltFromAChosenVector) {
  crowddb::Rng rng(42);
  for (int i = 0; i < 600; ++i) {
    gen::Spec spec;
    spec.shape = static_cast<gen::Shape>(i % 6);
    spec.actors = 1 + static_cast<uint32_t>(rng.below(40));
    spec.multirate = i % 5 != 0;
    spec.self_loops = i % 3 == 0;
    const gen::Generated gg = gen::generate(spec, rng);
    const Repetitions r = compute_repetitions(gg.graph);
    ASSERT_TRUE(r.consistent) << i;
    EXPECT_EQ(r.q, gg.q) << i;
    expect_primitive_solution(gg.graph, r.q);
  }
}

// `generate --max-rate R`: every rate at most R, the graph still built from its vector, and R
// reached where the other caps allow (a cap that is never approached would pass vacuously).
TEST(Repetitions, GeneratedRatesStayWithinTheirCap) {
  crowddb::Rng rng(4242);
  uint64_t at_cap = 0;
  for (int i = 0; i < 600; ++i) {
    gen::Spec spec;
    spec.shape = static_cast<gen::Shape>(i % 6);
    spec.actors = 2 + static_cast<uint32_t>(rng.below(20));
    spec.max_rate = 1 + static_cast<uint32_t>(rng.below(15));
    spec.max_q = 1 + static_cast<uint32_t>(rng.below(12));
    spec.max_multiplier = 1 + static_cast<uint32_t>(rng.below(3));
    const gen::Generated gg = gen::generate(spec, rng);
    uint64_t top = 0;
    for (const Channel& c : gg.graph.channels()) top = std::max({top, c.prd, c.cns});
    EXPECT_LE(top, spec.max_rate) << i;
    at_cap += top == spec.max_rate;
    const Repetitions r = compute_repetitions(gg.graph);
    ASSERT_TRUE(r.consistent) << i;
    EXPECT_EQ(r.q, gg.q) << i;
  }
  EXPECT_GT(at_cap, 100u);
}

TEST(Repetitions, PerturbedRandomGraphsAreInconsistentAtACycle) {
  crowddb::Rng rng(43);
  int inconsistent = 0;
  for (int i = 0; i < 300; ++i) {
    gen::Spec spec;
    spec.shape = gen::Shape::cyclic;
    spec.actors = 2 + static_cast<uint32_t>(rng.below(20));
    Graph g = gen::generate(spec, rng).graph;
    const auto c = static_cast<ChannelId>(rng.below(g.channel_count()));
    g.set_rates(c, g.channel(c).prd * 2, g.channel(c).cns);
    const Repetitions r = compute_repetitions(g);
    if (r.consistent) {
      expect_primitive_solution(g, r.q);  // the channel was a bridge: still balanced
    } else {
      ++inconsistent;
      const Channel& f = g.channel(r.channel);
      EXPECT_FALSE(balanced(r.q_src, f.prd, r.q_dst, f.cns));
    }
  }
  EXPECT_GT(inconsistent, 100);
}

// compute_repetitions against the plain walk (naive::repetitions): the same vector, the same
// failing channel with the same two sides, the same overflow error, on random graphs with
// several components, perturbed rates and rates large enough to overflow.
TEST(Repetitions, MatchesThePlainWalkExactly) {
  crowddb::Rng rng(44);
  int inconsistent = 0, overflowed = 0;
  for (int i = 0; i < 1500; ++i) {
    Graph g;
    const uint32_t pieces = 1 + static_cast<uint32_t>(rng.below(3));
    for (uint32_t p = 0; p < pieces; ++p) {
      gen::Spec spec;
      spec.shape = static_cast<gen::Shape>(rng.below(6));
      spec.actors = 1 + static_cast<uint32_t>(rng.below(30));
      spec.multirate = rng.below(5) != 0;
      spec.self_loops = rng.below(3) == 0;
      const Graph part = gen::generate(spec, rng).graph;
      const auto base = static_cast<ActorId>(g.actor_count());
      for (ActorId a = 0; a < part.actor_count(); ++a)
        g.add_actor("p" + std::to_string(p) + "_" + part.actor_name(a));
      for (const Channel& c : part.channels())
        g.add_channel(base + c.src, base + c.dst, c.prd, c.cns, c.delay);
    }
    const int perturb = static_cast<int>(rng.below(5));
    for (int k = 0; k < perturb && g.channel_count() > 0; ++k) {
      const auto c = static_cast<ChannelId>(rng.below(g.channel_count()));
      const uint64_t factor = rng.below(2) == 0 ? (uint64_t{1} << 40) + 1 : 2 + rng.below(3);
      g.set_rates(c, g.channel(c).prd * factor, g.channel(c).cns);
    }
    std::optional<Repetitions> fast, slow;
    std::string fast_error = "-", slow_error = "-";
    try {
      fast = compute_repetitions(g);
    } catch (const Error& e) {
      fast_error = e.what();
    }
    try {
      slow = naive::repetitions(g);
    } catch (const Error& e) {
      slow_error = e.what();
    }
    ASSERT_EQ(fast_error, slow_error) << i;
    ASSERT_EQ(fast.has_value(), slow.has_value()) << i;
    if (!fast) {
      ++overflowed;
      continue;
    }
    EXPECT_EQ(fast->consistent, slow->consistent) << i;
    EXPECT_EQ(fast->q, slow->q) << i;
    if (!fast->consistent) {
      ++inconsistent;
      EXPECT_EQ(fast->channel, slow->channel) << i;
      EXPECT_EQ(fast->q_src, slow->q_src) << i;
      EXPECT_EQ(fast->q_dst, slow->q_dst) << i;
    }
  }
  EXPECT_GT(inconsistent, 100);
  EXPECT_GT(overflowed, 20);
}

}  // namespace
}  // namespace sdf
