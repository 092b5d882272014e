// Who is passing whom, for ORCA's keeping to one side (steer/orca.cpp, docs/steering.md).
//
// Row j is *passing* row i when it comes towards i in i's lane ahead: ahead of i along i's unit
// wish u, within the two radii plus kSideReach to either side of i's line, wishing to go more
// than 120 degrees away from u, and each one's target lies behind the other (two people closing
// on one door from its two sides are converging, not passing).
//
// Seeing it only among the nearest neighbours came too late in a crowd: in a block of people
// walking one way, the ten nearest are the block's own, and the people coming the other way
// enter the list a metre or two away, when the lanes are already full of both streams (a 1 m
// corridor with 20 + 20 people: 94 of 240 arrive over six seeds). So the question is asked of
// everyone within `look` metres ahead: a uniform grid over the rows' positions, built each tick,
// and per row the cells that meet its lane ahead (a rectangle `look` long and r_i + r_max +
// kSideReach to either side), scanned band by band, each band's cells as one run. It stops at
// the first row found passing; the answer (whether there is one) does not depend on the order.
// Each cell keeps which sixteenths of the compass its rows walk towards (a 16-bit mask), and
// only cells holding a heading within 60 degrees (plus a margin) of the opposite of the query's
// are read: in a crowd walking one way (a door, a queue) few are. The rows' columns are copied
// in cell order, so adjacent cells read are one run of memory, filtered without branches. The
// naive twin, passing_ahead_naive, asks every row.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "steer/streams.hpp"  // kSameWay

namespace crowddb {
class Executor;
}

namespace crowddb::steer {

inline constexpr double kSideReach = 0.6;  // [m] beyond the two radii, to either side

// The columns the question reads, one entry per row.
struct PassingView {
  std::span<const double> x, y, radius;
  std::span<const double> wish_x, wish_y;      // preferred velocities [m/s]
  std::span<const double> target_x, target_y;  // the rows' current waypoints
};

// A wish's heading class, 0..15: the sixteenth of its direction's "diamond angle" (a
// pseudo-angle, in [0, 4) counter-clockwise from the x axis, only its order used), for (x, y)
// finite and not both zero. Without branches; heading_class_reference is the plain quadrant by
// quadrant form it equals (tests).
int heading_class(double x, double y);
int heading_class_reference(double x, double y);

// The heading classes (bit k: class k) a wish more than 120 degrees from the unit direction
// (ux, uy) (of length 1 up to rounding, as find() asks; not zero, NaN or infinite) can fall in:
// those of the arc within 60 degrees of (-ux, -uy), widened by 2 degrees on each side against
// rounding. PassingLookahead reads only cells holding one of them. opposite_classes_exact computes
// the arc's ends (two headings of turned vectors) and fills the classes between; opposite_classes
// takes them, or one or two more, from a table by a finer heading (the exact form was about 1 % of
// the tick at airport-20k). Never fewer (tests): a class too many only lets a query read a band
// that holds nobody passing, so the answer is the same.
uint16_t opposite_classes(double ux, double uy);
uint16_t opposite_classes_exact(double ux, double uy);

// Is row j passing row i, (ux, uy) being i's unit wish (see the top)? Only rows ahead within
// `look` count (along i's wish; INFINITY: any distance).
inline bool passing(const PassingView& v, std::size_t i, std::size_t j, double ux, double uy,
                    double look = INFINITY) {
  const double rx = v.x[j] - v.x[i], ry = v.y[j] - v.y[i];
  const double along = rx * ux + ry * uy;
  if (along <= 0 || along > look) return false;  // behind, beside or too far
  if (std::abs(rx * uy - ry * ux) > v.radius[i] + v.radius[j] + kSideReach) return false;
  const double wx = v.wish_x[j], wy = v.wish_y[j];
  const double w2 = wx * wx + wy * wy, dot = wx * ux + wy * uy;
  if (!(dot < 0 && dot * dot >= kSameWay * kSameWay * w2)) return false;  // not towards i
  if ((v.target_x[j] - v.x[i]) * ux + (v.target_y[j] - v.y[i]) * uy >= 0) return false;
  return (v.target_x[i] - v.x[j]) * wx + (v.target_y[i] - v.y[j]) * wy < 0;
}

// Keeping to one side stops near a waypoint where the path bends sharply (a corridor's mouth, a
// door; steer/orca.cpp), not where it bends gently (the corners of a route round a pillar, a
// metre apart and 15-25 degrees each). (dx, dy): from the agent to its waypoint; (ex, ey): from
// the waypoint to the point after it. Sharp: turning by more than kSharpBend degrees, or no
// direction after it (the waypoint is the last point). Squared, so that no root is taken.
inline constexpr double kSharpBend = 45;                      // [degrees]
inline constexpr double kSharpBendCos = 0.70710678118654752;  // its cosine
inline bool bends_sharply(double dx, double dy, double ex, double ey) {
  const double dot = dx * ex + dy * ey;
  return dot <= 0 ||
         dot * dot < kSharpBendCos * kSharpBendCos * (dx * dx + dy * dy) * (ex * ex + ey * ey);
}

// The naive twin: is any row passing row i within `look` ahead?
bool passing_ahead_naive(const PassingView& v, std::size_t i, double ux, double uy, double look);

// The indexed question (see the top).
class PassingLookahead {
 public:
  // Buckets every row of `v` (the positions must be finite).
  void build(const PassingView& v, Executor& ex);
  static constexpr uint32_t kNobody = ~0u;
  // A row passing row i within `look` ahead, or kNobody. (ux, uy): i's unit wish (its length must
  // be 1 up to rounding: it sets the lane's width); `tests` counts the rows looked at. `hint`, any
  // row number (kNobody: none), is asked first: last tick's answer usually still is one (people
  // pass each other over seconds), and then the grid is not read. Which row is returned may
  // depend on the hint; whether one is does not.
  uint32_t find(const PassingView& v, std::size_t i, double ux, double uy, double look,
                uint64_t& tests, uint32_t hint = kNobody) const;
  // Is any row passing row i within `look` ahead?
  bool ahead(const PassingView& v, std::size_t i, double ux, double uy, double look,
             uint64_t& tests) const {
    return find(v, i, ux, uy, look, tests) != kNobody;
  }

 private:
  int64_t col(double x) const;
  int64_t row(double y) const;

  double x0_ = 0, y0_ = 0, cell_ = 1, inv_cell_ = 1, rmax_ = 0;
  int64_t W_ = 1, H_ = 1;
  std::vector<uint32_t> start_;  // W * H + 1 offsets into rows_
  std::vector<uint32_t> rows_;   // rows in cell order (row-major cells)
  // The rows' columns in cell order (passing_lanes.hpp), each padded by kPassingPad entries for
  // the lanes.
  std::vector<double> cx_, cy_, cr_, cwx_, cwy_;
  std::vector<uint16_t> classes_;   // per cell: bit k set when a row's heading is in class k
  std::vector<int64_t> cell_of_;    // scratch: cell per row
  std::vector<uint16_t> class_of_;  // scratch: heading class bit per row (0: standing)
};

}  // namespace crowddb::steer
