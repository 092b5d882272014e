// A polygon with many edges, asked about points and discs: its edges bucketed into a uniform grid
// over its box, so that point_in_polygon and the boundary distance (world/geometry.hpp) look at
// the edges near the question instead of all of them. A walkable area's blocked pieces (the
// bounds less a curved hall drawn with 20,000 vertices) were tested edge by edge for every agent
// placed and checked: 10^5 agents took 28 s to load.
//
// Exact: the same per-edge expressions as geometry.hpp's loops, on the same operands, over a
// superset of the edges that can matter (each collected once), so the same answers:
//   inside()   the even-odd parity over the edges that cross the point's horizontal line to its
//              right: every such edge's box holds the point's y and reaches right of it, so it is
//              registered in the point's row of cells at or right of its cell (from one cell to
//              the left: the crossing's rounding);
//   dist2()    the smallest squared distance to an edge, equal to the loop's whenever that is at
//              most reach^2 (the nearest edge's box then meets the square of side 2 reach around
//              the point, grown by a cell for rounding); larger otherwise, which callers comparing
//              with reach^2 cannot tell apart.
// The grid is world/box_grid.hpp's over the edges' boxes: edges spanning many cells go to a list
// every question scans. The loops stay as the oracle (tests/world/ring_grid_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "world/box_grid.hpp"
#include "world/geometry.hpp"

namespace crowddb {

class RingGrid {
 public:
  // Rings with fewer edges are cheaper to loop over than to bucket.
  static constexpr std::size_t kMinEdges = 64;

  explicit RingGrid(std::span<const Vec2> ring) : n_(ring.size()) {
    std::vector<BoxBounds> boxes(n_);
    for (std::size_t s = 0; s < n_; ++s) {
      const Vec2 &p = ring[s], &q = ring[(s + 1) % n_];
      boxes[s] = {std::min(p.x, q.x), std::min(p.y, q.y), std::max(p.x, q.x), std::max(p.y, q.y)};
    }
    grid_ = BoxGrid(boxes, kMaxSide);
  }

  // point_in_polygon(ring, px, py), `ring` the one the grid was built over (another ring, one
  // of another size, say, gets the loop itself).
  bool inside(std::span<const Vec2> ring, double px, double py) const {
    if (ring.size() != n_) return point_in_polygon(ring, px, py);
    thread_local std::vector<uint32_t> near;
    if (!(std::isfinite(px) && std::isfinite(py))) {
      grid_.all(near);
    } else {
      const int64_t cy = grid_.cell_y(py);
      grid_.collect(grid_.cell_x(px) - 1, grid_.nx() - 1, cy, cy, near);
    }
    bool in = false;
    for (const uint32_t s : near)  // segment s joins ring[s] and ring[s + 1]; the loop's pairing
      if (crosses_right_of(ring[(s + 1) % n_], ring[s], px, py)) in = !in;
    return in;
  }

  // dist2_to_boundary(ring, px, py, closest) where that is <= reach^2 (reach >= 0), the same
  // closest point too (the first nearest edge in ring order: `near` is sorted); otherwise a value
  // above reach^2.
  double dist2(std::span<const Vec2> ring, double px, double py, double reach,
               Vec2* closest = nullptr) const {
    if (ring.size() != n_) return dist2_to_boundary(ring, px, py, closest);
    thread_local std::vector<uint32_t> near;
    edges_meeting(px - reach, py - reach, px + reach, py + reach, near);
    double best = INFINITY;
    for (const uint32_t s : near) offer_segment(ring[s], ring[(s + 1) % n_], px, py, best, closest);
    return best;
  }

  // The edges whose box may meet [x0, x1] x [y0, y1] (grown by a cell against rounding), sorted,
  // each once; every edge where there is no grid, a bound is not finite or the window has more
  // cells than there are edges. Returns the cells read. For questions the grid does not answer
  // itself (first-to-collide's ray against the edges' capsules).
  std::size_t edges_meeting(double x0, double y0, double x1, double y1,
                            std::vector<uint32_t>& out) const {
    if (!(std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1))) {
      grid_.all(out);
      return 0;
    }
    return grid_.collect(grid_.cell_x(x0) - 1, grid_.cell_x(x1) + 1, grid_.cell_y(y0) - 1,
                         grid_.cell_y(y1) + 1, out);
  }
  double cell() const { return grid_.cell(); }
  int64_t cells_across() const { return grid_.nx() + grid_.ny(); }
  std::size_t edges() const { return n_; }

  // Edges every question scans (long ones, or all where there is no grid): for tests.
  std::size_t scanned_edges() const { return grid_.scanned(); }

  // disc_overlaps_polygon(ring, px, py, r).
  bool disc_overlaps(std::span<const Vec2> ring, double px, double py, double r) const {
    return inside(ring, px, py) || dist2(ring, px, py, std::abs(r)) < r * r;
  }

 private:
  static constexpr int64_t kMaxSide = 1024;  // cells per axis, at most

  std::size_t n_ = 0;
  BoxGrid grid_;  // the edges' boxes: edge s joins ring[s] and ring[s + 1]
};

}  // namespace crowddb
