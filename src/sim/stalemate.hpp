// Stalemates: agents that make no progress, frozen or not (two agents that settle 1 m apart at
// speed 0 in a doorway are never frozen, so the backoff's nudge never sees them).
//
// Progress watch (every tick, after commit): an agent progresses when the path still ahead of it
// (sim::path_left: to its waypoint, along its route, to its goal) gets `progress` metres shorter
// than ever since its goal was set; stall_ticks counts the ticks since. Passing or skipping a
// waypoint, or a re-planned route, is no progress by itself (an agent wedged at a door jamb
// re-plans and skips waypoints every few seconds without getting anywhere). From `after` seconds on
// the agent is looked at: its blocker is the nearest agent in front of it (towards its target)
// within 0.6 m of its disc.
//   - queueing: the blocker walks the same way (the same goal, or directions within 60 degrees)
//     or stands idle at the agent's own goal, and is itself progressing or queueing: a queue ends
//     in someone who moves. Waiting in one is no stalemate (the back of a queue of 500 at a 1 m
//     exit gains a few centimetres a second): no action, not counted as stalled. A cycle of mutual
//     blockers (people arching in a door, all heading for it) has no moving head: they are
//     stalled.
//   - stalled: no blocker (walls, a local minimum), a blocker heading elsewhere, or one standing
//     idle anywhere but at the agent's goal (the other stream's arrivals: in Menge's stress
//     example one agent stood behind them for the last 250 s of 300, counted as queueing, so
//     nothing acted).
// Resolution (deterministic: it depends on the committed state, the seed and the ids only). Of
// two stalled agents one coming out of the goal the other heads for goes first (out before in,
// sim::out_before_in), else, of two bound for different goals the same way, the one ahead
// (sim::ahead), else the one with less of its path left (at a clogged door: the one nearest to
// getting through), as in orca's right of way; ties go by a seeded rank (a hash of seed and id):
//   - the blocker is stalled too and goes first: yield, i.e. step back from it and to the side
//     away from it at half speed; when the chain of stalled blockers in front ends in people
//     going its way or across (an arch at a door, not two streams head-on), the yield lasts
//     yield_time and goes first in orca, so that the people behind it make room (yield_ahead);
//     head-on it lasts head_on_yield_time (the same by default; shorter helps dense counter-flow
//     and hurts doors with mixed destinations, measured in docs/verify.md);
//   - the blocker is stalled too and goes second: keep going (the blocker yields; not while
//     the blocker is in the pause after a sidestep, below: then nobody acts for up to `after`);
//   - taking turns: when both have been stalled for reverse_after, the order is swapped in every
//     other reverse_period. An order that has not ended a stalemate in that long will not: in
//     dense counter-flow the block that went first pressed the other against the wall at its own
//     goal, where the people pressed there cannot yield (the wall is behind them) and the ones
//     with less path left cannot reach it; the other way round, those at the goal step aside;
//   - no blocker and already walking towards the target at half its preferred speed or more:
//     nothing (it is walking back to where a counter-stream carried it from; it stays counted as
//     stalled until it gets there, but a sidestep would only slow it down);
//   - otherwise: sidestep, i.e. walk at a seeded angle of 45-90 degrees off the target direction
//     for sidestep_time, then head for the target again for `after` before the next action (a
//     sidestep moves the agent off its best distance; acting again at once chained sidesteps
//     into a random walk). When the blocker has arrived (idle) and is bound for another goal,
//     it is also asked to make way (make_way): it steps off the agent's line, to the side it
//     stands on, at half its preferred speed for yield_time. Idle people do not move by
//     themselves, and one enclosed by the idle visitors of another booth (Menge's tradeshow)
//     stood there for 200 s of 300. Waiting agents (a goal's wait) are not asked.
// After the action the agent heads for its target again; with navigation, one that stays stalled
// also re-plans its path (NavigationParams::replan_after), and the rows stalled head-on
// (StallCounts::head_on) make the tick's path searches plan round them
// (NavigationParams::congestion_cost).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "crowddb/simulation.hpp"
#include "plan/access_path.hpp"
#include "sim/moved_lists.hpp"
#include "util/executor.hpp"

namespace crowddb::sim {

class AimMemo;  // stages.hpp

struct StallCounts {
  std::size_t stalled = 0, started = 0, longest = 0, queueing = 0, yielding = 0, sidestepping = 0;
  std::size_t making_way = 0;  // standing blockers asked to step aside this tick
  // Rows looked at whose blockers' search the model's lists answered (`move`), a scan of every
  // row (a few left), or the neighbour query.
  std::size_t by_lists = 0, by_scan = 0, by_query = 0;
  // Rows (in row order) stalled where streams meet head-on: the chain of stalled blockers in
  // front ends in someone heading at them, or is a cycle with two such (not an arch at a door,
  // where all walk one way). Path searches plan round them (NavigationParams::congestion_cost).
  // Filled only with cfg.stall.resolve.
  std::vector<uint32_t> head_on;
};

// The queueing test over the rows looked at: q waits in a queue when it walks the same way as
// its blocker (same_way[q]) and that blocker moves (moves[q]: it is not looked at, or stands idle)
// or waits in a queue itself (next[q]: the blocker's place among the rows looked at, -1 when
// none). A cycle of blockers has no moving head: nobody in it queues (the least fixed point).
// One walk along the chains, O(n) (the repeated sweeps it replaced took a sweep per link of a
// chain that runs against the row order: O(n^2) for a long queue). queue_members_naive: those
// sweeps, its twin in tests.
std::vector<uint8_t> queue_members(std::span<const uint8_t> same_way,
                                   std::span<const uint8_t> moves, std::span<const int64_t> next);
std::vector<uint8_t> queue_members_naive(std::span<const uint8_t> same_way,
                                         std::span<const uint8_t> moves,
                                         std::span<const int64_t> next);

// Is row i, standing, stepping out of a stalled walker's way at `tick` (StallAction::make_way,
// not yet over)?
inline bool making_way(const AgentTable& t, std::size_t i, uint64_t tick) {
  return t.stall_action[i] == StallAction::make_way && tick < t.stall_until[i];
}

// The progress watch, the queueing test and (with cfg.stall.resolve) the actions, for the tick
// `tick` just committed.
// `aim`: the rows' aim points, shared with the goal stage (stages.hpp). `move`: what the tick did
// since the steering model's neighbour lists, which then answer the search for blockers where
// they are sure to (sim/moved_lists.hpp; the same answer as `path`'s); without it, `path` answers.
StallCounts stalemates(World& world, const SimConfig& cfg, uint64_t tick, NeighbourPath& path,
                       Executor& ex, QueryStats& stats, AimMemo* aim = nullptr,
                       const TickMove* move = nullptr);

}  // namespace crowddb::sim
