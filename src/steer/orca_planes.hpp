// ORCA's half-plane per neighbour (steer/orca.cpp): the truncated velocity obstacle of horizon
// tau, left by the smallest change u, of which the agent takes `share`.
//
// Two ways to build them, with the same answers bit for bit: `agent_plane`, one neighbour at a
// time (the reference, as the paper reads), and `agent_planes`, a row's neighbours at once,
// several per instruction (xsimd: the build's lanes, two of SSE2 by default, and where the CPU
// has AVX2 its four, chosen at run time; CROWDDB_NATIVE builds for the machine's own). The batch
// computes every case (cut-off arc, left leg, right leg, overlapping) in every lane and selects,
// where the reference branches: which leg a neighbour's plane follows is a coin toss to the branch
// predictor. Both use the same operations in the same order, and the build keeps a*b+c unfused
// (-ffp-contract=off), so their answers agree to the bit; the test
// (tests/steer/orca_planes_test.cpp) compares them on random and degenerate neighbours.
#pragma once

#include <cstddef>

#include "world/halfplane_lp.hpp"

namespace crowddb::steer {

// The half-plane agent i gets from neighbour j: relative position p = p_j - p_i, relative
// velocity v = v_i - v_avoided_j, combined radius r, horizon tau, tick dt, agent i's velocity
// (vix, viy), i's share of the avoidance.
HalfPlane agent_plane(double px, double py, double vx, double vy, double r, double tau, double dt,
                      double vix, double viy, double share);

// A row's neighbours, one column per input of agent_plane (m entries each).
struct PlaneInputs {
  const double *px, *py, *vx, *vy, *r, *tau, *share;
};

// Which lanes agent_planes uses: the widest the CPU has (AVX2 where the build's own set is
// narrower: chosen at run time), or the build's own instruction set (tests compare both).
enum class PlaneLanes { widest, build };

// Are the widest lanes wider than the build's here (AVX2 chosen at run time)? When not, the two
// choices of PlaneLanes are the same code.
bool wider_plane_lanes();

// out[a] = agent_plane(in.px[a], ..., dt, vix, viy, in.share[a]) for a < m.
void agent_planes(const PlaneInputs& in, std::size_t m, double dt, double vix, double viy,
                  HalfPlane* out, PlaneLanes lanes = PlaneLanes::widest);

}  // namespace crowddb::steer
