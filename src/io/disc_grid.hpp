// A spatial hash of discs for placing agents without overlaps: the scenario reader's groups and
// the importers' random placement. Exact (the same predicate as the engine's overlap test) and
// bounded: a query window wider than the discs are many scans the discs instead of the cells.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "world/geometry.hpp"

namespace crowddb::io {

class DiscGrid {
 public:
  explicit DiscGrid(double cell) : cell_(cell > 0 ? cell : 1) {}
  void add(double x, double y, double r) {
    const std::size_t i = xs_.size();
    xs_.push_back(x);
    ys_.push_back(y);
    rs_.push_back(r);
    rmax_ = std::max(rmax_, r);
    // An intrusive list per cell (head in the table, links in next_): no allocation per cell.
    std::size_t& head = head_of(key(cell_of(x), cell_of(y)));
    next_.push_back(head);
    head = i;
  }
  void reserve(std::size_t n) {
    xs_.reserve(n);
    ys_.reserve(n);
    rs_.reserve(n);
    next_.reserve(n);
    grow(n);
  }
  // Does a placed disc overlap (x, y, r) with the extra gap? A window wider than the discs are
  // many (a huge gap) scans the discs instead of the cells: work stays bounded by the input.
  bool any_overlap(double x, double y, double r, double gap) const {
    const double reach = r + rmax_ + gap;
    const double side = 2 * reach / cell_ + 2;  // cells per side of the window
    if (!(side * side <= static_cast<double>(xs_.size()))) {
      for (std::size_t j = 0; j < xs_.size(); ++j)
        if (discs_overlap(xs_[j] - x, ys_[j] - y, rs_[j] + r + gap)) return true;
      return false;
    }
    const int64_t x0 = cell_of(x - reach), x1 = cell_of(x + reach);
    const int64_t y0 = cell_of(y - reach), y1 = cell_of(y + reach);
    for (int64_t cx = x0; cx <= x1; ++cx)
      for (int64_t cy = y0; cy <= y1; ++cy) {
        for (std::size_t j = find(key(cx, cy)); j != kEnd; j = next_[j])
          if (discs_overlap(xs_[j] - x, ys_[j] - y, rs_[j] + r + gap)) return true;
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
    for (std::size_t i = 0; i < xs_.size() && !out.capped; ++i) {
      const double reach = rs_[i] + rmax_;
      std::size_t first_j = SIZE_MAX;
      for (int64_t cx = cell_of(xs_[i] - reach); cx <= cell_of(xs_[i] + reach); ++cx)
        for (int64_t cy = cell_of(ys_[i] - reach); cy <= cell_of(ys_[i] + reach); ++cy) {
          for (std::size_t j = find(key(cx, cy)); j != kEnd; j = next_[j])
            if (j > i && discs_overlap(xs_[j] - xs_[i], ys_[j] - ys_[i], rs_[i] + rs_[j])) {
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
  // The cells' heads: open addressing with linear probing, at most half full, never erased.
  // (A node-based map cost a cache miss or two per lookup: checking 10^6 spawned agents for
  // overlaps took a second.) Cells whose keys coincide share one list: more candidates, the
  // same answers.
  std::size_t slot_of(uint64_t k) const {
    const uint64_t h = (k ^ (k >> 31)) * 0xbf58476d1ce4e5b9ull;
    return static_cast<std::size_t>(h >> 17) & (keys_.size() - 1);
  }
  std::size_t find(uint64_t k) const {
    if (keys_.empty()) return kEnd;
    for (std::size_t s = slot_of(k);; s = (s + 1) & (keys_.size() - 1)) {
      if (heads_[s] == kEnd) return kEnd;
      if (keys_[s] == k) return heads_[s];
    }
  }
  // Room for `cells` cells at most half full.
  void grow(std::size_t cells) {
    std::size_t cap = 64;
    while (cap < 2 * cells) cap *= 2;
    if (cap <= keys_.size()) return;
    std::vector<uint64_t> keys(cap, 0);
    std::vector<std::size_t> heads(cap, kEnd);
    keys.swap(keys_);
    heads.swap(heads_);
    for (std::size_t s = 0; s < keys.size(); ++s)
      if (heads[s] != kEnd) {
        std::size_t t = slot_of(keys[s]);
        while (heads_[t] != kEnd) t = (t + 1) & (keys_.size() - 1);
        keys_[t] = keys[s];
        heads_[t] = heads[s];
      }
  }
  // The head of cell k's list, a new empty list (kEnd) if it has none.
  std::size_t& head_of(uint64_t k) {
    if (2 * (cells_ + 1) > keys_.size()) grow(cells_ + 1);
    std::size_t s = slot_of(k);
    while (heads_[s] != kEnd && keys_[s] != k) s = (s + 1) & (keys_.size() - 1);
    if (heads_[s] == kEnd) {
      keys_[s] = k;
      ++cells_;
    }
    return heads_[s];
  }

  double cell_;
  double rmax_ = 0;
  std::vector<double> xs_, ys_, rs_;
  static constexpr std::size_t kEnd = SIZE_MAX;
  std::vector<uint64_t> keys_;      // cell keys
  std::vector<std::size_t> heads_;  // cell -> its newest disc; kEnd: an empty slot
  std::size_t cells_ = 0;
  std::vector<std::size_t> next_;  // disc -> the next older disc in its cell
};

}  // namespace crowddb::io
