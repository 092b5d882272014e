// The naive (nested-loop) access paths: the oracles every index is tested against.
#pragma once

#include "plan/access_path.hpp"

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
};

class CollisionNaive final : public CollisionPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out, Executor& ex,
           QueryStats& stats) override;
};

// The obstacle half of a collision query (disc against circles and polygons), shared by every
// collision method: obstacles are few and static, so methods differ only in the disc-disc part.
// Appends (row, obstacle) for rows [begin, end) in row order.
void disc_obstacle_overlaps(const DiscView& discs, const StaticScene& scene, std::size_t begin,
                            std::size_t end, std::vector<std::pair<uint32_t, Collider>>& out);

}  // namespace crowddb
