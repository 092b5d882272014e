// Timed analysis of SDF graphs: the homogeneous (HSDF) expansion and the throughput of
// self-timed execution, by two independent methods that the tests compare.
//
// Semantics (as SDF3's): every actor fires as soon as it is enabled, with unbounded
// auto-concurrency (a firing may start while earlier ones of the same actor run; a self-loop
// with k tokens allows at most k / cns at once); a firing takes the actor's execution time,
// consumes its input tokens when it starts and produces its outputs when it ends. Throughput is
// iterations (one repetitions vector's worth of firings) per time unit in the long run: an
// exact fraction in lowest terms. It is 0 when the graph deadlocks and unbounded when no cycle
// with positive execution time constrains it (an actor outside every cycle may fire
// arbitrarily often at once). On a graph that is not strongly connected it is the minimum over
// its strongly connected components, each analysed on its own.
//
//  - throughput_state_space: explores the timed state space of each strongly connected
//    component (tokens on its channels and the remaining times of the firings in progress)
//    until a state repeats; the repeated stretch is the periodic regime. SDF3's method.
//  - throughput_mcm: the maximum cycle ratio (time / tokens) of the HSDF expansion, by Karp's
//    algorithm on the graph of its initial tokens; also names a critical cycle.
//
// Thread-safety: pure functions.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sdf/graph.hpp"

namespace sdf {

// Every actor's execution time, or `default_time` where the graph has none. Throws Error(input)
// naming the first actor without one when there is no default.
std::vector<uint64_t> execution_times(const Graph& g,
                                      std::optional<uint64_t> default_time = std::nullopt);

// The HSDF expansion: firing k (0 ≤ k < q[a]) of actor a becomes actor `a_k` (error on a name
// clash), with a's execution time; for each channel and each token a firing consumes, an edge
// from the firing that produced it, carrying as many tokens as iterations separate the two
// (parallel edges merged, keeping the fewest tokens). Rates are 1. Throws Error(input) on an
// inconsistent graph and Error(limit) when Σq or an edge count exceeds `max_size` (edges +
// actors).
Graph to_hsdf(const Graph& g, uint64_t max_size = 50'000'000);

struct Throughput {
  // Iterations per time unit = num / den in lowest terms (num = 0: deadlock). Unbounded when no
  // cycle with positive time constrains the graph; num and den are then 0.
  bool unbounded = false;
  uint64_t num = 0, den = 1;
  // throughput_mcm only: the HSDF firings of one critical cycle, in order (`a_k` names), with
  // its total execution time and tokens (time / tokens = den / num). Empty when unbounded or
  // deadlocked (then `deadlock_cycle` holds a cycle of firings without tokens).
  std::vector<std::string> critical_cycle;
  uint64_t cycle_time = 0, cycle_tokens = 0;
  std::vector<std::string> deadlock_cycle;
  // throughput_state_space only: states stored, over all components.
  uint64_t states = 0;
  // "p/q", "0" or "unbounded".
  std::string str() const;
};

struct ThroughputLimits {
  uint64_t max_states = 20'000'000;        // state_space: stored states, all components
  uint64_t max_hsdf_size = 50'000'000;     // mcm: HSDF actors + edges
  uint64_t max_token_graph = 100'000'000;  // mcm: Karp's table, (tokens + 1) · tokens entries
};

// Both throw Error(input) for an inconsistent graph or a missing execution time (times come
// from execution_times(g, default_time)), Error(overflow) when a count or the time does not fit
// in 64 bits, and Error(limit) naming the limit when one is exceeded.
Throughput throughput_state_space(const Graph& g, std::optional<uint64_t> default_time = {},
                                  const ThroughputLimits& limits = {});
Throughput throughput_mcm(const Graph& g, std::optional<uint64_t> default_time = {},
                          const ThroughputLimits& limits = {});

}  // namespace sdf
