// The nearest of a list of points to a query, as a loop over the list that keeps the first point
// strictly nearer by std::hypot gives it, without that loop: a scenario group's "nearest" goal
// assignment looped over every goal for every agent, and a group's goals default to all the
// world's (one per agent after a group with "targets"): 10^5 agents over 10^5 goals made 10^10
// distances before the first tick.
//
// The points go into world/box_grid.hpp's grid (zero-size boxes). A query reads a square window
// of cells around its own, doubling it until the nearest distance found lies strictly below a
// lower bound on the distance of every point outside the window (the gap from the query to the
// window's edge, less a margin for the rounding of cell indices and of hypot), or the window
// covers the grid. Every point that could equal or beat the loop's answer is then read, and
// among them the least (distance, list position) pair is the loop's choice: bit for bit, ties
// included. Lists of few points, and queries or points that are not finite, take the loop
// itself. The loop stays as the oracle (tests/world/nearest_point_test.cpp).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "world/box_grid.hpp"
#include "world/geometry.hpp"

namespace crowddb {

class NearestPoint {
 public:
  // Fewer points are cheaper to loop over than to bucket.
  static constexpr std::size_t kMinPoints = 64;
  static constexpr std::size_t kNone = SIZE_MAX;

  explicit NearestPoint(std::span<const Vec2> points) : points_(points.begin(), points.end()) {
    if (points_.size() < kMinPoints) return;
    std::vector<BoxBounds> boxes;
    boxes.reserve(points_.size());
    for (const Vec2& p : points_) {
      if (!(std::isfinite(p.x) && std::isfinite(p.y))) return;  // the loop answers
      boxes.push_back({p.x, p.y, p.x, p.y});
    }
    grid_ = BoxGrid(boxes, kMaxSide);
    if (!grid_.gridded()) return;
    for (const Vec2& p : points_) magnitude_ = std::max({magnitude_, std::abs(p.x), std::abs(p.y)});
  }

  // The loop's answer: the position in the list of the first point p with the least
  // std::hypot(p.x - x, p.y - y), among distances below infinity; kNone where there is none
  // (no points, or every distance infinite or NaN).
  std::size_t nearest(double x, double y) const {
    if (!grid_.gridded() || !(std::isfinite(x) && std::isfinite(y))) return loop(x, y);
    const int64_t cx = grid_.cell_x(x), cy = grid_.cell_y(y), nx = grid_.nx(), ny = grid_.ny();
    const double cell = grid_.cell();
    // Cell indices come from (v - origin) / cell, rounded: a point may sit in the cell beside
    // the one its exact coordinate names, by far less than this.
    const double slack = 1e-6 * cell + 1e-12 * (std::abs(x) + std::abs(y) + magnitude_);
    double best = INFINITY;
    std::size_t best_k = kNone;
    for (int64_t k = 1;; k *= 2) {
      const int64_t wx0 = cx - k, wx1 = cx + k, wy0 = cy - k, wy1 = cy + k;
      const bool all = (wx0 <= 0 && wx1 >= nx - 1 && wy0 <= 0 && wy1 >= ny - 1) ||
                       static_cast<double>(2 * k + 1) * static_cast<double>(2 * k + 1) >
                           static_cast<double>(points_.size());
      best = INFINITY;
      best_k = kNone;
      grid_.visit(wx0, wx1, wy0, wy1, [&](uint32_t p) {
        const double d = std::hypot(points_[p].x - x, points_[p].y - y);
        if (d < best || (d == best && best_k != kNone && p < best_k)) {
          best = d;
          best_k = p;
        }
      });
      if (all) return best_k;
      // Outside the window, a point is at least `gap` away on one axis (a side of the window at
      // the grid's edge holds everything beyond it: no gap there).
      double gap = INFINITY;
      if (wx0 > 0) gap = std::min(gap, x - (grid_.x0() + static_cast<double>(wx0) * cell));
      if (wx1 < nx - 1) gap = std::min(gap, grid_.x0() + static_cast<double>(wx1 + 1) * cell - x);
      if (wy0 > 0) gap = std::min(gap, y - (grid_.y0() + static_cast<double>(wy0) * cell));
      if (wy1 < ny - 1) gap = std::min(gap, grid_.y0() + static_cast<double>(wy1 + 1) * cell - y);
      // (A gap that overflowed bounds nothing.)
      if (gap < INFINITY && best < (gap - slack) * (1 - 1e-12)) return best_k;
    }
  }

  // The loop itself: the oracle, and the answer for few points.
  std::size_t loop(double x, double y) const {
    double best = INFINITY;
    std::size_t best_k = kNone;
    for (std::size_t p = 0; p < points_.size(); ++p) {
      const double d = std::hypot(points_[p].x - x, points_[p].y - y);
      if (d < best) {
        best = d;
        best_k = p;
      }
    }
    return best_k;
  }

  // Whether queries read the grid (else the loop): for tests.
  bool gridded() const { return grid_.gridded(); }

 private:
  static constexpr int64_t kMaxSide = 1024;  // cells per axis, at most

  std::vector<Vec2> points_;
  BoxGrid grid_;
  double magnitude_ = 0;  // the points' largest coordinate, in absolute value
};

}  // namespace crowddb
