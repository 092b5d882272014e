// ORCA's pass over a row's neighbours (steer/orca.cpp): per neighbour, who of the two goes first
// (the right of way), the contact plane when it is within a tick's reach, the inputs of its agent
// plane (steer/orca_planes.hpp), and whether it caps the row's wish (the headways). It runs for
// every neighbour of every row each tick and was a sixth of the tick (airport-20k, one thread:
// 2.6 ms of 15), most of it instructions, not waiting for memory.
//
// Two ways with the same answers bit for bit:
// - one neighbour at a time: first_or_ask and pair_rest (who goes first), then pair_one (the
//   reference, as orca.cpp reads);
// - four at a time (pair_lanes, AVX2, orca_pairs_avx2.cpp, chosen at run time where the CPU has
//   it): the two records of four neighbours loaded as vectors and transposed, every case computed
//   in every lane and selected. A lane where out before in may decide who goes first (the two
//   rows' goals left and sought cross, rare) is marked for the caller, which asks
//   sim::out_before_in and computes the lane one at a time.
// Both use the same operations on the same operands in the same order, and the build keeps
// products and sums unfused (-ffp-contract=off). tests/steer/orca_pairs_test.cpp compares them.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "sim/stages.hpp"     // sim::AheadInput, sim::ahead
#include "steer/model.hpp"    // kSkin
#include "steer/streams.hpp"  // follows_at, kSameWay
#include "util/pick.hpp"

namespace crowddb::steer {

// sim::ahead's "the same way" and the caps' (follows_at), restated by the lanes as one constant.
static_assert(kSameWay == sim::kSameWay);

// Per row, what the others read of it as someone's neighbour besides sim::AheadInput, in one
// cache line (its columns were a dozen lines per neighbour): its velocity and the one others avoid
// it at when it goes first (orca.cpp), radius, time to arrive, path left, and its rank for ties.
struct alignas(64) Peer {
  double vx, vy, avoid_x, avoid_y, radius, arrive, remaining;
  uint64_t rank;
};
static_assert(sizeof(Peer) == 64);

// Row i's side of its pairs (orca.cpp fills it once per row).
struct PairRow {
  const sim::AheadInput* heading;  // its own records
  const Peer* peer;
  uint8_t yielding;           // in a stalemate's yield_ahead
  double x, y, r;             // position, radius
  double vx, vy;              // velocity
  double reach;               // 2 dt max_speed: a contact plane within this gap
  double beyond;              // reach + kSkin + r: centres farther than this plus r_j need none
  double dt, tau;             // the tick, time_horizon
  double lo_share, hi_share;  // the avoidance taken by the one going second, first
  // The headway caps (orca.cpp Caps): which apply (0 / 1 each), i's unit wish, and
  // v0 stream_gap + r.
  int headway, gap;
  double ux, uy, cap_reach;
};

// The tables a neighbour's values come from, by row.
struct PairColumns {
  const sim::AheadInput* heading;
  const Peer* peer;
  const uint8_t* yielding;
  const double *wish_x, *wish_y;  // the preferred velocities
};

// What the pass writes per neighbour (entry a of the row's list).
struct PairOut {
  double *px, *py, *vx, *vy, *r, *tau, *share;  // the agent plane's inputs (PlaneInputs)
  double *cpx, *cpy, *cnx, *cny;                // the contact plane, where contact[a]
  // pair_one: per entry, whether it gives a contact plane, and whether it caps the wish (bit 0:
  // by the headway, bit 1: by the stream gap).
  uint8_t *contact, *caps;
  // pair_lanes instead: per four entries (a / 4), bit l of each nibble for entry 4 (a / 4) + l:
  // bits 0-3 contact, 4-7 caps by the headway, 8-11 by the stream gap, 12-15 out before in may
  // decide who goes first (then the rest is unspecified: the caller computes it with pair_one).
  uint16_t* lanes;
};

// Who goes first when neither rule before it decides: for two walking to different goals the
// one ahead (sim::ahead), else less path left, ties by the seeded rank. Without branches: which
// way a pair goes is a coin toss to the branch predictor. (The tests as ints: & and | on them is
// meant, not && and ||.)
inline bool pair_rest(const PairRow& row, const sim::AheadInput& hj, const Peer& pj) {
  const Peer& pi = *row.peer;
  const bool by_path = int{pi.remaining < pj.remaining} |
                       (int{pi.remaining == pj.remaining} & int{pi.rank > pj.rank});
  bool by_place;
  const bool decides = int{std::isfinite(pi.remaining)} & int{std::isfinite(pj.remaining)} &
                       int{sim::ahead(*row.heading, hj, by_place)};
  // (As a mask: g++ made the ?: a jump on `decides`, a coin toss too.)
  const unsigned take = 0u - unsigned{decides};
  return ((take & unsigned{by_place}) | (~take & unsigned{by_path})) != 0;
}

// Does i go first (1), j (0), or may out before in decide (kAsk: the caller asks
// sim::out_before_in, and pair_rest when that does not decide)? An agent yielding to a stalemate
// goes first; out before in can only decide when one left the goal the other heads for.
inline constexpr int kAsk = 2;
inline int first_or_ask(const PairRow& row, const sim::AheadInput& hj, const Peer& pj,
                        uint8_t yielding_j) {
  if (row.yielding != yielding_j) return row.yielding;
  if (row.heading->left_goal == hj.goal || hj.left_goal == row.heading->goal) return kAsk;
  return pair_rest(row, hj, pj);
}

// Entry a for neighbour j, i_first saying who goes first (the reference; see orca.cpp for why
// each part is as it is).
inline void pair_one(const PairRow& row, const PairColumns& c, uint32_t j, bool i_first,
                     const PairOut& out, std::size_t a) {
  const sim::AheadInput& hj = c.heading[j];
  const Peer& pj = c.peer[j];
  const double dx = hj.x - row.x, dy = hj.y - row.y;
  const double d2 = dx * dx + dy * dy;
  // The contact plane (hard) of a neighbour within a tick's reach. One whose squared distance
  // clears (reach + skin + radii)^2 by a relative 1e-9 is beyond reach in the exact test whatever
  // its rounding (an error of a few ulps of d): most are, and they need no square root.
  const double far = row.beyond + pj.radius;
  const bool clear = d2 > far * far * (1 + 1e-9);
  const double d = clear ? 0.0 : std::sqrt(d2);
  const double gap = d - row.r - pj.radius - kSkin;
  const bool contact = !(clear || gap >= row.reach || d == 0);
  out.contact[a] = contact;
  if (contact) {
    const double nx = dx / d, ny = dy / d;
    // v . n <= g  <=>  v . (-n) >= -g: the plane through -n g with normal -n.
    const double share = pick(i_first, row.lo_share, row.hi_share);
    const double g = std::max(0.0, gap) * share / row.dt;
    out.cpx[a] = nx * g;
    out.cpy[a] = ny * g;
    out.cnx[a] = -nx;
    out.cny[a] = -ny;
  }
  // Right of way: a neighbour that goes first is avoided where it wants to go, as far as it is
  // held up (walking as it wishes, its velocity says it already). Picked by mask, not by a branch
  // on i_first (a coin toss to the predictor).
  const double vjx = pick(i_first, pj.vx, pj.avoid_x);
  const double vjy = pick(i_first, pj.vy, pj.avoid_y);
  out.px[a] = dx;
  out.py[a] = dy;
  out.vx[a] = row.vx - vjx;
  out.vy[a] = row.vy - vjy;
  out.r[a] = row.r + pj.radius;
  // The pair's horizon: no longer than until one of them arrives, and at least a tick (std::clamp
  // as libstdc++ writes it, spelt out for the lanes to restate).
  out.tau[a] = std::min(std::max(std::min(row.peer->arrive, pj.arrive), row.dt), row.tau);
  out.share[a] = pick(i_first, row.hi_share, row.lo_share);
  // follows() and follows_within_gap() (steer/streams.hpp) on the values at hand (the same
  // operands), without branches (whether one is followed is a coin toss to the predictor).
  uint8_t caps = 0;
  if (row.headway | row.gap) {
    const double wx = c.wish_x[j], wy = c.wish_y[j];
    const int h = row.headway & int{follows_at(dx, dy, row.ux, row.uy, row.r, pj.radius, wx, wy)};
    const int g = row.gap & int{follows_within_gap_at(dx, dy, d2, row.cap_reach, row.ux, row.uy,
                                                      row.r, pj.radius, wx, wy)};
    caps = static_cast<uint8_t>(h | g << 1);
  }
  out.caps[a] = caps;
}

// Does this CPU take pair_lanes' four lanes (AVX2)? False while use_pair_reference(true).
bool pair_lanes_avx2();

// For tests: with true, pair_lanes_avx2() answers false, so that orca takes the reference for
// every entry and whole runs of the two ways can be compared.
void use_pair_reference(bool on);

// Entries [0, m) for the neighbours rows[0, m), m a multiple of 4, four at a time, their flags in
// out.lanes (not out.contact, out.caps); only where pair_lanes_avx2().
void pair_lanes(const PairRow& row, const PairColumns& c, const uint32_t* rows, std::size_t m,
                const PairOut& out);

}  // namespace crowddb::steer
