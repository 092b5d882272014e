// Where streams meet, for ORCA's stream gap (steer/orca.cpp, docs/steering.md).
//
// A stream is the people bound for one goal. An agent is *at a meeting* when one of its
// neighbours is bound for another goal and wants to go more than 60 degrees away from its own
// wish (coming towards it or crossing). It is *behind a meeting* when someone it follows is at
// or behind one; it follows j when j is one of its neighbours, ahead of it, within the corridor
// of their combined width along its wish, and goes its way (wishes within 60 degrees) or
// stands, however far apart they are: a queue is one queue across its gaps. Marking is a
// reachability over the neighbour lists: the meetings, then their followers breadth first, so
// a whole queue learns of a jam at its head in one tick.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "crowddb/query.hpp"
#include "index/collision_common.hpp"

namespace crowddb {
class Executor;
}

namespace crowddb::steer {

inline constexpr double kSameWay = 0.5;  // cos 60 degrees: "the same way"

// The columns the marking reads, one entry per row; the lists are the rows' neighbours.
struct StreamView {
  std::span<const double> x, y, radius;
  std::span<const uint32_t> goal;
  std::span<const double> wish_x, wish_y;  // preferred velocities [m/s]
  const NeighbourLists* nb = nullptr;
  double gap = 1;  // [s] the stream gap (> 0; only follows_within_gap reads it)
};

// Is j ahead of i in its corridor, going its way or standing (see the top; the distance is the
// caller's)? (ux, uy) is i's unit wish. Exposed for the opt-in headway, which uses the same
// corridor. Squares instead of roots: "within 60 degrees" is dot >= cos 60 |w|. Without
// branches: whether a neighbour is followed is a coin toss to the predictor, and the stream gap
// asks it of every neighbour of nearly every row in a crowd where streams cross. (The tests as
// ints: & and | on them is meant.)
// The same on the values: (rx, ry) = p_j - p_i, radii ri and rj, j's wish (wx, wy). (Orca's linear
// programs ask it with a neighbour's columns already at hand.)
inline bool follows_at(double rx, double ry, double ux, double uy, double ri, double rj, double wx,
                       double wy) {
  const double w2 = wx * wx + wy * wy, dot = wx * ux + wy * uy;
  // Ahead (not behind or beside), in the corridor, and standing or going i's way.
  return int{!(rx * ux + ry * uy <= 0)} & int{!(std::abs(ry * ux - rx * uy) > ri + rj)} &
         (int{w2 == 0} | (int{dot >= 0} & int{dot * dot >= kSameWay * kSameWay * w2}));
}
inline bool follows(const StreamView& v, std::size_t i, std::size_t j, double ux, double uy) {
  return follows_at(v.x[j] - v.x[i], v.y[j] - v.y[i], ux, uy, v.radius[i], v.radius[j], v.wish_x[j],
                    v.wish_y[j]);
}

// Is row i at a meeting (see the top)?
bool at_meeting(const StreamView& v, std::size_t i);

// Does row i (unit wish u, speed w) follow the row of its list entry a closely enough for the
// stream gap to cap its wish (spacing below w x gap: beyond, v_ahead + spacing / gap >= w)?
// The distance first: it needs only the list and one radius.
// The same on the values (orca's pass over the neighbours asks it so): (rx, ry) = p_j - p_i and
// d2 its squared length, as the list has it; reach_i = w gap + r_i, the row's part of the reach.
inline bool follows_within_gap_at(double rx, double ry, double d2, double reach_i, double ux,
                                  double uy, double ri, double rj, double wx, double wy) {
  const double reach = reach_i + rj;
  return int{d2 < reach * reach} & int{follows_at(rx, ry, ux, uy, ri, rj, wx, wy)};
}
inline bool follows_within_gap(const StreamView& v, std::size_t i, uint32_t a, double ux, double uy,
                               double w) {
  const uint32_t j = v.nb->row[a];
  const double dx = v.x[j] - v.x[i], dy = v.y[j] - v.y[i];  // the list's own distance, bit for bit
  return follows_within_gap_at(dx, dy, dx * dx + dy * dy, w * v.gap + v.radius[i], ux, uy,
                               v.radius[i], v.radius[j], v.wish_x[j], v.wish_y[j]);
}

// The marking; the vectors keep their capacity from call to call.
struct StreamMarks {
  std::vector<uint8_t> marked;  // per row: at or behind a meeting
  // Per list entry a of row i: i follows nb.row[a]. Only for rows not at a meeting themselves
  // (0 for the others): the search needs no more, and where nearly everyone is at a meeting
  // (an airport's crossing travellers) the headway finds whom they follow as it goes.
  std::vector<uint8_t> follows;
  uint64_t count = 0;  // rows marked
  // Scratch: the "follows" edges (followed << 32 | follower) and the meetings per chunk, the
  // edges all together, and the search's queue.
  std::vector<std::vector<uint64_t>> chunk_edges;
  std::vector<std::size_t> chunk_meetings;
  std::vector<uint64_t> edges;
  index::RadixScratch radix;
  std::vector<uint32_t> queue;
  std::vector<uint32_t> start;  // with many edges: per row, where its followers begin in `edges`
  bool by_table = false;        // the last search looked followers up in `start` (tests)
};

// Marks every row at or behind a meeting. Rows with no wish are never marked (they follow no
// one). Work O(rows + list entries) on every thread, then O(E log E) on one for the E "follows"
// edges; the result does not depend on the thread count.
void mark_meetings(const StreamView& v, StreamMarks& out, Executor& ex);

// The naive twin for tests: the meetings, then sweeps over every row marking those that follow
// a marked row, until a sweep marks nothing. O(rows x list entries) at worst.
void mark_meetings_naive(const StreamView& v, std::vector<uint8_t>& marked);

}  // namespace crowddb::steer
