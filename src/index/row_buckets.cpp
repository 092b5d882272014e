#include "index/row_buckets.hpp"

#include <algorithm>
#include <cmath>

#include "util/executor.hpp"

namespace crowddb::index {
namespace {
constexpr std::size_t kBoxGrain = 8192;  // rows per chunk of the bounding box
}  // namespace

Box bounding_box(std::span<const double> x, std::span<const double> y, Executor& ex) {
  const std::size_t n = x.size();
  std::vector<Box> part((n + kBoxGrain - 1) / kBoxGrain);
  ex.for_each_chunk(n, kBoxGrain, [&](std::size_t b, std::size_t e) {
    Box m = {INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (std::size_t i = b; i < e; ++i) {
      m.xmin = std::min(m.xmin, x[i]);
      m.ymin = std::min(m.ymin, y[i]);
      m.xmax = std::max(m.xmax, x[i]);
      m.ymax = std::max(m.ymax, y[i]);
    }
    part[b / kBoxGrain] = m;
  });
  Box box = {INFINITY, INFINITY, -INFINITY, -INFINITY};
  for (const Box& m : part) {
    box.xmin = std::min(box.xmin, m.xmin);
    box.ymin = std::min(box.ymin, m.ymin);
    box.xmax = std::max(box.xmax, m.xmax);
    box.ymax = std::max(box.ymax, m.ymax);
  }
  return box;
}

void bucket_rows(std::span<const int64_t> cell_of, std::size_t cells, std::vector<uint32_t>& start,
                 std::vector<uint32_t>& rows) {
  const std::size_t n = cell_of.size();
  start.assign(cells + 1, 0);
  for (std::size_t i = 0; i < n; ++i) ++start[static_cast<std::size_t>(cell_of[i])];
  for (std::size_t c = 1; c < cells; ++c) start[c] += start[c - 1];  // start[c]: cell c's end
  start[cells] = static_cast<uint32_t>(n);
  rows.resize(n);
  for (std::size_t i = n; i-- > 0;)
    rows[--start[static_cast<std::size_t>(cell_of[i])]] = static_cast<uint32_t>(i);
}

}  // namespace crowddb::index
