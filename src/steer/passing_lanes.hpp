// Keeping to a side's look-ahead (steer/passing.hpp) reads, per band of cells meeting a lane, a
// run of rows in cell order and keeps those that passing()'s first tests do not reject: ahead
// within the look, within the two radii plus kSideReach of the lane's line, wishing to go more
// than 120 degrees away. Whether a row passes is a coin toss to the predictor, so the filter has no
// branch; it was a third of the look-ahead's time at airport-20k.
//
// Two ways with the same answers bit for bit: `passing_filter`, one row at a time (the
// reference), and its AVX2 twin (passing_lanes_avx2.cpp), four at a time (the passing rows'
// places packed to the front through a table of permutations), chosen at run time where the CPU
// has AVX2. Both evaluate the same expressions on the same doubles (no fused multiply-adds
// anywhere: -ffp-contract=off) and keep the places in their order.
// tests/steer/passing_lanes_test.cpp compares them.
#pragma once

#include <cmath>
#include <cstdint>

namespace crowddb::steer {

// The rows' columns in cell order (PassingLookahead's copies).
struct PassingColumns {
  const double *x, *y, *r, *wx, *wy;
};

// The query's side: its position, unit wish, look ahead and radius.
struct LaneQuery {
  double px, py, ux, uy, look, ri;
};

// What passing_filter_lanes may read past a run: the columns to hi + 3 (whole vectors of four),
// and pick[] up to hi - lo + 3 entries.
constexpr uint32_t kPassingPad = 3;

// Appends each place a in [lo, hi) whose row passing()'s first tests do not reject to pick[] and
// returns how many (at most hi - lo written). Written as the negations of passing()'s rejections
// (not along <= 0, not beyond the look, not wider than the reach), so that a row with a NaN
// among its values is kept when passing() would not reject it there either. `same_way2` is
// kSameWay squared and `side_reach` kSideReach: passed in, because their headers (streams.hpp,
// passing.hpp) hold inline functions that the lanes' file must not include.
inline uint32_t passing_filter(const PassingColumns& c, uint32_t lo, uint32_t hi,
                               const LaneQuery& q, double same_way2, double side_reach,
                               uint32_t* pick) {
  uint32_t m = 0;
  for (uint32_t a = lo; a < hi; ++a) {
    const double rx = c.x[a] - q.px, ry = c.y[a] - q.py;
    const double along = rx * q.ux + ry * q.uy;
    const double w2 = c.wx[a] * c.wx[a] + c.wy[a] * c.wy[a], dot = c.wx[a] * q.ux + c.wy[a] * q.uy;
    const double side = rx * q.uy - ry * q.ux;
    pick[m] = a;
    m += static_cast<uint32_t>(!(along <= 0) & !(along > q.look) &
                               !(std::abs(side) > q.ri + c.r[a] + side_reach) & (dot < 0) &
                               (dot * dot >= same_way2 * w2));
  }
  return m;
}

// Which way passing_filter_lanes goes.
enum class PassingLanes { widest, scalar };

// Does this CPU take the AVX2 lanes (when asked for the widest)?
bool passing_lanes_avx2();

// passing_filter, four rows at a time where the CPU has AVX2 (and `lanes` is widest), the
// reference elsewhere; the same result. See kPassingPad for the room it needs.
uint32_t passing_filter_lanes(const PassingColumns& c, uint32_t lo, uint32_t hi, const LaneQuery& q,
                              double same_way2, double side_reach, uint32_t* pick,
                              PassingLanes lanes = PassingLanes::widest);

}  // namespace crowddb::steer
