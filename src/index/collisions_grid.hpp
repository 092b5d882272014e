// Collision sets with a uniform grid (the game-engine baseline of DESIGN.md §3.2), made robust
// to mixed radii: discs are split into radius classes (a factor of 4 apart), each class a
// CellIndex whose cell is twice the class's largest radius. Pairs within a class come from each
// cell and its half neighbourhood; a pair across classes is found by probing one class's cells
// with the other's discs, whichever side costs less: a small disc meets at most 3 x 3 cells of
// a larger class, a large disc (2 R_big + 2 R_small) / cell rows of a smaller one. A handful of
// giant discs thus form their own class and probe the rest, instead of making every cell giant;
// ordinary inputs (radii within a factor of 4, or sparse enough that the widest cell still holds
// few centres) use one class.
//
// Exact: every candidate is decided by the oracle's discs_overlap on the original doubles and
// the cell reach carries the rounding margins of collision_common.hpp. Obstacles go through
// ObstacleIndex. Output: all pairs, sorted, as CollisionNaive.
//
// Cost: O(n) to build (radix sort per class), O(n + candidates) for pairs within a class,
// O(n_small log n_big) per pair of classes.
#pragma once

#include <vector>

#include "index/cell_index.hpp"
#include "index/obstacle_index.hpp"
#include "plan/access_path.hpp"
#include "world/geometry.hpp"

namespace crowddb::index {

class DiscGrid {
 public:
  // Indexes all rows of d. d's columns must outlive the queries. With `ex`, a level's keys and
  // sort run on its threads (the same index).
  void build(const DiscView& d, Executor* ex = nullptr);
  // Forgets the last build: a grid never built, or cleared, is not usable.
  void clear() {
    built_ = false;
    frame_ = Frame{};
    levels_.clear();
  }
  const Frame& frame() const { return frame_; }
  std::size_t rows() const { return frame_.count; }  // rows of the last build
  // false: never built, cleared, or non-finite input (use the naive loop)
  bool usable() const { return built_ && frame_.finite; }
  // One level per class of radii (ascending); one when the radii are equal.
  const std::vector<CellIndex>& levels() const { return levels_; }

  // Every overlapping pair (rows, i < j), appended unsorted.
  void pairs(PairList& out, uint64_t& tests) const;

  // fn(row) for every indexed row whose disc overlaps the disc (qx, qy, qr) by the oracle's
  // test (the query's own row included, if it is indexed at that position).
  template <class F>
  void for_each_overlap(double qx, double qy, double qr, F&& fn) const {
    for (const CellIndex& level : levels_)
      level.for_each_near(qx, qy, qr, [&](std::size_t k) {
        if (discs_overlap(level.x(k) - qx, level.y(k) - qy, qr + level.r(k))) fn(level.row(k));
      });
  }

 private:
  Frame frame_;
  bool built_ = false;
  std::vector<CellIndex> levels_;  // ascending radius
  std::vector<uint32_t> class_rows_;
};

class CollisionGrid final : public CollisionPath {
 public:
  void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out, Executor& ex,
           QueryStats& stats) override;
  const DiscGrid* disc_grid() const override { return grid_.usable() ? &grid_ : nullptr; }

 private:
  DiscGrid grid_;
  ObstacleIndex obstacles_;
};

}  // namespace crowddb::index
