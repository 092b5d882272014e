// Tables that pack the chosen lanes of a four-lane comparison to the front, for the sources of
// AVX2 intrinsics (index/neighbour_lanes_avx2.cpp, steer/passing_lanes_avx2.cpp). The table is
// made at compile time (consteval): no function of this header is compiled into a -mavx2 object
// where the linker could keep it for everyone.
#pragma once

#include <cstdint>

namespace crowddb {

// Per mask of chosen lanes (bit l: lane l is chosen), the permutation (_mm256_permutevar8x32)
// that moves them to the front, in order: `places` for four 32-bit values, `halves` for four
// doubles as pairs of 32-bit halves. The slots past the chosen ones take lane 0: written, never
// counted.
struct FrontPacks {
  alignas(32) int32_t halves[16][8] = {};
  alignas(32) int32_t places[16][8] = {};
};

consteval FrontPacks make_front_packs() {
  FrontPacks p;
  for (int mask = 0; mask < 16; ++mask) {
    int slot = 0;
    for (int lane = 0; lane < 4; ++lane)
      if (mask & (1 << lane)) {
        p.halves[mask][2 * slot] = 2 * lane;
        p.halves[mask][2 * slot + 1] = 2 * lane + 1;
        p.places[mask][slot] = lane;
        ++slot;
      }
    for (; slot < 4; ++slot) p.halves[mask][2 * slot + 1] = 1;
  }
  return p;
}

inline constexpr FrontPacks kFrontPacks = make_front_packs();

}  // namespace crowddb
