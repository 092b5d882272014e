#include "sdf/graph.hpp"

#include <gtest/gtest.h>

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
