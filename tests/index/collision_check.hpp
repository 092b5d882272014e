// Comparing a collision method with the naive oracle over the shared cases.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "index/collision_cases.hpp"
#include "query/naive_paths.hpp"

namespace crowddb::test {

inline build::Box box_of(const DiscTable& t) {
  if (t.size() == 0) return build::Box{0, 0, 10, 10};
  build::Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
  for (std::size_t i = 0; i < t.size(); ++i) {
    b.xmin = std::min(b.xmin, t.x[i]);
    b.ymin = std::min(b.ymin, t.y[i]);
    b.xmax = std::max(b.xmax, t.x[i]);
    b.ymax = std::max(b.ymax, t.y[i]);
  }
  if (b.xmax - b.xmin < 10) b.xmax = b.xmin + 10;
  if (b.ymax - b.ymin < 10) b.ymax = b.ymin + 10;
  return b;
}

inline CollisionPairs naive_pairs(const DiscView& d, const StaticScene& scene) {
  Executor ex(1);
  QueryStats st;
  CollisionPairs p;
  CollisionNaive().run(d, scene, p, ex, st);
  return p;
}

// Rows with a NaN or infinite coordinate (or radius, unless the method takes equal radii only):
// the method must give the naive answer (such discs overlap nothing), not hang, crash or sort
// NaNs. Tables never hold such rows; a bad caller of the query API might. `equal_radii_only`
// (nn): the set of colliding rows is compared, as that method returns one pair per disc.
inline void expect_naive_on_non_finite_rows(CollisionPath& path, bool equal_radii_only = false) {
  Executor ex(1);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int k = 0; k < (equal_radii_only ? 4 : 5); ++k) {
    DiscTable t = build::uniform(60, build::Box{0, 0, 20, 20}, 1, 1, 2, 3 + k);
    if (equal_radii_only)
      for (std::size_t i = 0; i < t.size(); ++i) t.radius[i] = 1;
    switch (k) {
      case 0:
        t.x[7] = nan;
        break;
      case 1:
        t.y[0] = nan, t.x[30] = nan;
        break;
      case 2:
        t.y[12] = -INFINITY;
        break;
      case 3:
        for (std::size_t i = 0; i < t.size(); ++i) t.x[i] = nan;
        break;
      default:
        t.radius[5] = nan;
        break;
    }
    QueryStats st;
    CollisionPairs got;
    path.run(t.view(), StaticScene(), got, ex, st);
    const CollisionPairs want = naive_pairs(t.view(), StaticScene());
    if (equal_radii_only)
      EXPECT_EQ(rows_of(got), rows_of(want)) << "case " << k;
    else
      EXPECT_EQ(got.agents, want.agents) << "case " << k;
  }
}

// Runs `path` on every case and scene and expects exactly the naive pairs (agents and obstacles).
// The same path object is reused across runs, as the tick reuses it.
inline void expect_exact_on_all_cases(CollisionPath& path, uint64_t seed,
                                      bool equal_radii_only = false) {
  Executor ex(1);
  for (const CollisionCase& c : collision_cases(seed)) {
    if (equal_radii_only && !c.equal_radii) continue;
    for (const auto& [scene_name, scene] : collision_scenes(box_of(c.discs))) {
      SCOPED_TRACE(c.name + " / " + scene_name);
      const DiscView d = c.discs.view();
      const CollisionPairs want = naive_pairs(d, scene);
      CollisionPairs got;
      QueryStats st;
      path.run(d, scene, got, ex, st);
      EXPECT_EQ(got.agents, want.agents);
      EXPECT_TRUE(got.obstacles == want.obstacles)
          << got.obstacles.size() << " vs " << want.obstacles.size();
    }
  }
}

// Every case must exercise something: guard against a generator that silently stops
// producing collisions (a test that cannot fail).
inline std::size_t count_naive_pairs(uint64_t seed) {
  std::size_t total = 0;
  for (const CollisionCase& c : collision_cases(seed))
    total += naive_pairs(c.discs.view(), StaticScene()).agents.size();
  return total;
}

}  // namespace crowddb::test
