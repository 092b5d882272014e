// The neighbour grid's gathering and ranking four at a time (gather_within_lanes,
// count_all_nearer_lanes: AVX2, chosen at run time in a default build) against the references
// (gather_within, count_all_nearer). The gathering: the same places and
// squared distances to the bit, in the same order, for every length of run (whole vectors and
// tails, whose lanes past the run's end would pass), the query's own place at every lane or
// outside, distances on the bound exactly, NaN and infinite coordinates, and every mask of
// passing lanes.
#include "index/neighbour_lanes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <iostream>
#include <vector>

#include "util/rng.hpp"

namespace crowddb::index {
namespace {

constexpr uint32_t kNoPlace = ~0u;

struct GatherResult {
  std::vector<uint32_t> at;
  std::vector<uint64_t> dist_bits;
};

GatherResult gather_run(std::vector<double> X, std::vector<double> Y, uint32_t lo, uint32_t hi,
                        double px, double py, double bound, uint32_t self_at, GatherLanes lanes) {
  // The lanes read past the run's end: what lies there is on the query (it would pass).
  X.resize(std::max<std::size_t>(X.size(), hi + kNeighbourPad), px);
  Y.resize(std::max<std::size_t>(Y.size(), hi + kNeighbourPad), py);
  // Filled with a marker past the room it may use: nothing is written there.
  const uint32_t room = hi - lo + kNeighbourPad;
  std::vector<uint32_t> at(room + 1, 0xdeadbeef);
  std::vector<double> dist(room + 1, -1.0);
  const uint32_t m = lanes == GatherLanes::scalar
                         ? gather_within(X.data(), Y.data(), lo, hi, px, py, bound, self_at,
                                         at.data(), dist.data())
                         : gather_within_lanes(X.data(), Y.data(), lo, hi, px, py, bound, self_at,
                                               at.data(), dist.data(), lanes);
  EXPECT_LE(m, hi - lo);
  EXPECT_EQ(at[room], 0xdeadbeef) << "wrote past its room";
  EXPECT_EQ(dist[room], -1.0) << "wrote past its room";
  GatherResult g;
  for (uint32_t u = 0; u < m; ++u) {
    g.at.push_back(at[u]);
    g.dist_bits.push_back(std::bit_cast<uint64_t>(dist[u]));
  }
  return g;
}

TEST(NeighbourLanes, GatherMatchesTheReferenceBitForBit) {
  Rng rng(20261204);
  uint64_t compared = 0, passed = 0, lanes_masks = 0;
  for (int trial = 0; trial < 20000; ++trial) {
    const auto n = static_cast<uint32_t>(rng.below(40));
    std::vector<double> X(n), Y(n);
    const double px = rng.uniform(-50, 50), py = rng.uniform(-50, 50);
    for (uint32_t a = 0; a < n; ++a) {
      switch (rng.below(8)) {
        case 0:  // on the query
          X[a] = px;
          Y[a] = py;
          break;
        case 1:  // a grid of quarter metres: many equal distances
          X[a] = px + 0.25 * static_cast<double>(rng.below(17)) - 2;
          Y[a] = py + 0.25 * static_cast<double>(rng.below(17)) - 2;
          break;
        case 2:  // far off, or not a number
          X[a] = rng.below(2) ? NAN : (rng.below(2) ? INFINITY : 1e300);
          Y[a] = py;
          break;
        default:
          X[a] = px + rng.uniform(-3, 3);
          Y[a] = py + rng.uniform(-3, 3);
      }
    }
    const auto lo = static_cast<uint32_t>(rng.below(n / 2 + 1));
    const auto hi = lo + static_cast<uint32_t>(rng.below(n - lo + 1));
    // The bound: random, exactly one candidate's distance (the <= edge), zero or infinite.
    double bound = rng.uniform(0, 6);
    if (hi > lo && rng.below(3) == 0) {
      const uint32_t a = lo + static_cast<uint32_t>(rng.below(hi - lo));
      const double dx = X[a] - px, dy = Y[a] - py;
      bound = dx * dx + dy * dy;
    } else if (rng.below(10) == 0) {
      bound = rng.below(2) ? 0.0 : INFINITY;
    }
    // The query's own place: inside the run at any lane, or not in it at all.
    const uint32_t self_at =
        hi > lo && rng.below(4) ? lo + static_cast<uint32_t>(rng.below(hi - lo)) : kNoPlace;
    const GatherResult want = gather_run(X, Y, lo, hi, px, py, bound, self_at, GatherLanes::scalar);
    const GatherResult got = gather_run(X, Y, lo, hi, px, py, bound, self_at, GatherLanes::widest);
    ASSERT_EQ(got.at, want.at) << "trial " << trial;
    ASSERT_EQ(got.dist_bits, want.dist_bits) << "trial " << trial;
    ++compared;
    passed += want.at.size();
    // Whole vectors of four in which some but not all pass: the packing's permutations.
    lanes_masks += hi - lo >= 4 && !want.at.empty() && want.at.size() < hi - lo;
  }
  // The trials reach what they are meant to (not all empty, not all full).
  EXPECT_GT(passed, compared);
  EXPECT_GT(lanes_masks, compared / 4);
}

// Every one of the sixteen masks of a vector of four, with the query's own place in each lane.
TEST(NeighbourLanes, EveryMaskAndOwnPlace) {
  for (uint32_t mask = 0; mask < 16; ++mask)
    for (uint32_t self = 0; self <= 8; ++self) {
      std::vector<double> X(8), Y(8, 0.0);
      for (uint32_t a = 0; a < 8; ++a) X[a] = mask >> (a % 4) & 1 ? 1.0 : 3.0;  // bound 4: 1 in
      const uint32_t self_at = self < 8 ? self : kNoPlace;
      const GatherResult want = gather_run(X, Y, 0, 8, 0, 0, 4, self_at, GatherLanes::scalar);
      const GatherResult got = gather_run(X, Y, 0, 8, 0, 0, 4, self_at, GatherLanes::widest);
      EXPECT_EQ(got.at, want.at) << "mask " << mask << " self " << self;
      EXPECT_EQ(got.dist_bits, want.dist_bits) << "mask " << mask << " self " << self;
      const auto in = static_cast<std::size_t>(2 * std::popcount(mask)) -
                      (self < 8 && (mask >> (self % 4) & 1) ? 1 : 0);
      EXPECT_EQ(want.at.size(), in);
    }
}

// The ranks four at a time against the reference, every count from 0 to 40 candidates: ties,
// zeros, infinities and NaN among them.
TEST(NeighbourLanes, RanksMatchTheReference) {
  Rng rng(20261205);
  uint64_t ties = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const auto m = static_cast<uint32_t>(trial % 41);
    std::vector<double> dist(m + kNeighbourPad, INFINITY);
    for (uint32_t u = 0; u < m; ++u) switch (rng.below(6)) {
        case 0:
          dist[u] = 0.25 * static_cast<double>(rng.below(4));  // ties
          break;
        case 1:
          dist[u] = rng.below(3) ? INFINITY : NAN;
          break;
        default:
          dist[u] = rng.uniform(0, 25);
      }
    std::vector<uint32_t> want(m), got(m, 0xdeadbeef);
    count_all_nearer(dist.data(), m, want.data());
    count_all_nearer_lanes(dist.data(), m, got.data());
    ASSERT_EQ(got, want) << "trial " << trial;
    for (uint32_t u = 0; u + 1 < m; ++u) ties += dist[u] == dist[u + 1];
  }
  EXPECT_GT(ties, 1000u);
}

TEST(NeighbourLanes, WidestIsChosenWhereTheCpuHasIt) {
  if (!gather_lanes_avx2()) std::cout << "[ note ] gathering one at a time on this CPU\n";
#if CROWDDB_TEST_AVX2_DISPATCH
  EXPECT_EQ(gather_lanes_avx2(), __builtin_cpu_supports("avx2") != 0);
#endif
}

}  // namespace
}  // namespace crowddb::index
