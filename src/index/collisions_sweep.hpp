// Collision sets by a plane sweep over bounding boxes (thesis §3.3.1, DESIGN.md §3.2), for any
// radii. Boxes enter in order of their left edge (a radix sort on a 24-bit quantised key), and
// the active set, the boxes the sweep line still crosses, is bucketed into horizontal slabs of
// height ~ twice the mean radius: a box joins every slab its y-extent touches, and a new box
// meets only the active boxes of its own slabs. A pair is examined once, in the lowest slab the
// two boxes share, and decided by the oracle's discs_overlap (box pairs whose discs do not meet
// are the thesis's false positives).
//
// Correctness of the order: the quantised order may swap boxes whose left edges lie within one
// quantum, so an active box expires only when its right edge lies a full quantum left of the
// current box's bucket; every box still to come starts at or after that bucket.
//
// Cost: O(n) to sort, then per box the active boxes of its slabs: O(n + k + s), k the
// box-intersecting pairs and s the active boxes of a shared slab that miss in y (bounded by
// slab height / smallest diameter per slab when discs do not overlap). A giant disc joins
// many slabs (its height / slab height), which is what it costs and no more.
#pragma once

#include <vector>

#include "index/collision_common.hpp"
#include "index/obstacle_index.hpp"
#include "plan/access_path.hpp"

namespace crowddb::index {

class CollisionSweep final : public CollisionPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out, Executor& ex,
           QueryStats& stats) override;

 private:
  struct Disc {
    double x, y, r;
    uint32_t row;
  };
  // An active box carries its disc, so the filters and the exact test read nothing else.
  struct Active {
    double xhi;    // right edge, frame coordinates, grown by the rounding margins
    double reach;  // Frame::reach(r)
    double x, y, r;
    uint32_t row;
    uint32_t slab0;  // its lowest slab
  };
  std::vector<uint64_t> order_;
  RadixScratch radix_;
  std::vector<Disc> packed_;
  std::vector<std::vector<Active>> slabs_;
  ObstacleIndex obstacles_;
};

}  // namespace crowddb::index
