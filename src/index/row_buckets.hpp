// Rows bucketed into the cells of a uniform grid: the rows' bounding box, then a counting sort.
// For the grids rebuilt every tick (index/neighbour_grid, steer/passing) and the obstacle
// features' grid, built once per scene (index/feature_grid: its rows are registrations).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace crowddb {
class Executor;
}

namespace crowddb::index {

struct Box {
  double xmin, ymin, xmax, ymax;  // INFINITY, INFINITY, -INFINITY, -INFINITY when empty
};

// The smallest box holding every (x[i], y[i]), in chunks on every thread (min and max are exact,
// so the answer does not depend on the thread count).
Box bounding_box(std::span<const double> x, std::span<const double> y, Executor& ex);

// The cell of a coordinate u measured from the grid's lowest edge, clamped to [0, n), by a
// product with the inverse cell (1 / cell, finite) rather than a division: a per-row look-up's
// cost. Where u / cell lies within rounding of a cell boundary it may give the cell beside the
// division's, so a caller needs a margin of a cell, or more than that rounding, wherever the
// answer depends on the cell (feature_grid's far test, obstacle_index's registrations, the
// neighbour grid's and the passing look-ahead's slack). Monotone in u. Below 1 and NaN give cell 0
// (truncation is the floor from 1 on).
inline int64_t cell_by_product(double u, double inv_cell, int64_t n) {
  const double c = u * inv_cell;
  if (!(c >= 1)) return 0;
  if (c >= static_cast<double>(n - 1)) return n - 1;
  return static_cast<int64_t>(c);
}

// A counting sort of rows into `cells` cells, cell_of[i] being row i's (in [0, cells)): rows
// lists the rows cell by cell, row order within a cell, and cell c's rows are
// rows[start[c] .. start[c + 1]). The rows are placed backwards from each cell's end, which
// leaves `start` holding the beginnings (no copy of the offsets to place with: a grid may have
// several cells per row). One pass (a few instructions per row), so the layout is that of one
// thread.
void bucket_rows(std::span<const int64_t> cell_of, std::size_t cells, std::vector<uint32_t>& start,
                 std::vector<uint32_t>& rows);

}  // namespace crowddb::index
