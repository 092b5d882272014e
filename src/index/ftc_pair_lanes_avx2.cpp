// The first-to-collide pair times in AVX2's four lanes, compiled with -mavx2 and called only when
// the CPU has it (index/ftc_tree.cpp). See ftc_pair_lanes.hpp for what may be used here.
#include "index/ftc_pair_lanes.hpp"

namespace crowddb::ftc {

uint32_t pair_times_lanes_avx2(const Columns& m, uint32_t n, const Query& q, double horizon,
                               double* out, double& earliest) {
  return pair_times_lanes<xsimd::avx2>(m, n, q, horizon, out, earliest);
}

}  // namespace crowddb::ftc
