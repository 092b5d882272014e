#include <algorithm>
#include <atomic>
#include <cmath>
#include <numbers>

#include "crowddb/query.hpp"
#include "world/geometry.hpp"
#include "world/ring_grid.hpp"

namespace crowddb {

namespace {

void sample_segment(const Vec2& a, const Vec2& e, double spacing, double charge,
                    std::vector<double>& px, std::vector<double>& py, std::vector<double>& pc) {
  const double len = std::hypot(e.x - a.x, e.y - a.y);
  const auto m = std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(len / spacing)));
  for (std::size_t k = 0; k < m; ++k) {
    const double t = static_cast<double>(k) / static_cast<double>(m);
    px.push_back(a.x + t * (e.x - a.x));
    py.push_back(a.y + t * (e.y - a.y));
    pc.push_back(charge);
  }
}

}  // namespace

StaticScene::StaticScene(std::vector<CircleObstacle> circles, std::vector<PolygonObstacle> polygons,
                         double spacing, ObstacleCharges charges, const Bounds* walls)
    : circles_(std::move(circles)), polygons_(std::move(polygons)) {
  static std::atomic<uint64_t> scenes{0};
  generation_ = ++scenes;
  if (!(spacing > 0) || !std::isfinite(spacing)) spacing = 1;
  wall_begin_ = polygons_.size();
  const bool charged = charges != ObstacleCharges::none;
  for (const CircleObstacle& c : circles_) {
    if (!charged) break;
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
    const std::size_t n = p.vertices.size();
    for (std::size_t i = 0; i < n && charged; ++i)
      sample_segment(p.vertices[i], p.vertices[(i + 1) % n], spacing, p.charge, px_, py_, pc_);
  }
  if (walls) {
    const Bounds& b = *walls;
    const double t = std::max(b.width(), b.height());
    auto rect = [&](double x0, double y0, double x1, double y1) {
      polygons_.push_back({{{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}}, 1.0});
    };
    rect(b.xmin - t, b.ymin - t, b.xmin, b.ymax + t);  // west, corners included
    rect(b.xmax, b.ymin - t, b.xmax + t, b.ymax + t);  // east
    rect(b.xmin, b.ymin - t, b.xmax, b.ymin);          // south
    rect(b.xmin, b.ymax, b.xmax, b.ymax + t);          // north
    const Vec2 c[4] = {{b.xmin, b.ymin}, {b.xmax, b.ymin}, {b.xmax, b.ymax}, {b.xmin, b.ymax}};
    for (int i = 0; i < 4 && charged; ++i)
      sample_segment(c[i], c[(i + 1) % 4], spacing, 1.0, px_, py_, pc_);
  }
  for (std::size_t k = 0; k < polygons_.size(); ++k) {
    const auto& v = polygons_[k].vertices;
    edge_start_.push_back(edge_start_.back() + static_cast<uint32_t>(v.size()));
    for (std::size_t e = 0; e < v.size(); ++e) {
      edge_polygon_.push_back(static_cast<uint32_t>(k));
      edges_.push_back({v[e], v[(e + 1) % v.size()]});
    }
  }
  for (const PolygonObstacle& p : polygons_) {
    Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (const Vec2& a : p.vertices)
      b = {std::min(b.xmin, a.x), std::min(b.ymin, a.y), std::max(b.xmax, a.x),
           std::max(b.ymax, a.y)};
    boxes_.push_back(b);
    grids_.push_back(p.vertices.size() >= RingGrid::kMinEdges
                         ? std::make_shared<const RingGrid>(p.vertices)
                         : nullptr);
  }
}

double feature_dist2(const StaticScene& scene, std::size_t f, double px, double py) {
  if (f < scene.circles().size()) {
    const CircleObstacle& c = scene.circles()[f];
    const double d = std::hypot(px - c.x, py - c.y) - c.radius;
    return d > 0 ? d * d : 0.0;
  }
  const StaticScene::Edge& e = scene.edge(f);
  return dist2_to_segment(e.a, e.b, px, py);
}

Vec2 feature_closest(const StaticScene& scene, std::size_t f, double px, double py) {
  if (f < scene.circles().size()) {
    const CircleObstacle& c = scene.circles()[f];
    const double dx = px - c.x, dy = py - c.y, d = std::hypot(dx, dy);
    if (d == 0) return {px, py};
    return {c.x + dx * c.radius / d, c.y + dy * c.radius / d};
  }
  const StaticScene::Edge& e = scene.edge(f);
  return closest_on_segment(e.a, e.b, px, py);
}

}  // namespace crowddb
