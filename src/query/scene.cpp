#include <algorithm>
#include <cmath>
#include <numbers>

#include "crowddb/query.hpp"

namespace crowddb {

StaticScene::StaticScene(std::vector<CircleObstacle> circles, std::vector<PolygonObstacle> polygons,
                         double spacing, ObstacleCharges charges)
    : circles_(std::move(circles)), polygons_(std::move(polygons)) {
  if (!(spacing > 0) || !std::isfinite(spacing)) spacing = 1;
  for (const CircleObstacle& c : circles_) {
    const double circumference = 2 * std::numbers::pi * c.radius;
    if (charges == ObstacleCharges::centres || c.radius <= spacing) {
      px_.push_back(c.x);
      py_.push_back(c.y);
      pc_.push_back(c.charge);
      continue;
    }
    const auto m = static_cast<std::size_t>(std::ceil(circumference / spacing));
    for (std::size_t i = 0; i < m; ++i) {
      const double a = 2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(m);
      px_.push_back(c.x + c.radius * std::cos(a));
      py_.push_back(c.y + c.radius * std::sin(a));
      pc_.push_back(c.charge);
    }
  }
  for (const PolygonObstacle& p : polygons_) {
    Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
    const std::size_t n = p.vertices.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2& a = p.vertices[i];
      const Vec2& e = p.vertices[(i + 1) % n];
      b = {std::min(b.xmin, a.x), std::min(b.ymin, a.y), std::max(b.xmax, a.x), std::max(b.ymax, a.y)};
      const double len = std::hypot(e.x - a.x, e.y - a.y);
      const auto m = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(len / spacing)));
      for (std::size_t k = 0; k < m; ++k) {
        const double t = static_cast<double>(k) / static_cast<double>(m);
        px_.push_back(a.x + t * (e.x - a.x));
        py_.push_back(a.y + t * (e.y - a.y));
        pc_.push_back(p.charge);
      }
    }
    boxes_.push_back(b);
  }
}

}  // namespace crowddb
