// The indexed neighbour query: a uniform grid over disc centres, rebuilt each tick (counting
// sort, O(n)), with a ring-by-ring k-nearest search.
//
// Search: the 3 x 3 block around the query's cell is scanned first, as three runs of adjacent
// cells; when the k-th best so far (or the range) is strictly nearer than the block's nearest
// outside edge, nothing beyond can contribute. Otherwise the rings beyond are visited outwards:
// every disc in ring
// rho (Chebyshev cell distance rho) is at least (rho - 1) * cell away from the query, so once the
// list holds k entries whose worst distance is below that bound, or the bound reaches the range,
// no further ring can contribute; within a ring, a cell whose nearest point is farther than the
// k-th best so far is skipped. Candidates are offered to the same NearestK selection as the
// naive scan, computing the same squared distance from the same doubles, so both give identical
// lists. The bound is lowered by a relative 1e-9 to stay conservative under rounding of the cell
// coordinates (bucketing decides only which candidates are looked at, never the answer).
//
// Cell side: about 2k discs per 3 x 3 block at the table's mean density (k = 0: half the range),
// never larger than the range, and never more than ~4 cells per disc (sparse or huge worlds).
// Query O(k + candidates of the rings visited).
#pragma once

#include <cstdint>
#include <vector>

#include "plan/access_path.hpp"

namespace crowddb::index {

class NeighbourGrid final : public NeighbourPath {
 public:
  void run(const DiscView& discs, std::span<const uint32_t> queries, double range, uint32_t k,
           NeighbourLists& out, Executor& ex, QueryStats& stats) override;

 private:
  void build(const DiscView& d, double range, uint32_t k, Executor& ex);
  int64_t col(double x) const;
  int64_t row(double y) const;

  double x0_ = 0, y0_ = 0, cell_ = 1;
  int64_t W_ = 1, H_ = 1;
  std::vector<uint32_t> start_;  // W * H + 1 offsets into the cell-ordered arrays
  std::vector<uint32_t> rows_;   // table rows in cell order
  std::vector<double> x_, y_;    // their positions, copied in cell order
  std::vector<uint64_t> id_;
  std::vector<int64_t> cell_of_;                 // scratch: cell per row
  std::vector<uint32_t> fill_;                   // scratch: next free place per cell
  std::vector<uint32_t> slot_count_, slot_row_;  // scratch: per-row lists of k (spatial order)
  std::vector<double> slot_d2_;
};

}  // namespace crowddb::index
