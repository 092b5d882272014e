// The closest point to a target inside a disc and a set of half-planes; when the half-planes
// leave nothing, the point that violates the soft ones least (a 3-D linear program over (v, d):
// minimise d subject to every soft plane moved back by d) while the hard ones hold. It is ORCA's
// velocity selection (van den Berg, Guy, Lin, Manocha 2011, §5: velocities, a speed disc, agent
// planes soft, obstacle planes hard) and also where a disc aims in a goal area (the nearest point
// of the area eroded by the disc's radius, geometry.hpp goal_target).
//
// Solved the incremental way (Seidel-style, planes in the given order, not shuffled, so the
// result is deterministic): the optimum only changes when a plane is violated, and then it lies
// on that plane's line, where the problem is one-dimensional (an interval of the line's
// parameter, cut by the earlier planes and the disc). The 3-D program is solved the same way on
// the planes' pairwise bisectors. O(m) expected per plane added, m <= ~20 in practice.
#pragma once

#include <cstddef>
#include <span>

namespace crowddb {

// Permitted velocities v with (v - point) . normal >= 0; `normal` has unit length.
struct HalfPlane {
  double px = 0, py = 0;
  double nx = 0, ny = 0;
};

struct LpResult {
  double vx = 0, vy = 0;
  bool feasible = true;  // false: the fallback's least-violating velocity
};

// planes[0, hard) are hard, planes[hard, end) may be violated when there is no velocity that
// satisfies them all. The caller builds hard planes that v = 0 satisfies; should rounding still
// leave them empty, the result is v = 0. |result| <= max_speed always.
LpResult solve_velocity_lp(std::span<const HalfPlane> planes, std::size_t hard, double max_speed,
                           double pref_x, double pref_y);

}  // namespace crowddb
