#include "sdf/graph.hpp"

#include <gtest/gtest.h>

#include <map>
#include <random>
#include <thread>

#include "helpers.hpp"

namespace sdf {
namespace {

TEST(Graph, DefaultChannelNamesCountParallelChannels) {
  const Graph g =
      test::make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"A", "B", 2, 2, 0}, {"B", "A", 1, 1, 1}});
  EXPECT_EQ(std::string(g.channel_name(0)), "A->B#0");
  EXPECT_EQ(std::string(g.channel_name(1)), "A->B#1");
  EXPECT_EQ(std::string(g.channel_name(2)), "B->A#0");
  EXPECT_EQ(g.find_channel("A->B#1"), 1u);
  EXPECT_FALSE(g.find_channel("A->B#2"));
}

// The count k of `src->dst#k` includes the named channels before it, also when every channel so
// far was named (the counts are only kept from the first default name on) and in the bulk form.
TEST(Graph, DefaultNamesCountNamedChannelsToo) {
  for (bool bulk : {false, true}) {
    Graph g;
    g.add_actor("A");
    g.add_actor("B");
    g.add_channel(0, 1, 1, 1, 0, "x");
    g.add_channel(1, 0, 1, 1, 0, "y");
    if (bulk) {
      const Graph::NewChannel cs[] = {
          {0, 1, 1, 1, 0, ""}, {0, 1, 1, 1, 0, "z"}, {0, 1, 1, 1, 0, ""}};
      EXPECT_EQ(g.add_channels(cs), 3u);
    } else {
      g.add_channel(0, 1, 1, 1, 0);
      g.add_channel(0, 1, 1, 1, 0, "z");
      g.add_channel(0, 1, 1, 1, 0);
    }
    EXPECT_EQ(g.channel_name(2), "A->B#1");
    EXPECT_EQ(g.channel_name(4), "A->B#3");
    EXPECT_THROW(g.add_channel(0, 1, 1, 1, 0, "A->B#3"), Error);
    EXPECT_EQ(g.add_channel(0, 1, 1, 1, 0), 5u);  // a refused channel is not counted
    EXPECT_EQ(g.channel_name(5), "A->B#4");
    EXPECT_EQ(g.channel_name(1), "y");
  }
}

// Names live in columns: a value set again replaces the old one, a view of the graph's own
// names may be passed back in, and copies keep their names.
TEST(Graph, NameColumnsKeepEveryName) {
  Graph g = test::make({"A", "B"}, {{"A", "B", 1, 1, 0}, {"B", "A", 1, 1, 1}});
  EXPECT_EQ(g.actor_type(0), "");
  g.set_actor_type(0, "a-long-type-name-beyond-any-small-buffer");
  g.set_actor_type(1, g.actor_type(0));  // a view into the column being appended to
  g.set_actor_type(0, "t");
  EXPECT_EQ(g.actor_type(0), "t");
  EXPECT_EQ(g.actor_type(1), "a-long-type-name-beyond-any-small-buffer");
  EXPECT_EQ(g.src_port(1), "");
  g.set_port_names(1, "o", "i");
  g.set_port_names(0, "out", "in");
  g.set_port_names(1, "o2", "i2");
  const Graph copy = g;
  EXPECT_EQ(copy.src_port(0), "out");
  EXPECT_EQ(copy.dst_port(1), "i2");
  EXPECT_EQ(copy.channel_name(1), "B->A#0");
  EXPECT_EQ(copy.actor_type(1), "a-long-type-name-beyond-any-small-buffer");
}

// The oracle of the channel names: every accepted channel's name (given, or src->dst#k with k
// the number of earlier channels from src to dst), names unique, kept in plain maps.
struct NameOracle {
  std::vector<std::string> actors, names;
  std::map<std::pair<ActorId, ActorId>, uint64_t> pairs;
  std::map<std::string, ChannelId> index;
  // The name the channel would get, or "" when it would be refused as a duplicate.
  std::string name_of(ActorId src, ActorId dst, const std::string& given) const {
    std::string n = given;
    if (n.empty()) {
      const auto it = pairs.find({src, dst});
      n = actors[src] + "->" + actors[dst] + "#" +
          std::to_string(it == pairs.end() ? 0 : it->second);
    }
    return index.count(n) ? std::string() : n;
  }
  void add(ActorId src, ActorId dst, const std::string& n) {
    index[n] = static_cast<ChannelId>(names.size());
    names.push_back(n);
    ++pairs[{src, dst}];
  }
};

// Default names are made only when asked for (or when a named channel or an actor whose name
// has "->" comes): whatever the order of additions, bulk and single, and of the reads in
// between, the names, the lookups and the refusals are those of the oracle. The actor names
// are chosen so that "->" in them makes default names collide (a->b->c#0 from a to b->c and
// from a->b to c), and some given names equal default names.
TEST(Graph, DeferredDefaultNamesAgreeWithTheOracle) {
  const std::vector<std::string> pool = {"a", "b", "c", "b->c", "a->b", "c#1", "x"};
  const std::vector<std::string> given = {"a->b#0", "a->b->c#0", "b->a#1", "q", "c->c#0", "x->a#0"};
  std::mt19937_64 rng(20261129);
  for (int trial = 0; trial < 3000; ++trial) {
    Graph g;
    NameOracle o;
    std::vector<std::string> actors = pool;
    std::shuffle(actors.begin(), actors.end(), rng);
    const size_t first_actors = 2 + rng() % 3;
    auto add_actor = [&](size_t i) {
      g.add_actor(actors[i]);
      o.actors.push_back(actors[i]);
    };
    for (size_t i = 0; i < first_actors; ++i) add_actor(i);
    const bool named_ever = rng() % 2 == 0;
    for (int step = 0; step < 12; ++step) {
      const uint64_t r = rng() % 10;
      if (r == 0 && o.actors.size() < actors.size()) {
        add_actor(o.actors.size());
        continue;
      }
      if (r == 1) {  // a read in between makes the names
        if (!o.names.empty()) {
          const auto c = static_cast<ChannelId>(rng() % o.names.size());
          ASSERT_EQ(g.channel_name(c), o.names[c]) << trial;
        }
        continue;
      }
      const size_t count = 1 + rng() % 4;
      std::vector<Graph::NewChannel> batch;
      std::vector<std::string> names;  // the given names, kept alive for the batch's views
      names.reserve(count);
      for (size_t i = 0; i < count; ++i) {
        const auto src = static_cast<ActorId>(rng() % o.actors.size());
        const auto dst = static_cast<ActorId>(rng() % o.actors.size());
        names.push_back(named_ever && rng() % 4 == 0 ? given[rng() % given.size()] : "");
        batch.push_back({src, dst, 1, 1, 0, names.back()});
      }
      if (r < 6) {  // single additions
        for (size_t i = 0; i < count; ++i) {
          const std::string n = o.name_of(batch[i].src, batch[i].dst, names[i]);
          if (n.empty()) {
            EXPECT_THROW(g.add_channel(batch[i].src, batch[i].dst, 1, 1, 0, names[i]), Error)
                << trial;
          } else {
            ASSERT_EQ(g.add_channel(batch[i].src, batch[i].dst, 1, 1, 0, names[i]), o.names.size())
                << trial;
            o.add(batch[i].src, batch[i].dst, n);
          }
        }
      } else {  // in bulk: up to the first refusal
        size_t expect = 0;
        for (; expect < count; ++expect) {
          const std::string n = o.name_of(batch[expect].src, batch[expect].dst, names[expect]);
          if (n.empty()) break;
          o.add(batch[expect].src, batch[expect].dst, n);
        }
        ASSERT_EQ(g.add_channels(batch), expect) << trial;
      }
    }
    ASSERT_EQ(g.channel_count(), o.names.size());
    for (ChannelId c = 0; c < g.channel_count(); ++c) {
      ASSERT_EQ(g.channel_name(c), o.names[c]) << trial << " channel " << c;
      ASSERT_EQ(g.find_channel(o.names[c]), c) << trial;
    }
    EXPECT_FALSE(g.find_channel("a->a#99"));
  }
}

// Names made under concurrent const use (and copies taken meanwhile) are made once and agree.
TEST(Graph, DeferredDefaultNamesAreMadeOnceUnderConcurrentReads) {
  Graph g;
  constexpr uint32_t kActors = 300;
  for (uint32_t a = 0; a < kActors; ++a) g.add_actor("actor" + std::to_string(a));
  std::vector<Graph::NewChannel> cs;
  for (uint32_t i = 0; i < 20000; ++i)
    cs.push_back({i % kActors, (i * 7919) % kActors, 1, 1, 0, {}});
  ASSERT_EQ(g.add_channels(cs), cs.size());
  const Graph& view = g;
  std::vector<std::vector<std::string>> seen(4);
  std::vector<Graph> copies(4);
  std::vector<std::thread> readers;
  for (size_t t = 0; t < seen.size(); ++t)
    readers.emplace_back([&, t] {
      if (t % 2) copies[t] = view;
      for (ChannelId c = 0; c < view.channel_count(); ++c)
        seen[t].emplace_back(view.channel_name(c));
      if (t % 2 == 0) copies[t] = view;
    });
  for (std::thread& r : readers) r.join();
  for (size_t t = 0; t < seen.size(); ++t) {
    EXPECT_EQ(seen[t], seen[0]);
    ASSERT_EQ(copies[t].channel_count(), cs.size());
    for (ChannelId c = 0; c < cs.size(); c += 997) EXPECT_EQ(copies[t].channel_name(c), seen[0][c]);
  }
  // Channel i goes from i mod 300 to 119 i mod 300 (7919 = 119 mod 300): the pair repeats every
  // 300 channels, so k = i div 300. 7920 = 26 * 300 + 120, and 120 * 119 = 180 mod 300.
  EXPECT_EQ(seen[0][7920], "actor120->actor180#26");
  EXPECT_EQ(g.find_channel("actor120->actor180#26"), 7920u);
}

// The actors' table keeps names of up to 7 bytes in its slots and compares longer ones in part
// there: names around that length, sharing prefixes, with NUL bytes, against a plain map, through
// the single and bulk additions and lookups (the table grows through several rehashes).
TEST(Graph, ActorLookupsAgreeWithAMap) {
  std::mt19937_64 rng(7);
  auto random_name = [&] {
    std::string s(1 + rng() % 10, 'a');
    for (char& c : s) c = "ab\0"[rng() % 3];
    return s;
  };
  for (int trial = 0; trial < 20; ++trial) {
    Graph g;
    std::map<std::string, ActorId> oracle;
    for (int step = 0; step < 200; ++step) {
      std::vector<std::string> names(1 + rng() % 20);
      for (std::string& n : names) n = random_name();
      if (rng() % 2) {
        for (const std::string& n : names) {
          if (oracle.count(n)) {
            EXPECT_THROW(g.add_actor(n), Error);
          } else {
            oracle[n] = g.add_actor(n);
          }
        }
      } else {
        const std::vector<std::string_view> views(names.begin(), names.end());
        size_t expect = 0;
        std::map<std::string, ActorId> batch;
        for (; expect < names.size(); ++expect) {
          if (oracle.count(names[expect]) || batch.count(names[expect])) break;
          batch[names[expect]] = static_cast<ActorId>(g.actor_count() + expect);
        }
        ASSERT_EQ(g.add_actors(views), expect);
        oracle.insert(batch.begin(), batch.end());
      }
      std::vector<std::string> probes(30);
      for (std::string& p : probes) p = random_name();
      const std::vector<std::string_view> views(probes.begin(), probes.end());
      std::vector<int64_t> ids(probes.size());
      g.find_actors(views, ids);
      for (size_t i = 0; i < probes.size(); ++i) {
        const auto it = oracle.find(probes[i]);
        const int64_t want = it == oracle.end() ? int64_t{-1} : int64_t{it->second};
        ASSERT_EQ(ids[i], want) << trial;
        ASSERT_EQ(g.find_actor(probes[i]),
                  it == oracle.end() ? std::nullopt : std::optional(it->second));
      }
    }
    ASSERT_EQ(g.actor_count(), oracle.size());
    for (const auto& [n, a] : oracle) ASSERT_EQ(g.actor_name(a), n);
  }
}

TEST(Graph, RejectsDuplicatesAndZeroRates) {
  Graph g;
  g.add_actor("A");
  EXPECT_THROW(g.add_actor("A"), Error);
  EXPECT_THROW(g.add_actor(""), Error);
  EXPECT_THROW(g.add_channel(0, 0, 0, 1, 0), Error);
  EXPECT_THROW(g.add_channel(0, 5, 1, 1, 0), Error);
  g.add_channel(0, 0, 1, 1, 1, "self");
  EXPECT_THROW(g.add_channel(0, 0, 1, 1, 1, "self"), Error);
}

TEST(Graph, AdjacencyListsChannelsInOrderAndSelfLoopsTwice) {
  const Graph g = test::make(
      {"A", "B", "C"},
      {{"A", "B", 1, 1, 0}, {"B", "B", 1, 1, 1}, {"A", "C", 1, 1, 0}, {"C", "B", 1, 1, 0}});
  const Adjacency adj(g);
  EXPECT_EQ(std::vector<ChannelId>(adj.outputs(0).begin(), adj.outputs(0).end()),
            (std::vector<ChannelId>{0, 2}));
  EXPECT_EQ(std::vector<ChannelId>(adj.inputs(1).begin(), adj.inputs(1).end()),
            (std::vector<ChannelId>{0, 1, 3}));
  EXPECT_EQ(std::vector<ChannelId>(adj.outputs(1).begin(), adj.outputs(1).end()),
            (std::vector<ChannelId>{1}));
}

TEST(Graph, ConnectedComponentsIgnoreDirection) {
  const Graph g = test::make({"A", "B", "C", "D", "E"}, {{"B", "A", 1, 1, 0}, {"D", "C", 1, 1, 0}});
  const Adjacency adj(g);
  const Components c = connected_components(g, adj);
  EXPECT_EQ(c.count, 3u);
  EXPECT_EQ(c.of_actor, (std::vector<uint32_t>{0, 0, 1, 1, 2}));
}

}  // namespace
}  // namespace sdf
