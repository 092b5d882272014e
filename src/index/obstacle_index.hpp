// The obstacle half of the indexed collision queries: static circles and polygons (walls
// included) bucketed into a coarse uniform grid over the discs' frame, so each disc is tested
// only against the obstacles registered in its own cell instead of all of them.
//
// Invariant: an obstacle is registered in every cell that its bounding box, grown by the
// largest disc reach (Frame::reach) and cell 2^-30, touches; a disc that overlaps the obstacle has
// its centre inside that grown box, at least cell 2^-30 from its edge, so its cell lists the
// obstacle, also when the query bins it by a product with 1 / cell, whose rounding may put it in
// the cell beside (obstacle_index.cpp). Candidates are then decided by the
// oracle's own tests (disc_hits_circle / disc_hits_polygon), and each cell lists obstacles in
// the oracle's order (circles by row, then polygons by row): the output is identical to
// disc_obstacle_overlaps. Build O(m + registrations), query O(1 + candidates) per disc.
#pragma once

#include <cstdint>
#include <utility>
#include <vector>

#include "index/collision_common.hpp"
#include "util/executor.hpp"

namespace crowddb::index {

class ObstacleIndex {
 public:
  void build(const StaticScene& scene, const Frame& frame);
  // Appends (row, obstacle) for rows [begin, end), in the order disc_obstacle_overlaps uses.
  void overlaps(const DiscView& d, std::size_t begin, std::size_t end,
                std::vector<std::pair<uint32_t, Collider>>& out, uint64_t& tests) const;
  // The same for every row, in chunks on `ex`'s threads, appended in row order (the same output
  // on any thread count).
  void overlaps(const DiscView& d, std::vector<std::pair<uint32_t, Collider>>& out, uint64_t& tests,
                Executor& ex) const;

 private:
  const StaticScene* scene_ = nullptr;
  Frame frame_;
  double cell_ = 1, inv_cell_ = 1;
  int64_t side_ = 0;             // cells per axis (0: no obstacles)
  std::vector<uint32_t> start_;  // CSR offsets per cell, side_^2 + 1
  std::vector<uint32_t> ids_;    // circle c as c, polygon p as circles + p
};

// The whole obstacle half in one call, with a private index (for methods that need nothing more).
void obstacle_overlaps(const DiscView& d, const StaticScene& scene, const Frame& frame,
                       std::vector<std::pair<uint32_t, Collider>>& out, QueryStats& stats);

}  // namespace crowddb::index
