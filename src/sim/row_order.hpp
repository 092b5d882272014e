// The order of the agents' rows. The tick's queries and the steering read the columns of each
// row's neighbours; with rows in insertion order those reads land anywhere in the columns, and
// from 10^5 agents on, where the columns outgrow the caches, each is a miss. So the tick puts the
// rows in the order of a space-filling curve now and then (Simulation, "reorder rows"): agents
// move a fraction of a metre per tick, and neighbours in space stay near each other in memory
// for seconds. Nothing but the row order changes: every stage breaks ties by agent id, not by
// row (tests/sim/row_order_test.cpp runs scenarios with and without it and compares every
// agent's trajectory).
#pragma once

#include <cstdint>
#include <vector>

#include "crowddb/world.hpp"
#include "index/collision_common.hpp"  // RadixScratch

namespace crowddb {
class Executor;
}

namespace crowddb::sim {

// [s] How often the rows are put in curve order (at least every tick).
inline constexpr double kReorderInterval = 2.0;
// Below this many rows the columns stay in cache anyway: no reordering.
inline constexpr std::size_t kReorderMinRows = 4096;

// The rows in Morton (Z-curve) order of their positions in cells of 1 m from the table's lowest
// corner, ties by agent id: order[new row] = old row, for World::permute_rows. A radix sort (a
// few passes over the rows) where the keys fit 32 bits (a world within 65 km), else a comparison
// sort, O(n log n); with `ex`, on its threads (the same order).
std::vector<uint32_t> curve_order(const AgentTable& t, Executor* ex = nullptr);

// What curve_order works in, for a caller that orders the rows again and again (the tick's
// reorder): memory never touched before cost about 10 µs a page to fault in on the benchmark's
// host, some 70 ms of every reorder at 10^6 rows for these buffers alone.
struct CurveScratch {
  std::vector<uint64_t> keys, words;
  index::RadixScratch radix;
};
// The same order, into `order`, working in `scratch`.
void curve_order(const AgentTable& t, Executor* ex, CurveScratch& scratch,
                 std::vector<uint32_t>& order);

// The naive twin (tests): the same order from one comparison sort on the calling thread.
std::vector<uint32_t> curve_order_naive(const AgentTable& t);

}  // namespace crowddb::sim
