#include "index/obstacle_index.hpp"

#include <algorithm>
#include <cmath>

#include "index/row_buckets.hpp"  // cell_by_product
#include "query/naive_paths.hpp"
#include "query/scene_polygons.hpp"

namespace crowddb::index {
namespace {

// Cell of frame coordinate u, clamped to [0, side).
int64_t clamp_cell(double u, double cell, int64_t side) {
  const double c = std::floor(u / cell);
  if (!(c > 0)) return 0;  // also NaN
  if (c >= static_cast<double>(side - 1)) return side - 1;
  return static_cast<int64_t>(c);
}

}  // namespace

void ObstacleIndex::build(const StaticScene& scene, const Frame& frame) {
  scene_ = &scene;
  frame_ = frame;
  const std::size_t circles = scene.circles().size(), m = circles + scene.polygons().size();
  side_ = 0;
  start_.clear();
  ids_.clear();
  if (m == 0 || !frame.finite) return;
  // Finer for more discs (fewer candidates each), coarser for few (cheaper to build).
  const double fine = std::sqrt(static_cast<double>(frame.count)) / 8;
  const double base = 4 * std::ceil(std::sqrt(static_cast<double>(m + 1)));
  side_ = static_cast<int64_t>(std::clamp(std::max(fine, base), 8.0, 512.0));
  cell_ = std::max(frame.extent / static_cast<double>(side_), frame.rmax);
  if (!(cell_ > 0)) cell_ = 1;
  inv_cell_ = 1 / cell_;
  side_ = std::min<int64_t>(side_, static_cast<int64_t>(std::floor(frame.extent / cell_)) + 1);

  // Grown boxes in frame coordinates; cells [cx0, cx1] x [cy0, cy1] per obstacle.
  struct Range {
    int64_t cx0, cx1, cy0, cy1;
    bool empty;
  };
  std::vector<Range> ranges(m);
  auto range_of = [&](double xmin, double ymin, double xmax, double ymax) {
    const double mag = std::max({std::abs(xmin - frame.x0), std::abs(xmax - frame.x0),
                                 std::abs(ymin - frame.y0), std::abs(ymax - frame.y0)});
    const double grow = frame.reach(frame.rmax, std::isfinite(mag) ? mag : 0) + cell_ * 0x1p-30;
    const double u0 = xmin - frame.x0 - grow, u1 = xmax - frame.x0 + grow;
    const double v0 = ymin - frame.y0 - grow, v1 = ymax - frame.y0 + grow;
    const double top = frame.extent + grow;
    Range r{};
    r.empty = u1 < -grow || v1 < -grow || u0 > top || v0 > top;
    r.cx0 = clamp_cell(u0, cell_, side_);
    r.cx1 = clamp_cell(u1, cell_, side_);
    r.cy0 = clamp_cell(v0, cell_, side_);
    r.cy1 = clamp_cell(v1, cell_, side_);
    return r;
  };
  for (std::size_t c = 0; c < circles; ++c) {
    const CircleObstacle& o = scene.circles()[c];
    ranges[c] = range_of(o.x - o.radius, o.y - o.radius, o.x + o.radius, o.y + o.radius);
  }
  for (std::size_t p = 0; p < scene.polygons().size(); ++p) {
    const auto& b = scene.polygon_boxes()[p];
    ranges[circles + p] = range_of(b.xmin, b.ymin, b.xmax, b.ymax);
  }
  start_.assign(static_cast<std::size_t>(side_ * side_) + 1, 0);
  for (const Range& r : ranges)
    if (!r.empty)
      for (int64_t cy = r.cy0; cy <= r.cy1; ++cy)
        for (int64_t cx = r.cx0; cx <= r.cx1; ++cx)
          ++start_[static_cast<std::size_t>(cy * side_ + cx) + 1];
  for (std::size_t i = 1; i < start_.size(); ++i) start_[i] += start_[i - 1];
  ids_.resize(start_.back());
  std::vector<uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::size_t id = 0; id < m; ++id) {  // ascending ids: each cell's list comes out sorted
    const Range& r = ranges[id];
    if (r.empty) continue;
    for (int64_t cy = r.cy0; cy <= r.cy1; ++cy)
      for (int64_t cx = r.cx0; cx <= r.cx1; ++cx)
        ids_[fill[static_cast<std::size_t>(cy * side_ + cx)]++] = static_cast<uint32_t>(id);
  }
}

void ObstacleIndex::overlaps(const DiscView& d, std::size_t begin, std::size_t end,
                             std::vector<std::pair<uint32_t, Collider>>& out,
                             uint64_t& tests) const {
  if (!scene_) return;
  if (side_ == 0) {
    if (!scene_->empty()) disc_obstacle_overlaps(d, *scene_, begin, end, out);  // non-finite frame
    return;
  }
  const auto circles = scene_->circles();
  const auto polygons = scene_->polygons();
  const auto boxes = scene_->polygon_boxes();
  const auto nc = static_cast<uint32_t>(circles.size());
  // Each row's cell by a product with 1 / cell: a disc that overlaps an obstacle has its centre
  // at least cell 2^-30 inside the obstacle's grown box (build), far more than the product's
  // rounding (a relative 1e-16 of at most 512 cells), so where it gives the cell beside the
  // division's, that cell too lists the obstacle (see the header). Not where 1 / cell overflows
  // (a cell below 2^-1024: discs of subnormal radii packed as close): the division there.
  const bool by_product = std::isfinite(inv_cell_);
  for (std::size_t i = begin; i < end; ++i) {
    const double x = d.x[i], y = d.y[i], r = d.radius[i];
    const double u = x - frame_.x0, v = y - frame_.y0;
    const int64_t cx =
        by_product ? cell_by_product(u, inv_cell_, side_) : clamp_cell(u, cell_, side_);
    const int64_t cy =
        by_product ? cell_by_product(v, inv_cell_, side_) : clamp_cell(v, cell_, side_);
    const auto c = static_cast<std::size_t>(cy * side_ + cx);
    for (uint32_t k = start_[c]; k < start_[c + 1]; ++k) {
      const uint32_t id = ids_[k];
      ++tests;
      if (id < nc) {
        if (disc_hits_circle(circles[id], x, y, r))
          out.push_back({static_cast<uint32_t>(i), {Collider::Kind::circle, id}});
      } else if (scene_disc_hits_polygon(*scene_, id - nc, x, y, r)) {
        out.push_back({static_cast<uint32_t>(i), {Collider::Kind::polygon, id - nc}});
      }
    }
  }
}

void ObstacleIndex::overlaps(const DiscView& d, std::vector<std::pair<uint32_t, Collider>>& out,
                             uint64_t& tests, Executor& ex) const {
  constexpr std::size_t kGrain = 2048;  // rows per chunk
  const std::size_t chunks = (d.n + kGrain - 1) / kGrain;
  std::vector<std::vector<std::pair<uint32_t, Collider>>> found(chunks);
  std::vector<uint64_t> found_tests(chunks, 0);
  ex.for_each_chunk(d.n, kGrain, [&](std::size_t b, std::size_t e) {
    // Into the chunk's own list and count, then moved in (the per-chunk entries and vector
    // headers share cache lines between the threads).
    std::vector<std::pair<uint32_t, Collider>> mine;
    uint64_t tests_c = 0;
    overlaps(d, b, e, mine, tests_c);
    found[b / kGrain] = std::move(mine);
    found_tests[b / kGrain] = tests_c;
  });
  for (std::size_t c = 0; c < chunks; ++c) {
    out.insert(out.end(), found[c].begin(), found[c].end());
    tests += found_tests[c];
  }
}

void obstacle_overlaps(const DiscView& d, const StaticScene& scene, const Frame& frame,
                       std::vector<std::pair<uint32_t, Collider>>& out, QueryStats& stats) {
  if (scene.empty() || d.n == 0) return;
  ObstacleIndex idx;
  idx.build(scene, frame);
  idx.overlaps(d, 0, d.n, out, stats.pair_tests);
}

}  // namespace crowddb::index
