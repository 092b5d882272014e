#include "query/ftc_geometry.hpp"

#include <algorithm>
#include <vector>

#include "world/geometry.hpp"
#include "world/ring_grid.hpp"

namespace crowddb {
namespace {

// Lowers `best` to the first time within the horizon at which the centre comes closer than r to
// edge ab: the capsule around it, discs at both ends plus the band between the offset lines.
// Every candidate is min-ed in, so the result over a set of edges does not depend on their order.
inline void edge_capsule_time(const Vec2& a, const Vec2& b, double px, double py, double vx,
                              double vy, double r, double horizon, double& best) {
  best = std::fmin(best, ray_disc_time(a.x - px, a.y - py, -vx, -vy, r, horizon));
  best = std::fmin(best, ray_disc_time(b.x - px, b.y - py, -vx, -vy, r, horizon));
  const double ex = b.x - a.x, ey = b.y - a.y;
  const double len = std::sqrt(ex * ex + ey * ey);
  if (len == 0) return;
  const double nx = -ey / len, ny = ex / len;           // unit normal
  const double s0 = nx * (px - a.x) + ny * (py - a.y);  // signed distance to the edge's line
  const double sv = nx * vx + ny * vy;
  const double gap = std::fabs(s0) - r;
  if (gap < 0) return;  // inside the band now: the disc caps (or overlap at t=0) decide
  const double closing = s0 > 0 ? -sv : sv;
  if (!(closing > 0)) return;
  const double t = gap / closing;
  if (!(t <= horizon) || !(t < best)) return;
  const double u = ex * (px + vx * t - a.x) + ey * (py + vy * t - a.y);  // along the edge * len
  if (u >= 0 && u <= len * len) best = t;
}

}  // namespace

double ray_polygon_time(std::span<const Vec2> ring, double px, double py, double vx, double vy,
                        double r, double horizon) {
  if (disc_overlaps_polygon(ring, px, py, r)) return 0;
  double best = INFINITY;
  const std::size_t n = ring.size();
  for (std::size_t i = 0; i < n; ++i)
    edge_capsule_time(ring[i], ring[(i + 1) % n], px, py, vx, vy, r, horizon, best);
  return best;
}

// The sweep is cut into slices of time; each slice's edges are those whose box meets the slice's
// stretch of the path grown by r (a hit at t in the slice puts the centre within r of the edge,
// so its box meets that window; the edge grid's one-cell margin covers the rounding), tested
// with the loop's own expressions. Once the best time lies within the slices swept, no edge left
// can beat it: the loop's minimum over all edges, bit for bit.
double ray_polygon_time(const StaticScene& scene, std::size_t p, double px, double py, double vx,
                        double vy, double r, double horizon, double cap) {
  const auto& ring = scene.polygons()[p].vertices;
  const RingGrid* g = scene.ring_grid(p);
  const double end = std::min(horizon, cap);
  if (!g || g->cells_across() == 0 || g->edges() != ring.size() ||
      !(std::isfinite(px) && std::isfinite(py) && std::isfinite(vx) && std::isfinite(vy) &&
        std::isfinite(r) && end >= 0 && end < INFINITY))
    return ray_polygon_time(ring, px, py, vx, vy, r, horizon);
  if (g->disc_overlaps(ring, px, py, r)) return 0;
  const std::size_t n = ring.size();
  // Slices about two cells of path long, at most as many as the grid's cells across (a line
  // crosses no more of them), whatever the speed; the cells they read and the edges they test,
  // at most the loop's count (below).
  const double speed = std::sqrt(vx * vx + vy * vy);
  const double step = std::max(speed > 0 ? 2 * g->cell() / speed : end,
                               end / static_cast<double>(g->cells_across() + 1));
  // The radius, and room for the rounding of positions far from a small ring (the grid's cells
  // are sized by the ring's coordinates, not the query's).
  const double grow =
      std::abs(r) * (1 + 1e-9) + 1e-15 * (std::abs(px) + std::abs(py) + speed * end);
  double best = INFINITY;
  std::size_t listed = 0;  // cells read and edges tested by the slices so far
  for (double t0 = 0;;) {
    const double t1 = step > 0 ? std::min(t0 + step, end) : end;
    const double xa = px + vx * t0, xb = px + vx * t1, ya = py + vy * t0, yb = py + vy * t1;
    // The minimum over a slice's edges does not depend on the order they come in. Long edges
    // come up in every slice, and a disc wider than many cells reads many cells or every edge:
    // past the loop's own work (cells read and edges tested), the rest of the slice is skipped
    // and the loop answers.
    const std::size_t cells = g->visit_edges_meeting(
        std::min(xa, xb) - grow, std::min(ya, yb) - grow, std::max(xa, xb) + grow,
        std::max(ya, yb) + grow, [&](uint32_t s) {
          if (++listed > n) return;
          edge_capsule_time(ring[s], ring[(s + 1) % n], px, py, vx, vy, r, horizon, best);
        });
    listed += cells;
    if (listed > n) return ray_polygon_time(ring, px, py, vx, vy, r, horizon);
    if (best <= t1 || !(t1 < end)) return best;
    t0 = t1;
  }
}

}  // namespace crowddb
