// The naive (nested-loop) access paths: the oracles every index is tested against.
#pragma once

#include "plan/access_path.hpp"
#include "world/geometry.hpp"

namespace crowddb {

class FtcNaive final : public FtcPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, double horizon, std::span<FtcHit> out,
           Executor& ex, QueryStats& stats) override;
};

class FieldNaive final : public FieldPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, const PotentialSpec& spec,
           FieldColumns& out, Executor& ex, QueryStats& stats) override;
  void probe(std::span<const Vec2> points, const DiscView& sources, const StaticScene& scene,
             const PotentialSpec& spec, FieldColumns& out, Executor& ex,
             QueryStats& stats) override;
};

class CollisionNaive final : public CollisionPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out, Executor& ex,
           QueryStats& stats) override;
};

// The exact disc-against-obstacle tests of a collision query. Every method calls these for
// every (disc, obstacle) candidate it keeps, so that all methods agree bit for bit.
inline bool disc_hits_circle(const CircleObstacle& c, double x, double y, double r) {
  return discs_overlap(c.x - x, c.y - y, r + c.radius);
}
// The bounding-box rejection is part of the definition (as the naive loop applies it), so an
// index that pre-filters more loosely must still call this, not disc_overlaps_polygon directly.
inline bool disc_hits_polygon(const PolygonObstacle& p, const StaticScene::Box& b, double x,
                              double y, double r) {
  if (x + r <= b.xmin || x - r >= b.xmax || y + r <= b.ymin || y - r >= b.ymax) return false;
  return disc_overlaps_polygon(p.vertices, x, y, r);
}

// The obstacle half of a collision query (disc against circles and polygons), shared by every
// collision method: obstacles are few and static, so methods differ only in the disc-disc part.
// Appends (row, obstacle) for rows [begin, end) in row order.
void disc_obstacle_overlaps(const DiscView& discs, const StaticScene& scene, std::size_t begin,
                            std::size_t end, std::vector<std::pair<uint32_t, Collider>>& out);

}  // namespace crowddb
