// Polygons of many edges for the tests of the edge grids and what uses them.
#pragma once

#include <cmath>
#include <numbers>
#include <vector>

#include "crowddb/world.hpp"
#include "util/rng.hpp"

namespace crowddb::test {

// A star-shaped ring of n vertices around (cx, cy): radii drawn in [r0, r1], some vertices
// snapped to a coarse lattice (horizontal and vertical edges, vertices sharing a y), some
// repeated (zero-length edges).
inline std::vector<Vec2> star(Rng& rng, std::size_t n, double cx, double cy, double r0, double r1) {
  std::vector<Vec2> ring;
  for (std::size_t k = 0; k < n; ++k) {
    const double a = 2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    const double r = rng.uniform(r0, r1);
    Vec2 v{cx + r * std::cos(a), cy + r * std::sin(a)};
    if (rng.below(4) == 0) v = {std::round(v.x * 2) / 2, std::round(v.y * 2) / 2};
    ring.push_back(v);
    if (rng.below(20) == 0) ring.push_back(v);
  }
  return ring;
}

// A square of side 2 h around (cx, cy) less a wavy disc of n vertices inside it: the blocked
// piece around a hall drawn as a walkable area, as one ring (around the square, then back along
// the hole's border, joined by a slit).
inline std::vector<Vec2> hall_piece(std::size_t n, double cx, double cy, double h) {
  std::vector<Vec2> ring = {
      {cx + h, cy}, {cx + h, cy + h}, {cx - h, cy + h}, {cx - h, cy - h}, {cx + h, cy - h}};
  for (std::size_t k = 0; k <= n; ++k) {  // clockwise around the hole, back to its start
    const double a = -2 * std::numbers::pi * static_cast<double>(k) / static_cast<double>(n);
    const double r = 0.8 * h * (1 + 0.05 * std::sin(7 * a));
    ring.push_back({cx + r * std::cos(a), cy + r * std::sin(a)});
  }
  return ring;
}

}  // namespace crowddb::test
