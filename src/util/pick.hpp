// `c ? a : b` for doubles without a branch. g++ turns a ?: on two loaded doubles into a jump,
// which mispredicts about every other time where c is a coin toss: orca's velocity and share
// of a neighbour by who of the two goes first, cfsm's clipping by whether a neighbour lies
// towards the heading. Those run once per neighbour of every row, every tick
// (docs/bench/journal.md, 2026-12-02 evening).
#pragma once

#include <bit>
#include <cstdint>

namespace crowddb {

inline double pick(bool c, double a, double b) {
  const uint64_t mask = uint64_t{0} - uint64_t{c};
  return std::bit_cast<double>((std::bit_cast<uint64_t>(a) & mask) |
                               (std::bit_cast<uint64_t>(b) & ~mask));
}

}  // namespace crowddb
