// The crowd world as a small in-memory database (DESIGN.md §2): agents, static obstacles and
// goals, stored as columns. Agents are addressed from outside by stable handles (index +
// generation) and inside by dense rows; inserts, deletes and re-targeting are buffered and
// applied as one batch at the start of the next tick.
//
// Thread-safety: a World is not synchronised; use it from one thread at a time. The tick's
// parallel stages only read it.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <unordered_map>
#include <vector>

#include "crowddb/error.hpp"

namespace crowddb {

class ObstacleLookup;  // src/world/obstacle_lookup.hpp

class ByteWriter;  // src/util/byte_codec.hpp
class Executor;    // src/util/executor.hpp
class ByteReader;

struct Vec2 {
  double x = 0;
  double y = 0;
};

// A stable agent handle. value() is the agent's public id (trajectories, CSV, hashes): it is
// never reused within a run because a reused slot gets a new generation.
struct AgentId {
  static constexpr uint32_t kNoIndex = std::numeric_limits<uint32_t>::max();
  uint32_t index = kNoIndex;
  uint32_t generation = 0;

  uint64_t value() const { return (static_cast<uint64_t>(generation) << 32) | index; }
  static AgentId from_value(uint64_t v) {
    return {static_cast<uint32_t>(v & 0xffffffffu), static_cast<uint32_t>(v >> 32)};
  }
  friend bool operator==(AgentId, AgentId) = default;
};

enum class AgentState : uint8_t {
  active = 0,   // steering normally
  frozen = 1,   // put back by the backoff loop in the last tick
  arrived = 2,  // reached its last goal and idles there (only when arrivals idle)
  waiting = 3,  // stands at a goal with a wait until AgentTable::wait_until, then goes on
};

// Arrived and waiting agents stand at their goal: they do not steer for it, go last when others
// pass and make way for them.
inline bool standing(AgentState s) {
  return s == AgentState::arrived || s == AgentState::waiting;
}

// One agent row as the user supplies it. Units: metres and seconds (velocities in m/s).
struct AgentSpec {
  double x = 0, y = 0;
  double vx = 0, vy = 0;
  double radius = 0.25;      // [m] > 0
  double pref_speed = 1.34;  // [m/s] > 0: the speed it walks at when nothing is in the way
  double max_speed = 1.34;   // [m/s] >= pref_speed: the fastest it may go (to avoid someone)
  double max_accel = std::numeric_limits<double>::infinity();  // [m/s^2] > 0, may be infinite
  double charge = 1;  // repulsive strength in the potential field, finite, >= 0
  uint32_t goal = 0;  // row of the goals table
  // Goals visited after `goal`, in order (a goal sequence); the arrival policy applies only at
  // the last one.
  std::vector<uint32_t> then;
};

// A goal is an area: a disc (the centre and arrival_radius) or a simple polygon. An agent has
// reached it when its centre is inside (a polygon's boundary counts).
struct Goal {
  std::string name;
  double x = 0, y = 0;        // [m] the disc's centre; for a polygon a point inside it (navigation
                              // plans towards it when nothing nearer is known)
  double charge = 1;          // attraction strength (c_goal) of the thesis model, finite
  double arrival_radius = 1;  // [m] > 0: the disc's radius (ignored for polygons)
  std::vector<Vec2> area;     // empty: a disc; else a simple polygon, stored counter-clockwise
  // [s] An agent that reaches the goal stands there for a time drawn (per agent and visit, from
  // the seeded generator) before it goes on to its next goal or its arrival policy applies:
  // uniformly in [wait_min, wait_max] (0 <= wait_min <= wait_max <= kMaxWait; 0: no wait), or,
  // when wait_mean > 0 (then wait_min = wait_max = 0), from an exponential distribution with
  // that mean, cut at kMaxWait (a queue's service time).
  double wait_min = 0, wait_max = 0, wait_mean = 0;
  // Derived, set by World::add_goal whatever the caller put there: for a convex area, the unit
  // inward normal of each edge (edge i runs from area[i] to area[i + 1]); empty otherwise. The
  // steering target (goal_target) reads them rather than taking square roots on every call.
  std::vector<Vec2> inward_normals{};
  static constexpr double kMaxWait = 1e7;  // [s] about 116 days
  bool is_polygon() const { return !area.empty(); }
  bool has_wait() const { return wait_max > 0 || wait_mean > 0; }
};

// Agents entering over time (the thesis's characters that join a crowd): from `start` on,
// `rate` agents per second appear at free spots of the area until `count` have entered or `end`
// has passed. A spot is free when the new disc overlaps no agent and no obstacle; when there is
// none the agent waits and enters at a later tick (no agent is dropped).
struct Source {
  std::string name;
  std::vector<Vec2> area;  // simple polygon (a box is four corners), counter-clockwise
  double rate = 1;         // [1/s] > 0
  uint64_t count = 1;      // agents in all, >= 1
  double start = 0;        // [s] >= 0
  double end = std::numeric_limits<double>::infinity();  // [s] > start
  AgentSpec agent;              // template: position and velocity are drawn, the rest is copied
  double radius_max = 0;        // > 0: radius drawn uniformly in [agent.radius, radius_max]
  double pref_speed_max = 0;    // > 0: pref_speed drawn in [agent.pref_speed, pref_speed_max]
  std::vector<uint32_t> goals;  // non-empty: goal drawn per agent, round robin over these
};

struct CircleObstacle {
  double x = 0, y = 0;
  double radius = 1;  // > 0
  double charge = 1;  // >= 0
};

// A simple polygon (no self-intersections), vertices in either order; stored counter-clockwise.
struct PolygonObstacle {
  std::vector<Vec2> vertices;  // >= 3, implicitly closed
  double charge = 1;
};

// [m] The largest world coordinate: 10^9 m, far beyond any site (UTM northings reach 10^7).
inline constexpr double kMaxCoordinate = 1e9;

struct Bounds {
  double xmin = 0, ymin = 0, xmax = 0, ymax = 0;
  double width() const { return xmax - xmin; }
  double height() const { return ymax - ymin; }
};

// What a stalled agent is doing about it (src/sim/stalemate.hpp).
enum class StallAction : uint8_t {
  none = 0,
  yield = 1,        // steps aside for a neighbour of higher priority
  sidestep = 2,     // walks off at an angle, no neighbour to yield to (or it has priority)
  yield_ahead = 3,  // yields in a jam of people going its way (src/sim/stalemate.hpp): steps
                    // back as `yield` does, and goes first in orca so the people behind make room
  make_way = 4,     // arrived and standing in the way of a stalled walker: steps aside
};

// The agents table: structure-of-arrays columns, one entry per dense row. Columns are public
// for reading; only World and the tick write them. Hot per-tick columns first.
struct AgentTable {
  // hot: read or written every tick
  std::vector<double> x, y;                // position [m]
  std::vector<double> vx, vy;              // velocity [m/s]
  std::vector<double> radius;              // [m]
  std::vector<double> pref_speed;          // [m/s]
  std::vector<double> max_speed;           // [m/s]
  std::vector<double> max_accel;           // [m/s^2], may be +inf
  std::vector<double> charge;              // potential-field charge
  std::vector<double> target_x, target_y;  // current waypoint (the goal when there is no route)
  std::vector<uint32_t> goal;              // row of the goals table
  std::vector<AgentState> state;
  std::vector<uint32_t> frozen_ticks;  // consecutive ticks frozen by backoff (gridlock detection)
  // progress watch: an agent that gets no closer to its current waypoint is stalled
  std::vector<double> progress_best;  // [m] closest distance to the waypoint since it was set
  std::vector<uint32_t> stall_ticks;  // ticks without progress towards the current waypoint
  // cold: bookkeeping
  std::vector<uint64_t> id;                 // AgentId::value()
  std::vector<std::vector<Vec2>> route;     // intermediate waypoints still ahead of the goal
  std::vector<std::vector<uint32_t>> then;  // goals still to visit after `goal`, in order
  // The goal reached last on the way (a goal sequence's stop, or the goal an idle agent stood at
  // when World::retarget sent it on), kNoGoal before any: whoever heads there lets it out first
  // (sim::out_before_in: steering's right of way, the stalemate stage).
  static constexpr uint32_t kNoGoal = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> left_goal;
  // stalemate resolution (only touched for stalled agents)
  std::vector<StallAction> stall_action;
  std::vector<uint64_t> stall_until;  // tick the action ends (a sidestep: its pause starts)
  std::vector<double> stall_dir_x, stall_dir_y;  // unit direction of the action
  // path service (DESIGN.md §6); only read when navigation is on
  static constexpr uint32_t kNoPath = std::numeric_limits<uint32_t>::max();
  std::vector<uint32_t> path_goal;     // goal row the route is planned for; kNoPath: none
  std::vector<uint64_t> path_ticket;   // the path request in flight (0: none)
  std::vector<uint32_t> replan_ticks;  // ticks without progress since the last path request
  // goal waits (Goal::wait_min/max); only read while the agent is waiting
  std::vector<uint64_t> wait_until;  // tick at whose commit the wait ends

  std::size_t size() const { return x.size(); }
  bool empty() const { return x.empty(); }
};

// Row i walks slower than half its preferred speed: held up (the goal stage's lost-sight look,
// the path service's queue counting at doors).
inline bool held_up(const AgentTable& t, std::size_t i) {
  return t.vx[i] * t.vx[i] + t.vy[i] * t.vy[i] < 0.25 * t.pref_speed[i] * t.pref_speed[i];
}

class World {
 public:
  // A world without bounds (nothing is outside it), or one inside `bounds` (set_bounds' checks).
  World() = default;
  explicit World(Bounds bounds) { set_bounds(bounds); }

  // ---- static tables; validated, applied immediately ----
  // Throws InvalidRow naming the field (a polygon goal that is not simple, a duplicate name).
  uint32_t add_goal(Goal goal);
  uint32_t add_source(Source source);
  uint32_t add_obstacle(const CircleObstacle& obstacle);
  uint32_t add_obstacle(PolygonObstacle obstacle);
  // Throws InvalidRow unless xmin < xmax, ymin < ymax and every coordinate lies within
  // ±kMaxCoordinate (beyond it, distances and navigation meshes lose all precision or overflow).
  void set_bounds(Bounds bounds);
  // Whether the bounds are solid walls (SimConfig::walls, default true; Simulation sets it from
  // its configuration). With walls, an agent's centre must lie within the bounds. Throws
  // InvalidRow when turning walls on leaves an agent (or a pending insert) outside.
  void set_walls(bool walls);
  bool walls() const { return walls_; }

  // ---- agent changes: validated now, applied by apply_pending() (start of the next tick) ----
  // Throws InvalidRow naming the field; nothing stored changes. An agent whose centre lies
  // outside the walkable area (outside the bounds with walls, or strictly inside an obstacle)
  // is refused too (field "x").
  AgentId insert(const AgentSpec& spec);
  // Throws Error(input) when the id is not alive or pending.
  void erase(AgentId id);
  void retarget(AgentId id, uint32_t goal);
  std::size_t pending_changes() const { return pending_.size(); }
  // Applies the buffered changes in call order. Returns the number applied.
  std::size_t apply_pending();
  // Room for `agents` agents in all (their rows and ids) and for the inserts that takes, as
  // std::vector::reserve: a hint, never a limit, and nothing else changes. A caller about to
  // insert many agents at once (a scenario's) saves the copies of growing tables. Throws
  // Error(usage) beyond the most agents a world can hold.
  void reserve(std::size_t agents);

  // ---- reads ----
  const AgentTable& agents() const { return agents_; }
  std::span<const Goal> goals() const { return goals_; }
  // Does any goal make its visitors wait (Goal::has_wait)?
  bool any_goal_wait() const { return any_goal_wait_; }
  std::span<const Source> sources() const { return sources_; }
  // Row of the goal with this name, or nothing.
  std::optional<uint32_t> goal_named(std::string_view name) const;
  std::span<const CircleObstacle> circles() const { return circles_; }
  std::span<const PolygonObstacle> polygons() const { return polygons_; }
  const Bounds& bounds() const { return bounds_; }
  // Dense row of a live agent, or nothing (unknown, erased, or insert still pending).
  std::optional<std::size_t> row_of(AgentId id) const;
  bool contains(AgentId id) const { return row_of(id).has_value(); }

  // Checks every cross-table invariant (slot map <-> rows, columns the same length, goal rows
  // valid). Throws std::logic_error on violation. For tests and debugging.
  void validate() const;

  // Mutable access for the tick's stages (and only them).
  AgentTable& agents_for_tick() { return agents_; }
  // Removes a row by swapping the last row into it; the handle of the removed agent dies.
  void remove_row(std::size_t row);
  // Removes these rows (distinct). The freed handles are reused in the order of their slots,
  // whatever the rows' order, so the ids of agents inserted later do not depend on it.
  void remove_rows(std::vector<std::size_t> rows);
  // Puts the rows in the order `order` (order[new row] = old row, a permutation of the rows);
  // every agent keeps its handle and its values. Throws std::invalid_argument otherwise. With
  // `ex`, the columns are gathered on its threads (the same result).
  void permute_rows(std::span<const uint32_t> order, Executor* ex = nullptr);
  // The current waypoint of a row: next route point, else the nearest point of its goal area.
  // Restarts the row's progress watch because the waypoint may have changed.
  void refresh_target(std::size_t row);
  // Moves a row on to the next goal of its sequence (its route is dropped, a path re-planned).
  // Returns false when the goal was its last.
  bool advance_goal(std::size_t row);
  // Has the row's centre reached its goal area?
  bool at_goal(std::size_t row) const;

  static void validate_spec(const AgentSpec& spec, std::size_t goal_count);
  // Throws InvalidRow("x") when (x, y) lies outside the walkable area: outside the bounds with
  // walls, or strictly inside an obstacle (on its boundary is walkable).
  void check_walkable(double x, double y) const;
  // The obstacles' lookup (src/world/obstacle_lookup.hpp: candidates near a point, edge grids for
  // polygons of many edges), built at the first call after an obstacle was added and shared by
  // everyone who asks (the walkable checks, the scenario reader, SteerBench's collision count).
  // It answers for the obstacles as they were when it was taken: after add_obstacle (which drops
  // the world's), take it again.
  std::shared_ptr<const ObstacleLookup> obstacle_lookup() const;

  // ---- checkpoints (Simulation::save_state) ----
  // The agents table, slot map and free list. The static tables (bounds, goals, sources,
  // obstacles) are the scenario's and are not saved: restore into a world built from it.
  // save_agents throws Error(usage) while changes are buffered; restore_agents throws
  // Error(input) on data that does not make a consistent table, leaving the world unchanged.
  void save_agents(ByteWriter& out) const;
  void restore_agents(ByteReader& in);

 private:
  struct Slot {
    uint32_t generation = 0;
    uint32_t row = kNoRow;  // dense row, or kNoRow
    bool pending = false;   // reserved by insert(), not applied yet
    bool doomed = false;    // erase() buffered: no further changes accepted
  };
  static constexpr uint32_t kNoRow = std::numeric_limits<uint32_t>::max();
  struct Change {
    enum class Kind : uint8_t { insert, erase, retarget } kind;
    AgentId id;
    AgentSpec spec;     // insert only
    uint32_t goal = 0;  // retarget only
  };

  const Slot* live_slot(AgentId id) const;
  void push_row(AgentId id, const AgentSpec& spec);

  Bounds bounds_{};
  bool has_bounds_ = false;
  bool walls_ = true;
  // obstacle_lookup()'s: built at the first call after an obstacle was added; shared by copies.
  mutable std::shared_ptr<const ObstacleLookup> lookup_;
  AgentTable agents_;
  std::vector<Goal> goals_;
  std::unordered_map<std::string, uint32_t> goal_rows_;  // goals_ by name: O(1) per new goal
  bool any_goal_wait_ = false;
  std::vector<Source> sources_;
  std::vector<CircleObstacle> circles_;
  std::vector<PolygonObstacle> polygons_;
  std::vector<Slot> slots_;
  std::vector<uint32_t> free_slots_;  // LIFO, deterministic reuse order
  std::vector<Change> pending_;
};

}  // namespace crowddb
