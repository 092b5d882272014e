// Neighbour lists after the tick's move, answered from the lists the steering model made before
// it, where those are sure to hold the answer.
//
// After the move the tick asks twice for the k nearest agents within a short range: the
// stalemate stage for each stalled row's blockers (505 of 20,000 rows at airport-20k), and, with
// idle arrivals or goal waits, the commit for each walker on its last goal (someone idle to join).
// A grid over every row for those searches was most of the stalemate stage's cost outside its
// progress watch, and did not get faster on two threads. The model's lists (NearLists: the k'
// nearest strictly within range' of every row, made at the start of the tick) already hold, for
// most rows, everyone who can be that near now: a row's list holds every row strictly closer than
// its bound b (range', or the distance of its k'-th when full), and since then the row has moved
// m_i and nobody more than m, so anyone not listed is now at least b - m_i - m away. Where that
// is at least the range asked (with a relative 1e-9 for the rounding of the distances, as the
// backoff's use of the lists), the answer is the listed rows strictly within range now, ranked as
// every neighbour method ranks them (NearestK: nearest first, ties by id), so it is the neighbour
// query's answer bit for bit. In a jam the k'-th is close and the bound falls short of the range;
// the answer is still the listed rows' k nearest when the k-th of them is now strictly nearer than
// b - m_i - m (with the same relative 1e-9), since nobody unlisted can be that near. The other rows
// (where even that fails) are left to a scan of every row when a few, else to the neighbour query
// (neighbours_after_move).
//
// The commit removes rows (World::remove_rows: swap-removes from the highest row down), so the
// lists' rows are mapped to the rows as they are now (RowRenumbering).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

#include "crowddb/world.hpp"
#include "plan/access_path.hpp"
#include "util/executor.hpp"

namespace crowddb::sim {

// The rows before and after World::remove_rows(removed) on a table of n_before rows.
class RowRenumbering {
 public:
  static constexpr uint32_t kGone = ~0u;
  RowRenumbering() = default;
  RowRenumbering(std::size_t n_before, std::vector<std::size_t> removed);
  std::size_t before() const { return n_before_; }
  std::size_t now() const { return n_now_; }
  // The row now of row `before`; kGone when it was removed.
  uint32_t now_of(uint32_t before) const;
  // The row before of row `now`.
  uint32_t before_of(uint32_t now) const;

 private:
  std::size_t n_before_ = 0, n_now_ = 0;
  // The rows that changed place: (before, now) sorted by before, and (now, before) by now.
  std::vector<std::pair<uint32_t, uint32_t>> by_before_, by_now_;
  std::vector<uint32_t> removed_;  // sorted
};

// What the tick did to the rows between the model's lists and now.
struct TickMove {
  NearLists lists;               // the model's, over the rows before (null: none this tick)
  std::span<const double> x, y;  // the positions the lists were made from, rows before
  double move_max = 0;           // the farthest any row has moved since (not finite: no use)
  RowRenumbering rows;           // the commit's removals
};

// For each of `queries` (rows now), the k nearest other rows of `t` strictly within `range`,
// nearest first, ties by id (NeighbourPath::run's answer), where the lists before the move are
// sure to hold them: out gets one list per query (empty for the others) and `unsure` the
// queries' places (indices into `queries`, ascending) whose answer is left to the caller.
// Everything is unsure when the move cannot be used (no lists, or lists of another table). On
// `ex`'s threads; the same answer on any number.
void lists_after_move(const AgentTable& t, const TickMove& move, std::span<const uint32_t> queries,
                      double range, uint32_t k, NeighbourLists& out, std::vector<uint32_t>& unsure,
                      Executor& ex);

// Up to this many unsure rows are answered by scan_rows; more by the neighbour query, whose grid
// over every row costs about as much as 16 scans.
inline constexpr std::size_t kScanMost = 16;

// The k nearest other rows of `t` strictly within `range` of each of `rows`, nearest first, ties
// by id (NeighbourPath::run's answer), by a scan of every row per query, four rows at a time where
// the CPU has AVX2 (index/neighbour_lanes.hpp): O(n) a query, for the few the lists leave.
void scan_rows(const AgentTable& t, std::span<const uint32_t> rows, double range, uint32_t k,
               NeighbourLists& out, Executor& ex);

// The farthest any row moved from (x0, y0) to (x1, y1) (rows the same), on `ex`'s threads; NaN
// when a position is not finite.
double largest_move(std::span<const double> x0, std::span<const double> y0,
                    std::span<const double> x1, std::span<const double> y1, Executor& ex);

// Who answered how many queries of neighbours_after_move.
struct AnsweredBy {
  std::size_t lists = 0, scan = 0, query = 0;
};

// The k nearest other rows of `t` strictly within `range` of each of `queries`, nearest first,
// ties by id, into `out` (its with_dist2 as set): from the lists before the move where they are
// sure to hold them (lists_after_move), up to kScanMost of the rest by scan_rows, more by `path`;
// without `move`, all by `path`. The same answer as path.run's, whichever way.
AnsweredBy neighbours_after_move(const AgentTable& t, const TickMove* move,
                                 std::span<const uint32_t> queries, double range, uint32_t k,
                                 NeighbourPath& path, NeighbourLists& out, Executor& ex,
                                 QueryStats& stats);

// Puts the lists of the unsure queries (`answers`: one list per entry of `unsure`, in its order)
// into `out` in their places, so that it holds every query's list.
void fill_unsure(NeighbourLists& out, std::span<const uint32_t> unsure,
                 const NeighbourLists& answers);

}  // namespace crowddb::sim
