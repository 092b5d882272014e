// One level of a uniform grid over disc centres, stored without a hash table: each disc gets
// the key cy * W + cx of its cell, the discs are radix-sorted by key, and a cell is the run of
// equal keys. Neighbouring cells are found by walking monotone pointers through the sorted keys
// (the next row of cells is keys + W), or by binary search for arbitrary boxes. Positions and
// radii are copied in key order so the pair loops read memory sequentially.
//
// Cell side: at least the largest reach of a pair within the level (2 R, padded by the frame's
// rounding margins), so two overlapping discs of the level lie in the same or adjacent cells.
// It is widened when the frame would need more than 2^30 cells per axis (keys stay < 2^61), so
// huge coordinates cost precision of the buckets, never correctness.
//
// Build O(n) (two or three radix passes for ordinary extents, std::sort when the key space
// exceeds 32 bits), pair enumeration O(n + candidates), box query O(rows log n + candidates).
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "index/collision_common.hpp"
#include "util/executor.hpp"

namespace crowddb::index {

class CellIndex {
 public:
  // Buckets `rows` of d (all rows when empty) with cell side >= 2 * reach(R); R must be >= every
  // radius among them. The frame is that of all discs the caller will ever query against.
  // With an executor, large builds run their passes in chunks on its threads (the same index);
  // the radix sort's passes only from kParallelRadix rows: every chunk scatters its rows over the
  // whole array, and below that one thread sorts as fast (a 22-bit key over 4 * 10^5 rows: 1.22
  // ms on one thread, 1.29 on two; over 10^6 rows 5.9 against 3.4 ms).
  static constexpr std::size_t kParallelRadix = std::size_t{1} << 19;
  void build(const DiscView& d, std::span<const uint32_t> rows, const Frame& frame, double R,
             Executor* ex = nullptr);
  void build_all(const DiscView& d, const Frame& frame, double R, Executor* ex = nullptr) {
    build(d, {}, frame, R, ex);
  }

  std::size_t size() const { return key_.size(); }
  double max_radius() const { return R_; }
  double cell() const { return cell_; }

  // Appends every overlapping pair within the level (rows, i < j; unsorted).
  void pairs(PairList& out, uint64_t& tests) const;

  // Calls fn(k) for every entry k (position in key order) that a disc of radius qr at (qx, qy)
  // may overlap: a superset, the entries of the cells that cover its box grown by R.
  template <class F>
  void for_each_near(double qx, double qy, double qr, F&& fn) const;

  // Calls fn(a, b) for every pair of entries (positions in key order) in the same or adjacent
  // cells, each pair once: a cell with itself and with its east, north-west, north and
  // north-east neighbours. Returns the number of pairs. With [from, to): only the pairs whose
  // first entry's cell begins in it (a cell is owned by the range its first entry falls in), so
  // ranges that cover [0, size()) share the pairs out, each pair once.
  template <class F>
  uint64_t for_each_candidate(F&& fn, std::size_t from = 0, std::size_t to = SIZE_MAX) const;

  // Calls fn(begin, end, nb) for every non-empty cell in key order, where [begin, end) are its
  // entries and nb[0..2] the entry ranges {first, last} of the 3 x 3 block around it, one per
  // row of cells (row below, own row, row above). O(n) in total: monotone pointers, no search.
  template <class F>
  void for_each_block(F&& fn) const;

  // Entry accessors (k: position in key order).
  uint32_t row(std::size_t k) const { return row_[k]; }
  double x(std::size_t k) const { return x_[k]; }
  double y(std::size_t k) const { return y_[k]; }
  double r(std::size_t k) const { return r_[k]; }

  // For a scan over cells in key order: [begin, end) of each cell, its key, and helpers to find
  // neighbouring cells.
  uint64_t key(std::size_t k) const { return key_[k]; }
  int64_t width() const { return W_; }
  int64_t height() const { return H_; }

 private:
  int64_t cell_of(double u) const;  // clamped to [0, W) (same rounding everywhere)
  int64_t row_of(double v) const;   // clamped to [0, H)

  Frame frame_;
  double R_ = 0, cell_ = 1;
  int64_t W_ = 1, H_ = 1;
  std::vector<uint64_t> key_;
  std::vector<uint32_t> row_;
  std::vector<double> x_, y_, r_;
  std::vector<uint64_t> packed_;
  RadixScratch radix_;
};

template <class F>
void CellIndex::for_each_near(double qx, double qy, double qr, F&& fn) const {
  if (key_.empty()) return;
  const double u = qx - frame_.x0, v = qy - frame_.y0;
  const double reach = frame_.reach(qr + R_, std::abs(u) + std::abs(v));
  const int64_t cx0 = cell_of(u - reach), cx1 = cell_of(u + reach);
  const int64_t cy0 = row_of(v - reach), cy1 = row_of(v + reach);
  for (int64_t cy = cy0; cy <= cy1; ++cy) {
    const auto lo = static_cast<uint64_t>(cy * W_ + cx0), hi = static_cast<uint64_t>(cy * W_ + cx1);
    auto it = std::lower_bound(key_.begin(), key_.end(), lo);
    for (; it != key_.end() && *it <= hi; ++it) fn(static_cast<std::size_t>(it - key_.begin()));
  }
}

template <class F>
uint64_t CellIndex::for_each_candidate(F&& fn, std::size_t from, std::size_t to) const {
  const std::size_t n = key_.size();
  // Both ends moved forward to a cell's first entry.
  auto cell_start = [&](std::size_t p) {
    p = std::min(p, n);
    while (p > 0 && p < n && key_[p] == key_[p - 1]) ++p;
    return p;
  };
  from = cell_start(from);
  to = cell_start(to);
  const auto W = static_cast<uint64_t>(W_), H = static_cast<uint64_t>(H_);
  uint64_t count = 0;
  auto block = [&](std::size_t a0, std::size_t a1, std::size_t b0, std::size_t b1) {
    for (std::size_t a = a0; a < a1; ++a)
      for (std::size_t b = b0; b < b1; ++b) fn(a, b);
    count += (a1 - a0) * (b1 - b0);
  };
  std::size_t next_row = from;   // first entry with key >= (this key + W - 1): monotone in it
  uint64_t cy = 0, row_key = 0;  // the current key's row of cells and that row's first key
  for (std::size_t i = from; i < to;) {
    const uint64_t k = key_[i];
    std::size_t e = i + 1;
    while (e < n && key_[e] == k) ++e;
    // Keys ascend: the row changes at most once per occupied row, so divide only then (two
    // divisions per cell were most of this loop's time on a sparse grid).
    if (k >= row_key + W) cy = k / W, row_key = cy * W;
    const uint64_t cx = k - row_key;
    for (std::size_t a = i; a < e; ++a)  // within the cell
      for (std::size_t b = a + 1; b < e; ++b) fn(a, b);
    count += (e - i) * (e - i - 1) / 2;
    if (cx + 1 < W && e < n && key_[e] == k + 1) {  // east: the next run, if it is the next cell
      std::size_t f = e + 1;
      while (f < n && key_[f] == k + 1) ++f;
      block(i, e, e, f);
    }
    if (cy + 1 < H) {  // the three cells of the next row
      const uint64_t lo = k + W - (cx > 0 ? 1 : 0), hi = k + W + (cx + 1 < W ? 1 : 0);
      while (next_row < n && key_[next_row] < lo) ++next_row;
      std::size_t f = next_row;
      while (f < n && key_[f] <= hi) ++f;
      if (f > next_row) block(i, e, next_row, f);
    }
    i = e;
  }
  return count;
}

template <class F>
void CellIndex::for_each_block(F&& fn) const {
  const std::size_t n = key_.size();
  const auto W = static_cast<uint64_t>(W_), H = static_cast<uint64_t>(H_);
  std::size_t ptr[3] = {0, 0, 0};  // per row offset: first entry with key >= block's low key
  std::size_t nb[3][2];
  uint64_t cy = 0, row_key = 0;  // as in for_each_candidate
  for (std::size_t i = 0; i < n;) {
    const uint64_t k = key_[i];
    std::size_t e = i + 1;
    while (e < n && key_[e] == k) ++e;
    if (k >= row_key + W) cy = k / W, row_key = cy * W;
    const uint64_t cx = k - row_key;
    for (int d = 0; d < 3; ++d) {
      nb[d][0] = nb[d][1] = 0;
      if ((d == 0 && cy == 0) || (d == 2 && cy + 1 >= H)) continue;
      const uint64_t mid = d == 0 ? k - W : (d == 1 ? k : k + W);
      const uint64_t lo = mid - (cx > 0 ? 1 : 0), hi = mid + (cx + 1 < W ? 1 : 0);
      std::size_t& p = ptr[d];
      while (p < n && key_[p] < lo) ++p;
      std::size_t f = p;
      while (f < n && key_[f] <= hi) ++f;
      nb[d][0] = p;
      nb[d][1] = f;
    }
    fn(i, e, nb);
    i = e;
  }
}

}  // namespace crowddb::index
