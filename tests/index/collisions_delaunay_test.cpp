#include "index/collisions_delaunay.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "index/collision_check.hpp"
#include "util/rng.hpp"

namespace crowddb::index {
namespace {

CollisionPairs run_delaunay(const DiscView& d, const StaticScene& scene) {
  CollisionDelaunay del;
  Executor ex(1);
  QueryStats st;
  CollisionPairs got;
  del.run(d, scene, got, ex, st);
  return got;
}

// A big disc (row 0, radius 10) and `outer` discs of radius 1 on a ring at 10.5 that overlap it
// and nothing else. With screens = true, two rings of tiny discs (8 at radius 3, 16 at radius 6)
// sit between: the big disc's Delaunay neighbours are then the first ring only, and the
// diagonals of its triangles reach the second ring only, so no candidate edge joins it to the
// outer ring. Positions are jittered slightly so no four centres are co-circular.
DiscTable screened_ring(bool screens, std::size_t outer = 24) {
  DiscTable t;
  Rng rng(5);
  auto ring = [&](std::size_t count, double radius, double phase, double r) {
    for (std::size_t k = 0; k < count; ++k) {
      const double a = phase +
                       2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(count) +
                       rng.uniform(-0.01, 0.01);
      t.push_back(t.size(), radius * std::cos(a), radius * std::sin(a), 0, 0, r);
    }
  };
  t.push_back(0, 0, 0, 0, 0, 10);
  if (screens) {
    ring(8, 3, 0, 0.1);
    ring(16, 6, 0.1, 0.1);
  }
  ring(outer, 10.5, 0.05, 1);
  return t;
}

TEST(CollisionDelaunay, NeverReportsAFalsePairOnAnyCase) {
  for (uint64_t seed : {1u, 2u}) {
    for (const auto& c : test::collision_cases(seed)) {
      for (const auto& [scene_name, scene] : test::collision_scenes(test::box_of(c.discs))) {
        SCOPED_TRACE(c.name + " / " + scene_name);
        const DiscView d = c.discs.view();
        const CollisionPairs want = test::naive_pairs(d, scene);
        const CollisionPairs got = run_delaunay(d, scene);
        EXPECT_TRUE(std::includes(want.agents.begin(), want.agents.end(), got.agents.begin(),
                                  got.agents.end()));
        EXPECT_TRUE(got.obstacles == want.obstacles);  // the obstacle half is exact
        const auto got_rows = test::rows_of(got), want_rows = test::rows_of(want);
        EXPECT_TRUE(
            std::includes(want_rows.begin(), want_rows.end(), got_rows.begin(), got_rows.end()));
      }
    }
  }
}

TEST(CollisionDelaunay, FindsEveryPairOfAPlainRingAroundOneDisc) {
  // A plain ring around one disc is a Delaunay fan: every spoke is an edge.
  const DiscTable t = screened_ring(false);
  const CollisionPairs want = test::naive_pairs(t.view(), StaticScene());
  ASSERT_EQ(want.agents.size(), 24u);
  EXPECT_EQ(run_delaunay(t.view(), StaticScene()).agents, want.agents);
}

TEST(CollisionDelaunay, MissesABigDiscWhoseNeighboursAreScreenedByOtherCentres) {
  const DiscTable t = screened_ring(true);
  const CollisionPairs want = test::naive_pairs(t.view(), StaticScene());
  const CollisionPairs got = run_delaunay(t.view(), StaticScene());
  // Naive: the big disc overlaps all 8 + 16 screens and all 24 outer discs, nothing else.
  ASSERT_EQ(want.agents.size(), 48u);
  for (auto [i, j] : want.agents) EXPECT_EQ(i, 0u);
  // Delaunay: not one of the outer discs (rows 25..48) is found; they collide with nothing else,
  // so they are missing from the collision set altogether.
  const auto rows = test::rows_of(got);
  for (uint32_t outer = 25; outer < 49; ++outer)
    EXPECT_FALSE(std::binary_search(rows.begin(), rows.end(), outer))
        << "outer disc " << outer << " was found";
  EXPECT_TRUE(std::binary_search(rows.begin(), rows.end(),
                                 0u));  // the big disc itself is (via its screens)
  EXPECT_EQ(test::rows_of(want).size(), 49u);
}

TEST(CollisionDelaunay, DuplicatesAndCollinearCentres) {
  DiscTable t;
  for (int i = 0; i < 10; ++i) t.push_back(i, 1.5 * (i / 3), 0, 0, 0, 1);  // triples on a line
  EXPECT_EQ(run_delaunay(t.view(), StaticScene()).agents,
            test::naive_pairs(t.view(), StaticScene()).agents);
  DiscTable one;
  one.push_back(0, 5, 5, 0, 0, 1);
  one.push_back(1, 5, 5, 0, 0, 1);
  EXPECT_EQ(run_delaunay(one.view(), StaticScene()).agents.size(), 1u);
}

TEST(CollisionDelaunay, NanOrInfiniteRowsGiveTheNaivePairs) {
  CollisionDelaunay path;
  test::expect_naive_on_non_finite_rows(path);
}

}  // namespace
}  // namespace crowddb::index
