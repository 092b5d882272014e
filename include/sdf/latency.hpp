// Latency of self-timed execution, over the first iterations (the semantics of throughput.hpp:
// every firing starts as soon as its tokens are there, consumes them when it starts and produces
// when it ends; auto-concurrency is unbounded unless a self-loop limits it).
//
// Number the firings of actor a from 1: firing k starts at S(a, k) and ends at
// E(a, k) = S(a, k) + t(a). Iteration i (from 0) of a is its firings i·q[a] + 1 .. (i+1)·q[a].
//  - from A to B, iteration i: L_i = E(B, (i+1)·q[B]) − S(A, i·q[A] + 1), from the first firing
//    of A in the iteration starting to the last firing of B in it ending (negative when B's part
//    of the iteration ends before A's begins: B does not wait for A).
//  - without A and B, the iteration's span: the latest E(a, (i+1)·q[a]) minus the earliest
//    S(a, i·q[a] + 1) over all actors. Iteration 0's span is the first iteration's makespan.
// The latency is the largest L_i over iterations 0 .. K − 1.
//
// A firing's start depends only on earlier firings (its tokens come from the producers' earlier
// firings, FIFO), so an event simulation in which each actor fires at most K·q[a] times gives
// these times exactly; it costs O(K·Σq·degree) and is bounded by `max_firings`. The naive twin
// takes the longest paths of the HSDF expansion unfolded K times (naive.hpp).
//
// Thread-safety: pure function.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "sdf/graph.hpp"

namespace sdf {

struct LatencyOptions {
  std::optional<ActorId> from, to;     // both or neither
  uint64_t iterations = 1;             // K ≥ 1
  uint64_t max_firings = 100'000'000;  // K·Σq at most
};

struct Latency {
  bool deadlock = false;               // the graph cannot complete K iterations
  std::vector<ActorId> stuck;          // when deadlocked: actors below K·q
  std::vector<int64_t> per_iteration;  // L_0 .. L_{K−1}
  int64_t max = 0;                     // the largest of them
  uint64_t iteration = 0;              // the first iteration with the largest
  uint64_t makespan = 0;               // E of the last firing of all K iterations (from time 0)
};

// Throws Error(input) for an inconsistent graph, a missing execution time (times from
// execution_times(g, default_time)), only one of from/to, K = 0, or more than max_firings
// firings; Error(overflow) when a time does not fit.
Latency latency(const Graph& g, const LatencyOptions& options = {},
                std::optional<uint64_t> default_time = std::nullopt);

}  // namespace sdf
