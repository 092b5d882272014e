// The tick's side of path planning (DESIGN.md §3 "path requests", §6): one navigation mesh per
// agent-radius class, the path service, and the operators the tick runs around the steering
// queries:
//
//   start of tick t:  apply_results  — results due at t become the agents' routes
//   Q1 attraction:    visible        — skip a waypoint when the one after it is in sight
//   after commit:     request_paths  — progress watch, lost sight, new requests, dispatch
//
// Requests: an agent asks for a path when its route was not planned for its current goal (a
// new agent, a changed goal) or when it made no progress towards its current waypoint for
// `replan_after` seconds (the progress watch of src/sim/stalemate.hpp counts the ticks), or lost
// sight of it (sim::goal_stage: pushed behind an obstacle). Requests
// wait in FIFO order; each tick at most `budget` of them are dispatched to the worker, with the
// agent's position at that moment, due `latency` ticks later. A newer request for the same agent
// supersedes an older one (tickets). Everything here is decided from simulation state only, so runs
// are bit-identical whatever the worker's timing.
//
// Congestion: while agents are stalled where streams meet head-on (src/sim/stalemate.hpp: no
// progress, not just waiting in a queue, and not in an arch where all walk one way), every
// search dispatched in the tick counts `congestion_cost` metres extra for each of them in a
// polygon it enters, but for those heading the searching agent's way (within 60 degrees). The
// costs are taken from the committed state and carried by the job. Two streams locked in a
// passage between two stands are then walked round by whoever plans next, instead of fed from
// both ends; with no way round, the route is the one it would be without. An arch at a door is
// not walked round: every route goes through the door anyway, and costs on the polygons before
// it only sent people along the wall to its posts (SteerSuite's bottleneck-evacuation lost a
// tenth of its arrivals over 10 seeds when every stalled agent counted).
//
// Queues at doors (`queue_flow`): a room's floor is one or a few mesh polygons, so costs on
// polygons cannot tell a way through one door from a way through another; a door is found on
// the agent's way instead. For a search dispatched (among the tick's first 8 with costs),
// Detour's route is found on the tick's thread, and along it the first place narrower than
// kDoorWidth within kDoorLook (NavMesh::first_narrows); the people queued ahead there (slow,
// bound for the same goal, on this side, nearer to it and heading into it) make crossing that
// cut cost their number over (queue_flow x the door's width) seconds, at the agent's preferred
// speed. The search (PathFinder::find) charges every step that crosses the cut: a way through
// another door wins when it is shorter by more. The other door's own queue is not charged; who
// plans there next sees it.
//
// Narrow passages: each class's mesh keeps the class radius plus a few cells of rounding from
// every obstacle, so a passage less than about 3.25 class radii wide is not on it (an aircraft's
// 0.46 m aisle for people of radius 0.21, a 0.9 m door for a radius of 0.3 rounded up to the 0.5
// class). When the class mesh has no path to the goal, or had to move the start or the goal
// farther than its own rounding to reach a polygon (the nearest one may lie across a wall), the
// search is repeated on a narrow mesh for the agent's own radius to the centimetre, with cells
// of an eighth of it (built when first needed): a door 1.9-2.3 radii wide is on it. Its route
// is taken only when it reaches the goal; the agent's line-of-sight checks and re-plans then use
// the narrow mesh too. The steering model keeps the agent's real disc off the walls either way; a
// passage that is on the narrow mesh but too narrow for the disc stops it at the passage instead
// of at the wall nearest the goal.
//
// Thread-safety: apply_results/request_paths on the tick's thread; visible() from any thread
// during the steering queries (the meshes are read-only then).
#pragma once

#include <cstdint>
#include <deque>
#include <map>
#include <memory>
#include <optional>
#include <set>
#include <string>

#include "crowddb/simulation.hpp"
#include "path/navmesh.hpp"
#include "path/path_service.hpp"
#include "util/executor.hpp"

namespace crowddb::path {

// Queues at doors (NavigationParams::queue_flow): how far from the agent the first door on its
// route may be, and how narrow a place must be to be a door.
inline constexpr double kDoorLook = 15;    // [m]
inline constexpr double kDoorWidth = 2.5;  // [m]
// At most this many doors are charged for one search; two cuts whose middles lie nearer than
// kSameDoor are one door.
inline constexpr int kDoorRounds = 3;
inline constexpr double kSameDoor = 1;  // [m]
// Nodes of the searches that find the doors on an agent's way (PathFinder's max_nodes).
inline constexpr int kDoorSearchNodes = 1024;

struct NavigationStats {
  uint64_t requests = 0;    // requests made (new goals + re-plans)
  uint64_t replans = 0;     // of which for lack of progress
  uint64_t dispatched = 0;  // sent to the worker
  uint64_t superseded =
      0;                 // dropped before dispatch or on return: a newer request or the agent left
  uint64_t applied = 0;  // results that became routes
  uint64_t failed = 0;   // of which with no path (the agent keeps steering straight)
  uint64_t partial = 0;  // of which towards an unreachable goal
  uint64_t queued = 0;   // requests waiting for dispatch now
  uint64_t sight_checks = 0;   // line-of-sight checks when applying results
  uint64_t narrow = 0;         // searches repeated on a narrow mesh
  uint64_t narrow_routes = 0;  // of which gave the route (the goal reached)
  uint64_t costed = 0;         // searches dispatched with congestion costs (agents stalled)
  uint64_t queue_costed = 0;   // of which with a queue at a door on the way
};

class Navigation {
 public:
  // Builds the meshes for the radius classes present; `threads` parallelise the tile builds.
  Navigation(const World& world, const SimConfig& cfg, Executor& ex);
  ~Navigation();

  // Applies the results due at `tick` (waits for the worker if one is late). Returns the
  // number of routes set.
  std::size_t apply_results(World& world, uint64_t tick);
  // After the commit of `tick`: progress watch, requests, dispatch. Returns requests made.
  // `head_on`: rows stalled where streams meet head-on (sim::StallCounts), in row order; the
  // searches dispatched plan round them.
  // `lost_sight`: ids of walkers that lost sight of their targets (sim::goal_stage): re-planned
  // now (counted as re-plans), unless a search for them is on its way.
  std::size_t request_paths(World& world, uint64_t tick, const std::vector<uint32_t>& head_on = {},
                            const std::vector<uint64_t>& lost_sight = {});

  // Line of sight for agent `agent` (AgentId value) of `radius`: on its class mesh, or on the
  // narrow one when its route came from there. False when that mesh is not built yet.
  bool visible(double radius, uint64_t agent, Vec2 from, Vec2 to) const;
  // Lost sight (sim::goal_stage): is an obstacle ahead of agent `agent` of `radius` on the
  // straight way from `from` to `to`? Not visible() alone: a walker pressed against a wall
  // stands off the mesh (within its rounding off the wall), and a ray from the mesh's edge along
  // that edge towards a corner on it is blocked as often as not (a queue along a wall towards a
  // door lost sight 9,000 times in 400 s). So when `from` is off the mesh, the way must also lead
  // into what lies beyond the edge (within 60 degrees of the line from the mesh's nearest point
  // to `from`), as it does for one pressed against a pillar it wants to walk through. False for
  // agents whose route ends short of their goal or came from a narrow mesh (navigation.cpp).
  bool blocked_ahead(double radius, uint64_t agent, Vec2 from, Vec2 to) const;
  // Agents still walking whose last route does not reach their goal: the search ended short
  // of it (no way there on the mesh: a goal walled in) or found no path at all (the agent
  // steers straight at the goal). A passage on the narrow mesh but narrower than the agent's
  // disc is not caught (its route reaches the goal).
  std::size_t without_path(const World& world) const;
  // Entries of the two route sets behind blocked_ahead and without_path, departed agents
  // included until the next sweep (forget_departed): what they cost in memory and checkpoints.
  std::size_t flagged_routes() const { return short_routes_.size() + narrow_routes_.size(); }

  double class_radius(double radius) const;
  const NavigationParams& params() const { return params_; }
  NavigationStats stats() const;
  PathService::Stats service_stats() const { return service_->stats(); }
  // One line per mesh: class radius, cell, tiles, polygons, build time.
  std::string describe_meshes() const;
  std::size_t mesh_count() const { return meshes_.size(); }
  double mesh_build_seconds() const;

  // Checkpoints: tickets, counters, the request queue and the searches in flight (submitted
  // again on restore; their results depend on the job and the mesh only, so they come out the
  // same). restore() replaces what the constructor requested; `tick` is the restored tick,
  // `world` the restored agents: a search that its agent will take must be on that agent's mesh,
  // and one it will not (the agent has gone or asked again since) builds no mesh, so that a
  // damaged checkpoint cannot make restore build meshes nobody uses (seconds each).
  void save(ByteWriter& out) const;
  void restore(ByteReader& in, uint64_t tick, const World& world);

 private:
  int class_of(double radius) const;
  // The mesh agent `agent`'s sight checks use: its class's, or the narrow one its route came from.
  const NavMesh* mesh_of_agent(double radius, uint64_t agent) const;
  const NavMesh& mesh_for(double radius);  // builds on first use
  // Class k's mesh; k < 0: the narrow mesh for radius -k cm (narrow_key). Builds on first use.
  const NavMesh& mesh_of_class(int k);
  int narrow_key(double radius) const;
  bool is_narrow(const NavMesh* m) const;
  bool off_mesh(const PathResult& r, const NavMesh& m) const;
  void forget_departed(const World& world);  // drops agents no longer in the world from the sets
  // A stalled agent's polygon on a mesh and its heading (unit vector to its waypoint).
  struct StalledAt {
    uint32_t ref;
    Vec2 dir;
  };
  static std::vector<StalledAt> locate(const World& world, const NavMesh& m,
                                       const std::vector<std::size_t>& stalled);
  // Congestion for a search by an agent heading `dir`: congestion_cost for each stalled agent
  // not heading its way in the polygon it stands in; null when there is none.
  std::shared_ptr<const PolygonCosts> congestion(const std::vector<StalledAt>& stalled,
                                                 Vec2 dir) const;
  // Rows walking slower than half their preferred speed, in row order.
  static std::vector<std::size_t> slow_walkers(const AgentTable& t);
  // The door cuts costed for row i's search to `goal` on mesh m (NavigationParams::queue_flow),
  // on top of `base` (or none): the first door on its way with the queue ahead of it there, then
  // the first door on the way the search takes with that charged, and so on (at most
  // kDoorRounds); empty when the first door has no queue, or there is none.
  // Runs on any thread: `scratch` is the caller's own (a path search and a query context per
  // mesh, made on first use).
  struct DoorScratch {
    std::map<const NavMesh*, std::unique_ptr<PathFinder>> finders;
    std::map<const NavMesh*, std::unique_ptr<NavMesh::Context>> contexts;
  };
  std::vector<DoorCut> queues_ahead(const AgentTable& t, const NavMesh& m, std::size_t i, Vec2 goal,
                                    const std::vector<std::size_t>& slow, const PolygonCosts* base,
                                    DoorScratch& scratch) const;
  // Drops the leading waypoints the agent has already passed (the one after is in sight).
  void trim_passed(World& world, std::size_t row);

  struct Queued {
    uint64_t ticket;
    uint64_t agent;
    bool narrow;  // search on the narrow mesh
  };
  NavigationParams params_;
  uint64_t latency_ticks_ = 1;  // params_.latency in ticks (>= 1)
  uint64_t replan_ticks_ = 0;   // params_.replan_after in ticks (0: never)
  NavGeometry geometry_;
  Executor& ex_;
  std::map<int, std::unique_ptr<NavMesh>> meshes_;  // by class (radius = class * radius_step);
                                                    // negative: narrow meshes (narrow_key)
  // Agents that left are swept out now and then (forget_departed): a source letting people in
  // for hours would otherwise keep everyone who ever took such a route, in memory and in every
  // checkpoint.
  std::set<uint64_t> short_routes_;   // agents whose last route does not reach their goal
  std::set<uint64_t> narrow_routes_;  // agents whose route came from a narrow mesh
  std::deque<Queued> queue_;
  uint64_t next_ticket_ = 0;
  NavigationStats stats_;
  // Searches on the tick's thread (queue_ahead's first door), one per mesh.
  // One per search costed at once (request_paths), kept between ticks.
  std::vector<std::unique_ptr<DoorScratch>> door_scratch_;
  std::unique_ptr<PathService> service_;  // declared last: stopped before the meshes go
};

}  // namespace crowddb::path
