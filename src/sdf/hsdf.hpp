// The HSDF expansion as plain arrays, shared by to_hsdf (which names it as a Graph) and the
// maximum-cycle-ratio throughput.
#pragma once

#include <cstdint>
#include <vector>

#include "sdf/graph.hpp"

namespace sdf::detail {

struct HsdfEdge {
  uint32_t src, dst;  // firings
  uint64_t tokens;    // iterations between the producing and the consuming firing
};

struct Hsdf {
  std::vector<ActorId> actor;   // per firing: its actor
  std::vector<uint64_t> index;  // per firing: k, it is firing k of its actor in an iteration
  std::vector<uint32_t> first;  // per actor: its firing 0 (firings of an actor are consecutive)
  std::vector<HsdfEdge> edges;  // sorted by (src, dst), one per pair
};

// q: the repetitions vector. Throws Error(limit) when Σq + edges exceeds max_size.
Hsdf expand(const Graph& g, const std::vector<uint64_t>& q, uint64_t max_size);

// q of a consistent graph; Error(input) naming the failing channel otherwise.
std::vector<uint64_t> repetitions_or_throw(const Graph& g, const char* analysis);

}  // namespace sdf::detail
