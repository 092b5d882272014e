// Dynamic rate changes (thesis 5.4): an actor's rates change after a given number of firings,
// mid-period. Three forms: every output channel of the actor produces `prd` per firing and every
// input channel consumes `cns` (`uniform`); every rate of the actor is scaled by a factor
// num/den, the thesis's "scaling its w_i's by a factor new rate / old rate" (`scaled`; each rate
// must stay a whole number; the graph stays consistent, the actor's count divided by the
// factor; self-loops keep their rates: they model the actor's state, as SDF3's one-token loops
// that make it sequential, and scaled they would deadlock it); or explicit new rates per channel
// of the actor. The thesis notes the result is the
// new graph with different initial delays (the tokens at the change).
//
// The static path recomputes the repetitions vector and builds a new ready-queue schedule from
// the tokens at the change: it is periodic at once (or deadlocks). The online path just
// continues from its scheduler state (keys and eligibility of the actor updated); the bounded
// path continues with the new repetitions vector and a new iteration. For the online paths the
// run is then driven to an outcome as in run_online and the firings until the state is periodic
// again are the transient's.
//
// Thread-safety: pure function.
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"

namespace sdf {

enum class Policy { static_order, online, online_bounded };
const char* policy_name(Policy p);

struct RateChange {
  ActorId actor = 0;
  // New rates of the actor's channels (each one an input or output of it; a self-loop is
  // both): an output's prd, an input's cns. Channels not listed keep their rates.
  std::vector<ChannelRates> rates;
  uint64_t at_firing = 0;  // the change happens after this many firings

  // Throw Error(input) for a zero rate, or a scaled rate that is not a whole number or does not
  // fit in 64 bits.
  static RateChange uniform(const Graph& g, ActorId a, uint64_t prd, uint64_t cns,
                            uint64_t at_firing);
  static RateChange scaled(const Graph& g, ActorId a, uint64_t num, uint64_t den,
                           uint64_t at_firing);
};

struct RateChangeResult {
  std::vector<uint64_t> q_before, q_after;  // q_after empty when the new graph is inconsistent
  Repetitions after;                        // consistency verdict of the changed graph
  Graph changed;                            // the graph with the new rates
  std::vector<uint64_t> tokens_at_change;
  // Static: `returns` or `deadlock`; online paths: run_online's outcome after the change.
  Outcome outcome = Outcome::returns;
  std::vector<ActorId> stuck;        // deadlock after the change: actors below their count (sorted)
  std::optional<ChannelId> channel;  // unbounded after the change
  uint64_t firings_until_periodic = 0;  // after the change
  uint64_t period_firings = 0;          // firings in one period / cycle after the change
  uint64_t period_decisions = 0;
  // The post-change period (the cycle, from the state where it starts) passed the checker;
  // period_checked is false when the cycle was too long to list (max_listed_runs).
  bool period_checked = false;
  bool period_valid = false;
  // The original graph's run: `returns` for the static policy; under the online policies
  // run_online's outcome (the rule may let a channel grow without bound, or deadlock, on a
  // graph that has a static schedule).
  Outcome outcome_before = Outcome::returns;
  std::optional<ChannelId> channel_before;  // the growing channel when unbounded before
  // Over one period of the original graph; empty when its run never becomes periodic.
  std::vector<uint64_t> buffers_before;
  std::vector<uint64_t> buffers_after;  // over one period / cycle after the change
};

// The original graph must be consistent and live (throws Error(input) naming the problem
// otherwise); the change's actor and rates must be valid. max_decisions in options bounds
// the run before the change as well.
RateChangeResult simulate_rate_change(const Graph& g, Policy policy, const RateChange& change,
                                      const OnlineRunOptions& options);

}  // namespace sdf
