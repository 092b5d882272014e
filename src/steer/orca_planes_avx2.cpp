// agent_planes' lanes for AVX2 (four doubles a vector), compiled with -mavx2 and called only
// when the CPU has it (steer/orca_planes.cpp). See orca_planes_lanes.hpp for what may be used.
#include "steer/orca_planes_lanes.hpp"

namespace crowddb::steer {

std::size_t agent_planes_avx2(const PlaneInputs& in, std::size_t m, double dt, double vix,
                              double viy, HalfPlane* out) {
  return agent_planes_lanes<xsimd::avx2>(in, m, dt, vix, viy, out);
}

}  // namespace crowddb::steer
