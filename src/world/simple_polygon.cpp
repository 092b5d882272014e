// CGAL's sweep-line simplicity test, in its own object library (CGAL's usage requirements, such
// as -frounding-math, apply to this translation unit only).
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_2_algorithms.h>

#include <vector>

#include "world/geometry.hpp"

namespace crowddb {

bool is_simple_polygon(std::span<const Vec2> ring) {
  using K = CGAL::Exact_predicates_inexact_constructions_kernel;
  std::vector<K::Point_2> points;
  points.reserve(ring.size());
  for (const Vec2& v : ring) points.emplace_back(v.x, v.y);
  return CGAL::is_simple_2(points.begin(), points.end(), K());
}

}  // namespace crowddb
