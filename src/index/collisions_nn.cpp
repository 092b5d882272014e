#include "index/collisions_nn.hpp"

#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::index {

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
  const double rsum = R + R, limit = rsum * rsum;
  constexpr uint32_t kNone = UINT32_MAX;
  uint64_t tests = 0;
  cells_.for_each_block([&](std::size_t begin, std::size_t end, const std::size_t(&nb)[3][2]) {
    for (std::size_t a = begin; a < end; ++a) {
      const double xa = cells_.x(a), ya = cells_.y(a);
      const uint32_t ra = cells_.row(a);
      double best = limit;
      uint32_t best_row = kNone;
      for (const auto& range : nb)
        for (std::size_t b = range[0]; b < range[1]; ++b) {
          if (b == a) continue;
          const double dx = cells_.x(b) - xa, dy = cells_.y(b) - ya;
          const double d2 = dx * dx + dy * dy;
          const uint32_t rb = cells_.row(b);
          if (d2 < best || (d2 == best && best_row != kNone && rb < best_row)) {
            best = d2;
            best_row = rb;
          }
        }
      tests += (nb[0][1] - nb[0][0]) + (nb[1][1] - nb[1][0]) + (nb[2][1] - nb[2][0]) - 1;
      if (best_row != kNone) out.agents.push_back(ordered(ra, best_row));
    }
  });
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
