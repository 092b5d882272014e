// Buffer sizing: how much storage each channel needs, and what more storage buys in throughput
// (Stuijk, Geilen, Basten, "Exploring trade-offs in buffer requirements and throughput
// constraints for synchronous dataflow graphs", DAC 2006; SDF3's `--algo buffersize`).
//
// Semantics (SDF3's): every channel, self-loops included, has a capacity in tokens. A firing
// claims prd places on each output channel and takes cns tokens from each input when it starts;
// when it ends it fills its claimed places with tokens and frees the places of the tokens it
// took. The initial tokens occupy places from the start (capacity ≥ delay). This is the graph
// in which every channel u → v gains a reverse channel v → u with prd = cns, cns = prd and
// capacity − delay initial tokens (`bounded_graph`), executed self-timed as in throughput.hpp.
// A storage distribution gives every channel a capacity; its size is their sum.
//
//  - buffer_lower_bounds: per channel, a capacity below which no distribution is deadlock-free:
//    p + c − gcd(p, c) + d mod gcd(p, c), and at least d (Geilen, Basten, Stuijk, DAC 2005);
//    a self-loop needs p + max(c, d) (one firing claims p places while d tokens sit there).
//  - minimal_storage: every deadlock-free distribution of the smallest size. Deadlock-freedom
//    does not depend on execution times (an SDF graph is determinate), so none are needed.
//  - storage_throughput_pareto: for every size at which the best throughput grows, that
//    throughput and every distribution of that size reaching it, up to the graph's throughput
//    with unbounded channels.
//
// Both search the distributions in order of size from the lower bounds, as the paper does: a
// distribution's run (to a deadlock, or through one period of its periodic regime) records
// which actor waited for which (a firing that could not start before tokens or places arrived
// from another actor's firing ending at that instant); a channel whose lack of places made its
// producer wait, on a cycle of such waits, has a storage dependency, and only enlarging such a
// channel (by gcd(p, c), the step at which capacities differ in effect) can raise throughput or
// cure a deadlock. Every distribution explored costs one bounded state-space exploration.
//
// The graph must be consistent and connected (analyse the components of a disconnected graph
// on their own). Work is bounded by BufferLimits; exceeding one is an Error(limit) naming it for
// minimal_storage and an incomplete result (`complete` false, `stopped` saying why) for the
// Pareto search, which keeps the points found so far.
//
// Thread-safety: pure functions.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/schedule.hpp"
#include "sdf/throughput.hpp"

namespace sdf {

// Per channel: the lower bound described above.
std::vector<uint64_t> buffer_lower_bounds(const Graph& g);

// The graph with every channel bounded by `capacity` (per channel): the original channels, then
// one reverse channel per channel, named `<name>#space`. Throws Error(input) when a capacity is
// below the channel's delay or a name clashes.
Graph bounded_graph(const Graph& g, std::span<const uint64_t> capacity);

// minimal_storage's untimed runs store no states: the state limits bind the Pareto search only.
// Firings count every firing simulated, of actors without execution time too; the run of a live
// distribution simulates at least one iteration (Σq firings), so a graph whose iteration exceeds
// max_firings_per_run is refused at once. A whole search is bounded by max_distributions runs of
// at most max_firings_per_run firings (and, timed, max_states_per_run states) each.
struct BufferLimits {
  uint64_t max_distributions = 1'000'000;      // distributions explored, whole search
  uint64_t max_states = 50'000'000;            // Pareto: states stored, summed over the runs
  uint64_t max_states_per_run = 5'000'000;     // Pareto: states stored by one exploration
  uint64_t max_firings_per_run = 100'000'000;  // firings simulated by one exploration
  uint64_t max_size = UINT64_MAX;              // no distribution larger than this is explored
};

struct StorageSearch {
  uint64_t size = 0;                                 // of each distribution below
  std::vector<std::vector<uint64_t>> distributions;  // capacity per channel, sorted
  uint64_t explored = 0;                             // distributions run
  uint64_t states = 0;                               // states stored, summed (none: untimed)
  uint64_t firings = 0;                              // firings simulated, summed
};

// Throws Error(input) when the graph is inconsistent, not connected, or deadlocks whatever the
// capacities (then no distribution is deadlock-free), and Error(limit) when a limit is exceeded
// (max_size: when no deadlock-free distribution is that small).
StorageSearch minimal_storage(const Graph& g, const BufferLimits& limits = {});

struct ParetoPoint {
  uint64_t size = 0;
  Throughput throughput;                             // num/den (num > 0), or unbounded
  std::vector<std::vector<uint64_t>> distributions;  // every one of this size with it, sorted
};

struct ParetoSearch {
  Throughput max_throughput;        // with unbounded channels: where the search stops
  std::vector<ParetoPoint> points;  // sizes and throughputs strictly increasing
  bool complete = false;            // the last point reaches max_throughput
  std::string stopped;              // when not complete: the limit that stopped the search
  uint64_t explored = 0;
  uint64_t states = 0;
  uint64_t firings = 0;
};

// Execution times from execution_times(g, default_time). Throws Error(input) as
// minimal_storage (a graph that always deadlocks has no point), or for a missing time; a limit
// reached ends the search with the points found so far (perhaps none).
ParetoSearch storage_throughput_pareto(const Graph& g,
                                       std::optional<uint64_t> default_time = std::nullopt,
                                       const BufferLimits& limits = {});

// The throughput of self-timed execution under one distribution, by the same bounded
// exploration the searches use (the tests compare it with throughput_state_space and
// throughput_mcm of bounded_graph). Throws as minimal_storage, and Error(input) when a capacity
// is below its channel's delay.
Throughput bounded_throughput(const Graph& g, std::span<const uint64_t> capacity,
                              std::optional<uint64_t> default_time = std::nullopt,
                              const BufferLimits& limits = {});

// The ready-queue schedule (static_schedule) of one period within a minimal deadlock-free
// distribution: its per-channel token maxima stay within that distribution, so their sum is the
// least any schedule of one period needs (self-loops aside: a sequential schedule keeps d tokens
// on a self-loop where the bounded model reserves p more places). `capacity` receives the
// distribution used (the first of minimal_storage's). Throws as minimal_storage.
std::vector<Run> min_buffer_schedule(const Graph& g, std::vector<uint64_t>* capacity = nullptr,
                                     const BufferLimits& limits = {});

}  // namespace sdf
