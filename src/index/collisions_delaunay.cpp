#include "index/collisions_delaunay.hpp"

#include <CGAL/Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>

#include <algorithm>
#include <numeric>

#include "index/collision_common.hpp"
#include "index/obstacle_index.hpp"
#include "query/naive_paths.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb::index {
namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<uint32_t, Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase>;
using Delaunay = CGAL::Delaunay_triangulation_2<Kernel, Tds>;

}  // namespace

void CollisionDelaunay::run(const DiscView& d, const StaticScene& scene, CollisionPairs& out,
                            Executor& ex, QueryStats& stats) {
  out.clear();
  const std::size_t n = d.n;
  if (n == 0) return;
  const Frame frame = Frame::of(d);
  if (!frame.finite) {
    CollisionNaive().run(d, scene, out, ex, stats);
    return;
  }
  Stopwatch sw;
  // Group coincident centres: one vertex per distinct point, members[start[g] .. start[g+1]).
  std::vector<uint32_t> members(n);
  std::iota(members.begin(), members.end(), 0u);
  std::sort(members.begin(), members.end(), [&](uint32_t a, uint32_t b) {
    return d.x[a] != d.x[b] ? d.x[a] < d.x[b] : (d.y[a] != d.y[b] ? d.y[a] < d.y[b] : a < b);
  });
  std::vector<uint32_t> start;
  std::vector<std::pair<Kernel::Point_2, uint32_t>> points;
  for (std::size_t k = 0; k < n; ++k) {
    const uint32_t i = members[k];
    if (k == 0 || d.x[i] != d.x[members[k - 1]] || d.y[i] != d.y[members[k - 1]]) {
      points.push_back({Kernel::Point_2(d.x[i], d.y[i]), static_cast<uint32_t>(start.size())});
      start.push_back(static_cast<uint32_t>(k));
    }
  }
  start.push_back(static_cast<uint32_t>(n));
  Delaunay dt;
  dt.insert(points.begin(), points.end());
  stats.build_seconds += sw.seconds();
  sw.restart();

  uint64_t tests = 0, edges = 0;
  auto check_groups = [&](uint32_t g, uint32_t h) {
    ++edges;
    for (uint32_t p = start[g]; p < start[g + 1]; ++p)
      for (uint32_t q = start[h]; q < start[h + 1]; ++q) {
        const uint32_t a = members[p], b = members[q];
        ++tests;
        if (discs_overlap(d.x[b] - d.x[a], d.y[b] - d.y[a], d.radius[a] + d.radius[b]))
          out.agents.push_back(ordered(a, b));
      }
  };
  for (uint32_t g = 0; g + 1 < start.size(); ++g)  // coincident centres always overlap; test anyway
    for (uint32_t p = start[g]; p < start[g + 1]; ++p)
      for (uint32_t q = p + 1; q < start[g + 1]; ++q) {
        const uint32_t a = members[p], b = members[q];
        ++tests;
        if (discs_overlap(d.x[b] - d.x[a], d.y[b] - d.y[a], d.radius[a] + d.radius[b]))
          out.agents.push_back(ordered(a, b));
      }
  for (auto e = dt.finite_edges_begin(); e != dt.finite_edges_end(); ++e) {
    const auto f = e->first;
    const int i = e->second;
    check_groups(f->vertex(f->cw(i))->info(), f->vertex(f->ccw(i))->info());
    if (dt.dimension() < 2) continue;
    // The missing diagonal of the two triangles that share this edge.
    const auto g = f->neighbor(i);
    if (dt.is_infinite(f) || dt.is_infinite(g)) continue;
    check_groups(f->vertex(i)->info(), dt.mirror_vertex(f, i)->info());
  }
  finish_pairs(out.agents);
  if (!scene.empty()) {
    ObstacleIndex obstacles;
    obstacles.build(scene, frame);
    obstacles.overlaps(d, 0, n, out.obstacles, tests);
  }
  stats.pair_tests += tests;
  stats.nodes_visited += edges;
  stats.rows += n;
  stats.query_seconds += sw.seconds();
}

}  // namespace crowddb::index
