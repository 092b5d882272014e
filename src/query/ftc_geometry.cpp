#include "query/ftc_geometry.hpp"

#include "world/geometry.hpp"

namespace crowddb {

double ray_polygon_time(std::span<const Vec2> ring, double px, double py, double vx, double vy,
                        double r, double horizon) {
  if (disc_overlaps_polygon(ring, px, py, r)) return 0;
  double best = INFINITY;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Vec2& a = ring[i];
    const Vec2& b = ring[(i + 1) % n];
    // The capsule around edge ab: discs at both ends plus the band between the offset lines.
    best = std::fmin(best, ray_disc_time(a.x - px, a.y - py, -vx, -vy, r, horizon));
    best = std::fmin(best, ray_disc_time(b.x - px, b.y - py, -vx, -vy, r, horizon));
    const double ex = b.x - a.x, ey = b.y - a.y;
    const double len = std::sqrt(ex * ex + ey * ey);
    if (len == 0) continue;
    const double nx = -ey / len, ny = ex / len;           // unit normal
    const double s0 = nx * (px - a.x) + ny * (py - a.y);  // signed distance to the edge's line
    const double sv = nx * vx + ny * vy;
    const double gap = std::fabs(s0) - r;
    if (gap < 0) continue;  // inside the band now: the disc caps (or overlap at t=0) decide
    const double closing = s0 > 0 ? -sv : sv;
    if (!(closing > 0)) continue;
    const double t = gap / closing;
    if (!(t <= horizon) || !(t < best)) continue;
    const double u = ex * (px + vx * t - a.x) + ey * (py + vy * t - a.y);  // along the edge * len
    if (u >= 0 && u <= len * len) best = t;
  }
  return best;
}

}  // namespace crowddb
