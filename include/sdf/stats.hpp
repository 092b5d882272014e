// Structural statistics of a graph: sizes, the repetitions vector's sum (the HSDF expansion's
// actor count) and maximum, connected and strongly connected components, and the number of
// simple cycles (Johnson, 1975), bounded.
//
// Cycles are counted on the channels: a self-loop is a cycle, and parallel channels make
// distinct cycles (A → B twice and B → A once: two cycles). Their number can grow exponentially
// with the graph, so the count stops at `max_cycles` cycles when there are more, or after
// `max_steps` arcs followed (then it is a lower bound and `cycles_complete` is false; a graph
// with exactly `max_cycles` cycles is counted completely). Everything else is O(V + E).
//
// Thread-safety: pure function.
#pragma once

#include <cstdint>
#include <optional>

#include "sdf/graph.hpp"

namespace sdf {

struct GraphStats {
  uint64_t actors = 0, channels = 0, self_loops = 0;
  std::optional<uint64_t> initial_tokens;  // the delays' sum; none when it exceeds 64 bits
  bool consistent = false;
  bool repetitions_overflow = false;  // a count beyond 64 bits: consistency not decided
  // Σq (the HSDF expansion's actors) and max q; none when inconsistent or beyond 64 bits.
  std::optional<uint64_t> repetitions_sum, repetitions_max;
  uint32_t components = 0;   // connected, ignoring directions
  uint32_t sccs = 0;         // strongly connected components
  uint32_t largest_scc = 0;  // actors in the largest
  uint32_t cyclic_sccs = 0;  // those holding a cycle (two actors or more, or a self-loop)
  uint64_t simple_cycles = 0;
  bool cycles_complete = true;
};

struct StatsLimits {
  uint64_t max_cycles = 1'000'000;
  uint64_t max_steps = 100'000'000;
};

GraphStats graph_stats(const Graph& g, const StatsLimits& limits = {});

}  // namespace sdf
