// Configurations shared by tests.
#pragma once

#include "crowddb/simulation.hpp"

namespace crowddb::test {

// The thesis's model in its own units (one tick per second, so durations count ticks) with the
// machinery added since switched off where it would change the behaviour a test pins down:
// stalemate resolution and the symmetry-breaking noise. Tests of the backoff, the indices and the
// thesis's rule use it.
inline SimConfig thesis_config() {
  SimConfig c;
  c.dt = 1;
  c.steering.model = "thesis";
  c.steering.perturbation = 0;
  c.stall.resolve = false;
  c.nudge_after = 2;
  c.gridlock_time = 50;
  c.navigation.latency = 2;
  c.navigation.replan_after = 40;
  return c;
}

// The same for scenario text: the JSON members that select it (to splice into a document).
inline const char* thesis_json() {
  return R"("dt": 1, "nudge_after": 2, "gridlock_time": 50, "stall": {"resolve": false})";
}

}  // namespace crowddb::test
