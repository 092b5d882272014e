// Fairness and buffer metrics of a schedule, measured by replaying its decisions.
//
// Fairness (thesis 5.5): for each decision, the number of decisions taken between its actor
// becoming eligible and its firing; reported as max and mean over the decisions. "Eligible"
// follows the scheduler: Eligibility::fireable for `online` (every input holds cns tokens),
// Eligibility::owing for `static` and `online-bounded` (fireable and still owing firings in the
// current iteration; a new iteration starts when every actor has reached q). An actor that fires
// and is still eligible counts as newly eligible. The thesis claims max < n - 1.
//
// Buffers: the largest token count each channel holds between firings (the start included).
// Within a run of k firings of one actor every channel changes monotonically, so checking the
// state before and after each run is exact.
//
// Thread-safety: a Meter is single-threaded state.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "sdf/graph.hpp"
#include "sdf/schedule.hpp"

namespace sdf {

enum class Eligibility { fireable, owing };

struct Fairness {
  uint64_t max = 0;
  double mean = 0;
  uint64_t decisions = 0;
};

struct Metrics {
  std::vector<uint64_t> buffers;  // per channel
  Fairness fairness;
  // False when a replayed decision fired an actor the eligibility model did not consider
  // eligible, or fired more than it could (the schedule does not follow the model).
  bool followed_model = true;
};

class Meter {
 public:
  // tokens/counts: the start state (default: the delays, zero counts).
  Meter(const Graph& g, std::span<const uint64_t> q, Eligibility model,
        std::span<const uint64_t> tokens = {}, std::span<const uint64_t> counts = {});
  void record(const Run& run);
  const Metrics& metrics();

 private:
  bool eligible(ActorId a) const;
  void update(ActorId a);
  void start_iteration();

  const Graph* g_;
  Adjacency adj_;
  std::vector<uint64_t> q_, tokens_, count_, stamp_;
  std::vector<char> is_eligible_;
  Eligibility model_;
  uint64_t decision_ = 0, sum_wait_ = 0;
  size_t owing_ = 0;
  Metrics m_;
};

// Replays runs from the start state and returns the metrics.
Metrics measure(const Graph& g, std::span<const uint64_t> q, Eligibility model,
                std::span<const Run> runs, std::span<const uint64_t> tokens = {});

}  // namespace sdf
