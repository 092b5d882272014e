// Collision sets for equal radii by a nearest-neighbour query per disc (thesis §3.2, DESIGN.md
// §3.2): disc i collides iff its nearest neighbour's centre is closer than 2R.
//
// What it returns: for each disc i whose nearest neighbour j (smallest distance, ties to the
// smaller row) lies closer than 2R, the pair (min(i, j), max(i, j)); sorted, duplicates removed;
// plus the exact obstacle hits. The rows covered by these pairs are exactly the naive collision
// set (a disc that overlaps anyone overlaps its nearest neighbour), and there is a pair iff the
// naive answer has one. But it is NOT every overlapping pair: a disc overlapping three others
// reports one. Consumers that need every pair (overlap counts, the backoff's tolerance of pairs
// that already overlapped at the start of the tick) must not use it; the planner knows this
// (CollisionQueryShape::need_all_pairs).
//
// The query is bounded: only neighbours closer than 2R matter, and they lie in the 3 x 3 block of
// cells of side >= 2R around the disc, so a single-level CellIndex (DiscGrid's one level for equal
// radii, lent to the backoff's probes) answers it exactly in O(n + candidates), each candidate
// pair examined once for both discs. Distances are compared as
// the oracle computes them (dx*dx + dy*dy against (R + R)^2), so "closer than 2R" agrees with
// discs_overlap bit for bit.
#pragma once

#include "index/cell_index.hpp"
#include "index/collisions_grid.hpp"
#include "index/obstacle_index.hpp"
#include "plan/access_path.hpp"

namespace crowddb::index {

class CollisionNn final : public CollisionPath {
 public:
  // Throws Error(usage) when the radii are not all equal.
  void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out, Executor& ex,
           QueryStats& stats) override;
  const DiscGrid* disc_grid() const override { return grid_.usable() ? &grid_ : nullptr; }

 private:
  DiscGrid grid_;
  ObstacleIndex obstacles_;
  // Per part of the entries (one per thread): per entry, the squared distance to its nearest
  // neighbour so far, and that neighbour's row.
  std::vector<std::vector<double>> best_;
  std::vector<std::vector<uint32_t>> best_row_;
};

}  // namespace crowddb::index
