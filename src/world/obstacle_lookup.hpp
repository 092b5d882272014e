// Which obstacles may hold a point or touch a disc: World's check of every agent inserted and the
// scenario reader's checks of every goal, agent and placement attempt against the obstacles.
// Those checks scanned every obstacle per query: SteerSuite's scenarioSpace (5,000 agents and
// 15,000 goals among 5,000 boxes) made 10^8 polygon tests before the first tick.
//
// The obstacles' bounding boxes are bucketed into a uniform grid over their extent
// (world/box_grid.hpp). A query lists the obstacles whose box, grown by the query's reach, holds
// the point: a superset of those the exact tests can accept, in obstacle order (circles by row,
// then polygons by row), so a caller that stops at the first hit names the obstacle a scan would.
// Bounded by the input: long walls sit in a list every query scans, and a query window of more
// cells than there are obstacles lists them all. The linear scan stays as the oracle
// (tests/world/obstacle_lookup_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "crowddb/world.hpp"
#include "world/box_grid.hpp"
#include "world/ring_grid.hpp"

namespace crowddb {

class ObstacleLookup {
 public:
  // Whether polygons with many edges get edge grids for the polygon tests below (without them,
  // those tests loop over the edges): a caller asking only for candidates skips building them.
  enum class EdgeGrids { build, skip };

  // Obstacle k: circle k for k < circles.size(), else polygon k - circles.size().
  ObstacleLookup(std::span<const CircleObstacle> circles, std::span<const PolygonObstacle> polygons,
                 EdgeGrids edge_grids = EdgeGrids::build) {
    std::vector<BoxBounds> boxes;
    boxes.reserve(circles.size() + polygons.size());
    for (const CircleObstacle& c : circles)
      boxes.push_back({c.x - c.radius, c.y - c.radius, c.x + c.radius, c.y + c.radius});
    ring_of_.assign(polygons.size(), -1);
    for (std::size_t k = 0; k < polygons.size(); ++k)
      if (edge_grids == EdgeGrids::build && polygons[k].vertices.size() >= RingGrid::kMinEdges) {
        ring_of_[k] = static_cast<int32_t>(rings_.size());
        rings_.emplace_back(polygons[k].vertices);
      }
    for (const PolygonObstacle& p : polygons) boxes.push_back(ring_box(p.vertices));
    grid_ = BoxGrid(boxes, kMaxSide);
  }

  // The exact tests of world/geometry.hpp on polygon p (of those the lookup was built over;
  // `ring` its vertices), through an edge grid (world/ring_grid.hpp) where it has many edges
  // and the lookup built edge grids (else the loops):
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
    if (!(std::isfinite(x) && std::isfinite(y) && reach < INFINITY))
      grid_.all(out);
    else
      grid_.collect(grid_.cell_x(x - reach), grid_.cell_x(x + reach), grid_.cell_y(y - reach),
                    grid_.cell_y(y + reach), out);
  }

 private:
  static constexpr int64_t kMaxSide = 2048;  // cells per axis, at most

  BoxGrid grid_;                  // the obstacles' bounding boxes, obstacle k as box k
  std::vector<RingGrid> rings_;   // the edge grids of polygons with many edges
  std::vector<int32_t> ring_of_;  // per polygon: its grid in rings_, or -1
};

}  // namespace crowddb
