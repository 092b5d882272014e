// Collision set by nested loop over all pairs. O(n^2 + n m).
#include <algorithm>

#include "query/naive_paths.hpp"
#include "world/geometry.hpp"

namespace crowddb {

void disc_obstacle_overlaps(const DiscView& d, const StaticScene& scene, std::size_t begin,
                            std::size_t end, std::vector<std::pair<uint32_t, Collider>>& out) {
  const auto circles = scene.circles();
  const auto polygons = scene.polygons();
  const auto boxes = scene.polygon_boxes();
  for (std::size_t i = begin; i < end; ++i) {
    const double x = d.x[i], y = d.y[i], r = d.radius[i];
    for (std::size_t c = 0; c < circles.size(); ++c)
      if (discs_overlap(circles[c].x - x, circles[c].y - y, r + circles[c].radius))
        out.push_back(
            {static_cast<uint32_t>(i), {Collider::Kind::circle, static_cast<uint32_t>(c)}});
    for (std::size_t p = 0; p < polygons.size(); ++p) {
      const auto& b = boxes[p];
      if (x + r <= b.xmin || x - r >= b.xmax || y + r <= b.ymin || y - r >= b.ymax) continue;
      if (disc_overlaps_polygon(polygons[p].vertices, x, y, r))
        out.push_back(
            {static_cast<uint32_t>(i), {Collider::Kind::polygon, static_cast<uint32_t>(p)}});
    }
  }
}

void CollisionNaive::run(const DiscView& d, const StaticScene& scene, CollisionPairs& out,
                         Executor& ex, QueryStats& stats) {
  out.clear();
  // Per-chunk buffers concatenated in chunk order keep the output sorted and thread-independent.
  constexpr std::size_t kGrain = 64;
  const std::size_t chunks = (d.n + kGrain - 1) / kGrain;
  std::vector<CollisionPairs> parts(chunks);
  ex.for_each_chunk(d.n, kGrain, [&](std::size_t begin, std::size_t end) {
    CollisionPairs& part = parts[begin / kGrain];
    for (std::size_t i = begin; i < end; ++i) {
      const double x = d.x[i], y = d.y[i], r = d.radius[i];
      for (std::size_t j = i + 1; j < d.n; ++j)
        if (discs_overlap(d.x[j] - x, d.y[j] - y, r + d.radius[j]))
          part.agents.push_back({static_cast<uint32_t>(i), static_cast<uint32_t>(j)});
    }
    disc_obstacle_overlaps(d, scene, begin, end, part.obstacles);
  });
  for (auto& part : parts) {
    out.agents.insert(out.agents.end(), part.agents.begin(), part.agents.end());
    out.obstacles.insert(out.obstacles.end(), part.obstacles.begin(), part.obstacles.end());
  }
  stats.rows += d.n;
  stats.pair_tests += d.n * (d.n ? d.n - 1 : 0) / 2;
}

}  // namespace crowddb
