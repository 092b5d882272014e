// Boxes bucketed into a uniform grid over their extent, for lookups that list which boxes may
// meet a window: ObstacleLookup (obstacles' boxes) and RingGrid (a polygon's edges' boxes).
//
// Cells about as wide as the boxes are apart, or as large as they are, whichever is more; at most
// `max_side` per axis, and no finer than 10^-12 of the coordinates, so a one-cell margin exceeds
// any rounding of a caller's crossing or window edge (points within 10^9 m). Bounded by the
// input: a box spanning more than kMaxCells cells (a long wall, a long edge) is kept in a list
// every question scans instead of being registered cell by cell, and a window of more cells than
// there are boxes lists them all. Registrations in box order (count, then place: CSR) keep each
// cell's list sorted; collect() returns ids sorted, each once.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "util/bucket_lists.hpp"
#include "world/geometry.hpp"  // BoxBounds

namespace crowddb {

class BoxGrid {
 public:
  BoxGrid() = default;
  BoxGrid(std::span<const BoxBounds> boxes, int64_t max_side) : count_(boxes.size()) {
    max_side = std::clamp<int64_t>(max_side, 1, 1 << 20);  // (cells per axis fit first_'s int32)
    BoxBounds all;                                         // (empty)
    double extent = 0;  // the boxes' mean larger side: cells no smaller than a box
    for (const BoxBounds& b : boxes) {
      all = {std::min(all.x0, b.x0), std::min(all.y0, b.y0), std::max(all.x1, b.x1),
             std::max(all.y1, b.y1)};
      extent += std::max(b.x1 - b.x0, b.y1 - b.y0);
    }
    if (count_ == 0 || !(all.x1 - all.x0 < INFINITY && all.y1 - all.y0 < INFINITY)) {
      for (std::size_t k = 0; k < count_; ++k) big_.push_back(static_cast<uint32_t>(k));
      return;  // nothing to bucket, or coordinates beyond any grid: every question scans
    }
    x0_ = all.x0;
    y0_ = all.y0;
    const double w = std::max(all.x1 - all.x0, 1e-9), h = std::max(all.y1 - all.y0, 1e-9);
    const double magnitude =
        std::max({std::abs(all.x0), std::abs(all.x1), std::abs(all.y0), std::abs(all.y1)});
    const auto n = static_cast<double>(count_);
    const auto side = static_cast<double>(max_side);
    cell_ = std::max({std::sqrt(w * h / n), extent / n, w / side, h / side, 1e-12 * magnitude});
    nx_ = std::clamp<int64_t>(static_cast<int64_t>(w / cell_) + 1, 1, max_side + 1);
    ny_ = std::clamp<int64_t>(static_cast<int64_t>(h / cell_) + 1, 1, max_side + 1);
    // Each box's first cell, or its place in the list every question scans (big_).
    first_.resize(count_);
    for (std::size_t k = 0; k < count_; ++k) {
      const BoxBounds& b = boxes[k];
      const int64_t cx0 = cell_x(b.x0), cy0 = cell_y(b.y0);
      if ((cell_x(b.x1) - cx0 + 1) * (cell_y(b.y1) - cy0 + 1) > kMaxCells) {
        first_[k] = {kBig, kBig};
        big_.push_back(static_cast<uint32_t>(k));
      } else {
        first_[k] = {static_cast<int32_t>(cx0), static_cast<int32_t>(cy0)};
      }
    }
    fill_bucket_lists(
        static_cast<std::size_t>(nx_ * ny_), count_,
        [&](std::size_t k, auto&& to) {
          if (first_[k].x == kBig) return;
          const int64_t cx1 = cell_x(boxes[k].x1), cy1 = cell_y(boxes[k].y1);
          for (int64_t cy = first_[k].y; cy <= cy1; ++cy)
            for (int64_t cx = first_[k].x; cx <= cx1; ++cx)
              to(static_cast<std::size_t>(cy * nx_ + cx));
        },
        start_, ids_);
  }

  // The boxes collect() would list, each once, in no set order: f(id) for each. Where a box is
  // registered in several cells of the window, only the window's cell nearest its own first
  // cell (the larger of the two firsts on each axis) calls f; no list, no sort. Returns the
  // cells read.
  template <class F>
  std::size_t visit(int64_t cx0, int64_t cx1, int64_t cy0, int64_t cy1, F&& f) const {
    if (!gridded() || static_cast<double>(cx1 - cx0 + 1) * static_cast<double>(cy1 - cy0 + 1) >
                          static_cast<double>(count_)) {
      for (std::size_t k = 0; k < count_; ++k) f(static_cast<uint32_t>(k));
      return 0;
    }
    cx0 = std::max<int64_t>(cx0, 0), cx1 = std::min(cx1, nx_ - 1);
    cy0 = std::max<int64_t>(cy0, 0), cy1 = std::min(cy1, ny_ - 1);
    for (const uint32_t k : big_) f(k);
    for (int64_t cy = cy0; cy <= cy1; ++cy)
      for (int64_t cx = cx0; cx <= cx1; ++cx) {
        const auto c = static_cast<std::size_t>(cy * nx_ + cx);
        for (uint32_t a = start_[c]; a < start_[c + 1]; ++a) {
          const uint32_t k = ids_[a];
          const FirstCell first = first_[k];
          if ((cx == cx0 || first.x == cx) && (cy == cy0 || first.y == cy)) f(k);
        }
      }
    return static_cast<std::size_t>(std::max<int64_t>(cx1 - cx0 + 1, 0) *
                                    std::max<int64_t>(cy1 - cy0 + 1, 0));
  }

  bool gridded() const { return !start_.empty(); }
  int64_t nx() const { return nx_; }
  int64_t ny() const { return ny_; }
  std::size_t count() const { return count_; }
  double cell() const { return cell_; }
  // The grid's corner: cell (i, j) covers [x0 + i cell, x0 + (i + 1) cell) x (likewise in y).
  double x0() const { return x0_; }
  double y0() const { return y0_; }
  // Boxes every question scans: for tests.
  std::size_t scanned() const { return big_.size(); }

  // Clamped into the grid: a point outside it asks the border cells, which hold every box that
  // reaches there (a superset stays a superset).
  int64_t cell_x(double v) const { return clamp_cell((v - x0_) / cell_, nx_); }
  int64_t cell_y(double v) const { return clamp_cell((v - y0_) / cell_, ny_); }

  // Every id, in order.
  void all(std::vector<uint32_t>& out) const {
    out.resize(count_);
    for (std::size_t k = 0; k < count_; ++k) out[k] = static_cast<uint32_t>(k);
  }
  // The boxes registered in cells [cx0, cx1] x [cy0, cy1] (clamped into the grid) and the big
  // ones, sorted, each once; every box where there is no grid or the window, as given, has more
  // cells than there are boxes. `out` is overwritten. Returns the cells read.
  std::size_t collect(int64_t cx0, int64_t cx1, int64_t cy0, int64_t cy1,
                      std::vector<uint32_t>& out) const {
    if (!gridded() || static_cast<double>(cx1 - cx0 + 1) * static_cast<double>(cy1 - cy0 + 1) >
                          static_cast<double>(count_)) {
      all(out);
      return 0;
    }
    cx0 = std::max<int64_t>(cx0, 0), cx1 = std::min(cx1, nx_ - 1);
    cy0 = std::max<int64_t>(cy0, 0), cy1 = std::min(cy1, ny_ - 1);
    out = big_;
    for (int64_t cy = cy0; cy <= cy1; ++cy)
      for (int64_t cx = cx0; cx <= cx1; ++cx) {
        const auto c = static_cast<std::size_t>(cy * nx_ + cx);
        out.insert(out.end(), ids_.begin() + start_[c], ids_.begin() + start_[c + 1]);
      }
    std::sort(out.begin(), out.end());
    out.erase(std::unique(out.begin(), out.end()), out.end());
    return static_cast<std::size_t>(std::max<int64_t>(cx1 - cx0 + 1, 0) *
                                    std::max<int64_t>(cy1 - cy0 + 1, 0));
  }

 private:
  static constexpr int64_t kMaxCells = 64;  // cells a box may be registered in

  static int64_t clamp_cell(double c, int64_t n) {
    if (!(c >= 0)) return 0;  // below the grid, or NaN
    return c < static_cast<double>(n - 1) ? static_cast<int64_t>(c) : n - 1;
  }

  std::size_t count_ = 0;
  double x0_ = 0, y0_ = 0, cell_ = 1;
  int64_t nx_ = 0, ny_ = 0;
  std::vector<uint32_t> start_;  // CSR offsets per cell (row-major), nx_ * ny_ + 1; empty: no grid
  std::vector<uint32_t> ids_;    // the boxes registered in each cell, in box order
  std::vector<uint32_t> big_;    // boxes spanning more than kMaxCells cells, in order
  struct FirstCell {
    int32_t x, y;  // (nx_, ny_ <= max_side + 1: callers pass at most a few thousand)
  };
  static constexpr int32_t kBig = -1;  // first_ of a box in big_ (registered in no cell)
  std::vector<FirstCell> first_;       // each registered box's lowest cell on each axis: visit()
};

}  // namespace crowddb
