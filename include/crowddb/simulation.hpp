// One simulation tick = one set-at-a-time query plan over the world tables (DESIGN.md §3):
//
//   apply batch -> Q1 attraction, Q2 inner avoidance (potential field), Q3 outer avoidance
//   (first-to-collide) -> combine into one effect row per agent -> integrate (tentative)
//   -> backoff: freeze the collision set until none is left -> commit, arrivals, metrics, hash
//
// The planner picks an access path per query (naive nested loop or an index) by table size or
// as forced by the configuration; explain() shows the plan and explain_analyze() the rows and
// time per operator so far. Same world + config -> bit-identical states on any thread count.
//
// Thread-safety: a Simulation is used from one thread; step() uses `threads` threads inside.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "crowddb/query.hpp"
#include "crowddb/world.hpp"

namespace crowddb {

// The steering rule of DESIGN.md §3.1. Every weight is a scenario parameter.
struct SteeringParams {
  double tau = 2;       // attraction: ticks to relax towards the preferred velocity (> 0)
  double w_apf = 1;     // inner avoidance weight (>= 0; 0 switches the query off)
  double w_ftc = 1;     // outer avoidance weight (>= 0; 0 switches the query off)
  double horizon = 30;  // first-to-collide look-ahead [ticks] (> 0)
  PotentialSpec potential;
  ObstacleCharges obstacle_charges = ObstacleCharges::boundary;
};

enum class ArrivalPolicy {
  remove,    // agents that reach their goal leave the table
  idle,      // they stay where they are, still and solid
  retarget,  // they head on to another goal, drawn from the seeded generator (a traveller
             // walking on to a connecting gate): the table keeps its size
};

// Access path per query: "auto" lets the planner choose, or a registered method name.
struct AccessChoice {
  std::string ftc = "auto";
  std::string field = "auto";
  std::string collisions = "auto";
};

// The path service (DESIGN.md §6): a Recast/Detour navigation mesh per agent-radius class, path
// requests served asynchronously on a worker thread, and waypoint following in Q1. Off unless
// the scenario has a "navigation" block (docs/scenario-format.md, "Navigation").
struct NavigationParams {
  bool enabled = false;
  // A request dispatched at tick t is applied at the start of tick t + latency (>= 1), whatever
  // the worker's timing: the tick waits for a due result that is not ready yet.
  uint32_t latency = 2;
  uint32_t budget = 64;        // path searches dispatched per tick (>= 1); the rest wait, FIFO
  uint32_t replan_after = 40;  // re-plan after this many ticks without progress; 0: never
  double radius_step = 0.25;   // radius classes: an agent's radius rounded up to a multiple (> 0)
  double cell_size = 0;        // navmesh cell [length]; 0: auto (a quarter of the class radius,
                               // at most 4096 cells along the world's longer side)
  double clearance = 0;        // extra distance kept from obstacles beyond the class radius (>= 0)
  uint32_t tile_size = 256;    // navmesh tile side [cells] (16..4096)
  bool skip_visible = true;    // skip a waypoint when the one after it is in sight (Detour raycast)
  // Ticks between an agent's line-of-sight checks (>= 1), staggered by agent id: each check is a
  // mesh query, about a microsecond, and at 10^4 agents they add up.
  uint32_t sight_interval = 1;
};

struct SimConfig {
  double dt = 1;  // [ticks per step] (> 0)
  uint64_t seed = 1;
  SteeringParams steering;
  bool backoff = true;  // freeze loop on (DESIGN.md §3.2)
  bool walls = true;    // the world bounds are solid walls (obstacles in every query)
  ArrivalPolicy arrival = ArrivalPolicy::remove;
  AccessChoice access;
  int threads = 1;
  uint32_t gridlock_ticks = 50;  // frozen this many ticks in a row counts as gridlocked
  // An agent frozen this many ticks in a row sidesteps: its preferred velocity is turned by a
  // random angle of 45-90 degrees to either side (seeded by seed, id and tick), so a frozen
  // cluster does not repeat the same colliding moves for ever. 0 switches nudging off.
  uint32_t nudge_after = 2;
  double waypoint_radius =
      0;  // advance to the next waypoint within this distance; 0: the agent's radius
  NavigationParams navigation;
  // Throws Error(input) naming the field when a value is out of range.
  void validate() const;
};

// What one tick did. Counts are rows of the agents table.
struct TickMetrics {
  uint64_t tick = 0;        // ticks completed so far (1 after the first step)
  std::size_t agents = 0;   // rows after the tick
  std::size_t arrived = 0;  // agents that reached their goal in this tick
  std::size_t frozen = 0;   // agents the backoff loop froze in this tick
  std::size_t freeze_iterations =
      0;  // rounds of the freeze loop (1: nothing to freeze; 0: backoff off)
  std::size_t overlapping_pairs = 0;  // agent-agent pairs overlapping after the tick
  std::size_t obstacle_overlaps = 0;  // agent-obstacle (and agent-wall) overlaps after the tick
  std::size_t gridlocked = 0;         // agents frozen for >= gridlock_ticks consecutive ticks
  std::size_t gridlock_started =
      0;                           // agents whose frozen streak reached gridlock_ticks in this tick
  std::size_t longest_frozen = 0;  // longest current frozen streak [ticks] among the agents
  std::size_t nudged = 0;          // agents that sidestepped in this tick (SimConfig::nudge_after)
  double seconds = 0;              // wall time of the tick
  uint64_t state_hash = 0;  // hash of the committed state (ids, positions, velocities, states)
};

class Simulation {
 public:
  // Applies the world's pending inserts (the initial batch) at once, so tick 0 has its agents.
  Simulation(World world, SimConfig config);
  ~Simulation();
  Simulation(Simulation&&) noexcept;
  Simulation& operator=(Simulation&&) noexcept;

  // Changes made here are buffered and applied at the start of the next step.
  World& world() { return world_; }
  const World& world() const { return world_; }
  const SimConfig& config() const { return config_; }

  const TickMetrics& step();
  uint64_t ticks() const { return last_.tick; }
  const TickMetrics& last_metrics() const { return last_; }
  std::size_t arrived_total() const { return arrived_total_; }
  // Hash of the current committed state; equal hashes mean bit-identical states.
  uint64_t state_hash() const;

  // The plan the next tick will run (EXPLAIN).
  std::string explain() const;
  // The plan with rows, loops and time per operator accumulated over all ticks so far
  // (EXPLAIN ANALYZE).
  std::string explain_analyze() const;

 private:
  struct Engine;
  World world_;
  SimConfig config_;
  TickMetrics last_;
  std::size_t arrived_total_ = 0;
  std::unique_ptr<Engine> engine_;
};

}  // namespace crowddb
