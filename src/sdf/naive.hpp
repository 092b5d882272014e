// Brute-force twins of the schedulers, for tests: obviously correct, slow.
//
// naive_max_run: fires single firings of a randomly chosen actor that can fire and still owes
// (count < q) until none can; returns the counts reached. By persistence they are the same for
// every order, so comparing with static_schedule's counts checks its deadlock report.
//
// naive_online: the online rules recomputed from scratch every decision (every key, every
// eligibility, the argmax by scanning), with every state stored in a map for exact repeat
// detection. Same outcome rules and caps as run_online.
#pragma once

#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"
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

}  // namespace sdf::naive
