// The repetitions vector: the smallest positive integers q with q[src]·prd = q[dst]·cns on every
// channel, per connected component (thesis 5.2.1, the Ptolemy algorithm).
//
// Rational propagation: a union-find over the channels in file order keeps each actor's
// q / q_root as a reduced fraction; when the graph is consistent and every count fits, the
// fractions scaled by the lcm of their denominators are the answer (unique, whatever forest
// found it). Otherwise a depth-first walk from each component's lowest actor gives each actor a
// fraction relative to that actor, the fractions are scaled, then every channel's balance
// equation is checked: the walk's spanning tree defines the failing channel and its two sides.
// O(V + E) per component with 64-bit checked arithmetic: every intermediate numerator and
// denominator is bounded by the largest entry of the result, so an overflow means the answer
// itself does not fit and is reported as Error(overflow).
//
// Thread-safety: pure function.
#pragma once

#include <cstdint>
#include <vector>

#include "sdf/graph.hpp"

namespace sdf {

struct Repetitions {
  bool consistent = false;
  std::vector<uint64_t> q;  // per actor, when consistent
  // When inconsistent: a channel whose balance equation fails, and the two sides of it as
  // computed (q_src·prd versus q_dst·cns, with q from the spanning tree of the walk).
  ChannelId channel = 0;
  uint64_t q_src = 0, q_dst = 0;
};

// Throws Error(overflow) when the vector (or an intermediate of the walk) exceeds 64 bits.
Repetitions compute_repetitions(const Graph& g);

}  // namespace sdf
