#include "index/collisions_nn.hpp"

#include <gtest/gtest.h>

#include "index/collision_check.hpp"

namespace crowddb::index {
namespace {

// Brute-force nearest neighbour of row i closer than 2R (ties: smaller row); -1 when none.
int64_t brute_nn(const DiscView& d, std::size_t i) {
  const double rsum = d.radius[i] + d.radius[i];
  double best = rsum * rsum;
  int64_t arg = -1;
  for (std::size_t j = 0; j < d.n; ++j) {
    if (j == i) continue;
    const double dx = d.x[j] - d.x[i], dy = d.y[j] - d.y[i], d2 = dx * dx + dy * dy;
    if (d2 < best) {
      best = d2;
      arg = static_cast<int64_t>(j);
    }
  }
  return arg;
}

TEST(CollisionNn, SetEqualsNaiveAndPairsAreNearestNeighbours) {
  CollisionNn nn;
  Executor ex(1);
  std::size_t cases = 0;
  for (uint64_t seed : {1u, 2u, 3u}) {
    for (const auto& c : test::collision_cases(seed)) {
      if (!c.equal_radii) continue;
      ++cases;
      for (const auto& [scene_name, scene] : test::collision_scenes(test::box_of(c.discs))) {
        SCOPED_TRACE(c.name + " / " + scene_name);
        const DiscView d = c.discs.view();
        const CollisionPairs want = test::naive_pairs(d, scene);
        CollisionPairs got;
        QueryStats st;
        nn.run(d, scene, got, ex, st);
        EXPECT_EQ(test::rows_of(got), test::rows_of(want));  // the collision set: exact
        EXPECT_TRUE(got.obstacles == want.obstacles);
        EXPECT_EQ(got.agents.empty(), want.agents.empty());
        // Exactly the pairs (i, NN(i)) for every i with a neighbour closer than 2R.
        std::vector<std::pair<uint32_t, uint32_t>> expect;
        for (std::size_t i = 0; i < d.n; ++i)
          if (const int64_t j = brute_nn(d, i); j >= 0)
            expect.push_back(index::ordered(static_cast<uint32_t>(i), static_cast<uint32_t>(j)));
        finish_pairs(expect);
        EXPECT_EQ(got.agents, expect);
        EXPECT_TRUE(std::includes(want.agents.begin(), want.agents.end(), got.agents.begin(),
                                  got.agents.end()));
      }
    }
  }
  EXPECT_GE(cases, 18u);
}

// Tables large enough to be split between threads (each thread takes the cells of one range of
// entries and the nearest neighbours are merged): the pairs are those of one thread and of the
// brute force, ties (a lattice at exactly equal distances) included.
TEST(CollisionNn, ThreadsSplittingTheCellsChangeNothing) {
  for (int shape = 0; shape < 3; ++shape) {
    DiscTable t;
    if (shape == 2) {  // a lattice: every disc overlaps its four neighbours at the same distance
      for (int i = 0; i < 80; ++i)
        for (int j = 0; j < 80; ++j)
          t.push_back(static_cast<uint64_t>(i * 80 + j), i * 1.5, j * 1.5, 0, 0, 1);
    } else {
      t = build::uniform(6000, {0, 0, shape == 0 ? 120.0 : 60.0, 120}, 1, 1, 1, 17 + shape);
    }
    const DiscView d = t.view();
    std::vector<std::pair<uint32_t, uint32_t>> expect;
    for (std::size_t i = 0; i < d.n; ++i)
      if (const int64_t j = brute_nn(d, i); j >= 0)
        expect.push_back(index::ordered(static_cast<uint32_t>(i), static_cast<uint32_t>(j)));
    finish_pairs(expect);
    ASSERT_GT(expect.size(), 100u) << shape;
    for (int threads : {1, 2, 3}) {
      CollisionNn nn;
      Executor ex(threads);
      QueryStats st;
      CollisionPairs got;
      nn.run(d, StaticScene(), got, ex, st);
      EXPECT_EQ(got.agents, expect) << "shape " << shape << ", threads " << threads;
      // With obstacles: the disc-obstacle half runs in chunks of rows on every thread.
      for (const auto& [scene_name, scene] : test::collision_scenes(test::box_of(t))) {
        const CollisionPairs want = test::naive_pairs(d, scene);
        if (!scene.empty()) {
          ASSERT_FALSE(want.obstacles.empty()) << scene_name;
        }
        nn.run(d, scene, got, ex, st);
        EXPECT_TRUE(got.obstacles == want.obstacles)
            << "shape " << shape << ", " << scene_name << ", threads " << threads;
        EXPECT_EQ(got.agents, expect);
      }
    }
  }
}

TEST(CollisionNn, ReportsNearestNeighbourPairsNotEveryPair) {
  // Three discs in a row: 0-1 at 1.0, 1-2 at 0.9, 0-2 at 1.9 all overlap (R = 1), but nobody's
  // nearest neighbour pairs 0 with 2. The set {0, 1, 2} is still exact.
  DiscTable t;
  t.push_back(0, 0, 0, 0, 0, 1);
  t.push_back(1, 1.0, 0, 0, 0, 1);
  t.push_back(2, 1.9, 0, 0, 0, 1);
  using Pairs = std::vector<std::pair<uint32_t, uint32_t>>;
  CollisionNn nn;
  Executor ex(1);
  QueryStats st;
  CollisionPairs got;
  nn.run(t.view(), StaticScene(), got, ex, st);
  EXPECT_EQ(got.agents, (Pairs{{0, 1}, {1, 2}}));
  EXPECT_EQ(test::naive_pairs(t.view(), StaticScene()).agents, (Pairs{{0, 1}, {0, 2}, {1, 2}}));
  EXPECT_EQ(test::rows_of(got), (std::vector<uint32_t>{0, 1, 2}));
  // Ties go to the smaller row: 1 and 2 equally near to 0.
  t.x[1] = 1.5;
  t.x[2] = -1.5;
  nn.run(t.view(), StaticScene(), got, ex, st);
  EXPECT_EQ(got.agents, (Pairs{{0, 1}, {0, 2}}));
  t.push_back(3, 0, 1.5, 0, 0, 1);  // a third at the same distance: 0 still names row 1
  nn.run(t.view(), StaticScene(), got, ex, st);
  EXPECT_EQ(got.agents, (Pairs{{0, 1}, {0, 2}, {0, 3}}));
}

TEST(CollisionNn, UnequalRadiiAreAUsageError) {
  const DiscTable t = build::uniform(10, build::Box{}, 1, 1, 2, 1);
  CollisionNn nn;
  Executor ex(1);
  QueryStats st;
  CollisionPairs got;
  try {
    nn.run(t.view(), StaticScene(), got, ex, st);
    FAIL() << "expected a usage error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), Error::Kind::usage);
  }
}

// The grid nn lends to the backoff (disc_grid()) is that of the discs of its last run, or none:
// a run that throws or has no rows must not leave the previous run's grid out on loan.
TEST(CollisionNn, LendsAGridOnlyForTheDiscsOfItsLastRun) {
  const DiscTable equal = build::uniform(40, build::Box{0, 0, 50, 50}, 1, 1, 1, 4);
  const DiscTable mixed = build::uniform(10, build::Box{}, 1, 1, 2, 1);
  CollisionNn nn;
  Executor ex(1);
  QueryStats st;
  CollisionPairs got;
  EXPECT_EQ(nn.disc_grid(), nullptr);  // never run
  nn.run(equal.view(), StaticScene(), got, ex, st);
  ASSERT_NE(nn.disc_grid(), nullptr);
  EXPECT_EQ(nn.disc_grid()->rows(), 40u);
  EXPECT_THROW(nn.run(mixed.view(), StaticScene(), got, ex, st), Error);
  EXPECT_EQ(nn.disc_grid(), nullptr);
  nn.run(equal.view(), StaticScene(), got, ex, st);
  ASSERT_NE(nn.disc_grid(), nullptr);
  nn.run(DiscView{}, StaticScene(), got, ex, st);
  EXPECT_EQ(nn.disc_grid(), nullptr);
}

TEST(CollisionNn, NanOrInfiniteRowsGiveTheNaivePairs) {
  CollisionNn path;
  test::expect_naive_on_non_finite_rows(path, true);
}

}  // namespace
}  // namespace crowddb::index
