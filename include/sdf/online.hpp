// Online schedulers (thesis 5.3.2 and DESIGN §8).
//
// `online`, the thesis's rule verbatim: key(i) = min over the input channels of tokens/cns
// (an actor without inputs has key 1); an actor is eligible when key >= 1; the eligible actor
// with the largest key wins and fires ⌊key⌋ times in one decision (FiringRule::one: once).
// Ties: the actor that became eligible earlier wins (one that fires and is still eligible counts
// as newly eligible), then the lower actor id. Keys are compared exactly as fractions.
//
// `online-bounded` (Options::bounded): the same priority and tie-break, but an actor is eligible
// only while it has fired fewer than q times in the current iteration, and fires at most what it
// still owes. When every actor has reached its count a new iteration starts. On a live
// consistent graph every iteration is a valid period (any greedy choice among actors that owe
// firings completes one, by persistence).
//
// The scheduler state is the token vector, the eligible actors in tie-break order and, when
// bounded, the per-iteration counts: two equal states have identical futures. Each decision
// costs O(log n + the degrees of the winner and of its successors): eligible actors with a key
// above 1 sit in an indexed binary heap, those with key exactly 1 (sources, SDF3 self-loops) in
// a FIFO list in tie-break order; keys are recomputed only for the actors whose inputs changed,
// and a linear hash of the state is maintained incrementally for repeat detection.
//
// run_online() drives a scheduler until an honest outcome: the start token state returns after
// every actor has fired (`returns`, a valid period), the full scheduler state repeats (`periodic`:
// Brent's cycle detection in O(1) extra memory, then the transient is located by a second run
// λ decisions apart), a channel exceeds its growth cap (`unbounded`), nothing is eligible
// (`deadlock`) or the decision limit is reached (`limit`). It never loops for ever.
//
// Thread-safety: a scheduler is single-threaded state; distinct schedulers are independent.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/metrics.hpp"
#include "sdf/schedule.hpp"

namespace sdf {

enum class FiringRule {
  floor_key,  // ⌊key⌋ firings per decision (the thesis)
  one,        // one firing per decision
};

struct OnlineOptions {
  FiringRule firings = FiringRule::floor_key;
  bool bounded = false;  // online-bounded
};

class OnlineScheduler {
 public:
  // q is required when bounded (and used by nothing else). tokens: start state (default delays).
  OnlineScheduler(const Graph& g, std::span<const uint64_t> q, OnlineOptions options,
                  std::span<const uint64_t> tokens = {});

  // One decision, at most max_firings firings. Returns nullopt when no actor is eligible.
  // Throws Error(overflow) if a token count would exceed 64 bits.
  std::optional<Run> step(uint64_t max_firings = UINT64_MAX);

  // Optional per-channel token caps: the first channel to exceed its cap is remembered.
  void set_caps(std::vector<uint64_t> caps);
  std::optional<ChannelId> exceeded_channel() const;

  // Dynamic rates: the listed channels, each an input or output of `a`, get their new prd and
  // cns. Bounded mode: q_new is the repetitions vector of the changed graph and a new iteration
  // starts from the current tokens (counts back to zero). Keys, eligibility and hashes are
  // updated for the actors concerned (only a's key depends on the rates of its channels).
  void change_rates(ActorId a, std::span<const ChannelRates> rates,
                    std::span<const uint64_t> q_new = {});

  std::span<const uint64_t> tokens() const { return tokens_; }
  uint64_t decisions() const { return decisions_; }
  uint64_t firings() const { return firings_; }
  // Actors that have fired at least once since construction or the last reset_fired().
  size_t actors_fired() const { return actors_fired_; }
  void reset_fired();
  std::span<const uint64_t> iteration_counts() const { return count_; }
  uint64_t iterations_completed() const { return iterations_; }
  // Hash of the full state except the eligibility order (incremental, O(1)): a linear form
  // sum(value · salt) with fixed odd pseudo-random salts; equality is then checked exactly.
  uint64_t state_hash() const { return token_hash_ ^ count_hash_; }
  // Eligible actors in tie-break order (earliest eligibility first, then id).
  std::vector<ActorId> eligibility_order() const;
  // Exact comparison of the full scheduler state (tokens, counts, eligibility order).
  bool same_state(const OnlineScheduler& other) const;
  size_t actor_count() const { return n_; }

 private:
  struct Topology;  // immutable incidence lists, shared between copies
  // A heap entry carries a copy of what the comparison needs, so sifting does not chase
  // pointers: the key as a double, exact enough on its own when numerator and denominator are
  // both below 2^21 (`small`: distinct such fractions differ by more than double rounding),
  // else only a first guess that falls back to the exact fraction when the doubles are close.
  struct Entry {
    double key;
    uint64_t stamp;
    ActorId actor;
    bool small;
  };
  bool eligible(ActorId a) const;
  void recompute_key(ActorId a);
  Entry entry(ActorId a) const;
  bool better(const Entry& x, const Entry& y) const;
  bool better_exact(const Entry& x, const Entry& y) const;
  void heap_push(ActorId a);
  void list_insert(ActorId a);
  void list_remove(ActorId a);
  void insert_eligible(ActorId a);
  void remove_eligible(ActorId a);
  void heap_remove(ActorId a);
  void sift_up(uint32_t i);
  void sift_down(uint32_t i);
  void set_tokens(ChannelId c, uint64_t value);
  void set_count(ActorId a, uint64_t value);
  void start_iteration();
  void refresh(ActorId a);

  std::shared_ptr<const Topology> topo_;
  OnlineOptions opt_;
  size_t n_ = 0;
  // Per channel (hot): rates, tokens, caps, hash multipliers.
  std::vector<uint64_t> prd_, cns_, tokens_, caps_, salt_;
  // Per actor (hot): key = key_num_/key_den_, eligibility stamp, heap position, counts.
  std::vector<uint64_t> key_num_, key_den_, stamp_, count_, q_;
  std::vector<uint32_t> pos_;      // UINT32_MAX when not in the heap
  std::vector<uint32_t> key_arg_;  // the input channel that sets the key (kNone: no inputs)
  std::vector<char> has_fired_;
  std::vector<Entry> heap_;  // eligible actors with key > 1
  // Eligible actors with key exactly 1, in (stamp, id) order: a doubly linked list.
  static constexpr uint32_t kNone = UINT32_MAX;
  std::vector<uint32_t> prev_, next_;
  std::vector<char> in_list_;
  uint32_t head_ = kNone, tail_ = kNone;
  size_t listed_ = 0;
  uint64_t decisions_ = 0, firings_ = 0, iterations_ = 0;
  size_t actors_fired_ = 0, owing_ = 0;
  uint64_t token_hash_ = 0, count_hash_ = 0;
  int64_t exceeded_ = -1;
};

enum class Outcome { returns, periodic, unbounded, deadlock, limit };
const char* outcome_name(Outcome o);

struct OnlineRunOptions {
  OnlineOptions scheduler;
  uint64_t max_decisions = 100'000'000;  // the `limit` outcome beyond this
  // A channel is declared unbounded once it holds more than its start tokens plus
  // growth_periods times the tokens one period moves through it (q_src·prd).
  uint64_t growth_periods = 16;
  uint64_t max_listed_runs = 1'000'000;  // runs kept in OnlineRun::runs (metrics use all)
};

struct OnlineRun {
  Outcome outcome = Outcome::limit;
  // The reported window is transient + cycle decisions from the start: for `returns` the
  // period (transient 0), for `periodic` the transient and one cycle, otherwise the run up to
  // the stop (all of it counted as transient).
  uint64_t transient_decisions = 0, cycle_decisions = 0;
  uint64_t transient_firings = 0, cycle_firings = 0;
  std::vector<Run> runs;  // the window's decisions, if at most max_listed_runs
  bool runs_listed = false;
  std::vector<uint64_t> cycle_fired;  // per actor, firings in the period / cycle
  std::optional<ChannelId> channel;   // `unbounded`: the channel past its cap
  std::vector<ActorId> stuck;  // `deadlock`: actors below their count in the iteration (sorted)
  uint64_t decisions_explored = 0;  // decisions taken by the detection pass
  Metrics metrics;                  // buffers and fairness over the window
};

// q: the repetitions vector (for caps, bounded mode and metrics). start: the scheduler to run
// from (it is copied; pass a fresh one to start from the delays).
OnlineRun run_online(const Graph& g, std::span<const uint64_t> q, const OnlineScheduler& start,
                     const OnlineRunOptions& options);
OnlineRun run_online(const Graph& g, std::span<const uint64_t> q, const OnlineRunOptions& options);

}  // namespace sdf
