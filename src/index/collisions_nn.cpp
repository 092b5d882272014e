#include "index/collisions_nn.hpp"

#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::index {
namespace {

constexpr uint32_t kNone = UINT32_MAX;

}  // namespace

void CollisionNn::run(const DiscView& d, const StaticScene& scene, CollisionPairs& out,
                      Executor& ex, QueryStats& stats) {
  out.clear();
  if (d.n == 0) return;
  const double R = d.radius[0];
  for (std::size_t i = 1; i < d.n; ++i)
    if (d.radius[i] != R)
      throw Error(Error::Kind::usage, "collision method 'nn' needs equal radii (row " +
                                          std::to_string(i) +
                                          " differs from row 0); use grid, sweep or naive");
  const Frame frame = Frame::of(d);
  if (!frame.finite) {
    CollisionNaive().run(d, scene, out, ex, stats);
    return;
  }
  Stopwatch sw;
  cells_.build_all(d, frame, R);
  stats.build_seconds += sw.seconds();
  sw.restart();
  // Each candidate pair once (half neighbourhood), updating both discs' nearest neighbour:
  // the order of updates does not matter, (distance, row) is a total order.
  const double rsum = R + R, limit = rsum * rsum;
  const std::size_t m = cells_.size();
  best_.assign(m, limit);
  best_row_.assign(m, kNone);
  auto offer = [&](std::size_t k, double d2, uint32_t row) {
    if (d2 < best_[k] || (d2 == best_[k] && best_row_[k] != kNone && row < best_row_[k])) {
      best_[k] = d2;
      best_row_[k] = row;
    }
  };
  uint64_t tests = cells_.for_each_candidate([&](std::size_t a, std::size_t b) {
    const double dx = cells_.x(b) - cells_.x(a), dy = cells_.y(b) - cells_.y(a);
    const double d2 = dx * dx + dy * dy;  // as discs_overlap computes it
    if (d2 < limit) {
      offer(a, d2, cells_.row(b));
      offer(b, d2, cells_.row(a));
    }
  });
  for (std::size_t k = 0; k < m; ++k)
    if (best_row_[k] != kNone) out.agents.push_back(ordered(cells_.row(k), best_row_[k]));
  finish_pairs(out.agents);
  if (!scene.empty()) {
    obstacles_.build(scene, frame);
    obstacles_.overlaps(d, 0, d.n, out.obstacles, tests);
  }
  stats.pair_tests += tests;
  stats.rows += d.n;
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
