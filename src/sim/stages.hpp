// The operators of one tick (DESIGN.md §3), each a function over columns: it reads the current
// agent columns and writes effect or next-state columns for its rows. simulation.cpp runs them
// in plan order; none of them decides which access path to use.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "crowddb/simulation.hpp"
#include "plan/access_path.hpp"
#include "util/executor.hpp"

namespace crowddb::path {
class Navigation;
}

namespace crowddb::sim {

// The effects table: at most one row per agent, one column pair per steering query.
// combine() sums them, in this fixed order, into one acceleration per agent.
struct Effects {
  std::vector<double> attract_x, attract_y;  // Q1 [length/tick^2]
  std::vector<double> apf_x, apf_y;          // Q2
  std::vector<double> ftc_x, ftc_y;          // Q3
  std::vector<uint8_t> skip;  // Q1: route waypoints passed by line of sight (popped at commit)
  void reset(std::size_t n);
};

// Next-state columns written by integrate and backoff, swapped in by commit.
struct NextState {
  std::vector<double> x, y, vx, vy;
  std::vector<uint8_t> frozen;  // 1 when the backoff loop put the agent back this tick
  void resize(std::size_t n);
};

// Q1: preferred velocity towards the current waypoint, (v_pref - v) / tau, times the goal's
// charge; turned aside for agents frozen cfg.nudge_after ticks in a row. Idle (arrived) agents
// get no effect. `tick` is the tick being computed (it seeds the sidesteps).
// Waypoint following: with `nav` (and cfg.navigation.skip_visible, every sight_interval ticks
// per agent), an agent whose waypoint after the current one is in sight (a disc of its radius class
// can walk straight there) steers at that one instead and records the skipped waypoint in fx.skip;
// commit pops it.
void attraction(const AgentTable& t, std::span<const Goal> goals, const SimConfig& cfg,
                uint64_t tick, Effects& fx, Executor& ex, const path::Navigation* nav = nullptr);

// Q2: -w_apf * gradient of the potential field at each agent.
void inner_avoidance(const FieldColumns& field, const SimConfig& cfg, Effects& fx, Executor& ex);

// Q3: push away from the first collider along the line of centres predicted at the collision
// time, scaled by (1 - t/T); the perpendicular of the relative velocity when that line is zero.
void outer_avoidance(const AgentTable& t, const StaticScene& scene, std::span<const FtcHit> hits,
                     const SimConfig& cfg, Effects& fx, Executor& ex);

// Sum the effects, clamp |a| <= max_accel, v' = v + a dt clamped to max_speed, p' = p + v' dt.
// Idle agents stay put with zero velocity.
void combine_integrate(const AgentTable& t, const Effects& fx, const SimConfig& cfg,
                       NextState& next, Executor& ex);

// Overlaps among the next-state positions, split into those the backoff must resolve and those
// it tolerates (pairs that overlapped at the start of the tick and did not get deeper).
struct OverlapReport {
  std::size_t agent_pairs = 0;      // all overlapping agent pairs
  std::size_t obstacle_hits = 0;    // all agent-obstacle overlaps (walls are obstacles)
  std::vector<uint32_t> violators;  // rows in a new or deepened overlap, sorted, unique
};

// Is the overlapping pair (i, j) (next-state positions) a violation: new, or deeper than at the
// start of the tick? A pair that already overlapped is tolerated while its centres get no closer.
bool pair_violates(const AgentTable& t, const NextState& next, uint32_t i, uint32_t j);
// The same for agent i overlapping an obstacle (depth for polygons, centre distance for circles).
bool obstacle_violates(const AgentTable& t, const NextState& next, const StaticScene& scene,
                       uint32_t i, Collider with);

// Finds overlaps among the next-state positions with the planned collision method (one query).
OverlapReport find_overlaps(const AgentTable& t, const NextState& next, const StaticScene& scene,
                            CollisionPath& path, Executor& ex, QueryStats& stats);

// Backoff (DESIGN.md §3.2): freeze the violators (back to the start position, zero velocity)
// until none is left. Returns the overlaps of the final state (exact counts, and no violators)
// and the number of iterations in `iterations` (1 when nothing had to be frozen).
//
// One full collision query, then only probes: after a freeze, a pair can only become a new
// violation if one of its agents moved, i.e. was frozen in the previous iteration, so iteration
// k+1 asks just for the overlaps of the agents frozen in iteration k (through a DiscGrid over the
// current positions). The frozen sets, iterations and final counts are those of the plain loop
// that re-runs the full query every iteration (backoff_reference; tested equal).
OverlapReport backoff(const AgentTable& t, NextState& next, const StaticScene& scene,
                      CollisionPath& path, Executor& ex, QueryStats& stats,
                      std::size_t& iterations);

// The plain loop of DESIGN.md §3.2: find the violators with a full query, freeze them, repeat.
// The oracle for backoff() (tests), and the thesis's algorithm as written.
OverlapReport backoff_reference(const AgentTable& t, NextState& next, const StaticScene& scene,
                                CollisionPath& path, Executor& ex, QueryStats& stats,
                                std::size_t& iterations);

// Hash of the committed state: tick, then per row id, position, velocity and state bits.
uint64_t state_hash(const AgentTable& t, uint64_t tick);

}  // namespace crowddb::sim
