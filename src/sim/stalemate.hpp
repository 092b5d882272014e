// Stalemates: agents that make no progress, frozen or not (two agents that settle 1 m apart at
// speed 0 in a doorway are never frozen, so the backoff's nudge never sees them).
//
// Progress watch (every tick, after commit): an agent progresses when it gets `progress` metres
// closer to its current target than ever since the target was set; stall_ticks counts the ticks
// since. It is stalled from `after` seconds on.
//
// Resolution (deterministic: it depends on the committed state, the seed and the ids only):
// a stalled agent looks for its blocker, the nearest agent in front of it (towards its target)
// within 0.6 m of its disc. Every agent has a seeded priority (a hash of seed and id).
//   - the blocker is stalled and has the higher priority: yield, i.e. step back from it and to
//     the side away from it at half speed for yield_time;
//   - the blocker is stalled and has the lower priority: keep going (the blocker yields);
//   - otherwise (no blocker, an idle or a moving one, or walls): sidestep, i.e. walk at a
//     seeded angle of 45-90 degrees off the target direction for sidestep_time.
// After the action the agent heads for its target again; with navigation, one that stays stalled
// also re-plans its path (NavigationParams::replan_after).
#pragma once

#include <cstdint>

#include "crowddb/simulation.hpp"
#include "plan/access_path.hpp"
#include "util/executor.hpp"

namespace crowddb::sim {

struct StallCounts {
  std::size_t stalled = 0, started = 0, longest = 0, yielding = 0, sidestepping = 0;
};

// Updates the progress watch of every active row and returns the counts (before resolution).
StallCounts watch_progress(World& world, const SimConfig& cfg);

// Picks an action for each stalled row that has none running; `tick` is the tick just committed.
// Adds the new actions to `counts`.
void resolve_stalemates(World& world, const SimConfig& cfg, uint64_t tick, NeighbourPath& path,
                        Executor& ex, QueryStats& stats, StallCounts& counts);

}  // namespace crowddb::sim
