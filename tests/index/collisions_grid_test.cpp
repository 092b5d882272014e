#include "index/collisions_grid.hpp"

#include <gtest/gtest.h>

#include "index/collision_check.hpp"
#include "util/rng.hpp"

namespace crowddb::index {
namespace {

using test::collision_cases;

TEST(CollisionGrid, EqualsNaiveOnRandomAndAdversarialCases) {
  CollisionGrid grid;
  for (uint64_t seed : {1u, 2u, 3u}) test::expect_exact_on_all_cases(grid, seed);
}

TEST(CollisionGrid, CasesContainOverlapsAndTouchingPairs) {
  // The touching-pair generator: exactly touching pairs never overlap; pairs nudged one ulp
  // closer overlap (but for the odd one whose nudge vanishes in the rounding of dx^2 + dy^2).
  const DiscTable t = build::touching(200, build::Box{0, 0, 1000, 1000}, 5);
  const CollisionPairs p = test::naive_pairs(t.view(), StaticScene());
  std::size_t nudged = 0, touching = 0;
  for (auto [i, j] : p.agents) {
    if (i / 2 != j / 2) continue;
    ((i / 2) % 2 ? nudged : touching) += 1;
  }
  EXPECT_EQ(touching, 0u);
  EXPECT_GE(nudged, 95u);
  EXPECT_GT(test::count_naive_pairs(1), 5000u);
}

TEST(DiscGrid, OverlapQueryEqualsBruteForce) {
  for (const auto& c : collision_cases(7)) {
    SCOPED_TRACE(c.name);
    const DiscView d = c.discs.view();
    DiscGrid g;
    g.build(d);
    ASSERT_TRUE(g.usable());
    Rng rng(11);
    for (int q = 0; q < 60 && d.n; ++q) {
      // Queries at table rows (as the backoff asks) and at points nearby, of varied radius.
      const std::size_t i = rng.below(d.n);
      const double qx = d.x[i] + (q % 2 ? rng.uniform(-5, 5) : 0),
                   qy = d.y[i] + (q % 2 ? rng.uniform(-5, 5) : 0);
      const double qr = q % 3 == 0 ? d.radius[i] : rng.uniform(0.01, 60);
      std::vector<uint32_t> got, want;
      g.for_each_overlap(qx, qy, qr, [&](uint32_t row) { got.push_back(row); });
      for (std::size_t j = 0; j < d.n; ++j)
        if (discs_overlap(d.x[j] - qx, d.y[j] - qy, qr + d.radius[j]))
          want.push_back(static_cast<uint32_t>(j));
      std::sort(got.begin(), got.end());
      EXPECT_EQ(got, want);
    }
  }
}

TEST(DiscGrid, UsableOnlyOnceBuiltAndUntilCleared) {
  const DiscTable t = build::uniform(20, build::Box{0, 0, 30, 30}, 1, 1, 2, 5);
  DiscGrid g;
  EXPECT_FALSE(g.usable());  // a default frame is finite; a grid never built is not usable
  g.build(t.view());
  EXPECT_TRUE(g.usable());
  EXPECT_EQ(g.rows(), 20u);
  g.clear();
  EXPECT_FALSE(g.usable());
  EXPECT_EQ(g.rows(), 0u);
}

TEST(CollisionGrid, NonFiniteInputFallsBackInsteadOfHanging) {
  DiscTable t = build::uniform(50, build::Box{0, 0, 20, 20}, 1, 1, 2, 3);
  t.x[7] = INFINITY;
  CollisionGrid grid;
  Executor ex(1);
  QueryStats st;
  CollisionPairs got;
  grid.run(t.view(), StaticScene(), got, ex, st);
  EXPECT_EQ(got.agents, test::naive_pairs(t.view(), StaticScene()).agents);
}

TEST(CollisionGrid, NanOrInfiniteRowsGiveTheNaivePairs) {
  CollisionGrid path;
  test::expect_naive_on_non_finite_rows(path);
}

}  // namespace
}  // namespace crowddb::index
