// The bigger sweep of the first-to-collide index against the naive oracle (label `slow`; run with
// CROWDDB_SLOW_TESTS=1 or ctest -L slow): thousands of random tables, larger sizes, every option.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "index/ftc_tree.hpp"
#include "query/naive_paths.hpp"
#include "scenario/builders.hpp"
#include "support/random_tables.hpp"
#include "util/rng.hpp"

namespace crowddb {
namespace {

using Opt = FtcIndexOptions;

std::size_t differences(const DiscTable& t, const StaticScene& s, double horizon,
                        const std::vector<Opt>& opts) {
  const DiscView d = t.view();
  Executor ex(1);
  QueryStats st;
  std::vector<FtcHit> want(d.n), got(d.n);
  FtcNaive naive;
  naive.run(d, s, horizon, want, ex, st);
  std::size_t bad = 0;
  for (const Opt& o : opts) {
    FtcIndex index(o);
    index.run(d, s, horizon, got, ex, st);
    EXPECT_EQ(index.validate(), "");
    for (std::size_t i = 0; i < d.n; ++i)
      if (!(got[i].with == want[i].with) ||
          std::memcmp(&got[i].time, &want[i].time, sizeof(double)) != 0)
        ++bad;
  }
  return bad;
}

std::vector<Opt> options() {
  std::vector<Opt> v;
  for (auto bound : {Opt::Bound::chord, Opt::Bound::frustum})
    for (auto order : {Opt::Order::bottom_up, Opt::Order::leaf_queue, Opt::Order::nearer_first,
                       Opt::Order::best_first})
      for (int slices : {1, 2, 4, 8})
        for (std::size_t leaf : {1, 4, 16, 64}) {
          if (bound == Opt::Bound::frustum && slices != 1) continue;
          Opt o;
          o.bound = bound;
          o.order = order;
          o.slices = slices;
          o.leaf_size = leaf;
          v.push_back(o);
          if (leaf == 16) {  // the overlap phase by the tree search instead of the join
            o.overlap_join = false;
            v.push_back(o);
          }
          o.overlaps_first = false;
          v.push_back(o);
        }
  return v;
}

TEST(FtcIndexSlow, RandomTablesEveryOption) {
  const auto opts = options();
  for (uint64_t seed = 0; seed < 2000; ++seed) {
    Rng rng(seed * 104729 + 3);
    const std::size_t n = rng.below(600);
    const double side = rng.uniform(5, 2000);
    DiscTable t = test::random_shape_table(rng, n, side, seed);
    if (rng.below(4) == 0) build::offset(t, rng.uniform(-1e7, 1e7), rng.uniform(-1e7, 1e7));
    const double horizon = rng.below(8) == 0 ? INFINITY : rng.uniform(0, 60);
    // Four option sets per table (all of them on every 50th).
    std::vector<Opt> some;
    if (seed % 50 == 0)
      some = opts;
    else
      for (int k = 0; k < 4; ++k) some.push_back(opts[rng.below(opts.size())]);
    ASSERT_EQ(differences(t, StaticScene{}, horizon, some), 0u) << "seed " << seed;
  }
}

TEST(FtcIndexSlow, LargeWorlds) {
  const std::vector<Opt> opts = {Opt{}, Opt{.bound = Opt::Bound::frustum}, Opt{.slices = 8}};
  for (int w = 0; w < 3; ++w) {
    DiscTable t = w == 0
                      ? build::uniform(20000, {}, 50, 1, 3, 5)
                      : build::big_crunch(20000, {}, 20, w == 1 ? 1 : 0.1, w == 1 ? 3 : 0.3, 1, 5);
    build::shuffle_ids(t, 9);
    EXPECT_EQ(differences(t, StaticScene{}, 30, opts), 0u) << w;
  }
}

}  // namespace
}  // namespace crowddb
