// Schedules as data, and the static (compile-time) scheduler of thesis 5.2.2.
//
// A schedule is a list of runs: `count` consecutive firings of one actor. Each run is one
// scheduling decision (the unit the fairness metric counts), and the run-length form keeps
// periods with billions of firings small.
//
// The ready-queue construction: every actor that can fire and still owes firings in the period
// sits in a FIFO queue; the head fires as often as it can in a row (bounded by what it owes and
// by its input tokens), then the actors it fed that became fireable join the tail. O(V + E + R)
// for R runs. Because SDF is persistent (only an actor's own firing can disable it) the counts it
// reaches when the queue empties are the unique maximal ones: an actor below its repetition count
// then cannot reach it however the others fire, even if they may fire without bound. Those are
// reported as stuck, together with one cycle of channels that lacks tokens.
//
// Thread-safety: pure functions.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sdf/graph.hpp"

namespace sdf {

struct Run {
  ActorId actor = 0;
  uint64_t count = 0;
  bool operator==(const Run&) const = default;
};

// Total firings in a list of runs (saturating at 2^64 - 1).
uint64_t total_firings(std::span<const Run> runs);
// The run-length form "(3 A)(2 B)" (a count of 1 is still written).
std::string run_length_form(const Graph& g, std::span<const Run> runs);

struct StaticSchedule {
  bool complete = false;        // every actor reached its repetition count
  std::vector<Run> runs;        // one period when complete; the maximal prefix otherwise
  std::vector<uint64_t> fired;  // firings per actor
  std::vector<ActorId> stuck;   // actors below their count (sorted), when not complete
  // One cycle of channels among the stuck actors, each lacking tokens for the next firing of its
  // consumer (in cycle order), when not complete. Empty only if the blockage is a self-loop-free
  // path to nothing, which cannot happen in a consistent graph.
  std::vector<ChannelId> starved_cycle;
};

// q: the repetitions vector. tokens: the state to start from (default: the delays).
// Throws Error(overflow) if a token count exceeds 64 bits.
StaticSchedule static_schedule(const Graph& g, std::span<const uint64_t> q,
                               std::span<const uint64_t> tokens = {});

}  // namespace sdf
