// First-to-collide by nested loop: every disc against every other disc and every obstacle.
// O(n^2 + n m). The oracle for the index of issue 3.
#include "query/ftc_geometry.hpp"
#include "query/naive_paths.hpp"

namespace crowddb {

void FtcNaive::run(const DiscView& d, const StaticScene& scene, double horizon,
                   std::span<FtcHit> out, Executor& ex, QueryStats& stats) {
  const auto circles = scene.circles();
  const auto polygons = scene.polygons();
  const auto boxes = scene.polygon_boxes();
  ex.for_each_chunk(d.n, 64, [&](std::size_t begin, std::size_t end) {
    for (std::size_t a = begin; a < end; ++a) {
      FtcHit best;
      uint64_t best_key = 0;
      auto offer = [&](double t, Collider::Kind kind, uint32_t row, uint64_t key) {
        if (t == INFINITY) return;
        if (best.with.kind == Collider::Kind::none ||
            precedes(t, kind, key, best.time, best.with.kind, best_key)) {
          best = {{kind, row}, t};
          best_key = key;
        }
      };
      const double ax = d.x[a], ay = d.y[a], avx = d.vx[a], avy = d.vy[a], ar = d.radius[a];
      for (std::size_t b = 0; b < d.n; ++b) {
        if (b == a) continue;
        const double t = ray_disc_time(d.x[b] - ax, d.y[b] - ay, d.vx[b] - avx, d.vy[b] - avy,
                                       ar + d.radius[b], horizon);
        offer(t, Collider::Kind::agent, static_cast<uint32_t>(b), d.id[b]);
      }
      for (std::size_t c = 0; c < circles.size(); ++c) {
        const double t = ray_disc_time(circles[c].x - ax, circles[c].y - ay, -avx, -avy,
                                       ar + circles[c].radius, horizon);
        offer(t, Collider::Kind::circle, static_cast<uint32_t>(c), c);
      }
      for (std::size_t p = 0; p < polygons.size(); ++p) {
        // The swept disc's box over [0, horizon] must meet the polygon's box.
        const auto& bx = boxes[p];
        const double ex0 = ax + std::fmin(0.0, avx * horizon) - ar,
                     ex1 = ax + std::fmax(0.0, avx * horizon) + ar;
        const double ey0 = ay + std::fmin(0.0, avy * horizon) - ar,
                     ey1 = ay + std::fmax(0.0, avy * horizon) + ar;
        if (ex1 < bx.xmin || ex0 > bx.xmax || ey1 < bx.ymin || ey0 > bx.ymax) continue;
        const double t = ray_polygon_time(polygons[p].vertices, ax, ay, avx, avy, ar, horizon);
        offer(t, Collider::Kind::polygon, static_cast<uint32_t>(p), p);
      }
      out[a] = best;
    }
  });
  stats.rows += d.n;
  stats.pair_tests += d.n * (d.n ? d.n - 1 : 0) + d.n * (circles.size() + polygons.size());
}

}  // namespace crowddb
