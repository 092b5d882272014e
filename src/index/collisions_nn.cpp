#include "index/collisions_nn.hpp"

#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::index {
namespace {

constexpr uint32_t kNone = UINT32_MAX;
constexpr std::size_t kParallelEntries = 4096;  // below, one pass: the merge would not pay

}  // namespace

void CollisionNn::run(const DiscView& d, const StaticScene& scene, CollisionPairs& out,
                      Executor& ex, QueryStats& stats) {
  out.clear();
  grid_.clear();  // lent by disc_grid() only when built for these discs
  if (d.n == 0) return;
  const double R = d.radius[0];
  for (std::size_t i = 1; i < d.n; ++i)
    if (d.radius[i] != R)
      throw Error(Error::Kind::usage, "collision method 'nn' needs equal radii (row " +
                                          std::to_string(i) +
                                          " differs from row 0); use grid, sweep or naive");
  Stopwatch sw;
  grid_.build(d, &ex);  // equal radii: one level, cells of side >= 2R
  if (!grid_.usable()) {
    CollisionNaive().run(d, scene, out, ex, stats);
    return;
  }
  const CellIndex& cells = grid_.levels().front();
  const Frame& frame = grid_.frame();
  stats.build_seconds += sw.seconds();
  sw.restart();
  // Each candidate pair once (half neighbourhood), updating both discs' nearest neighbour:
  // the order of updates does not matter, (distance, row) is a total order.
  const double rsum = R + R, limit = rsum * rsum;
  const std::size_t m = cells.size();
  // On several threads each takes the cells of one range of entries and keeps its own nearest
  // per entry (a pair may touch an entry of the other range); the lists are merged by the same
  // total order, (distance, row), so the result is that of one pass.
  const std::size_t parts = ex.threads() > 1 && m >= kParallelEntries ? 2 : 1;
  best_.resize(parts);
  best_row_.resize(parts);
  std::vector<uint64_t> part_tests(parts, 0);
  ex.for_each_chunk(parts, 1, [&](std::size_t p, std::size_t) {
    std::vector<double>& best = best_[p];
    std::vector<uint32_t>& best_row = best_row_[p];
    best.assign(m, limit);
    best_row.assign(m, kNone);
    auto offer = [&](std::size_t k, double d2, uint32_t row) {
      if (d2 < best[k] || (d2 == best[k] && best_row[k] != kNone && row < best_row[k])) {
        best[k] = d2;
        best_row[k] = row;
      }
    };
    part_tests[p] = cells.for_each_candidate(
        [&](std::size_t a, std::size_t b) {
          const double dx = cells.x(b) - cells.x(a), dy = cells.y(b) - cells.y(a);
          const double d2 = dx * dx + dy * dy;  // as discs_overlap computes it
          if (d2 < limit) {
            offer(a, d2, cells.row(b));
            offer(b, d2, cells.row(a));
          }
        },
        m * p / parts, m * (p + 1) / parts);
  });
  uint64_t tests = 0;
  for (uint64_t t : part_tests) tests += t;
  std::vector<double>& best = best_[0];
  std::vector<uint32_t>& best_row = best_row_[0];
  for (std::size_t p = 1; p < parts; ++p)
    for (std::size_t k = 0; k < m; ++k) {
      const double d2 = best_[p][k];
      const uint32_t row = best_row_[p][k];
      if (row == kNone) continue;
      if (best_row[k] == kNone || d2 < best[k] || (d2 == best[k] && row < best_row[k])) {
        best[k] = d2;
        best_row[k] = row;
      }
    }
  for (std::size_t k = 0; k < m; ++k)
    if (best_row[k] != kNone) out.agents.push_back(ordered(cells.row(k), best_row[k]));
  finish_pairs(out.agents);
  if (!scene.empty()) {
    obstacles_.build(scene, frame);
    obstacles_.overlaps(d, out.obstacles, tests, ex);
  }
  stats.pair_tests += tests;
  stats.rows += d.n;
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
