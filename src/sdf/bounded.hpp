// Execution of a graph whose channels have capacities (the model of include/sdf/buffers.hpp),
// without building the bounded graph: each channel keeps its tokens and its free places.
//
// live(): untimed. The ready-queue run of static_schedule, each actor capped at q: by
// persistence it completes an iteration exactly when the bounded graph is live. If it does not,
// the run continues without the cap until nothing can fire (a connected bounded graph that is
// not live comes to a complete standstill; every count stays within the capacities of its
// channels from the stuck ones), and the waits of that state give the storage dependencies.
//
// run(): self-timed (the engine of self_timed.hpp with capacities), as throughput_state_space
// but over the whole (connected) graph. The state
// (tokens and the remaining times of the firings in progress; free places follow from them) is
// stored each time the reference actor (smallest q, lowest id) completes another multiple of
// its count; the first repeat closes the period, F firings of it in T time units giving
// F / (q·T) iterations per time unit. For the dependencies the run then goes through that period
// once more, recording for each batch of firings that starts at an instant which channels
// could not have supplied its tokens or places without what arrived at that instant: the batch
// waited for the actor that delivered them. A channel whose places were waited for, with both
// ends in one strongly connected component of those waits, has a storage dependency.
//
// Thread-safety: a BoundedModel is immutable after construction; run() and live() are const.
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/throughput.hpp"
#include "self_timed.hpp"

namespace sdf::detail {

// A limit of BufferLimits exceeded: an Error(limit) naming it, which the Pareto search turns into
// an incomplete result (other errors it lets through).
class LimitExceeded : public Error {
 public:
  explicit LimitExceeded(const std::string& message) : Error(Error::Kind::limit, message) {}
};

// What one run may do and what it did: the firings it simulates (of every actor, those without
// execution time included) and the states it stores (run() only). Exceeding a maximum throws
// LimitExceeded.
struct RunBudget {
  uint64_t max_firings = UINT64_MAX, max_states = UINT64_MAX;
  uint64_t firings = 0, states = 0;
};

class BoundedModel {
 public:
  // g: consistent and connected; q: its repetitions vector; times: per actor (empty: live() only).
  BoundedModel(const Graph& g, std::vector<uint64_t> q, std::vector<uint64_t> times);

  // cap ≥ delay on every channel. When not live and `dependency` is given, it receives the
  // storage dependencies of the deadlock. A live distribution costs Σq firings, a deadlocked one
  // at most Σq plus what the capacities let the run continue by.
  bool live(std::span<const uint64_t> cap, RunBudget& budget,
            std::vector<char>* dependency = nullptr) const;

  // The throughput (unbounded when every actor takes no time and the graph is live; `states`:
  // those stored) and, when `dependency` is given, the storage dependencies per channel.
  Throughput run(std::span<const uint64_t> cap, RunBudget& budget,
                 std::vector<char>* dependency = nullptr) const;

  uint64_t iteration_firings() const { return sum_q_; }  // Σq, saturated at 2^64 − 1

 private:
  // An actor's side of a channel (self_timed.hpp): for an input the producer and cns, for an
  // output the consumer and prd, one contiguous block per actor.
  using Port = TimedPorts::Port;
  std::span<const Port> inputs(ActorId a) const { return ports_.inputs(a); }
  std::span<const Port> outputs(ActorId a) const { return ports_.outputs(a); }

  const Graph& g_;
  TimedPorts ports_;  // the whole graph: local numbers are the graph's
  std::vector<uint64_t> q_, times_;
  // Counts k more firings against the budget.
  void spend(RunBudget& budget, uint64_t k) const;

  ActorId reference_ = 0;
  uint64_t sum_q_ = 0;
  bool all_untimed_ = true;
};

}  // namespace sdf::detail
