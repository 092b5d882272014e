// Running a scenario to its end and what the run reports: the text summary of `crowddb run`,
// the JSON of `--summary-json` (every key is documented in docs/summary-json.md) and the rows of
// `crowddb bench`. One loop for all three, so they cannot disagree.
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "metrics/steerbench.hpp"

namespace crowddb::io {
class TrajectoryWriter;
}

namespace crowddb::metrics {

struct RunSummary {
  std::string name, source, format, model;
  double dt = 0;
  int threads = 1;
  uint64_t ticks = 0;          // ticks run
  uint64_t ticks_planned = 0;  // the scenario's (or the command line's) tick count
  double sim_seconds = 0;
  bool stopped_when_all_arrived = false;  // ended before ticks_planned: everyone had arrived
  std::size_t agents_at_start = 0, entered = 0, waiting_to_enter = 0, agents_at_end = 0;
  std::size_t agents_total = 0;  // at start + entered
  std::size_t arrived = 0;
  std::size_t still_walking = 0;     // not arrived at the end
  std::size_t waiting_at_goals = 0;  // of those, waiting at a goal (Goal::wait_min/max)
  std::size_t without_path = 0;      // of those, with a route that does not reach their goal
  bool all_arrived = false;          // nobody still walking and nobody waiting to enter
  double last_arrival_s = -1;        // -1: nobody arrived
  std::size_t max_overlapping_pairs = 0, max_obstacle_overlaps = 0, overlapping_pairs_at_end = 0;
  std::size_t frozen_agent_ticks = 0, freeze_iterations_total = 0, freeze_iterations_max = 0;
  std::size_t gridlock_streaks = 0, gridlocked_max = 0, gridlocked_at_end = 0;
  double longest_frozen_s = 0;
  std::size_t stall_streaks = 0, stalled_max = 0, stalled_at_end = 0;
  double max_stalled_s = 0;
  std::size_t yields = 0, sidesteps = 0, make_ways = 0, nudged = 0;
  double wall_seconds = 0, ms_per_tick_median = 0, ms_per_tick_mean = 0;
  uint64_t state_hash = 0;
  SteerBenchTotals steerbench;

  // The JSON object of --summary-json (docs/summary-json.md), pretty-printed.
  std::string json() const;
  // The summary `crowddb run` prints.
  std::string text(const SimConfig& cfg) const;
};

struct RunControl {
  io::TrajectoryWriter* writer = nullptr;  // frames, metrics and the run's facts, if any
  // Asked before each tick; true stops the run with Error(io) "interrupted".
  std::function<bool()> interrupted;
  // After each tick (progress lines).
  std::function<void(const Simulation&, const TickMetrics&, uint64_t ticks_planned)> on_tick;
  // [s] of wall time between checkpoints written to the writer (one also when interrupted);
  // negative: none. Checkpoints go with a batch of frames: resuming from one loses nothing.
  double checkpoint_every = -1;
  // Resuming: `sim` was restored from a checkpoint, and this is the run's own state from the
  // same checkpoint (summary counters, SteerBench, tick times).
  const std::string* resume_from = nullptr;
};

// Runs `sim` (built from `sc`) for sc.ticks ticks, or until everyone has arrived when
// sc.stop_when_all_arrived. On an exception the writer is stopped: what it wrote is kept in
// PATH.partial, marked incomplete.
RunSummary run_to_end(const Scenario& sc, Simulation& sim, const RunControl& control);

// "0123456789abcdef"
std::string hex(uint64_t v);

}  // namespace crowddb::metrics
