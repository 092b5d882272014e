// A polygon with many edges, asked about points and discs: its edges bucketed into a uniform grid
// over its box, so that point_in_polygon and the boundary distance (world/geometry.hpp) look at
// the edges near the question instead of all of them. A walkable area's blocked pieces (the
// bounds less a curved hall drawn with 20,000 vertices) were tested edge by edge for every agent
// placed and checked: 10^5 agents took 28 s to load.
//
// Exact: the same per-edge expressions as geometry.hpp's loops, on the same operands, over a
// superset of the edges that can matter (each visited once), so the same answers:
//   inside()   the even-odd parity over the edges that cross the point's horizontal line to its
//              right: every edge crossing that line is listed in the point's horizontal strip
//              (build_strips() below); where that strip lists many edges, every such edge's box
//              holds the point's y and reaches right of it, so it is registered in the point's
//              row of cells at or right of its cell (from one cell to the left: the crossing's
//              rounding). A parity does not depend on the order;
//   dist2()    the smallest squared distance to an edge, equal to the loop's whenever that is at
//              most reach^2 (the nearest edge's box then meets the square of side 2 reach around
//              the point, grown by a cell for rounding); larger otherwise, which callers comparing
//              with reach^2 cannot tell apart. The first nearest edge in ring order gives the
//              closest point, as in the loop: the least (distance, edge) pair.
// The grid is world/box_grid.hpp's over the edges' boxes: edges spanning many cells go to a list
// every question scans. The loops stay as the oracle (tests/world/ring_grid_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "util/bucket_lists.hpp"
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
    build_strips(ring);
  }

  // point_in_polygon(ring, px, py), `ring` the one the grid was built over (another ring, one
  // of another size, say, gets the loop itself).
  bool inside(std::span<const Vec2> ring, double px, double py) const {
    if (ring.size() != n_ || !(std::isfinite(px) && std::isfinite(py)))
      return point_in_polygon(ring, px, py);
    // Each crossing edge once, in no set order: a parity does not depend on the order.
    bool in = false;
    if (const std::size_t st = answering_strip(py); st != kNoStrip) {
      for (uint32_t a = strip_start_[st]; a < strip_start_[st + 1]; ++a) {
        const uint32_t s = strip_ids_[a];
        in ^= crosses_right_of(ring[(s + 1) % n_], ring[s], px, py);
      }
      return in;
    }
    const int64_t cy = grid_.cell_y(py);
    grid_.visit(grid_.cell_x(px) - 1, grid_.nx() - 1, cy, cy, [&](uint32_t s) {
      // Segment s joins ring[s] and ring[s + 1]; the loop's pairing.
      in ^= crosses_right_of(ring[(s + 1) % n_], ring[s], px, py);
    });
    return in;
  }

  // dist2_to_boundary(ring, px, py, closest) where that is <= reach^2 (reach >= 0), the same
  // closest point too; otherwise a value above reach^2. The edges come in no set order, so the
  // loop's "first nearest edge in ring order" is kept as the least (distance, edge) pair.
  double dist2(std::span<const Vec2> ring, double px, double py, double reach,
               Vec2* closest = nullptr) const {
    const double x0 = px - reach, y0 = py - reach, x1 = px + reach, y1 = py + reach;
    if (ring.size() != n_ ||
        !(std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1)))
      return dist2_to_boundary(ring, px, py, closest);
    double best = INFINITY;
    uint32_t best_edge = UINT32_MAX;  // none offered below INFINITY yet: the loop keeps nothing
    Vec2 at{};
    grid_.visit(grid_.cell_x(x0) - 1, grid_.cell_x(x1) + 1, grid_.cell_y(y0) - 1,
                grid_.cell_y(y1) + 1, [&](uint32_t s) {
                  Vec2 c;
                  const double d2 = segment_dist2(ring[s], ring[(s + 1) % n_], px, py, c);
                  if (d2 < best || (d2 == best && best_edge != UINT32_MAX && s < best_edge)) {
                    best = d2;
                    best_edge = s;
                    at = c;
                  }
                });
    if (closest && best_edge != UINT32_MAX) *closest = at;
    return best;
  }

  // f(s) for each edge s whose box may meet [x0, x1] x [y0, y1] (grown by a cell against
  // rounding), each once, in no set order; every edge where there is no grid, a bound is not
  // finite or the window has more cells than there are edges. Returns the cells read. For
  // questions the grid does not answer itself (first-to-collide's ray against the edges'
  // capsules).
  template <class F>
  std::size_t visit_edges_meeting(double x0, double y0, double x1, double y1, F&& f) const {
    if (!(std::isfinite(x0) && std::isfinite(y0) && std::isfinite(x1) && std::isfinite(y1))) {
      for (std::size_t s = 0; s < n_; ++s) f(static_cast<uint32_t>(s));
      return 0;
    }
    return grid_.visit(grid_.cell_x(x0) - 1, grid_.cell_x(x1) + 1, grid_.cell_y(y0) - 1,
                       grid_.cell_y(y1) + 1, f);
  }
  double cell() const { return grid_.cell(); }
  int64_t cells_across() const { return grid_.nx() + grid_.ny(); }
  std::size_t edges() const { return n_; }

  // Whether inside() answers a point at height py from its strip (else from the grid's row of
  // cells), and the strips' entries in all (at most about 8 n): for tests.
  bool strip_answers(double py) const { return answering_strip(py) != kNoStrip; }
  std::size_t strip_entries() const { return strip_ids_.size(); }

  // Edges every question scans (long ones, or all where there is no grid): for tests.
  std::size_t scanned_edges() const { return grid_.scanned(); }

  // disc_overlaps_polygon(ring, px, py, r).
  bool disc_overlaps(std::span<const Vec2> ring, double px, double py, double r) const {
    return inside(ring, px, py) || dist2(ring, px, py, std::abs(r)) < r * r;
  }

 private:
  static constexpr int64_t kMaxSide = 1024;  // cells per axis, at most

  // Horizontal strips of the ring's height, each listing the edges whose y range meets it. An
  // edge crosses the line y = py only if one end lies above py and the other not, so py lies in
  // [lower end's y, upper end's y]; the strip index is monotone in y (a difference, a product by a
  // positive constant and a floor, each rounded monotonically), so py's strip lies between those
  // of the edge's ends, where the edge is listed: no margin needed. About one strip per edge, fewer
  // where the edges' heights add up to many times the ring's (a zigzag), so that the lists hold
  // at most about 8 n entries; a strip listing more than strip_scan_ edges leaves the question to
  // the grid's row of cells.
  void build_strips(std::span<const Vec2> ring) {
    double lo = INFINITY, hi = -INFINITY, climb = 0;
    for (std::size_t s = 0; s < n_; ++s) {
      lo = std::min(lo, ring[s].y);
      hi = std::max(hi, ring[s].y);
      climb += std::abs(ring[(s + 1) % n_].y - ring[s].y);
    }
    const double height = hi - lo;
    if (!(height > 0 && height < INFINITY && climb < INFINITY)) return;  // the grid answers
    const auto n = static_cast<double>(n_);
    strips_ = static_cast<int64_t>(std::clamp(std::min(n, 6 * n * height / climb), 1.0, n));
    strip_y0_ = lo;
    strip_inv_ = static_cast<double>(strips_) / height;
    if (!(strip_inv_ < INFINITY)) return;
    fill_bucket_lists(
        static_cast<std::size_t>(strips_), n_,
        [&](std::size_t s, auto&& to) {
          const double ya = ring[s].y, yb = ring[(s + 1) % n_].y;
          for (int64_t t = strip_of(std::min(ya, yb)), end = strip_of(std::max(ya, yb)); t <= end;
               ++t)
            to(static_cast<std::size_t>(t));
        },
        strip_start_, strip_ids_);
    // A strip's list beyond this costs more than the row of cells would (roughly).
    strip_scan_ = 2 * static_cast<uint32_t>(std::sqrt(n)) + 16;
  }
  // py's strip where it lists few enough edges to answer inside(), else kNoStrip.
  static constexpr std::size_t kNoStrip = SIZE_MAX;
  std::size_t answering_strip(double py) const {
    if (strip_start_.empty()) return kNoStrip;
    const auto st = static_cast<std::size_t>(strip_of(py));
    return strip_start_[st + 1] - strip_start_[st] <= strip_scan_ ? st : kNoStrip;
  }
  int64_t strip_of(double y) const {
    const double t = (y - strip_y0_) * strip_inv_;
    if (!(t >= 0)) return 0;  // below the ring, or NaN
    return t < static_cast<double>(strips_ - 1) ? static_cast<int64_t>(t) : strips_ - 1;
  }

  std::size_t n_ = 0;
  BoxGrid grid_;  // the edges' boxes: edge s joins ring[s] and ring[s + 1]
  int64_t strips_ = 0;
  double strip_y0_ = 0, strip_inv_ = 0;
  uint32_t strip_scan_ = 0;
  std::vector<uint32_t> strip_start_;  // CSR offsets per strip, strips_ + 1; empty: no strips
  std::vector<uint32_t> strip_ids_;    // the edges meeting each strip, in edge order
};

}  // namespace crowddb
