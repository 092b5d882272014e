// Brute-force twins of the schedulers, for tests: obviously correct, slow.
//
// naive_max_run: fires single firings of a randomly chosen actor that can fire and still owes
// (count < q) until none can; returns the counts reached. By persistence they are the same for
// every order, so comparing with static_schedule's counts checks its deadlock report.
//
// naive_online: the online rules recomputed from scratch every decision (every key, every
// eligibility, the argmax by scanning), with every state stored in a map for exact repeat
// detection. Same outcome rules and caps as run_online.
//
// latency: see below. stats: see below.
//
// minimal_storage / pareto: every storage distribution (each capacity at least its channel's
// delay, nothing else assumed: no lower bound, no dependencies) in order of size, each judged on
// the explicit bounded_graph — deadlock-free when static_schedule completes an iteration there,
// throughput by throughput_state_space and throughput_mcm of it, which must agree.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "sdf/buffers.hpp"
#include "sdf/graph.hpp"
#include "sdf/latency.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"
#include "sdf/stats.hpp"
#include "util/rng.hpp"

namespace sdf::naive {

// The repetitions vector by the plain walk over Adjacency with a fraction per actor (the first
// implementation of compute_repetitions): same spanning tree, so the same vector, the same
// failing channel and q_src / q_dst, and the same overflow errors.
Repetitions repetitions(const Graph& g);

std::vector<uint64_t> max_run(const Graph& g, std::span<const uint64_t> q, crowddb::Rng& rng);

struct NaiveOnline {
  Outcome outcome = Outcome::limit;
  std::vector<Run> runs;        // every decision taken (up to the stop or the end of the cycle)
  std::vector<uint64_t> waits;  // per decision: decisions between eligibility and firing
  uint64_t transient = 0, cycle = 0;  // in decisions (returns: transient 0, cycle = period)
  std::optional<ChannelId> channel;
};

NaiveOnline online(const Graph& g, std::span<const uint64_t> q, const OnlineRunOptions& options);

// The deadlock-free distributions of the smallest size (sorted), or size 0 and none when there
// is none of size at most max_size.
StorageSearch minimal_storage(const Graph& g, uint64_t max_size);

// Latency by longest paths in the HSDF expansion unfolded K times: firing f of iteration i
// starts at the latest end of its predecessors (an edge with t tokens from firing u means u of
// iteration i − t; none before iteration 0), relaxed until nothing changes; L_i then straight
// from the definitions (S(a, i·q[a] + 1) is a_0's start in iteration i, E(a, (i + 1)·q[a])
// a_{q[a]−1}'s end), sharing nothing with latency() but q and the times. Deadlock when the
// expansion has a cycle without tokens (Kahn's topological sort fails); `stuck` is left empty.
// No firing limit.
Latency latency(const Graph& g, const LatencyOptions& options,
                std::optional<uint64_t> default_time);

// Statistics by brute force: components and strongly connected components from the reachability
// of every actor (a breadth-first search from each), simple cycles by enumerating every path of
// channels from each actor s through actors above s back to s (no blocking, no limit).
GraphStats stats(const Graph& g);

// The SDF3 reader before the streaming one: pugixml's document tree, actors then channels.
// Same graphs; its error messages may differ (it reports in two passes, not in file order).
Graph read_sdf3(std::string_view text, const std::string& source);

// Points as storage_throughput_pareto's; `complete` when the graph's throughput (with unbounded
// channels, by throughput_mcm) is reached at a size of at most max_size. Needs execution times.
// Capacities start at `floor` (default: the delays). The tests pass the lower bounds, which
// enumeration from the delays checks on its own (MinimalStorageMatchesEnumeration): below them
// every distribution deadlocks, and the count of distributions to try shrinks a hundredfold.
ParetoSearch pareto(const Graph& g, uint64_t max_size, std::span<const uint64_t> floor = {});

}  // namespace sdf::naive
