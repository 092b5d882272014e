// The velocity selection of ORCA (van den Berg, Guy, Lin, Manocha 2011, §5): the velocity
// closest to the preferred one inside the speed disc and every half-plane of permitted
// velocities; when the half-planes leave nothing, the velocity that violates the agents' planes
// least (the paper's 3-D linear program over (v, d): minimise d subject to every agent plane
// moved back by d), while the obstacle planes stay hard.
//
// Solved the incremental way (Seidel-style, planes in the given order, not shuffled, so the
// result is deterministic): the optimum only changes when a plane is violated, and then it lies
// on that plane's line, where the problem is one-dimensional (an interval of the line's
// parameter, cut by the earlier planes and the disc). The 3-D program is solved the same way on
// the planes' pairwise bisectors. O(m) expected per plane added, m <= ~20 in practice.
#pragma once

#include <cstddef>
#include <span>

namespace crowddb::steer {

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

}  // namespace crowddb::steer
