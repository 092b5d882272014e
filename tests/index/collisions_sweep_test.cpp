#include "index/collisions_sweep.hpp"

#include <gtest/gtest.h>

#include "index/collision_check.hpp"

namespace crowddb::index {
namespace {

TEST(CollisionSweep, EqualsNaiveOnRandomAndAdversarialCases) {
  CollisionSweep sweep;
  for (uint64_t seed : {1u, 2u, 3u}) test::expect_exact_on_all_cases(sweep, seed);
}

TEST(CollisionSweep, SameXForEveryDiscStillExact) {
  // Every left edge equal: one bucket, nothing ever expires; the slabs alone bound the work.
  DiscTable t;
  for (int i = 0; i < 500; ++i) t.push_back(i, 3, 1.99 * i, 0, 0, 1);
  CollisionSweep sweep;
  Executor ex(1);
  QueryStats st;
  CollisionPairs got;
  sweep.run(t.view(), StaticScene(), got, ex, st);
  EXPECT_EQ(got.agents.size(), 499u);
  EXPECT_EQ(got.agents, test::naive_pairs(t.view(), StaticScene()).agents);
  EXPECT_LT(st.pair_tests, 5000u);  // slabs keep far-apart discs out of each other's way
}

TEST(CollisionSweep, NanOrInfiniteRowsGiveTheNaivePairs) {
  CollisionSweep path;
  test::expect_naive_on_non_finite_rows(path);
}

}  // namespace
}  // namespace crowddb::index
