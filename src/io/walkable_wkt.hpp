#pragma once

#include <memory>
#include <string>
#include <string_view>
#include <vector>

#include "crowddb/world.hpp"

namespace crowddb::io {

// The walkable area as WKT (JuPedSim's `geometry` table): the bounds minus every obstacle,
// circles as 64-gons. A POLYGON with holes, or a MULTIPOLYGON when obstacles cut the area apart.
// Computed with Boost.Geometry, so overlapping obstacles still give valid geometry.
std::string walkable_area_wkt(const World& world);

// A walkable area given as WKT (the JuPedSim convention: a POLYGON whose holes are obstacles,
// or a MULTIPOLYGON of such). Either ring orientation is accepted; every ring must be closed.
class WalkableArea {
 public:
  // Throws Error(input) with a one-line reason: malformed WKT, a ring that is not closed, too
  // few points, non-finite coordinates, a self-intersection (with its point), holes outside or
  // nested or cutting the polygon apart, overlapping polygons, zero area.
  static WalkableArea parse(std::string_view wkt);
  ~WalkableArea();
  WalkableArea(WalkableArea&&) noexcept;
  WalkableArea& operator=(WalkableArea&&) noexcept;

  Bounds envelope() const;
  double area() const;
  // Inside or on the boundary.
  bool covers(double x, double y) const;
  // The same by Boost.Geometry's covered_by alone: covers' oracle (tests), and what it asks
  // for points near the boundary.
  bool covers_by_boost(double x, double y) const;
  // Whether the area lies within `b` (boundary contact allowed).
  bool within(const Bounds& b) const;
  // Everything in `b` that is not walkable, as simple polygons (no holes; polygons with holes
  // are split along horizontal lines through a hole), counter-clockwise, for the obstacle table.
  std::vector<std::vector<Vec2>> blocked_pieces(const Bounds& b) const;

 private:
  struct Impl;
  explicit WalkableArea(std::unique_ptr<Impl> impl);
  std::vector<std::vector<Vec2>> split_blocked(const Bounds& b) const;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crowddb::io
