// The grids' shared counting sort and bounding box (src/index/row_buckets.*) against their naive
// twins: a stable sort of the rows by cell, and a min / max over every row.
#include "index/row_buckets.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

#include "util/executor.hpp"

namespace crowddb::index {
namespace {

TEST(RowBuckets, PlacesRowsAsAStableSortByCell) {
  std::mt19937_64 rng(3);
  std::vector<uint32_t> start, rows;  // reused between rounds, as the grids do
  for (const std::size_t n : {0, 1, 2, 17, 1000, 20000}) {
    for (const std::size_t cells : {1, 2, 7, 5000}) {
      std::uniform_int_distribution<int64_t> pick(0, static_cast<int64_t>(cells) - 1);
      std::vector<int64_t> cell_of(n);
      for (int64_t& c : cell_of) c = pick(rng);
      if (n > 0) cell_of[n / 2] = static_cast<int64_t>(cells) - 1;  // the last cell too
      bucket_rows(cell_of, cells, start, rows);
      std::vector<uint32_t> want(n);
      std::iota(want.begin(), want.end(), 0u);
      std::stable_sort(want.begin(), want.end(),
                       [&](uint32_t a, uint32_t b) { return cell_of[a] < cell_of[b]; });
      ASSERT_EQ(rows, want) << n << " rows, " << cells << " cells";
      ASSERT_EQ(start.size(), cells + 1);
      EXPECT_EQ(start.front(), 0u);
      EXPECT_EQ(start.back(), n);
      for (std::size_t c = 0; c < cells; ++c)
        for (uint32_t a = start[c]; a < start[c + 1]; ++a)
          ASSERT_EQ(cell_of[rows[a]], static_cast<int64_t>(c)) << "cell " << c;
    }
  }
}

TEST(RowBuckets, BoundingBoxIsTheMinAndMaxOnAnyThreadCount) {
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> u(-1e6, 1e6);
  for (const std::size_t n : {0, 1, 8191, 8192, 8193, 50000}) {
    std::vector<double> x(n), y(n);
    for (std::size_t i = 0; i < n; ++i) {
      x[i] = u(rng);
      y[i] = u(rng) * 1e-3;
    }
    if (n > 3) {  // extremes in the last chunk and at the very end
      x[n - 1] = 2e6;
      y[n - 2] = -5e3;
    }
    Box want = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (std::size_t i = 0; i < n; ++i) {
      want.xmin = std::min(want.xmin, x[i]);
      want.ymin = std::min(want.ymin, y[i]);
      want.xmax = std::max(want.xmax, x[i]);
      want.ymax = std::max(want.ymax, y[i]);
    }
    for (int threads : {1, 2}) {
      Executor ex(threads);
      const Box got = bounding_box(x, y, ex);
      EXPECT_EQ(got.xmin, want.xmin) << n << " rows, " << threads << " threads";
      EXPECT_EQ(got.ymin, want.ymin);
      EXPECT_EQ(got.xmax, want.xmax);
      EXPECT_EQ(got.ymax, want.ymax);
    }
  }
}

}  // namespace
}  // namespace crowddb::index
