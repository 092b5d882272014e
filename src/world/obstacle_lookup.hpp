// Which obstacles may hold a point or touch a disc: World's check of every agent inserted and the
// scenario reader's checks of every goal, agent and placement attempt against the obstacles.
// Those checks scanned every obstacle per query: SteerSuite's scenarioSpace (5,000 agents and
// 15,000 goals among 5,000 boxes) made 10^8 polygon tests before the first tick.
//
// The obstacles' bounding boxes are bucketed into a uniform grid over their extent (cells about
// as wide as the obstacles are apart, at most kMaxSide per axis). A query lists the obstacles
// whose box, grown by the query's reach, holds the point: a superset of those the exact tests can
// accept, in obstacle order (circles by row, then polygons by row), so a caller that stops at the
// first hit names the obstacle a scan would. Bounded by the input: an obstacle whose box spans
// more than kMaxCells cells (a long wall) is kept in a list every query scans instead of being
// registered cell by cell, and a query window of more cells than there are obstacles lists them
// all. The linear scan stays as the oracle (tests/world/obstacle_lookup_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "crowddb/world.hpp"
#include "world/ring_grid.hpp"

namespace crowddb {

class ObstacleLookup {
 public:
  // Obstacle k: circle k for k < circles.size(), else polygon k - circles.size().
  ObstacleLookup(std::span<const CircleObstacle> circles, std::span<const PolygonObstacle> polygons)
      : count_(circles.size() + polygons.size()) {
    std::vector<Box> boxes;
    boxes.reserve(count_);
    for (const CircleObstacle& c : circles)
      boxes.push_back({c.x - c.radius, c.y - c.radius, c.x + c.radius, c.y + c.radius});
    ring_of_.assign(polygons.size(), -1);
    for (std::size_t k = 0; k < polygons.size(); ++k)
      if (polygons[k].vertices.size() >= RingGrid::kMinEdges) {
        ring_of_[k] = static_cast<int32_t>(rings_.size());
        rings_.emplace_back(polygons[k].vertices);
      }
    for (const PolygonObstacle& p : polygons) {
      Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
      for (const Vec2& v : p.vertices)
        b = {std::min(b.x0, v.x), std::min(b.y0, v.y), std::max(b.x1, v.x), std::max(b.y1, v.y)};
      boxes.push_back(b);
    }
    Box all{INFINITY, INFINITY, -INFINITY, -INFINITY};
    double extent = 0;
    for (const Box& b : boxes) {
      all = {std::min(all.x0, b.x0), std::min(all.y0, b.y0), std::max(all.x1, b.x1),
             std::max(all.y1, b.y1)};
      extent += std::max(b.x1 - b.x0, b.y1 - b.y0);
    }
    if (count_ == 0 || !(all.x1 - all.x0 < INFINITY && all.y1 - all.y0 < INFINITY)) {
      for (std::size_t k = 0; k < count_; ++k) big_.push_back(static_cast<uint32_t>(k));
      return;  // nothing, or boxes beyond any grid: every query scans them all
    }
    origin_x_ = all.x0;
    origin_y_ = all.y0;
    // Cells about as wide as the obstacles are apart, or as large as they are, whichever is more.
    const double w = std::max(all.x1 - all.x0, 1e-9), h = std::max(all.y1 - all.y0, 1e-9);
    cell_ = std::max({std::sqrt(w * h / static_cast<double>(count_)),
                      extent / static_cast<double>(count_), w / kMaxSide, h / kMaxSide});
    nx_ = std::clamp<int64_t>(static_cast<int64_t>(w / cell_) + 1, 1, kMaxSide + 1);
    ny_ = std::clamp<int64_t>(static_cast<int64_t>(h / cell_) + 1, 1, kMaxSide + 1);
    // Count, then place (CSR): registrations in obstacle order keep each cell's list sorted.
    start_.assign(static_cast<std::size_t>(nx_ * ny_) + 1, 0);
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<uint32_t> fill;
      if (pass == 1) {
        for (std::size_t c = 1; c < start_.size(); ++c) start_[c] += start_[c - 1];
        ids_.resize(start_.back());
        fill.assign(start_.begin(), start_.end() - 1);
      }
      for (std::size_t k = 0; k < count_; ++k) {
        const Box& b = boxes[k];
        const int64_t cx0 = cell_x(b.x0), cx1 = cell_x(b.x1), cy0 = cell_y(b.y0),
                      cy1 = cell_y(b.y1);
        if ((cx1 - cx0 + 1) * (cy1 - cy0 + 1) > kMaxCells) {
          if (pass == 0) big_.push_back(static_cast<uint32_t>(k));
          continue;
        }
        for (int64_t cy = cy0; cy <= cy1; ++cy)
          for (int64_t cx = cx0; cx <= cx1; ++cx) {
            const auto c = static_cast<std::size_t>(cy * nx_ + cx);
            if (pass == 0)
              ++start_[c + 1];
            else
              ids_[fill[c]++] = static_cast<uint32_t>(k);
          }
      }
    }
  }

  // The exact tests of world/geometry.hpp on polygon p (of those the lookup was built over;
  // `ring` its vertices), through an edge grid (world/ring_grid.hpp) where it has many edges:
  // point_in_polygon; dist2_to_boundary where that is <= reach^2 (else a value above reach^2);
  // disc_overlaps_polygon.
  bool polygon_holds(std::size_t p, std::span<const Vec2> ring, double x, double y) const {
    return ring_of_[p] < 0 ? point_in_polygon(ring, x, y)
                           : rings_[static_cast<std::size_t>(ring_of_[p])].inside(ring, x, y);
  }
  double polygon_dist2(std::size_t p, std::span<const Vec2> ring, double x, double y,
                       double reach) const {
    return ring_of_[p] < 0 ? dist2_to_boundary(ring, x, y)
                           : rings_[static_cast<std::size_t>(ring_of_[p])].dist2(ring, x, y, reach);
  }
  bool disc_overlaps_polygon(std::size_t p, std::span<const Vec2> ring, double x, double y,
                             double r) const {
    return ring_of_[p] < 0
               ? crowddb::disc_overlaps_polygon(ring, x, y, r)
               : rings_[static_cast<std::size_t>(ring_of_[p])].disc_overlaps(ring, x, y, r);
  }

  // The obstacles whose bounding box, grown by `reach` (>= 0), holds (x, y), in obstacle order,
  // each once (a superset of those a disc of radius `reach` there touches). `out` is overwritten.
  void candidates(double x, double y, double reach, std::vector<uint32_t>& out) const {
    out.clear();
    if (start_.empty() || !(std::isfinite(x) && std::isfinite(y) && reach < INFINITY)) {
      all(out);
      return;
    }
    const int64_t cx0 = cell_x(x - reach), cx1 = cell_x(x + reach), cy0 = cell_y(y - reach),
                  cy1 = cell_y(y + reach);
    if (static_cast<double>(cx1 - cx0 + 1) * static_cast<double>(cy1 - cy0 + 1) >
        static_cast<double>(count_)) {
      all(out);
      return;
    }
    out = big_;
    for (int64_t cy = cy0; cy <= cy1; ++cy)
      for (int64_t cx = cx0; cx <= cx1; ++cx) {
        const auto c = static_cast<std::size_t>(cy * nx_ + cx);
        out.insert(out.end(), ids_.begin() + start_[c], ids_.begin() + start_[c + 1]);
      }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
  }

 private:
  static constexpr int64_t kMaxSide = 2048;  // cells per axis, at most
  static constexpr int64_t kMaxCells = 64;   // cells an obstacle may be registered in
  struct Box {
    double x0, y0, x1, y1;
  };
  void all(std::vector<uint32_t>& out) const {
    out.resize(count_);
    for (std::size_t k = 0; k < count_; ++k) out[k] = static_cast<uint32_t>(k);
  }
  // Clamped into the grid: a point outside it queries the border cells, which hold every
  // obstacle its box reaches there (a superset stays a superset).
  int64_t cell_x(double v) const { return clamp_cell((v - origin_x_) / cell_, nx_); }
  int64_t cell_y(double v) const { return clamp_cell((v - origin_y_) / cell_, ny_); }
  static int64_t clamp_cell(double c, int64_t n) {
    if (!(c >= 0)) return 0;  // below the grid, or NaN
    return c < static_cast<double>(n - 1) ? static_cast<int64_t>(c) : n - 1;
  }

  std::size_t count_ = 0;
  double origin_x_ = 0, origin_y_ = 0, cell_ = 1;
  int64_t nx_ = 0, ny_ = 0;
  std::vector<uint32_t> start_;   // CSR offsets per cell (row-major), nx_ * ny_ + 1; empty: no grid
  std::vector<uint32_t> ids_;     // the obstacles registered in each cell, in obstacle order
  std::vector<uint32_t> big_;     // obstacles spanning more than kMaxCells cells, in order
  std::vector<RingGrid> rings_;   // the edge grids of polygons with many edges
  std::vector<int32_t> ring_of_;  // per polygon: its grid in rings_, or -1
};

}  // namespace crowddb
