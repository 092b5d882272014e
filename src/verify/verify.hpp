// crowddb verify: a suite of small scenarios written here, modelled on the RiMEA guideline's tests
// and SteerSuite's test families, each with stated pass criteria (../shared/VALIDATION.md lists
// where the numbers come from). A case is one or more runs of scenario documents plus a function
// that turns the runs' measurements into checks; `crowddb verify` runs every case under one model
// or all of them and prints a pass/fail table (and CSV).
#pragma once

#include <cstdint>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "crowddb/world.hpp"

namespace crowddb::verify {

// What one run of a scenario measured. Agents are those of the initial table, in spawn order.
struct RunStats {
  std::size_t agents = 0, arrived = 0;
  double dt = 0, duration = 0;   // [s]
  double first_arrival = 0;      // [s] (0 when nobody arrived)
  double last_arrival = 0;       // [s]
  std::size_t max_pairs = 0;     // most overlapping agent pairs after any tick
  std::size_t max_obstacle = 0;  // most agent-obstacle overlaps after any tick
  std::size_t frozen = 0;        // agent-ticks the backoff froze
  double max_stall = 0;          // [s] longest stretch any agent went without progress
  std::size_t stalled_at_end = 0;
  // Per agent of the initial table:
  std::vector<double> arrival;    // [s], NaN when it did not arrive
  std::vector<double> walked;     // [m] length of its trajectory
  std::vector<double> shortest;   // [m] shortest path for its disc to its (first) goal area
  std::vector<double> free_time;  // [s] shortest / pref_speed
  std::vector<uint32_t> goal;     // its first goal row
  std::vector<std::string> goal_name;
};

// One measured value against its limits: passes when low <= value <= high.
struct Check {
  std::string name;
  double value = 0;
  double low = -std::numeric_limits<double>::infinity();
  double high = std::numeric_limits<double>::infinity();
  bool pass() const { return value >= low && value <= high; }
};

struct Case {
  std::string name;    // e.g. "rimea-01-corridor"
  std::string family;  // where it comes from: "RiMEA 1", "SteerSuite one-on-one", ...
  std::string what;    // one line
  std::vector<std::string> scenarios;  // scenario documents, run in order
  std::function<std::vector<Check>(const std::vector<RunStats>&)> evaluate;
};

const std::vector<Case>& cases();

// Runs one scenario document under `model` ("" keeps the document's), after setting the fields
// `overrides` names ("KEY=VALUE", as crowddb run --set; io/overrides.hpp).
RunStats run_scenario(const std::string& json, const std::string& source, const std::string& model,
                      int threads, const std::vector<std::string>& overrides = {});

struct CaseResult {
  std::string name, family, model;
  std::vector<Check> checks;
  double wall_seconds = 0;
  bool pass() const {
    for (const Check& c : checks)
      if (!c.pass()) return false;
    return true;
  }
};
CaseResult run_case(const Case& c, const std::string& model, int threads,
                    const std::vector<std::string>& overrides = {});

// Limits of the checks every case shares. Time: each agent's arrival time over its free-flow
// time (shortest path / pref_speed); path: its walked length over its shortest path. Encounters
// of a few people bound the worst agent tightly; crowd cases bound the mean, and the worst agent
// more loosely (one person may have to wait or go round). 0 switches a check off.
struct Limits {
  double time_mean = 0, time_max = 0;
  double path_mean = 0, path_max = 0;
  double max_stall = 30;  // [s] nobody stalled longer (queueing is not stalling)
};

// Everyone arrives, no overlapping pair and no agent-obstacle overlap after any tick, nobody
// stalled for longer than the limit nor at the end, and the time and path limits. A shortest
// path that could not be computed makes its check fail (never pass vacuously).
std::vector<Check> standard_checks(const RunStats& r, const Limits& limits);

}  // namespace crowddb::verify
