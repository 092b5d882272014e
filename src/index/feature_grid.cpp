#include "index/feature_grid.hpp"

#include <algorithm>
#include <cmath>

#include "index/row_buckets.hpp"
#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::index {
namespace {

constexpr std::size_t kFeatureGrain = 256;

// A feature's bounding box (Box of index/row_buckets.hpp).
Box feature_box(const StaticScene& scene, std::size_t f) {
  if (f < scene.circles().size()) {
    const CircleObstacle& c = scene.circles()[f];
    return {c.x - c.radius, c.y - c.radius, c.x + c.radius, c.y + c.radius};
  }
  const auto [a, b] = scene.edge(f);
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y)};
}

}  // namespace

void FeatureGrid::build(const StaticScene& scene, double cell) {
  generation_ = scene.generation();
  const std::size_t F = scene.feature_count();
  x0_ = y0_ = INFINITY;
  x1_ = y1_ = -INFINITY;
  for (std::size_t f = 0; f < F; ++f) {
    const Box b = feature_box(scene, f);
    x0_ = std::min(x0_, b.xmin);
    y0_ = std::min(y0_, b.ymin);
    x1_ = std::max(x1_, b.xmax);
    y1_ = std::max(y1_, b.ymax);
  }
  W_ = H_ = 0;
  start_.assign(1, 0);
  items_.clear();
  if (F == 0) return;
  const double side = std::max({x1_ - x0_, y1_ - y0_, 1e-9});
  cell_ = std::max(cell, side / 1024);
  if (!(cell_ > 0) || !std::isfinite(cell_)) cell_ = side;
  inv_cell_ = 1 / cell_;
  W_ = static_cast<int64_t>(std::floor((x1_ - x0_) / cell_)) + 1;
  H_ = static_cast<int64_t>(std::floor((y1_ - y0_) / cell_)) + 1;
  // (cell, feature) registrations in feature order, then a counting sort by cell: each cell's
  // features stay ascending. One vector per cell instead took 40 ms on a walled 200 m square (the
  // walls reach 200 m beyond it: 667 x 667 cells); now 14-20 ms, most of it the first touch of
  // the per-cell arrays' memory.
  const std::size_t cells = static_cast<std::size_t>(W_ * H_);
  std::vector<int64_t> reg_cell;
  std::vector<uint32_t> reg_feature;
  const double half_diag = cell_ * std::sqrt(0.5) * (1 + 1e-9);
  for (std::size_t f = 0; f < F; ++f) {
    const Box b = feature_box(scene, f);
    const int64_t cx0 =
        std::clamp<int64_t>(static_cast<int64_t>(std::floor((b.xmin - x0_) / cell_)), 0, W_ - 1);
    const int64_t cx1 =
        std::clamp<int64_t>(static_cast<int64_t>(std::floor((b.xmax - x0_) / cell_)), 0, W_ - 1);
    const int64_t cy0 =
        std::clamp<int64_t>(static_cast<int64_t>(std::floor((b.ymin - y0_) / cell_)), 0, H_ - 1);
    const int64_t cy1 =
        std::clamp<int64_t>(static_cast<int64_t>(std::floor((b.ymax - y0_) / cell_)), 0, H_ - 1);
    const bool edge = f >= scene.circles().size();
    for (int64_t cy = cy0; cy <= cy1; ++cy)
      for (int64_t cx = cx0; cx <= cx1; ++cx) {
        if (edge && (cx1 > cx0 + 1 || cy1 > cy0 + 1)) {
          // A long edge: only the cells it passes near (their centre within half a diagonal).
          const double mx = x0_ + (static_cast<double>(cx) + 0.5) * cell_;
          const double my = y0_ + (static_cast<double>(cy) + 0.5) * cell_;
          if (feature_dist2(scene, f, mx, my) > half_diag * half_diag) continue;
        }
        reg_cell.push_back(cy * W_ + cx);
        reg_feature.push_back(static_cast<uint32_t>(f));
      }
  }
  std::vector<uint32_t> order;
  bucket_rows(reg_cell, cells, start_, order);
  items_.resize(order.size());
  for (std::size_t a = 0; a < order.size(); ++a) items_[a] = reg_feature[order[a]];
  // Chebyshev distance transform (two passes, each cell from its four earlier neighbours).
  constexpr uint16_t kFar = UINT16_MAX;  // > 1025, the most cells an axis has
  clear_.assign(cells, kFar);
  for (std::size_t c = 0; c < cells; ++c)
    if (start_[c + 1] > start_[c]) clear_[c] = 0;
  const auto at = [&](int64_t cx, int64_t cy) -> uint16_t& {
    return clear_[static_cast<std::size_t>(cy * W_ + cx)];
  };
  auto relax = [&](int64_t cx, int64_t cy, int64_t nx, int64_t ny) {
    if (nx < 0 || ny < 0 || nx >= W_ || ny >= H_) return;
    const uint16_t d = at(nx, ny);
    if (d != kFar && d + 1 < at(cx, cy)) at(cx, cy) = static_cast<uint16_t>(d + 1);
  };
  for (int64_t cy = 0; cy < H_; ++cy)
    for (int64_t cx = 0; cx < W_; ++cx) {
      relax(cx, cy, cx - 1, cy);
      relax(cx, cy, cx - 1, cy - 1);
      relax(cx, cy, cx, cy - 1);
      relax(cx, cy, cx + 1, cy - 1);
    }
  for (int64_t cy = H_ - 1; cy >= 0; --cy)
    for (int64_t cx = W_ - 1; cx >= 0; --cx) {
      relax(cx, cy, cx + 1, cy);
      relax(cx, cy, cx + 1, cy + 1);
      relax(cx, cy, cx, cy + 1);
      relax(cx, cy, cx - 1, cy + 1);
    }
}

void FeatureGrid::run(const DiscView& p, std::span<const double> reach, const StaticScene& scene,
                      FeatureLists& out, Executor& ex, QueryStats& stats) {
  Stopwatch sw;
  if (generation_ != scene.generation()) {
    double mean = 0;
    for (std::size_t i = 0; i < p.n; ++i) mean += reach[i];
    build(scene, p.n ? mean / static_cast<double>(p.n) : 1.0);
    stats.build_seconds += sw.seconds();
    sw.restart();
  }
  const std::size_t chunks = (p.n + kFeatureGrain - 1) / kFeatureGrain;
  ListChunks lists;
  lists.reset(chunks);
  std::vector<uint64_t> tests(chunks, 0);
  ex.for_each_chunk(p.n, kFeatureGrain, [&](std::size_t b, std::size_t e) {
    const std::size_t c = b / kFeatureGrain;
    // The chunk's lists and count are its own until the end (util/executor.hpp).
    ListChunks::Chunk mine;
    mine.counts.reserve(e - b);  // one allocation, not one per doubling
    uint64_t tests_c = 0;
    std::vector<uint32_t> cand;
    for (std::size_t i = b; i < e; ++i) {
      const double px = p.x[i], py = p.y[i], r = reach[i];
      uint32_t count = 0;
      cand.clear();
      if (W_ > 0 && px + r >= x0_ && px - r <= x1_ && py + r >= y0_ && py - r <= y1_) {
        // Clamped in double before the conversion, which a far-away probe would overflow.
        auto clamp_cell = [&](double v, int64_t n) {
          const double k = std::floor(v / cell_);
          return !(k > 0)                          ? int64_t{0}
                 : k >= static_cast<double>(n - 1) ? n - 1
                                                   : static_cast<int64_t>(k);
        };
        auto clamp_col = [&](double x) { return clamp_cell(x - x0_, W_); };
        auto clamp_row = [&](double y) { return clamp_cell(y - y0_, H_); };
        // Far from every feature: nothing to look at (see the header). A point outside the
        // grid is binned to the border cell, which is nearer to every feature than it is. The
        // cell by a product with the inverse, not a division (the obstacle query 44.6 -> 38.8 ms
        // per 100 ticks at airport-20k, one thread): it is the true cell or a neighbour of it,
        // as the division's is, and the test's margin allows for that.
        const uint16_t m =
            clear_[static_cast<std::size_t>(cell_by_product(py - y0_, inv_cell_, H_) * W_ +
                                            cell_by_product(px - x0_, inv_cell_, W_))];
        const double slack = 1e-9 * (cell_ + std::abs(px) + std::abs(py) + r);
        if (m >= 3 && static_cast<double>(m - 3) * cell_ > r + slack) {
          mine.counts.push_back(0);
          continue;
        }
        // One cell of slack on each side against rounding of the box.
        const int64_t cx0 = std::max<int64_t>(0, clamp_col(px - r) - 1);
        const int64_t cx1 = std::min<int64_t>(W_ - 1, clamp_col(px + r) + 1);
        const int64_t cy0 = std::max<int64_t>(0, clamp_row(py - r) - 1);
        const int64_t cy1 = std::min<int64_t>(H_ - 1, clamp_row(py + r) + 1);
        for (int64_t cy = cy0; cy <= cy1; ++cy) {
          const auto base = static_cast<std::size_t>(cy * W_);
          for (uint32_t a = start_[base + static_cast<std::size_t>(cx0)];
               a < start_[base + static_cast<std::size_t>(cx1) + 1]; ++a)
            cand.push_back(items_[a]);
        }
        std::sort(cand.begin(), cand.end());
        cand.erase(std::unique(cand.begin(), cand.end()), cand.end());
        const double r2 = r * r;
        for (uint32_t f : cand) {
          const double d2 = feature_dist2(scene, f, px, py);
          if (d2 < r2) {
            mine.items.push_back(f);
            mine.d2.push_back(d2);
            ++count;
          }
        }
        tests_c += cand.size();
      }
      mine.counts.push_back(count);
    }
    tests[c] = tests_c;
    lists.put(c, std::move(mine));
  });
  lists.gather(out, &FeatureLists::feature, &ex);
  stats.rows += p.n;
  for (uint64_t t : tests) stats.pair_tests += t;
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
