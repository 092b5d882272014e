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
// Edges whose box spans more than kMaxCells cells go to a list every question scans. The loops
// stay as the oracle (tests/world/ring_grid_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "world/geometry.hpp"

namespace crowddb {

class RingGrid {
 public:
  // Rings with fewer edges are cheaper to loop over than to bucket.
  static constexpr std::size_t kMinEdges = 64;

  explicit RingGrid(std::span<const Vec2> ring) : n_(ring.size()) {
    const RingBox b = ring_box(ring);
    if (n_ < 3 || !(b.x1 - b.x0 < INFINITY && b.y1 - b.y0 < INFINITY)) {
      for (std::size_t s = 0; s < n_; ++s) big_.push_back(static_cast<uint32_t>(s));
      return;  // nothing to bucket, or coordinates beyond any grid: every question scans
    }
    x0_ = b.x0;
    y0_ = b.y0;
    const double w = std::max(b.x1 - b.x0, 1e-9), h = std::max(b.y1 - b.y0, 1e-9);
    // Cells no finer than 10^-12 of the coordinates: the one-cell margins then exceed any
    // rounding of a crossing or of a query window's edges (callers' points lie within 10^9 m).
    const double magnitude =
        std::max({std::abs(b.x0), std::abs(b.x1), std::abs(b.y0), std::abs(b.y1)});
    double extent = 0;  // the edges' mean box side: cells no smaller than an edge
    for (std::size_t s = 0; s < n_; ++s) {
      const Vec2 &p = ring[s], &q = ring[(s + 1) % n_];
      extent += std::max(std::abs(q.x - p.x), std::abs(q.y - p.y));
    }
    const auto edges = static_cast<double>(n_);
    cell_ = std::max(
        {std::sqrt(w * h / edges), extent / edges, w / kMaxSide, h / kMaxSide, 1e-12 * magnitude});
    nx_ = std::clamp<int64_t>(static_cast<int64_t>(w / cell_) + 1, 1, kMaxSide + 1);
    ny_ = std::clamp<int64_t>(static_cast<int64_t>(h / cell_) + 1, 1, kMaxSide + 1);
    start_.assign(static_cast<std::size_t>(nx_ * ny_) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {  // count, then place (CSR)
      std::vector<uint32_t> fill;
      if (pass == 1) {
        for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        ids_.resize(start_.back());
        fill.assign(start_.begin(), start_.end() - 1);
      }
      for (std::size_t s = 0; s < n_; ++s) {
        const Vec2 &p = ring[s], &q = ring[(s + 1) % n_];
        const int64_t cx0 = cell_x(std::min(p.x, q.x)), cx1 = cell_x(std::max(p.x, q.x));
        const int64_t cy0 = cell_y(std::min(p.y, q.y)), cy1 = cell_y(std::max(p.y, q.y));
        if ((cx1 - cx0 + 1) * (cy1 - cy0 + 1) > kMaxCells) {
          if (pass == 0) big_.push_back(static_cast<uint32_t>(s));
          continue;
        }
        for (int64_t cy = cy0; cy <= cy1; ++cy)
          for (int64_t cx = cx0; cx <= cx1; ++cx) {
            const auto c = static_cast<std::size_t>(cy * nx_ + cx);
            if (pass == 0)
              ++start_[c + 1];
            else
              ids_[fill[c]++] = static_cast<uint32_t>(s);
          }
      }
    }
  }

  // point_in_polygon(ring, px, py), `ring` the one the grid was built over (another ring, one
  // of another size, say, gets the loop itself).
  bool inside(std::span<const Vec2> ring, double px, double py) const {
    if (ring.size() != n_) return point_in_polygon(ring, px, py);
    thread_local std::vector<uint32_t> near;
    if (start_.empty() || !(std::isfinite(px) && std::isfinite(py))) {
      all(near);
    } else {
      const int64_t cy = cell_y(py);
      collect(std::max<int64_t>(cell_x(px) - 1, 0), nx_ - 1, cy, cy, near);
    }
    bool in = false;
    for (const uint32_t s : near) {        // segment s joins ring[s] and ring[s + 1]
      const Vec2& a = ring[(s + 1) % n_];  // (the loop's pairing: a = ring[i], b = ring[i - 1])
      const Vec2& b = ring[s];
      if ((a.y > py) != (b.y > py)) {
        const double xcross = a.x + (py - a.y) * (b.x - a.x) / (b.y - a.y);
        if (px < xcross) in = !in;
      }
    }
    return in;
  }

  // dist2_to_boundary(ring, px, py) where that is <= reach^2 (reach >= 0); otherwise a value
  // above reach^2.
  double dist2(std::span<const Vec2> ring, double px, double py, double reach) const {
    if (ring.size() != n_) return dist2_to_boundary(ring, px, py);
    thread_local std::vector<uint32_t> near;
    if (start_.empty() || !(std::isfinite(px) && std::isfinite(py) && reach < INFINITY)) {
      all(near);
    } else {
      const int64_t cx0 = cell_x(px - reach) - 1, cx1 = cell_x(px + reach) + 1;
      const int64_t cy0 = cell_y(py - reach) - 1, cy1 = cell_y(py + reach) + 1;
      if (static_cast<double>(cx1 - cx0 + 1) * static_cast<double>(cy1 - cy0 + 1) >
          static_cast<double>(n_))
        all(near);
      else
        collect(std::max<int64_t>(cx0, 0), std::min(cx1, nx_ - 1), std::max<int64_t>(cy0, 0),
                std::min(cy1, ny_ - 1), near);
    }
    double best = INFINITY;
    for (const uint32_t s : near) {
      const Vec2 c = closest_on_segment(ring[s], ring[(s + 1) % n_], px, py);
      const double dx = px - c.x, dy = py - c.y;
      best = std::min(best, dx * dx + dy * dy);
    }
    return best;
  }

  // Edges every question scans (more than kMaxCells cells long, or no grid): for tests.
  std::size_t scanned_edges() const { return big_.size(); }

  // disc_overlaps_polygon(ring, px, py, r).
  bool disc_overlaps(std::span<const Vec2> ring, double px, double py, double r) const {
    return inside(ring, px, py) || dist2(ring, px, py, std::abs(r)) < r * r;
  }

 private:
  static constexpr int64_t kMaxSide = 1024;  // cells per axis, at most
  static constexpr int64_t kMaxCells = 64;   // cells an edge may be registered in

  void all(std::vector<uint32_t>& out) const {
    out.resize(n_);
    for (std::size_t s = 0; s < n_; ++s) out[s] = static_cast<uint32_t>(s);
  }
  // The edges registered in cells [cx0, cx1] x [cy0, cy1] and the big ones, each once.
  void collect(int64_t cx0, int64_t cx1, int64_t cy0, int64_t cy1,
               std::vector<uint32_t>& out) const {
    out = big_;
    for (int64_t cy = cy0; cy <= cy1; ++cy)
      for (int64_t cx = cx0; cx <= cx1; ++cx) {
        const auto c = static_cast<std::size_t>(cy * nx_ + cx);
        out.insert(out.end(), ids_.begin() + start_[c], ids_.begin() + start_[c + 1]);
      }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }
  // Clamped into the grid (as ObstacleLookup's): a point outside it asks the border cells.
  int64_t cell_x(double v) const { return clamp_cell((v - x0_) / cell_, nx_); }
  int64_t cell_y(double v) const { return clamp_cell((v - y0_) / cell_, ny_); }
  static int64_t clamp_cell(double c, int64_t n) {
    if (!(c >= 0)) return 0;
    return c < static_cast<double>(n - 1) ? static_cast<int64_t>(c) : n - 1;
  }

  std::size_t n_ = 0;
  double x0_ = 0, y0_ = 0, cell_ = 1;
  int64_t nx_ = 0, ny_ = 0;
  std::vector<uint32_t> start_;  // CSR offsets per cell (row-major); empty: no grid
  std::vector<uint32_t> ids_;    // the segments registered in each cell
  std::vector<uint32_t> big_;    // segments spanning more than kMaxCells cells
};

}  // namespace crowddb
