// The exact polygon tests of world/geometry.hpp on a scene's polygon p, through its edge grid
// (StaticScene::ring_grid) where it has many edges, else the loops: the same answers bit for bit
// (world/ring_grid.hpp's argument). For the tick's per-agent questions about obstacles (the
// collision query's obstacle half, the backoff's depths, the thesis model's contact points, the
// sources' spot test); the loops stay as the oracles (query/naive_paths.hpp, tests).
#pragma once

#include <cstddef>

#include "crowddb/query.hpp"
#include "query/naive_paths.hpp"  // disc_misses_box
#include "world/geometry.hpp"
#include "world/ring_grid.hpp"

namespace crowddb {

// point_in_polygon.
inline bool scene_polygon_holds(const StaticScene& scene, std::size_t p, double x, double y) {
  const auto& ring = scene.polygons()[p].vertices;
  const RingGrid* g = scene.ring_grid(p);
  return g ? g->inside(ring, x, y) : point_in_polygon(ring, x, y);
}

// dist2_to_boundary (and its closest point), whatever the distance: through the grid when it is
// within `reach` (the caller's expectation; any value >= 0 is exact), else the loop.
inline double scene_polygon_dist2(const StaticScene& scene, std::size_t p, double x, double y,
                                  double reach, Vec2* closest = nullptr) {
  const auto& ring = scene.polygons()[p].vertices;
  const RingGrid* g = scene.ring_grid(p);
  if (g && reach >= 0) {
    const double d2 = g->dist2(ring, x, y, reach, closest);
    if (d2 <= reach * reach) return d2;
  }
  return dist2_to_boundary(ring, x, y, closest);
}

// disc_hits_polygon (query/naive_paths.hpp): the box rejection, then disc_overlaps_polygon.
inline bool scene_disc_hits_polygon(const StaticScene& scene, std::size_t p, double x, double y,
                                    double r) {
  if (disc_misses_box(scene.polygon_boxes()[p], x, y, r)) return false;
  const auto& ring = scene.polygons()[p].vertices;
  const RingGrid* g = scene.ring_grid(p);
  return g ? g->disc_overlaps(ring, x, y, r) : disc_overlaps_polygon(ring, x, y, r);
}

}  // namespace crowddb
