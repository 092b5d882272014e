#include "index/collisions_grid.hpp"

#include <cmath>

#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::index {
namespace {

constexpr double kClassRatio = 4;     // radii within one class differ by less than this factor
constexpr double kMaxCandidates = 8;  // one class while it costs fewer candidates per disc

}  // namespace

void DiscGrid::build(const DiscView& d, Executor* ex) {
  frame_ = Frame::of(d);
  built_ = true;
  if (!frame_.finite || d.n == 0) {
    levels_.clear();
    return;
  }
  // One class when the radii are close, or when even the largest disc's cell would hold few
  // centres (sparse tables with mixed radii: classes would only add cross-class probes).
  // Expected candidates per disc in one class: ~4.5 cells x density x cell^2.
  const double cell = 2 * frame_.reach(frame_.rmax);
  const double area = frame_.width * frame_.height;
  const double per_disc = area > 0 ? 4.5 * static_cast<double>(d.n) / area * cell * cell : INFINITY;
  if (frame_.rmax <= kClassRatio * frame_.rmin || per_disc <= kMaxCandidates) {
    levels_.resize(1);
    levels_[0].build_all(d, frame_, frame_.rmax, ex);
    return;
  }
  // Radius classes: floor(log_4(r / rmin)); a counting sort of the rows by class.
  const double scale = 1 / std::log2(kClassRatio);
  auto class_of = [&](double r) {
    return static_cast<std::size_t>(std::floor(std::log2(r / frame_.rmin) * scale));
  };
  const std::size_t classes = class_of(frame_.rmax) + 1;
  std::vector<uint32_t> start(classes + 1, 0);
  std::vector<double> rmax(classes, 0);
  std::vector<uint32_t> cls(d.n);
  for (std::size_t i = 0; i < d.n; ++i) {
    const std::size_t c = std::min(class_of(d.radius[i]), classes - 1);
    cls[i] = static_cast<uint32_t>(c);
    ++start[c + 1];
    rmax[c] = std::max(rmax[c], d.radius[i]);
  }
  for (std::size_t c = 0; c < classes; ++c) start[c + 1] += start[c];
  class_rows_.resize(d.n);
  std::vector<uint32_t> fill(start.begin(), start.end() - 1);
  for (std::size_t i = 0; i < d.n; ++i) class_rows_[fill[cls[i]]++] = static_cast<uint32_t>(i);
  levels_.clear();
  for (std::size_t c = 0; c < classes; ++c) {
    if (start[c] == start[c + 1]) continue;
    levels_.emplace_back();
    levels_.back().build(
        d, std::span<const uint32_t>(class_rows_).subspan(start[c], start[c + 1] - start[c]),
        frame_, rmax[c], ex);
  }
}

void DiscGrid::pairs(PairList& out, uint64_t& tests) const {
  for (std::size_t j = 0; j < levels_.size(); ++j) {
    const CellIndex& small = levels_[j];
    small.pairs(out, tests);
    // Across classes: the side with less work probes the other. A small disc probes at most
    // 3 rows of the larger class's cells; a large one about (2 R_big + 2 R_small) / cell rows of
    // the smaller class's. So a few giants probe the small discs, and many large discs are
    // probed by fewer small ones.
    for (std::size_t k = j + 1; k < levels_.size(); ++k) {
      const CellIndex& big = levels_[k];
      const double rows = std::ceil(2 * (big.max_radius() + small.max_radius()) / small.cell()) + 1;
      const bool big_probes =
          static_cast<double>(big.size()) * rows < 3 * static_cast<double>(small.size());
      const CellIndex& probing = big_probes ? big : small;
      const CellIndex& probed = big_probes ? small : big;
      for (std::size_t a = 0; a < probing.size(); ++a) {
        const double xa = probing.x(a), ya = probing.y(a), ra = probing.r(a);
        probed.for_each_near(xa, ya, ra, [&](std::size_t b) {
          ++tests;
          if (discs_overlap(probed.x(b) - xa, probed.y(b) - ya, ra + probed.r(b)))
            out.push_back(ordered(probing.row(a), probed.row(b)));
        });
      }
    }
  }
}

void CollisionGrid::run(const DiscView& d, const StaticScene& scene, CollisionPairs& out,
                        Executor& ex, QueryStats& stats) {
  Stopwatch sw;
  out.clear();
  grid_.build(d, &ex);
  if (!grid_.usable()) {
    CollisionNaive().run(d, scene, out, ex, stats);
    return;
  }
  stats.build_seconds += sw.seconds();
  sw.restart();
  grid_.pairs(out.agents, stats.pair_tests);
  finish_pairs(out.agents);
  if (!scene.empty()) {
    obstacles_.build(scene, grid_.frame());
    obstacles_.overlaps(d, 0, d.n, out.obstacles, stats.pair_tests);
  }
  stats.rows += d.n;
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
