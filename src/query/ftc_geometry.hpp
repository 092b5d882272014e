// The exact pair primitives of first-to-collide (DESIGN.md §5). The naive path and every index
// compute a pair's time with these functions and order hits with `precedes`, so "exact" means
// bit-identical times and identical winners.
#pragma once

#include <cmath>
#include <cstdint>
#include <span>

#include "crowddb/query.hpp"

namespace crowddb {

// Earliest t in [0, horizon] with |d + w t| < R (d = p_b - p_a, w = v_b - v_a, R = r_a + r_b):
// 0 when already overlapping, the entry time when the rays come closer than R, else +inf.
// Grazing contact (closest distance exactly R) is not a collision, as for the collision set.
inline double ray_disc_time(double dx, double dy, double wx, double wy, double R, double horizon) {
  const double c = dx * dx + dy * dy - R * R;
  if (c < 0) return 0;
  const double b = dx * wx + dy * wy;  // half the linear coefficient; < 0 when approaching
  if (!(b < 0)) return INFINITY;
  const double a = wx * wx + wy * wy;
  // b^2 - a c, rewritten with Lagrange's identity (d.w)^2 - |d|^2 |w|^2 = -(d x w)^2 so that it
  // does not cancel: head-on at 2e9 m the textbook form loses every digit and misses the contact.
  const double cross = dx * wy - dy * wx;
  const double disc = a * (R * R) - cross * cross;
  if (!(disc > 0)) return INFINITY;
  // c / (-b + sqrt(disc)) is the smaller root without the cancellation of (-b - sqrt(disc)) / a.
  const double t = c / (-b + std::sqrt(disc));
  return t <= horizon ? t : INFINITY;
}

// Earliest t in [0, horizon] at which a disc (centre p, velocity v, radius r) overlaps a static
// polygon (counter-clockwise ring): 0 if it overlaps now, else the first time its centre comes
// closer than r to an edge. +inf if never within the horizon.
double ray_polygon_time(std::span<const Vec2> ring, double px, double py, double vx, double vy,
                        double r, double horizon);

// The same for the scene's polygon p through its edge grid (StaticScene::ring_grid) where it has
// one: bit for bit the loop's time where that is <= cap, else a value above cap (a caller whose
// best hit so far is at cap cannot tell them apart). The loop stays the naive path's and the
// tests' oracle.
double ray_polygon_time(const StaticScene& scene, std::size_t p, double px, double py, double vx,
                        double vy, double r, double horizon, double cap);

// Tie rule: earlier time first; at equal times agents before circles before polygons; then the
// smaller agent id or obstacle row. `key` is the agent's id or the obstacle's row.
inline bool precedes(double t1, Collider::Kind k1, uint64_t key1, double t2, Collider::Kind k2,
                     uint64_t key2) {
  if (t1 != t2) return t1 < t2;
  if (k1 != k2) return k1 < k2;
  return key1 < key2;
}

}  // namespace crowddb
