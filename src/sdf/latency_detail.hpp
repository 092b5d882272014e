// Shared by latency() and its naive twin: the checks and firing caps, and the latencies L_i
// from the first start and last end of every actor in every iteration.
#pragma once

#include <cstdint>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/latency.hpp"

namespace sdf::detail {

// K·q[a] per actor; throws Error(input) for bad options or more than max_firings firings.
std::vector<uint64_t> latency_caps(const Graph& g, const LatencyOptions& o,
                                   const std::vector<uint64_t>& q);

// first_start / last_end are indexed a·K + i; fills per_iteration, max, iteration, makespan.
void latencies_from_times(const LatencyOptions& o, size_t actors,
                          const std::vector<uint64_t>& first_start,
                          const std::vector<uint64_t>& last_end, Latency& r);

}  // namespace sdf::detail
