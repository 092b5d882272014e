// Comparing a collision method with the naive oracle over the shared cases.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>

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
