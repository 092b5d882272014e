// The neighbour grid's ranked search (neighbour_grid.cpp) gathers, from a run of adjacent cells,
// every disc within a squared distance `bound` of the query: the cell-ordered positions
// X[lo, hi), Y[lo, hi) are read in order, and each one within the bound (other than the query's
// own place `self_at`) is appended with its place and squared distance. Then it ranks them: each
// one's count of those nearer. The two loops were two thirds of the search's time, and which
// candidate passes or is nearer is a coin toss, so both are written without branches.
//
// Two ways with the same answers bit for bit: `gather_within` and `count_all_nearer`, one at a
// time (the references), and their AVX2 twins (neighbour_lanes_avx2.cpp), four at a time (the
// passing candidates packed to the front of the vector through a table of permutations); chosen
// at run time where the CPU has AVX2. Both compute dx * dx + dy * dy from the same doubles (no
// fused multiply-adds anywhere: -ffp-contract=off), test it with <= (false for NaN), compare with
// < and keep the candidates in their order. At airport-20k (one thread, min of 8 interleaved
// runs) the lanes took the neighbour stage from 280 to 260 ms per 100 ticks; with the chords of
// the disc instead of the rows of its square (runs of ~7 candidates rather than ~20) they had
// gained nothing. tests/index/neighbour_lanes_test.cpp compares them.
#pragma once

#include <cstdint>

namespace crowddb::index {

// Appends the candidates a in [lo, hi) with d2 = (X[a] - px)^2 + (Y[a] - py)^2 <= bound and
// a != self_at to at[], dist[] and returns how many. Writes at most hi - lo entries of each.
inline uint32_t gather_within(const double* X, const double* Y, uint32_t lo, uint32_t hi, double px,
                              double py, double bound, uint32_t self_at, uint32_t* at,
                              double* dist) {
  uint32_t m = 0;
  for (uint32_t a = lo; a < hi; ++a) {
    const double dx = X[a] - px, dy = Y[a] - py;
    const double d2 = dx * dx + dy * dy;
    at[m] = a;
    dist[m] = d2;
    m += static_cast<uint32_t>((d2 <= bound) & (a != self_at));
  }
  return m;
}

// What gather_within_lanes may read and write past a run: X and Y to hi + 3, at and dist up to
// hi - lo + 3 entries (the lanes take whole vectors of four).
constexpr uint32_t kNeighbourPad = 3;

// before[u] = how many of dist[0, m) are nearer than dist[u], for every u < m: the ranks of the
// gathered candidates (the same count as count_nearer, query/naive_paths.hpp, gives one by one).
inline void count_all_nearer(const double* dist, uint32_t m, uint32_t* before) {
  for (uint32_t u = 0; u < m; ++u) {
    uint32_t c = 0;
    for (uint32_t f = 0; f < m; ++f) c += static_cast<uint32_t>(dist[f] < dist[u]);
    before[u] = c;
  }
}

// Which way gather_within_lanes and count_all_nearer_lanes go.
enum class GatherLanes { widest, scalar };

// Does this CPU take the AVX2 lanes (when asked for the widest)?
bool gather_lanes_avx2();

// gather_within, four candidates at a time where the CPU has AVX2 (and `lanes` is widest), the
// reference elsewhere; the same result. See kNeighbourPad for the room it needs.
uint32_t gather_within_lanes(const double* X, const double* Y, uint32_t lo, uint32_t hi, double px,
                             double py, double bound, uint32_t self_at, uint32_t* at, double* dist,
                             GatherLanes lanes = GatherLanes::widest);

// count_all_nearer, four candidates compared at a time where the CPU has AVX2 (and `lanes` is
// widest); dist[m, m + 3) must be readable and never nearer (INFINITY) then.
void count_all_nearer_lanes(const double* dist, uint32_t m, uint32_t* before,
                            GatherLanes lanes = GatherLanes::widest);

}  // namespace crowddb::index
