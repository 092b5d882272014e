// A spatial hash of discs for placing agents without overlaps: the scenario reader's groups, the
// importers' random placement and the sources' free spots. Exact (the same predicate as the
// engine's overlap test) and bounded: a query window wider than the discs are many scans the discs
// instead of the cells. Discs are added one at a time (index::DiscGrid is built over a table).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "util/flat_map.hpp"
#include "world/geometry.hpp"

namespace crowddb {

class PlacementGrid {
 public:
  explicit PlacementGrid(double cell) : cell_(cell > 0 ? cell : 1) {}
  void add(double x, double y, double r) {
    const std::size_t i = discs_.size();
    rmax_ = std::max(rmax_, r);
    // An intrusive list per cell (head in the table, links in the discs): no allocation per cell.
    std::size_t& head = heads_.at(key(cell_of(x), cell_of(y)));
    discs_.push_back({x, y, r, head});
    head = i;
  }
  void reserve(std::size_t n) {
    discs_.reserve(n);
    heads_.reserve(n);
  }
  // Does a placed disc overlap (x, y, r) with the extra gap? A window wider than the discs are
  // many (a huge gap) scans the discs instead of the cells: work stays bounded by the input.
  bool any_overlap(double x, double y, double r, double gap) const {
    const double reach = r + rmax_ + gap;
    const double side = 2 * reach / cell_ + 2;  // cells per side of the window
    if (!(side * side <= static_cast<double>(discs_.size()))) {
      for (const Disc& d : discs_)
        if (discs_overlap(d.x - x, d.y - y, d.r + r + gap)) return true;
      return false;
    }
    const int64_t x0 = cell_of(x - reach), x1 = cell_of(x + reach);
    const int64_t y0 = cell_of(y - reach), y1 = cell_of(y + reach);
    for (int64_t cx = x0; cx <= x1; ++cx)
      for (int64_t cy = y0; cy <= y1; ++cy) {
        for (std::size_t j = heads_.find(key(cx, cy)); j != kEnd; j = discs_[j].next)
          if (discs_overlap(discs_[j].x - x, discs_[j].y - y, discs_[j].r + r + gap)) return true;
      }
    return false;
  }
  // Overlapping pairs (i < j) among the placed discs: how many (counting stops at `cap`, so a
  // pile of 10^5 discs on one spot costs no more than the cap) and the first in (i, j) order.
  struct PairCount {
    uint64_t count = 0;
    bool capped = false, found = false;
    std::size_t first_i = 0, first_j = 0;
  };
  PairCount count_pairs(uint64_t cap) const {
    PairCount out;
    for (std::size_t i = 0; i < discs_.size() && !out.capped; ++i) {
      const Disc& a = discs_[i];
      const double reach = a.r + rmax_;
      std::size_t first_j = SIZE_MAX;
      for (int64_t cx = cell_of(a.x - reach); cx <= cell_of(a.x + reach); ++cx)
        for (int64_t cy = cell_of(a.y - reach); cy <= cell_of(a.y + reach); ++cy) {
          for (std::size_t j = heads_.find(key(cx, cy)); j != kEnd; j = discs_[j].next)
            if (j > i && discs_overlap(discs_[j].x - a.x, discs_[j].y - a.y, a.r + discs_[j].r)) {
              first_j = std::min(first_j, j);
              if (++out.count >= cap) out.capped = true;
            }
        }
      if (first_j != SIZE_MAX && !out.found) {
        out.found = true;
        out.first_i = i;
        out.first_j = first_j;
      }
    }
    return out;
  }

 private:
  // Clamped: a cell number beyond int64 (positions near 1e308) would be undefined behaviour.
  int64_t cell_of(double v) const {
    const double c = std::floor(v / cell_);
    if (!(c > -0x1p62)) return c == c ? -(int64_t{1} << 62) : 0;
    return c < 0x1p62 ? static_cast<int64_t>(c) : int64_t{1} << 62;
  }
  static uint64_t key(int64_t cx, int64_t cy) {
    return (static_cast<uint64_t>(cx) * 0x9e3779b97f4a7c15ull) ^ static_cast<uint64_t>(cy);
  }
  double cell_;
  double rmax_ = 0;
  static constexpr std::size_t kEnd = SIZE_MAX;
  // A disc and the next older disc in its cell, side by side: a probe's candidate is one cache
  // miss, not four (placing 10^6 agents at random is mostly such misses).
  struct Disc {
    double x, y, r;
    std::size_t next;
  };
  std::vector<Disc> discs_;
  // Cell -> its newest disc. (A node-based map cost a cache miss or two per lookup: checking 10^6
  // spawned agents for overlaps took a second.) Cells whose keys coincide share one list: more
  // candidates, the same answers.
  FlatMap<std::size_t, kEnd> heads_;
};

}  // namespace crowddb
