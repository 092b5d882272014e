// The indexed neighbour query: a uniform grid over disc centres, rebuilt each tick (counting
// sort, O(n)), with a ring-by-ring k-nearest search seeded by the lists of the call before.
//
// Hints (k nearest, asked once per tick: the steering models' query of every row, the stalemate
// stage's of the rows it looks at): each row's list of the last call with the same k is kept and
// offered first, in its old order (a row left out of a call keeps its older list). Between two
// ticks a list hardly changes, so the hints arrive nearly sorted (cheap insertions) and fill the
// list with a tight bound on the k-th distance at once. Any rows would do as hints: the answer is
// the best k of all candidates in whatever order they come, so stale hints (rows reordered,
// removed, or another table) cost time, never exactness, as long as they are distinct rows (a list
// is; rows_permuted refuses anything but a permutation); the scans skip the hinted rows, so no
// candidate is offered twice (test: NeighbourGrid.ListsOfTheCallBeforeChangeNothing).
//
// Search: when the hints are k rows within range and the farthest of them within 1.5 cells (the
// usual case), every disc within that distance is gathered from the cells meeting its bounding
// square, row by row, each row's cells as one run, and nothing beyond; the gathered ones (the
// hints among them) are ranked by (distance, id), each rank counted without branches, and the
// first k are the answer. A row without a full list of the last call (the first call, rows new
// to a subset, a short list) is gathered and ranked the same way within a bound from the density of
// its 3 x 3 block of cells (a disc expected to hold 2 k others), when at least k lie within it.
// Otherwise (too few hints or found within the bound, more than 256 gathered, ids not distinct) the
// hints are offered to the selection first, and with a full list whose k-th distance is within 1.5
// cells its disc's chords of cells are scanned for anything better. Otherwise the 3 x 3 block
// around the query's cell is scanned first, as three runs; when the k-th best so far (or the range)
// is strictly nearer than the block's nearest outside edge, nothing beyond can contribute. Else the
// rings beyond are visited outwards: every disc in ring rho (Chebyshev cell distance rho) is at
// least (rho - 1) * cell away from the query, so once the list holds k entries whose worst distance
// is below that bound, or the bound reaches the range, no further ring can contribute; within a
// ring, a cell whose nearest point is farther than the k-th best so far is skipped. Each run's
// candidates within the bound are picked without a branch, then offered to the same NearestK
// selection as the naive scan, computing the same squared distance from the same doubles, so both
// give identical lists. Cell tests are widened by a relative 1e-9 to stay conservative under
// rounding of the cell coordinates (bucketing decides only which candidates are looked at, never
// the answer).
//
// Cell side: about 6k discs per 3 x 3 block at the table's mean density (k = 0: half the range;
// measured in neighbour_grid.cpp), never larger than the range, and never more than ~4 cells per
// disc (sparse or huge worlds). Query O(k + candidates of the cells visited).
#pragma once

#include <cstdint>
#include <vector>

#include "plan/access_path.hpp"

namespace crowddb::index {

class NeighbourGrid final : public NeighbourPath {
 public:
  void run(const DiscView& discs, std::span<const uint32_t> queries, double range, uint32_t k,
           NeighbourLists& out, Executor& ex, QueryStats& stats) override;
  // Carries the hints of a call for every row along: each row's list moves to the row's new
  // place and names the new rows of its entries. A subset's hints are dropped.
  void rows_permuted(std::span<const uint32_t> order, Executor* ex = nullptr) override;

 private:
  void build(const DiscView& d, double range, uint32_t k, Executor& ex);
  int64_t col(double x) const;
  int64_t row(double y) const;
  bool chord_cells(double px, double py, double bound, double slack, int64_t cy, int64_t& cx0,
                   int64_t& cx1) const;

  double x0_ = 0, y0_ = 0, cell_ = 1, inv_cell_ = 1;  // (a product, not a division, per probe)
  double slack_ = 0;                                  // rounding of cell coordinates (see build)
  int64_t W_ = 1, H_ = 1;
  std::vector<uint32_t> start_;  // W * H + 1 offsets into the cell-ordered arrays
  std::vector<uint32_t> rows_;   // table rows in cell order
  std::vector<double> x_, y_;    // their positions, copied in cell order
  std::vector<uint64_t> id_;
  std::vector<int64_t> cell_of_;  // scratch: cell per row
  std::vector<uint32_t> at_;      // per row: its place in the cell-ordered arrays
  // Per-row lists of k (spatial order): the rows, kept as the next call's hints; their distances
  // are written into the output's slots. Room for every row of the table, however few a subset
  // asks for: 4 k bytes a row (24 MB for the stalemate stage's k = 6 at 10^6 rows).
  std::vector<uint32_t> slot_count_, slot_row_;
  // rows_permuted's: the lists in the new order are written here, then swapped with the slots,
  // and the renaming of rows. Kept from one reorder to the next: memory never touched before cost
  // about 10 µs a page to fault in on the benchmark's host, 0.1 s for the 44 MB of lists and
  // counts at 10^6 rows and k = 10, every reorder. The slots hold as much again, so the reorder's
  // peak is what it was.
  std::vector<uint32_t> spare_count_, spare_row_, new_of_;
  uint32_t hint_k_ = 0;  // k of the last call when its lists are in the slots (hints), else 0
  bool hints_of_subset_ = false;  // the last call asked for a subset of the rows
  // Entries per query of the last call gathered per chunk: the chunks' lists are made with room
  // for a quarter more, the selection for twice as many (at k = 0, cfsm's everyone within the
  // cut-off, growing them by doubling made cfsm's tick at 2 * 10^4 agents 10,900 allocations,
  // now 2,200).
  double list_mean_ = 0;
};

}  // namespace crowddb::index
