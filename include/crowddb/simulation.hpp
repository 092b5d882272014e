// One simulation tick = one set-at-a-time query plan over the world tables (DESIGN.md §3):
//
//   apply batch (inserts, deletes, re-targets, sources) -> path results -> goal stage (preferred
//   velocity towards the waypoint, stalemate actions) -> the steering model's queries and rule
//   (thesis, orca, cfsm: one new velocity per agent) -> integrate (tentative) -> backoff: freeze
//   the collision set until none is left -> commit (arrivals, goal sequences, progress watch,
//   stalemates) -> path requests
//
// Units: metres and seconds. The planner picks an access path per query (naive nested loop or
// an index) by table size or as forced by the configuration; explain() shows the plan and
// explain_analyze() the rows and time per operator so far. Same world + config -> bit-identical
// states on any thread count.
//
// Thread-safety: a Simulation is used from one thread; step() uses `threads` threads inside.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <string_view>

#include "crowddb/query.hpp"
#include "crowddb/world.hpp"

namespace crowddb {

// The thesis's steering rule (DESIGN.md §3.1), model "thesis". Every weight is a parameter.
struct ThesisParams {
  double tau = 2;       // [s] attraction: time to relax towards the preferred velocity (> 0)
  double w_apf = 1;     // inner avoidance weight (>= 0; 0 switches the query off)
  double w_ftc = 1;     // outer avoidance weight (>= 0; 0 switches the query off)
  double horizon = 30;  // [s] first-to-collide look-ahead (> 0)
  PotentialSpec potential;
  // How obstacles repel. `nearest` (default): the nearest obstacle geometry within
  // obstacle_cutoff pushes along its normal with the potential's kernel, so walls cannot form the
  // local minima that hundreds of charged points do. `charges`: the thesis's charged points in
  // the potential field (obstacle_charges says where they sit), as the experiments use it.
  enum class ObstacleRepulsion { nearest, charges } obstacle_repulsion = ObstacleRepulsion::nearest;
  double obstacle_cutoff = 2;  // [m] (> 0)
  ObstacleCharges obstacle_charges = ObstacleCharges::boundary;
};

// Optimal reciprocal collision avoidance (van den Berg, Guy, Lin, Manocha 2011), model "orca".
// Defaults: pedestrian scale (RVO2's examples are unitless; VALIDATION.md).
struct OrcaParams {
  double neighbor_dist = 5;        // [m] neighbours considered within this distance (> 0)
  uint32_t max_neighbors = 10;     // at most this many, the nearest (>= 1)
  double time_horizon = 2;         // [s] velocities stay collision-free with agents this long (> 0)
  double time_horizon_obst = 0.5;  // [s] ... and with obstacles (> 0)
  // Share of an avoidance taken by the agent that goes first (less path left), in (0, 1); the
  // other takes the rest. 0.5: the paper's even split (steer/orca.cpp explains why not).
  double first_share = 0.25;
  // [s] headway: the preferred speed is capped at spacing / time_gap to the agent ahead going the
  // same way or standing (>= 0; 0: off, the default). steer/orca.cpp says when it helps.
  double time_gap = 0;
  // [s] stream gap: where streams meet (neighbours bound for another goal coming towards or
  // across) and in the queues behind such a meeting, the preferred speed is capped at the speed
  // of the agent ahead plus spacing / stream_gap (>= 0; 0: off). steer/orca.cpp says why.
  double stream_gap = 1;
  // No sweeping back: a hard plane keeps the velocity's component against the preferred direction
  // at most max_retreat * pref_speed (>= 0; a value >= max_speed / pref_speed never binds, so a
  // large one such as 10 switches it off). steer/orca.cpp says why.
  double max_retreat = 0.25;
  // Keeping to one side: someone coming towards an agent in its lane ahead turns its wish a little
  // to this side, so that people meeting head-on pass each other on the same side and counter-
  // flows sort into lanes (none: off). steer/orca.cpp says why.
  enum class PassSide { none, right, left } pass_side = PassSide::right;
  // [m] ... looking this far ahead for people coming towards the agent, not only among its
  // neighbours (>= 0; 0: the neighbours only). steer/passing.hpp says why.
  double pass_look = 10;
};

// The collision-free speed model (Tordeux, Chraibi, Seyfried 2016), model "cfsm"; defaults are
// JuPedSim's (VALIDATION.md §3).
struct CfsmParams {
  double time_gap = 1;           // [s] T in v = min(max(s / T, 0), v0) (> 0)
  double strength_neighbor = 8;  // a in a exp((l - d) / D) for neighbours (>= 0)
  double range_neighbor = 0.1;   // [m] D for neighbours (> 0)
  double strength_geometry = 5;  // the same for walls and obstacles (>= 0)
  double range_geometry = 0.02;  // [m] (> 0)
  double cutoff = 3;             // [m] neighbours and walls considered within this (> 0)
};

struct SteeringParams {
  std::string model = "orca";  // a registered steering model (src/steer/registry.cpp)
  ThesisParams thesis;
  OrcaParams orca;
  CfsmParams cfsm;
  // Each preferred velocity is turned by a tiny seeded angle so that exactly symmetric set-ups
  // (two agents head-on on one line, four groups crossing) do not balance for ever; RVO2's
  // examples add such noise too. [m/s] magnitude of the change, >= 0 (0: off).
  double perturbation = 1e-4;
};

enum class ArrivalPolicy {
  remove,    // agents that reach their last goal leave the table
  idle,      // they stay, still and solid (and step off a goal area others still head for)
  retarget,  // they head on to another goal, drawn from the seeded generator (a traveller
             // walking on to a connecting gate): the table keeps its size
};

// Access path per query: "auto" lets the planner choose, or a registered method name.
struct AccessChoice {
  std::string ftc = "auto";
  std::string field = "auto";
  std::string collisions = "auto";
  std::string neighbours = "auto";
  std::string edges = "auto";
  // The agents' rows: "curve" puts them in Z-curve order of their positions every 2 s, so that
  // neighbours sit together in memory (src/sim/row_order.hpp); "none" keeps insertion order;
  // "auto" is "curve" from 4096 agents on under orca and cfsm, where only the row order changes,
  // never a result; the thesis model's potential field sums charges in row order, so there the
  // rounding of its sums would change, and "auto" keeps insertion order.
  std::string row_order = "auto";
};

// The path service (DESIGN.md §6): a Recast/Detour navigation mesh per agent-radius class, path
// requests served asynchronously on a worker thread, and waypoint following in the goal stage.
// Off unless the scenario has a "navigation" block (docs/scenario-format.md, "Navigation").
struct NavigationParams {
  bool enabled = false;
  // [s] A request dispatched at tick t is applied at the start of the tick latency later (at
  // least one tick), whatever the worker's timing: the tick waits for a due result not ready yet.
  double latency = 0.2;
  uint32_t budget = 64;     // path searches dispatched per tick (>= 1); the rest wait, FIFO
  double replan_after = 4;  // [s] re-plan after this long without progress; 0: never
  // [m] Congestion-aware planning: a path search dispatched while agents are stalled where
  // streams meet head-on (two streams locked in a passage) counts this much extra for each of
  // them (not heading the searcher's way) in a mesh polygon it enters, so that a way round the
  // jam wins when it is shorter than that; 0: off. src/path/navigation.hpp has the detail.
  double congestion_cost = 5;
  // [1/(m s)] Queues at doors: a path search counts, at the first door on the agent's way (a
  // place narrower than 2.5 m within 15 m of it), the slow people ahead of it there bound for
  // its goal, each as the time the door takes to let one through at this specific flow (1.3
  // /(m s): the bottleneck flows of docs/validation.md), walked at the agent's preferred speed;
  // a way through another door wins when it is shorter than that. 0: off.
  // src/path/navigation.hpp has the detail.
  double queue_flow = 1.3;
  double radius_step = 0.25;  // [m] radius classes: an agent's radius rounded up to a multiple
  double cell_size = 0;       // [m] navmesh cell; 0: auto (a quarter of the class radius, at
                              // most 4096 x 4096 cells over the world's area)
  double clearance = 0;       // [m] extra distance kept from obstacles beyond the class radius
  // [m] A path's corners keep this far inside the mesh's edges where there is room, moving by
  // at most an eighth of a passage's width from either side (so beyond the class radius from a
  // door's posts or a corner's wall). 0: Detour's straight path, its corners on the mesh's
  // edge. Opt-in: it eases arches of people 1 m wide at a door, and slows doors for people of
  // 0.2-0.25 m by a tenth (docs/steering.md, "Corners off the door posts").
  double corner_push = 0;
  uint32_t tile_size = 256;  // navmesh tile side [cells] (16..4096)
  bool skip_visible = true;  // skip a waypoint when the one after it is in sight (Detour raycast)
  // [s] Time between an agent's line-of-sight checks (at least every tick), staggered by agent
  // id: each check is a mesh query, about a microsecond, and at 10^4 agents they add up.
  double sight_interval = 0;
};

// Stalemates (issue "crowds that flow"): an agent that gets no closer to its current waypoint
// for `after` seconds, frozen or not, and is not just queueing behind someone walking its way,
// is stalled. With `resolve`, a stalled agent that has a stalled neighbour of higher seeded
// priority in its way yields (steps aside for yield_time in a jam, head_on_yield_time where two
// streams meet head-on), otherwise it sidesteps at a seeded angle (for sidestep_time); with
// navigation, one that stays stalled re-plans (NavigationParams::replan_after).
// src/sim/stalemate.hpp has the detail.
struct StallParams {
  double after = 2;       // [s] (> 0)
  double progress = 0.1;  // [m] getting this much closer than ever counts as progress (> 0)
  bool resolve = true;
  double yield_time = 1.5;          // [s] a yield in a jam (an arch at a door) (> 0)
  double head_on_yield_time = 1.5;  // [s] a yield where two streams meet head-on (> 0)
  double sidestep_time = 1.5;       // [s] (> 0)
  // [s] Two stalled agents blocking each other who have both been stalled this long take turns:
  // in every other period of reverse_period the one that would go on yields instead (an order
  // that has not ended a stalemate in this long is tried the other way). 0 switches it off.
  double reverse_after = 12;
  double reverse_period = 3;  // [s] (> 0)
};

struct SimConfig {
  double dt = 0.1;  // [s] per tick (> 0)
  uint64_t seed = 1;
  SteeringParams steering;
  bool backoff = true;  // freeze loop on (DESIGN.md §3.2): the zero-overlap safety net
  bool walls = true;    // the world bounds are solid walls (obstacles in every query)
  ArrivalPolicy arrival = ArrivalPolicy::remove;
  AccessChoice access;
  int threads = 1;
  double gridlock_time = 5;  // [s] frozen this long in a row counts as gridlocked
  // [s] An agent frozen this long in a row sidesteps: its preferred velocity is turned by a
  // random angle of 45-90 degrees to either side (seeded by seed, id and tick), so a frozen
  // cluster does not repeat the same colliding moves for ever. 0 switches nudging off.
  double nudge_after = 0.2;
  StallParams stall;
  double waypoint_radius = 0;  // [m] advance to the next waypoint within this; 0: the radius
  NavigationParams navigation;
  // Throws Error(input) naming the field when a value is out of range.
  void validate() const;
  // A duration in ticks: ceil(seconds / dt), at least `min` (durations that mean "at least one
  // tick" pass 1, those that may be off pass 0).
  uint64_t ticks_for(double seconds, uint64_t min = 1) const;
};

// What one tick did. Counts are rows of the agents table.
struct TickMetrics {
  uint64_t tick = 0;        // ticks completed so far (1 after the first step)
  double time = 0;          // [s] simulated time after the tick (tick * dt)
  std::size_t agents = 0;   // rows after the tick
  std::size_t active = 0;   // rows still heading for a goal (not arrived)
  std::size_t entered = 0;  // agents that entered from sources at the start of this tick
  std::size_t arrived = 0;  // agents that reached their last goal in this tick
  std::size_t frozen = 0;   // agents the backoff loop froze in this tick
  std::size_t freeze_iterations =
      0;  // rounds of the freeze loop (1: nothing to freeze; 0: backoff off)
  std::size_t overlapping_pairs = 0;  // agent-agent pairs overlapping after the tick
  std::size_t obstacle_overlaps = 0;  // agent-obstacle (and agent-wall) overlaps after the tick
  std::size_t gridlocked = 0;         // agents frozen for >= gridlock_time in a row
  std::size_t gridlock_started = 0;   // agents whose frozen streak reached gridlock_time now
  std::size_t longest_frozen = 0;     // longest current frozen streak [ticks] among the agents
  std::size_t nudged = 0;             // agents that sidestepped in this tick (nudge_after)
  std::size_t stalled = 0;            // agents stalled now (no progress for stall.after, not
                                      // queueing behind someone walking their way)
  std::size_t queueing = 0;           // agents waiting behind someone walking their way
  std::size_t stall_started = 0;      // agents that became stalled in this tick
  std::size_t longest_stall = 0;      // longest current stretch without progress [ticks]
  std::size_t yielding = 0;           // stalled agents yielding in this tick
  std::size_t sidestepping = 0;       // stalled agents sidestepping in this tick
  std::size_t making_way = 0;         // standing agents asked to step out of a stalled walker's way
  double seconds = 0;                 // wall time of the tick
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
  double time() const { return static_cast<double>(last_.tick) * config_.dt; }  // [s]
  const TickMetrics& last_metrics() const { return last_; }
  std::size_t arrived_total() const { return arrived_total_; }
  std::size_t entered_total() const { return entered_total_; }
  // Agents that sources have still to let in (waiting for a free spot or for their time).
  std::size_t waiting_to_enter() const;
  // Agents still walking whose last planned route does not reach their goal (with navigation;
  // 0 without): a goal walled in, or out of the mesh's reach.
  std::size_t without_path() const;
  // Hash of the current committed state; equal hashes mean bit-identical states.
  uint64_t state_hash() const;

  // Checkpoints. save_state(): the whole state after the last step (the agents table and slot
  // map, the sources' random streams, path requests queued and in flight, tick and counters) as
  // bytes. restore_state() on a Simulation built from the same scenario and configuration (any
  // thread count) continues bit-identically: every later step gives the same state hash as the
  // run that saved it. Throws Error(input) on bytes that are damaged or from another scenario
  // (a fingerprint of its static tables and settings is checked), leaving this simulation
  // unusable only if the error came after the agents were restored (then build it anew).
  // Not saved: EXPLAIN ANALYZE's operator times, which count from the restore.
  std::string save_state() const;
  // The same bytes, handed to `sink` piece by piece as they are written (in order; about a
  // megabyte at a time) instead of returned whole: a checkpoint of 10^6 agents is 200 MB.
  void save_state(const std::function<void(std::string_view)>& sink) const;
  void restore_state(std::string_view bytes, const std::string& what = "checkpoint");

  // The plan the next tick will run (EXPLAIN).
  std::string explain() const;
  // The plan with rows, loops and time per operator accumulated over all ticks so far
  // (EXPLAIN ANALYZE).
  std::string explain_analyze() const;

 private:
  struct Engine;
  void write_state(ByteWriter& out) const;  // save_state's body, between magic and seal
  World world_;
  SimConfig config_;
  TickMetrics last_;
  std::size_t arrived_total_ = 0;
  std::size_t entered_total_ = 0;
  std::unique_ptr<Engine> engine_;
};

}  // namespace crowddb
