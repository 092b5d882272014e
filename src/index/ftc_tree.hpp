// First-to-collide index (DESIGN.md §5, thesis §2.1): a kinetic k-d tree with exact best-first
// search. Registered as the "index" access path of the first-to-collide query.
//
// DESIGN (draft; completed with measurements below)
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "plan/access_path.hpp"

namespace crowddb {

struct FtcIndexOptions {
  std::size_t leaf_size = 16;  // most members in a leaf (>= 1)
  // How a node bounds where its members can be at a time t in [0, horizon].
  enum class Bound : uint8_t {
    frustum,  // the thesis's: the t = 0 box, its edges moving at the members' velocity bounds
    chord,    // boxes of the members' positions at K + 1 knot times, linearly interpolated
  };
  Bound bound = Bound::chord;
  int slices = 4;  // chord: K, the number of equal time slices over [0, horizon] (>= 1)
  // Search order. All are exact; they differ in the work done before the answer is certain.
  enum class Order : uint8_t {
    best_first,    // from the root, every child through the queue (the thesis's algorithm)
    nearer_first,  // from the root, descend into the child with the smaller bound, queue the other
    bottom_up,     // from the query's own leaf up: each sibling of the path, nearest first,
                   // searched nearer-first (the query's neighbours fix an early best time)
    leaf_queue,    // from the query's own leaf up: the siblings of the path go into the queue,
                   // which is then searched nearer-first in bound order
  };
  Order order = Order::leaf_queue;
  bool seed_own_leaf = true;  // top-down orders: scan the query's own leaf first
  bool overlaps_first = true;  // first look only for agents overlapping the query now (t = 0)
};

class FtcIndex final : public FtcPath {
 public:
  explicit FtcIndex(FtcIndexOptions options = {});
  ~FtcIndex() override;
  FtcIndex(const FtcIndex&) = delete;
  FtcIndex& operator=(const FtcIndex&) = delete;

  // build() then query_all(); fills stats.build_seconds and stats.query_seconds.
  void run(const DiscView& discs, const StaticScene& scene, double horizon, std::span<FtcHit> out,
           Executor& ex, QueryStats& stats) override;

  // The two halves of run(), for tests, benchmarks and experiments. The index keeps pointers
  // into `discs` and `scene`: they must stay alive and unchanged while it is queried.
  // Throws Error(input) naming the row and column when a disc has a non-finite value.
  void build(const DiscView& discs, const StaticScene& scene, double horizon);
  // out[i] for every disc i; deterministic whatever the executor's thread count.
  void query_all(std::span<FtcHit> out, Executor& ex, QueryStats& stats) const;
  // One disc's answer; adds its counters (rows, pair_tests, nodes_visited, queue pushes and
  // pops) to *stats. Not thread-safe (uses the index's own scratch space).
  FtcHit query(std::size_t row, QueryStats* stats = nullptr) const;

  // Whole-structure check: ranges partition the rows, every member lies inside its node's
  // bounds at every knot time, radii and keys are bounded. "" when all hold, else the first
  // violation.
  std::string validate() const;
  std::size_t node_count() const;  // agent tree
  bool uses_chord_bound() const;   // false: fell back to frustum (horizon 0 or infinite)
  const FtcIndexOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crowddb
