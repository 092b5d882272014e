// The choice of pair_lanes' lanes (steer/orca_pairs.hpp).
#include "steer/orca_pairs.hpp"

#include <atomic>

#include "util/cpu.hpp"

namespace crowddb::steer {

#if (CROWDDB_PAIRS_AVX2 && !defined(__AVX2__)) || (CROWDDB_PAIRS_AVX2_NATIVE && defined(__AVX2__))
#define CROWDDB_PAIRS_LANES 1
// orca_pairs_avx2.cpp
void pair_lanes_avx2_impl(const PairRow& row, const PairColumns& c, const uint32_t* rows,
                          std::size_t m, const PairOut& out);
#endif

namespace {
std::atomic<bool> reference_only{false};  // use_pair_reference
}  // namespace

void use_pair_reference(bool on) {
  reference_only = on;
}

bool pair_lanes_avx2() {
#if CROWDDB_PAIRS_LANES
  return cpu_has_avx2() && !reference_only;
#else
  return false;
#endif
}

void pair_lanes(const PairRow& row, const PairColumns& c, const uint32_t* rows, std::size_t m,
                const PairOut& out) {
#if CROWDDB_PAIRS_LANES
  pair_lanes_avx2_impl(row, c, rows, m, out);
#else
  // Never called: pair_lanes_avx2() is false.
  (void)row, (void)c, (void)rows, (void)m, (void)out;
#endif
}

}  // namespace crowddb::steer
