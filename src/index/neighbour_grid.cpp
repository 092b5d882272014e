#include "index/neighbour_grid.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::index {
namespace {

constexpr std::size_t kGrain = 64;
constexpr std::size_t kCopyGrain = 4096;   // rows per chunk of the lists' compaction
constexpr std::size_t kBuildGrain = 8192;  // rows per chunk of the grid's build

}  // namespace

int64_t NeighbourGrid::col(double x) const {
  const double c = std::floor((x - x0_) / cell_);
  return c < 0 ? 0 : (c >= static_cast<double>(W_) ? W_ - 1 : static_cast<int64_t>(c));
}

int64_t NeighbourGrid::row(double y) const {
  const double c = std::floor((y - y0_) / cell_);
  return c < 0 ? 0 : (c >= static_cast<double>(H_) ? H_ - 1 : static_cast<int64_t>(c));
}

// The counting sort's passes over the rows run in chunks on every thread (the bounding box, each
// row's cell, the copies in cell order); the count, its prefix sum and the placement, a few
// instructions per row, stay in one pass in row order, so the layout is that of one thread.
void NeighbourGrid::build(const DiscView& d, double range, uint32_t k, Executor& ex) {
  const std::size_t chunks = (d.n + kBuildGrain - 1) / kBuildGrain;
  std::vector<std::array<double, 4>> box(chunks);  // min x, min y, -max x, -max y
  ex.for_each_chunk(d.n, kBuildGrain, [&](std::size_t b, std::size_t e) {
    std::array<double, 4> m = {INFINITY, INFINITY, INFINITY, INFINITY};
    for (std::size_t i = b; i < e; ++i) {
      m[0] = std::min(m[0], d.x[i]);
      m[1] = std::min(m[1], d.y[i]);
      m[2] = std::min(m[2], -d.x[i]);
      m[3] = std::min(m[3], -d.y[i]);
    }
    box[b / kBuildGrain] = m;
  });
  double xmin = INFINITY, ymin = INFINITY, xmax = -INFINITY, ymax = -INFINITY;
  for (const auto& m : box) {  // min and max are exact: the order of the chunks is immaterial
    xmin = std::min(xmin, m[0]);
    ymin = std::min(ymin, m[1]);
    xmax = std::max(xmax, -m[2]);
    ymax = std::max(ymax, -m[3]);
  }
  const double w = std::max(xmax - xmin, 1e-9), h = std::max(ymax - ymin, 1e-9);
  const auto n = static_cast<double>(std::max<std::size_t>(d.n, 1));
  const double density = n / (w * h);
  double cell = k ? std::sqrt(2.0 * k / (9.0 * density)) : range / 2;
  cell = std::min(cell, range);
  cell = std::max(cell, std::sqrt(w * h / (4 * n)));  // at most ~4 cells per disc
  if (!(cell > 0) || !std::isfinite(cell)) cell = std::max(w, h);
  x0_ = xmin;
  y0_ = ymin;
  cell_ = cell;
  W_ = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(w / cell)) + 1);
  H_ = std::max<int64_t>(1, static_cast<int64_t>(std::ceil(h / cell)) + 1);
  const auto cells = static_cast<std::size_t>(W_ * H_);
  start_.assign(cells + 1, 0);
  cell_of_.resize(d.n);
  ex.for_each_chunk(d.n, kBuildGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) cell_of_[i] = row(d.y[i]) * W_ + col(d.x[i]);
  });
  for (std::size_t i = 0; i < d.n; ++i) ++start_[static_cast<std::size_t>(cell_of_[i]) + 1];
  for (std::size_t c = 0; c < cells; ++c) start_[c + 1] += start_[c];
  rows_.resize(d.n);
  x_.resize(d.n);
  y_.resize(d.n);
  id_.resize(d.n);
  fill_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < d.n; ++i)
    rows_[fill_[static_cast<std::size_t>(cell_of_[i])]++] = static_cast<uint32_t>(i);
  ex.for_each_chunk(d.n, kBuildGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t a = b; a < e; ++a) {
      const uint32_t i = rows_[a];
      x_[a] = d.x[i];
      y_[a] = d.y[i];
      id_[a] = d.id[i];
    }
  });
}

void NeighbourGrid::run(const DiscView& d, std::span<const uint32_t> queries, double range,
                        uint32_t k, NeighbourLists& out, Executor& ex, QueryStats& stats) {
  Stopwatch sw;
  build(d, range, k, ex);
  stats.build_seconds += sw.seconds();
  sw.restart();
  const std::size_t q = queries.empty() ? d.n : queries.size();
  const double r2 = range * range;
  const std::size_t chunks = (q + kGrain - 1) / kGrain;
  ListChunks lists;
  lists.reset(chunks);
  std::vector<uint64_t> tests(chunks, 0), rings(chunks, 0);
  // Raw pointers into the grid, hoisted: writes to the per-query lists could otherwise alias
  // them and force a reload of every vector's data pointer per candidate.
  const double* const X = x_.data();
  const double* const Y = y_.data();
  const uint32_t* const R = rows_.data();
  const uint64_t* const I = id_.data();
  const uint32_t* const S = start_.data();
  // Every row with a bounded k: walk the queries in the grid's cell order (neighbouring queries
  // read the same cells, which stay in cache) and write each list into its row's own slot of k;
  // the slots are compacted into the CSR in row order afterwards. Otherwise: query order, lists
  // gathered per chunk.
  const bool spatial = queries.empty() && k > 0;
  if (spatial) {
    slot_count_.assign(d.n, 0);
    slot_row_.resize(d.n * k);
    slot_d2_.resize(d.n * k);
  }
  ex.for_each_chunk(q, kGrain, [&](std::size_t b, std::size_t e) {
    const std::size_t c = b / kGrain;
    NearestK best;
    for (std::size_t qi = b; qi < e; ++qi) {
      const std::size_t i = spatial ? R[qi] : queries.empty() ? qi : queries[qi];
      const double px = d.x[i], py = d.y[i];
      best.reset(k);
      auto scan = [&](int64_t cy, int64_t cx0, int64_t cx1) {
        const auto base = static_cast<std::size_t>(cy * W_);
        const uint32_t lo = S[base + static_cast<std::size_t>(cx0)];
        const uint32_t hi = S[base + static_cast<std::size_t>(cx1) + 1];
        // Candidates beyond the k-th best (ties may still win on id) never reach offer(). The
        // captured values are copied into locals: offer() stores doubles, which could alias
        // them and force a reload of each one per candidate.
        const double x = px, y = py, rr = r2;
        const double* const xs = X;
        const double* const ys = Y;
        const uint32_t* const rs = R;
        const uint64_t* const is = I;
        const std::size_t self = i;
        double limit = std::min(rr, best.bound());
        for (uint32_t a = lo; a < hi; ++a) {
          const double dx = xs[a] - x, dy = ys[a] - y;
          const double d2 = dx * dx + dy * dy;
          if (d2 < rr && d2 <= limit && rs[a] != self) {
            best.offer(rs[a], is[a], d2);
            limit = std::min(rr, best.bound());
          }
        }
        tests[c] += hi - lo;
      };
      const int64_t qx = col(px), qy = row(py);
      if (k == 0) {
        // Every cell the range box touches (one cell of slack against rounding).
        const int64_t cx0 = std::max<int64_t>(0, col(px - range) - 1);
        const int64_t cx1 = std::min<int64_t>(W_ - 1, col(px + range) + 1);
        const int64_t cy0 = std::max<int64_t>(0, row(py - range) - 1);
        const int64_t cy1 = std::min<int64_t>(H_ - 1, row(py + range) + 1);
        for (int64_t cy = cy0; cy <= cy1; ++cy) scan(cy, cx0, cx1);
      } else {
        // Cells are skipped when even their nearest point is farther than the k-th best so
        // far (and than the range); `slack` keeps the test conservative under rounding of the
        // cell coordinates (an entry may sit a rounding error outside its cell's rectangle).
        const double slack = 1e-9 * (cell_ + std::abs(px) + std::abs(py));
        auto cell_far = [&](int64_t cx, int64_t cy) {
          const double lx = x0_ + static_cast<double>(cx) * cell_;
          const double ly = y0_ + static_cast<double>(cy) * cell_;
          const double ddx = std::max({lx - px - slack, px - (lx + cell_) - slack, 0.0});
          const double ddy = std::max({ly - py - slack, py - (ly + cell_) - slack, 0.0});
          const double near2 = ddx * ddx + ddy * ddy;
          return near2 >= r2 || (best.full() && near2 > best.bound());
        };
        auto scan_cell = [&](int64_t cx, int64_t cy) {
          if (!cell_far(cx, cy)) scan(cy, cx, cx);
        };
        // Rings 0 and 1 first, as three runs of adjacent cells (contiguous in the arrays).
        const int64_t bx0 = std::max<int64_t>(0, qx - 1), bx1 = std::min(W_ - 1, qx + 1);
        const int64_t by0 = std::max<int64_t>(0, qy - 1), by1 = std::min(H_ - 1, qy + 1);
        // The query's own row of cells first: its candidates are the likeliest nearest, so the
        // k-th best bound tightens early and more of the other rows' candidates are cut at once.
        scan(qy, bx0, bx1);
        if (by0 < qy) scan(by0, bx0, bx1);
        if (by1 > qy) scan(by1, bx0, bx1);
        rings[c] += 2;
        // Every disc outside the block is at least `gap` away (a side on the grid's edge has
        // nothing beyond it); done when the k-th best, or the range, is strictly nearer.
        double gap = INFINITY;
        if (bx0 > 0) gap = std::min(gap, px - (x0_ + static_cast<double>(bx0) * cell_));
        if (bx1 < W_ - 1) gap = std::min(gap, x0_ + static_cast<double>(bx1 + 1) * cell_ - px);
        if (by0 > 0) gap = std::min(gap, py - (y0_ + static_cast<double>(by0) * cell_));
        if (by1 < H_ - 1) gap = std::min(gap, y0_ + static_cast<double>(by1 + 1) * cell_ - py);
        gap -= slack;
        const bool done = gap > 0 && (gap * gap >= r2 || (best.full() && best.bound() < gap * gap));
        const int64_t max_ring = done ? 1 : std::max({qx, W_ - 1 - qx, qy, H_ - 1 - qy});
        for (int64_t rho = 2; rho <= max_ring; ++rho) {
          const double reach = static_cast<double>(rho - 1) * cell_ * (1 - 1e-9);
          if (reach >= range || (best.full() && best.bound() < reach * reach)) break;
          ++rings[c];
          const int64_t cx0 = std::max<int64_t>(0, qx - rho), cx1 = std::min(W_ - 1, qx + rho);
          for (int64_t cx = cx0; cx <= cx1; ++cx) {
            if (qy - rho >= 0) scan_cell(cx, qy - rho);  // bottom row of the ring
            if (qy + rho < H_) scan_cell(cx, qy + rho);  // top row
          }
          const int64_t cy0 = std::max<int64_t>(0, qy - rho + 1),
                        cy1 = std::min(H_ - 1, qy + rho - 1);
          for (int64_t cy = cy0; cy <= cy1; ++cy) {  // the two side columns
            if (qx - rho >= 0) scan_cell(qx - rho, cy);
            if (qx + rho < W_) scan_cell(qx + rho, cy);
          }
        }
      }
      best.finish();
      if (spatial) {
        slot_count_[i] = static_cast<uint32_t>(best.size());
        std::copy(best.rows().begin(), best.rows().end(),
                  slot_row_.begin() + static_cast<std::ptrdiff_t>(i * k));
        std::copy(best.dist2().begin(), best.dist2().end(),
                  slot_d2_.begin() + static_cast<std::ptrdiff_t>(i * k));
        continue;
      }
      lists.counts[c].push_back(static_cast<uint32_t>(best.size()));
      lists.items[c].insert(lists.items[c].end(), best.rows().begin(), best.rows().end());
      lists.d2[c].insert(lists.d2[c].end(), best.dist2().begin(), best.dist2().end());
    }
  });
  if (spatial) {
    out.offset.resize(d.n + 1);
    out.offset[0] = 0;
    for (std::size_t i = 0; i < d.n; ++i) out.offset[i + 1] = out.offset[i] + slot_count_[i];
    out.row.resize(out.offset[d.n]);
    out.dist2.resize(out.offset[d.n]);
    ex.for_each_chunk(d.n, kCopyGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        std::copy_n(slot_row_.begin() + static_cast<std::ptrdiff_t>(i * k), slot_count_[i],
                    out.row.begin() + out.offset[i]);
        std::copy_n(slot_d2_.begin() + static_cast<std::ptrdiff_t>(i * k), slot_count_[i],
                    out.dist2.begin() + out.offset[i]);
      }
    });
  } else {
    lists.gather(out, &NeighbourLists::row);
  }
  stats.rows += q;
  for (std::size_t c = 0; c < chunks; ++c) {
    stats.pair_tests += tests[c];
    stats.nodes_visited += rings[c];
  }
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
