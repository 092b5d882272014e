// Reference shortest paths (the oracle of the navigation mesh in tests, and the yardstick of
// crowddb verify's path-length criteria) for a disc among static obstacles, independent of
// Recast/Detour: a visibility graph over the obstacles inflated by the disc radius, then Dijkstra.
//
// The free space for a disc of radius r is the plane minus every obstacle grown by r (and, with
// walls, the bounds shrunk by r). A shortest path runs along straight tangents and arcs of
// radius r around convex obstacle corners (and around circles). The graph's nodes are the start,
// the goal and points sampled on those arcs every kStep radians; an edge joins two nodes when
// the segment keeps at least r * cos(kStep / 2) from every polygon (the chord between two
// neighbouring arc points dips that much; around circles, (radius + r) * cos(kStep / 2) from the
// centre). The result is therefore a hair *shorter* than the true
// shortest path (by under 0.1% for kStep = pi/32) — on the strict side for "walked <= 1.2 x".
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <queue>
#include <vector>

#include "crowddb/world.hpp"

namespace crowddb::path {

struct DiscWorld {
  Bounds bounds{};
  bool walls = true;
  std::vector<CircleObstacle> circles;
  std::vector<std::vector<Vec2>> polygons;  // simple, counter-clockwise

  static DiscWorld of(const World& w, bool walls = true) {
    DiscWorld d;
    d.bounds = w.bounds();
    d.walls = walls;
    d.circles.assign(w.circles().begin(), w.circles().end());
    for (const PolygonObstacle& p : w.polygons()) d.polygons.push_back(p.vertices);
    return d;
  }
};

namespace vg {

constexpr double kStep = std::numbers::pi / 32;

inline double seg_point_dist(Vec2 a, Vec2 b, Vec2 p) {
  const double ex = b.x - a.x, ey = b.y - a.y, l2 = ex * ex + ey * ey;
  double t = l2 > 0 ? ((p.x - a.x) * ex + (p.y - a.y) * ey) / l2 : 0;
  t = std::clamp(t, 0.0, 1.0);
  return std::hypot(a.x + t * ex - p.x, a.y + t * ey - p.y);
}

inline double orient(Vec2 a, Vec2 b, Vec2 c) {
  return (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
}

inline bool segments_cross(Vec2 a, Vec2 b, Vec2 c, Vec2 d) {
  const double o1 = orient(a, b, c), o2 = orient(a, b, d), o3 = orient(c, d, a),
               o4 = orient(c, d, b);
  return ((o1 > 0) != (o2 > 0)) && ((o3 > 0) != (o4 > 0)) && o1 != 0 && o2 != 0 && o3 != 0 &&
         o4 != 0;
}

inline bool inside(const std::vector<Vec2>& ring, Vec2 p) {
  bool in = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++) {
    const Vec2 &a = ring[i], &b = ring[j];
    if ((a.y > p.y) != (b.y > p.y) && p.x < a.x + (p.y - a.y) * (b.x - a.x) / (b.y - a.y)) in = !in;
  }
  return in;
}

// Distance from segment ab to a polygon (0 when they meet).
inline double seg_polygon_dist(Vec2 a, Vec2 b, const std::vector<Vec2>& ring) {
  if (inside(ring, a) || inside(ring, b)) return 0;
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < ring.size(); ++i) {
    const Vec2 c = ring[i], e = ring[(i + 1) % ring.size()];
    if (segments_cross(a, b, c, e)) return 0;
    d = std::min({d, seg_point_dist(c, e, a), seg_point_dist(c, e, b), seg_point_dist(a, b, c)});
  }
  return d;
}

}  // namespace vg

// Length of the shortest path of a disc of radius r from a to b, or +inf when there is none.
inline double shortest_path(const DiscWorld& w, double r, Vec2 a, Vec2 b) {
  using namespace vg;
  const double slack = r * std::cos(kStep / 2) - 1e-9;
  const Bounds& B = w.bounds;
  auto free_point = [&](Vec2 p, double need) {
    if (w.walls &&
        (p.x < B.xmin + need || p.x > B.xmax - need || p.y < B.ymin + need || p.y > B.ymax - need))
      return false;
    for (const CircleObstacle& c : w.circles)
      if (std::hypot(p.x - c.x, p.y - c.y) < c.radius + need) return false;
    for (const auto& ring : w.polygons)
      if (seg_polygon_dist(p, p, ring) < need) return false;
    return true;
  };
  auto free_segment = [&](Vec2 p, Vec2 q) {
    // Walls: the shrunk bounds are convex, so the endpoints decide (checked as nodes). Around a
    // circle the arc nodes lie at radius + r from its centre, and chords dip by that times
    // (1 - cos(kStep / 2)).
    for (const CircleObstacle& c : w.circles)
      if (seg_point_dist(p, q, {c.x, c.y}) < (c.radius + r) * std::cos(kStep / 2) - 1e-9)
        return false;
    for (const auto& ring : w.polygons)
      if (seg_polygon_dist(p, q, ring) < slack) return false;
    return true;
  };

  std::vector<Vec2> nodes{a, b};
  auto arc = [&](Vec2 centre, double radius, double from, double to) {
    const int n = std::max(1, static_cast<int>(std::ceil((to - from) / kStep)));
    for (int k = 0; k <= n; ++k) {
      const double t = from + (to - from) * k / n;
      const Vec2 p{centre.x + radius * std::cos(t), centre.y + radius * std::sin(t)};
      if (free_point(p, slack)) nodes.push_back(p);
    }
  };
  for (const CircleObstacle& c : w.circles) arc({c.x, c.y}, c.radius + r, 0, 2 * std::numbers::pi);
  for (const auto& ring : w.polygons) {
    const std::size_t n = ring.size();
    for (std::size_t i = 0; i < n; ++i) {
      const Vec2 p = ring[(i + n - 1) % n], v = ring[i], q = ring[(i + 1) % n];
      if (orient(p, v, q) <= 0) continue;  // reflex (or flat) corner of a CCW ring: never touched
      // Outward normals of the edges into and out of v (right of the direction, for CCW).
      const double a0 = std::atan2(-(v.x - p.x), v.y - p.y);
      double a1 = std::atan2(-(q.x - v.x), q.y - v.y);
      while (a1 < a0) a1 += 2 * std::numbers::pi;
      arc(v, r, a0, a1);
    }
  }
  if (!free_point(a, slack) || !free_point(b, slack))
    return std::numeric_limits<double>::infinity();

  const std::size_t n = nodes.size();
  std::vector<double> dist(n, std::numeric_limits<double>::infinity());
  std::vector<bool> done(n, false);
  dist[0] = 0;
  for (;;) {
    std::size_t u = n;
    for (std::size_t i = 0; i < n; ++i)
      if (!done[i] && (u == n || dist[i] < dist[u])) u = i;
    if (u == n || !std::isfinite(dist[u])) break;
    if (u == 1) return dist[1];
    done[u] = true;
    for (std::size_t v = 0; v < n; ++v) {
      if (done[v]) continue;
      const double d = dist[u] + std::hypot(nodes[v].x - nodes[u].x, nodes[v].y - nodes[u].y);
      if (d < dist[v] && free_segment(nodes[u], nodes[v])) dist[v] = d;
    }
  }
  return std::numeric_limits<double>::infinity();
}

// Smallest distance from point p to any obstacle or (with walls) the bounds.
inline double clearance_at(const DiscWorld& w, Vec2 p) {
  double d = std::numeric_limits<double>::infinity();
  if (w.walls)
    d = std::min(
        {p.x - w.bounds.xmin, w.bounds.xmax - p.x, p.y - w.bounds.ymin, w.bounds.ymax - p.y});
  for (const CircleObstacle& c : w.circles)
    d = std::min(d, std::hypot(p.x - c.x, p.y - c.y) - c.radius);
  for (const auto& ring : w.polygons) d = std::min(d, vg::seg_polygon_dist(p, p, ring));
  return d;
}

}  // namespace crowddb::path
