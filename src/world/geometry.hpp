// Small exact-as-doubles geometry shared by every access path. Naive and indexed paths must call
// the same primitive for the same pair, so that "exact" comparisons between them are meaningful.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <optional>
#include <span>
#include <utility>

#include "crowddb/world.hpp"

namespace crowddb {

// sqrt(x^2 + y^2). Not std::hypot: its guard against overflow costs about 20 ns a call (3 % of
// an ORCA tick at 2 * 10^4 agents), and coordinates (|x| <= 10^9 m, the loader's bound), speeds
// and their differences stay far from where x^2 overflows.
inline double length(double x, double y) {
  return std::sqrt(x * x + y * y);
}

// Twice the signed area (positive when counter-clockwise), halved.
inline double signed_area(std::span<const Vec2> ring) {
  double a = 0;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
    const Vec2& p = ring[i];
    const Vec2& q = ring[(i + 1) % n];
    a += p.x * q.y - q.x * p.y;
  }
  return a / 2;
}

inline double cross(double ax, double ay, double bx, double by) {
  return ax * by - ay * bx;
}

// Closest point of segment [a, b] to p, as the parameter in [0, 1].
inline double segment_param(const Vec2& a, const Vec2& b, double px, double py) {
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double len2 = ex * ex + ey * ey;
  if (len2 == 0) return 0;
  const double t = ((px - a.x) * ex + (py - a.y) * ey) / len2;
  return t < 0 ? 0 : (t > 1 ? 1 : t);
}

inline Vec2 closest_on_segment(const Vec2& a, const Vec2& b, double px, double py) {
  const double t = segment_param(a, b, px, py);
  return {a.x + t * (b.x - a.x), a.y + t * (b.y - a.y)};
}

// The squared distance from p to the segment a-b, and its point c nearest to p.
inline double segment_dist2(const Vec2& a, const Vec2& b, double px, double py, Vec2& c) {
  c = closest_on_segment(a, b, px, py);
  const double dx = px - c.x, dy = py - c.y;
  return dx * dx + dy * dy;
}
inline double dist2_to_segment(const Vec2& a, const Vec2& b, double px, double py) {
  Vec2 c;
  return segment_dist2(a, b, px, py, c);
}

// Whether the edge from b to a (a the later vertex) crosses the horizontal line through p to
// p's right: one step of the even-odd count below, shared with world/ring_grid.hpp so that the
// two cannot drift apart.
inline bool crosses_right_of(const Vec2& a, const Vec2& b, double px, double py) {
  if ((a.y > py) == (b.y > py)) return false;
  const double xcross = a.x + (py - a.y) * (b.x - a.x) / (b.y - a.y);
  return px < xcross;
}

// Even-odd rule; points exactly on the boundary may go either way (callers also test the
// boundary distance, so the disc tests below are exact where it matters).
inline bool point_in_polygon(std::span<const Vec2> ring, double px, double py) {
  bool inside = false;
  for (std::size_t i = 0, j = ring.size() - 1; i < ring.size(); j = i++)
    if (crosses_right_of(ring[i], ring[j], px, py)) inside = !inside;
  return inside;
}

// One step of the boundary distance below: the segment a-b's nearest point to p replaces `best`
// (and `closest`) where strictly nearer, so that the first nearest edge in order wins.
// (world/ring_grid.hpp visits edges in no set order and keeps the same winner as the least
// (distance, edge) pair.)
inline void offer_segment(const Vec2& a, const Vec2& b, double px, double py, double& best,
                          Vec2* closest) {
  Vec2 c;
  const double d2 = segment_dist2(a, b, px, py, c);
  if (d2 < best) {
    best = d2;
    if (closest) *closest = c;
  }
}

// Squared distance from p to the polygon's boundary, and the closest boundary point.
inline double dist2_to_boundary(std::span<const Vec2> ring, double px, double py,
                                Vec2* closest = nullptr) {
  double best = INFINITY;
  for (std::size_t i = 0, n = ring.size(); i < n; ++i)
    offer_segment(ring[i], ring[(i + 1) % n], px, py, best, closest);
  return best;
}

// An axis-aligned box; empty (inside out) until something is added.
struct BoxBounds {
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
};

// The axis-aligned box of a ring's vertices.
inline BoxBounds ring_box(std::span<const Vec2> ring) {
  BoxBounds b;
  for (const Vec2& v : ring) {
    b.x0 = std::min(b.x0, v.x);
    b.y0 = std::min(b.y0, v.y);
    b.x1 = std::max(b.x1, v.x);
    b.y1 = std::max(b.y1, v.y);
  }
  return b;
}

// Does a disc of radius r centred at p overlap the polygon (interior or boundary closer than r)?
inline bool disc_overlaps_polygon(std::span<const Vec2> ring, double px, double py, double r) {
  return point_in_polygon(ring, px, py) || dist2_to_boundary(ring, px, py) < r * r;
}

// Discs overlap when the distance of centres is strictly less than the sum of radii.
inline bool discs_overlap(double dx, double dy, double rsum) {
  return dx * dx + dy * dy < rsum * rsum;
}

// The unit vector from (px, py) towards p; (0, 0) when on it.
inline Vec2 unit_towards(double px, double py, Vec2 p) {
  const double dx = p.x - px, dy = p.y - py, l = std::sqrt(dx * dx + dy * dy);
  return l > 0 ? Vec2{dx / l, dy / l} : Vec2{0, 0};
}

// Has a point reached a goal area? A disc goal: within arrival_radius of its centre. A polygon
// goal: inside or on the boundary (within a micrometre, so that an agent that steps exactly onto
// the nearest boundary point arrives whatever the rounding).
inline bool inside_goal(const Goal& g, double px, double py) {
  if (!g.is_polygon()) return length(g.x - px, g.y - py) <= g.arrival_radius;
  // A point a millimetre outside the area's box is outside (and far beyond the micrometre): this
  // runs for every walking agent and tick, and the boundary distance divides once per edge.
  constexpr double kFar = 1e-3;
  const BoxBounds b = ring_box(g.area);
  if (px < b.x0 - kFar || px > b.x1 + kFar || py < b.y0 - kFar || py > b.y1 + kFar) return false;
  return point_in_polygon(g.area, px, py) || dist2_to_boundary(g.area, px, py) <= 1e-12;
}

// The unit inward normals of a counter-clockwise ring's edges (edge i runs from ring[i] to
// ring[i + 1]) when the ring is convex (collinear edges allowed); empty otherwise.
std::vector<Vec2> convex_inward_normals(std::span<const Vec2> ring);

// Where an agent at p steers for its goal when no waypoint is left: a disc goal's centre, or a
// polygon goal's nearest point where a disc of radius r fits (the nearest point of the area
// eroded by r; when the area is thinner than the disc, its middle across), so that a disc aiming
// at a goal area behind a door aims through the door, not at a jamb. p itself when inside.
// Non-convex areas: their nearest point (the edge offsets do not make their erosion).
Vec2 goal_target(const Goal& g, double px, double py, double r = 0);

// Whether the ring (>= 3 vertices, implicitly closed) is a simple polygon: no repeated vertex,
// no two edges meeting except consecutive ones at their shared vertex. Exact (CGAL's sweep with
// exact predicates), O(v log v).
bool is_simple_polygon(std::span<const Vec2> ring);

// A pair of edges (i, j), i < j, that touch or cross (or consecutive edges that fold back onto
// each other, or a repeated vertex), if the ring is not simple; nullopt if it is. Simplicity is
// decided by is_simple_polygon; the pair is then the first in (i, j) order for rings of up to
// kNamedCrossingLimit vertices, else the first a bounded sweep over edge boxes finds.
// `named == false` when that sweep ran out of its budget (O(v) box tests beyond the rings a
// pathological star shape can make quadratic): the ring is not simple, its edges unnamed.
struct SelfIntersection {
  std::size_t first = 0, second = 0;
  bool named = true;
};
inline constexpr std::size_t kNamedCrossingLimit = 2000;
std::optional<SelfIntersection> first_self_intersection(std::span<const Vec2> ring);

}  // namespace crowddb
