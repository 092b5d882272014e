#include "world/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include "world/halfplane_lp.hpp"

namespace crowddb {
namespace {

int orientation(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double v = cross(b.x - a.x, b.y - a.y, c.x - a.x, c.y - a.y);
  return (v > 0) - (v < 0);
}

bool on_segment(const Vec2& a, const Vec2& b, const Vec2& p) {
  return std::min(a.x, b.x) <= p.x && p.x <= std::max(a.x, b.x) && std::min(a.y, b.y) <= p.y &&
         p.y <= std::max(a.y, b.y);
}

bool segments_touch(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on_segment(a, b, c)) || (o2 == 0 && on_segment(a, b, d)) ||
         (o3 == 0 && on_segment(c, d, a)) || (o4 == 0 && on_segment(c, d, b));
}

}  // namespace

namespace {

// Whether edges i < j of the ring meet in a way a simple polygon forbids.
bool edges_meet(std::span<const Vec2> ring, std::size_t i, std::size_t j) {
  const std::size_t n = ring.size();
  const Vec2& a = ring[i];
  const Vec2& b = ring[(i + 1) % n];
  const Vec2& c = ring[j];
  const Vec2& d = ring[(j + 1) % n];
  if (j == i + 1 || (i == 0 && j == n - 1)) {
    // Adjacent edges share one vertex; they may not fold back onto each other.
    const Vec2& shared = (j == i + 1) ? b : a;
    const Vec2& p = (j == i + 1) ? a : b;
    const Vec2& q = (j == i + 1) ? d : c;
    return orientation(p, shared, q) == 0 &&
           (p.x - shared.x) * (q.x - shared.x) + (p.y - shared.y) * (q.y - shared.y) > 0;
  }
  return segments_touch(a, b, c, d);
}

std::optional<SelfIntersection> repeated_vertex(std::span<const Vec2> ring) {
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % n];
    if (a.x == b.x && a.y == b.y) return SelfIntersection{i, (i + 1) % n};
  }
  return std::nullopt;
}

// Every pair in (i, j) order: O(v^2), for short rings, whose messages then name the first pair.
std::optional<SelfIntersection> scan_all_pairs(std::span<const Vec2> ring) {
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j)
      if (edges_meet(ring, i, j)) return SelfIntersection{i, j};
  return std::nullopt;
}

// Edges in order of their boxes' left sides; each is tested against the earlier edges whose boxes
// it overlaps. Bounded: at most 64 v + 10^6 box tests.
std::optional<SelfIntersection> sweep_boxes(std::span<const Vec2> ring) {
  const std::size_t n = ring.size();
  struct Box {
    double xmin, xmax, ymin, ymax;
    std::size_t edge;
  };
  std::vector<Box> boxes(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % n];
    boxes[i] = {std::min(a.x, b.x), std::max(a.x, b.x), std::min(a.y, b.y), std::max(a.y, b.y), i};
  }
  std::sort(boxes.begin(), boxes.end(), [](const Box& p, const Box& q) {
    return p.xmin != q.xmin ? p.xmin < q.xmin : p.edge < q.edge;
  });
  std::uint64_t budget = 64 * static_cast<std::uint64_t>(n) + 1000000;
  std::vector<Box> active;
  for (const Box& e : boxes) {
    std::size_t kept = 0;
    for (const Box& o : active) {
      if (budget-- == 0) return SelfIntersection{0, 0, false};
      if (o.xmax < e.xmin) continue;  // behind the sweep for good
      active[kept++] = o;
      if (o.ymax < e.ymin || e.ymax < o.ymin) continue;
      const std::size_t i = std::min(o.edge, e.edge), j = std::max(o.edge, e.edge);
      if (edges_meet(ring, i, j)) return SelfIntersection{i, j};
    }
    active.resize(kept);
    active.push_back(e);
  }
  return SelfIntersection{0, 0, false};
}

}  // namespace

std::optional<SelfIntersection> first_self_intersection(std::span<const Vec2> ring) {
  if (ring.size() < 3) return std::nullopt;
  if (auto dup = repeated_vertex(ring)) return dup;
  if (is_simple_polygon(ring)) return std::nullopt;
  // Not simple (decided exactly). Name the edges with the same doubles predicates as before; if
  // rounding hides the crossing from them, it is reported unnamed rather than not at all.
  const auto found = ring.size() <= kNamedCrossingLimit ? scan_all_pairs(ring) : sweep_boxes(ring);
  return found ? *found : SelfIntersection{0, 0, false};
}

std::vector<Vec2> convex_inward_normals(std::span<const Vec2> ring) {
  const std::size_t n = ring.size();
  if (n < 3) return {};
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % n];
    const Vec2& c = ring[(i + 2) % n];
    if (cross(b.x - a.x, b.y - a.y, c.x - b.x, c.y - b.y) < 0) return {};
  }
  std::vector<Vec2> normals(n);
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % n];
    const double ex = b.x - a.x, ey = b.y - a.y, l = std::sqrt(ex * ex + ey * ey);
    normals[i] = {-ey / l, ex / l};
  }
  return normals;
}

Vec2 goal_target(const Goal& g, double px, double py, double r) {
  if (!g.is_polygon()) return {g.x, g.y};
  if (point_in_polygon(g.area, px, py)) return {px, py};
  const std::size_t n = g.area.size();
  std::vector<Vec2> computed;  // a goal not from World::add_goal
  std::span<const Vec2> normals = g.inward_normals;
  if (r > 0 && normals.size() != n) normals = computed = convex_inward_normals(g.area);
  if (!(r > 0) || normals.size() != n) {  // a point, or an area that is not convex
    Vec2 c{};
    dist2_to_boundary(g.area, px, py, &c);
    return c;
  }
  // The area's edges moved inwards by r, as half-planes (the area is counter-clockwise: inside
  // is left of each edge); the closest point to p within them. The planes live in a buffer of
  // the thread's, neither allocated nor cleared per call: this runs for every agent and tick.
  thread_local std::vector<HalfPlane> buffer;
  if (buffer.size() < n) buffer.resize(n);
  const std::span<HalfPlane> planes(buffer.data(), n);
  double extent = std::abs(px) + std::abs(py);
  for (const Vec2& a : g.area) extent = std::max(extent, std::abs(a.x) + std::abs(a.y));
  auto eroded = [&](double by) {
    for (std::size_t i = 0; i < n; ++i)
      planes[i] = {g.area[i].x + normals[i].x * by, g.area[i].y + normals[i].y * by, normals[i].x,
                   normals[i].y};
    return solve_velocity_lp(planes, 0, 4 * extent + 1, px, py);
  };
  LpResult q = eroded(r);
  if (!q.feasible) {
    // The disc is wider than the area somewhere: erode by the largest radius that fits (the
    // area's inradius: r less the smallest worst violation the program found), just inside.
    double worst = 0;
    for (const HalfPlane& h : planes)
      worst = std::max(worst, -((q.vx - h.px) * h.nx + (q.vy - h.py) * h.ny));
    q = eroded(std::max(0.0, (r - worst) * (1 - 1e-9)));
  }
  return {q.vx, q.vy};
}

}  // namespace crowddb
