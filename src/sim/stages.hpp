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

// Preferred velocities: the goal stage's output, every model's input.
inline constexpr uint8_t kSkipWaypoint = 1, kLostSight = 2;
// Lost sight: a walker slower than half its preferred speed, whose target is farther than
// kLostSightFar, looks this far towards it once every kLostSightInterval, through the navigation
// mesh (Detour raycast). Half a metre: an obstacle that near holds it up; one farther off does
// not yet (the people in front do: in a queue beside a door, looking 3 m had everyone behind the
// door's post "lose sight" of the corridor beyond, and the routes re-planned for them, with a
// corner at the post, drew them at the post instead of into the door; Vadere's RiMEA 11 exit
// selection got 8 % fewer through in 400 s).
inline constexpr double kLostSightLook = 0.5;    // [m]
inline constexpr double kLostSightFar = 3;       // [m]
inline constexpr double kLostSightInterval = 1;  // [s]

struct Preferred {
  std::vector<double> vx, vy;  // [m/s]
  // kSkipWaypoint: the waypoint after the current one is in sight (popped at commit);
  // kLostSight: the way towards the current target is not (a re-plan is asked for at commit).
  std::vector<uint8_t> skip;
  std::vector<double> left;   // [m] path_left of each row; infinite for those standing
  void reset(std::size_t n);  // n rows, their values left to goal_stage (it writes them all)
};

// Next-state columns written by the model, integrate and backoff, swapped in by commit.
struct NextState {
  std::vector<double> x, y, vx, vy;
  std::vector<uint8_t> frozen;  // 1 when the backoff loop put the agent back this tick
  void resize(std::size_t n);
};

// The aim point each row asked for last (goal_target: a small linear program per call, for every
// walking agent and tick). The stalemate watch of one tick and the goal stage of the next ask
// for the same row at the same position, so the second reads the first's answer. An entry
// answers only the goal, point (bit for bit) and radius it was computed for, and any other
// question recomputes it: the memo never changes a result, whatever rows were reordered,
// removed or added in between. A row's entry is only touched by the thread that has the row.
// A goal that is a point is its own aim and is not kept: with no area among the goals the memo
// holds nothing (it was 48 bytes a row, read and written twice a tick: 48 MB at 10^6 agents).
class AimMemo {
 public:
  // Entries for `rows` rows when some goal is an area, else none.
  void resize(std::size_t rows, std::span<const Goal> goals);
  std::size_t rows_kept() const { return entries_.size(); }
  // goal_target(goals[goal], px, py, r), the answer kept for row `row`.
  Vec2 target(std::span<const Goal> goals, uint32_t goal, double px, double py, double r,
              std::size_t row);

 private:
  struct Entry {
    uint32_t goal = UINT32_MAX;
    uint64_t x = 0, y = 0, r = 0;  // the question's bits
    Vec2 target;
  };
  std::vector<Entry> entries_;
};

// Where row i is heading now: its next route waypoint, else the nearest point of its goal area
// (through `aim` when given).
Vec2 current_target(const AgentTable& t, std::span<const Goal> goals, std::size_t i,
                    AimMemo* aim = nullptr);
// Length of the path still ahead of row i: to its waypoint, along its route, to its goal's
// target point. Continuous when a waypoint is passed, so progress along a route can be watched
// with one number across waypoint changes.
double path_left(const AgentTable& t, std::span<const Goal> goals, std::size_t i,
                 AimMemo* aim = nullptr);

// Out before in: of two walking agents, one that has just left the goal the other heads for
// (AgentTable::left_goal) and is nearer to it goes first, as people let those who come out of a
// door, off a train or away from a ticket machine out before they go in. Pressing in first, the
// crowd around a point everyone must touch locks those who touched it inside (SteerSuite's
// free-tickets). +1: i goes first, -1: j goes first, 0: the rule does not decide (neither, or
// both, each leaving the other's goal). Antisymmetric: out_before_in(i, j) == -out_before_in(j, i).
// Goal sequences only: under the `retarget` arrival policy (a wandering crowd, each visit's next
// goal drawn at random) left_goal is not set, because there it cost a third of the visits (a
// tradeshow of 1,025 visitors with booth waits: 1,744 -> 1,271 visits in 300 s, seeds 1-3).
int out_before_in(const AgentTable& t, std::span<const Goal> goals, std::size_t i, std::size_t j);

// Cos 60 degrees: two directions this close are "the same way".
inline constexpr double kSameWay = 0.5;

// The one ahead (orca's right of way, docs/steering.md item 3): path left to different goals
// does not say who is in front. Of two walking rows bound for different goals the same way (the
// straight lines to their goals within 60 degrees) whose headings (unit vectors to their
// waypoints) are less than 120 degrees apart, the one further along the sum of the headings
// goes first: their paths left, linearised. What a row brings to the test, from its columns:
// One cache line each: orca reads a neighbour's for every neighbour of every row, and in an
// array aligned to 16 bytes only every one of them could straddle two lines.
struct alignas(64) AheadInput {
  double x = 0, y = 0;                       // [m] its position
  double way_x = 0, way_y = 0;               // the unit vector to its waypoint (0 on it)
  double goal_x = 0, goal_y = 0, goal2 = 0;  // [m] the offset to its goal's point, its square
  uint32_t goal = 0;
  uint32_t left_goal = 0;  // the goal it last left (orca's out-before-in; in the line's spare room)
};
static_assert(sizeof(AheadInput) == 64);
AheadInput ahead_input(const AgentTable& t, std::span<const Goal> goals, std::size_t i);
// The test for two walking rows (that they walk is the caller's part): true when it decides,
// with a_first true when a is ahead. Antisymmetric bit for bit. Without branches: which of two
// goes first is a coin toss to the predictor, and orca asks it for every neighbour of every row.
inline bool ahead(const AheadInput& a, const AheadInput& b, bool& a_first) {
  const double sx = a.way_x + b.way_x, sy = a.way_y + b.way_y;
  const double d = sx * (a.x - b.x) + sy * (a.y - b.y);
  a_first = d > 0;
  // Bound the same way, squared so that no root is taken per row; the headings within 120
  // degrees: |u_a + u_b| >= 1.
  const double dot = a.goal_x * b.goal_x + a.goal_y * b.goal_y;
  return (a.goal != b.goal) & (dot > 0) & (dot * dot >= kSameWay * kSameWay * (a.goal2 * b.goal2)) &
         (sx * sx + sy * sy >= 1) & (d != 0);
}

// The goal stage: per row, the preferred velocity pref_speed towards its current target (slower
// when it would overshoot within one tick). On top of it, in this order:
// - a stalemate action in progress (yield or sidestep: StallAction) replaces the direction;
// - an agent frozen nudge_after seconds in a row turns it by a seeded 45-90 degrees;
// - a tiny seeded perturbation (steering.perturbation) breaks exact symmetries.
// Idle (arrived) agents prefer to stand still, unless `demand` (active agents per goal row;
// empty when arrivals do not idle) says others still head for their goal: at a polygon goal they
// walk on into the area towards its inner point (its edge stays free for those coming), at a
// disc goal they step off the disc, away from its centre; both at half their preferred speed.
// An idle agent in the way of another disc goal others still head for (closer to the disc than
// the widest of them needs to reach it) steps off that one the same way (the first in goal order).
// Waypoint following: with `nav` (and skip_visible, every sight interval per agent), an agent whose
// waypoint after the current one is in sight steers at that one and records the skip.
// Lost sight (with `nav`): a walker pushed so that an obstacle stands between it and its target
// (a straight last leg to a far goal, seen past a pillar, then pressed behind it by a crowd)
// presses against the obstacle; the progress watch re-plans it only when it stops getting
// closer, and sliding along the obstacle still gets it closer. So a walker slower than half its
// preferred speed looks kLostSightLook towards its target every kLostSightInterval (staggered by
// id); blocked, it records kLostSight and is re-planned from where it stands.
void goal_stage(const AgentTable& t, std::span<const Goal> goals, const SimConfig& cfg,
                uint64_t tick, std::span<const uint32_t> demand, Preferred& pref, Executor& ex,
                const path::Navigation* nav = nullptr, AimMemo* aims = nullptr);

// Tentative positions from the model's velocities: p' = p + v' dt.
void integrate(const AgentTable& t, NextState& next, double dt, Executor& ex);

// Overlaps among the next-state positions, split into those the backoff must resolve and those
// it tolerates (pairs that overlapped at the start of the tick and did not get deeper).
struct OverlapReport {
  std::size_t agent_pairs = 0;      // all overlapping agent pairs
  std::size_t obstacle_hits = 0;    // all agent-obstacle overlaps (walls are obstacles)
  std::vector<uint32_t> violators;  // rows in a new or deepened overlap, sorted, unique
  bool agents_by_lists = false;     // the model's neighbour lists ruled agent overlaps out
  uint32_t moved_grid_rounds = 0;   // backoff rounds whose moved rows were probed via their grid
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

// Do a steering model's neighbour lists of this tick (`near`, over the start-of-tick rows) show
// that no two agents overlap at their next positions? A row that moves D_i this tick can only
// come to overlap a row whose start lies within r_i + r_j + D_i + D_j of its own (triangle
// inequality), so within need_i = r_i + r_max + 2 D_max (plus a relative 1e-9 for rounding).
// A row whose list bound (NearLists) reaches need_i holds all of them; its listed pairs that near
// are tested. A pair of which one row's list falls short is then tested from the other's side;
// pairs of two such rows (at most 256 of them, else no) are tested one by one. Verlet lists,
// with the tick's moves as the skin. False when not shown: no lists, too many short lists (a
// dense crowd, a fast agent), an overlap, or a position or radius that is not finite.
bool lists_rule_out_overlaps(const AgentTable& t, const NextState& next, const NearLists& near,
                             Executor& ex);

// Backoff (DESIGN.md §3.2): freeze the violators (back to the start position, zero velocity)
// until none is left. Returns the overlaps of the final state (exact counts, and no violators)
// and the number of iterations in `iterations` (1 when nothing had to be frozen).
//
// One full collision query, then only probes: after a freeze, a pair can only become a new
// violation if one of its agents moved, i.e. was frozen in the previous iteration, so iteration
// k+1 asks just for the overlaps of the agents frozen in iteration k (through a DiscGrid over the
// current positions). The frozen sets, iterations and final counts are those of the plain loop
// that re-runs the full query every iteration (backoff_reference; tested equal).
// With `near` lists that rule agent overlaps out (lists_rule_out_overlaps), the full query is
// just its obstacle half: the path would have found no agent pair either.
OverlapReport backoff(const AgentTable& t, NextState& next, const StaticScene& scene,
                      CollisionPath& path, Executor& ex, QueryStats& stats, std::size_t& iterations,
                      const NearLists& near = {});

// The plain loop of DESIGN.md §3.2: find the violators with a full query, freeze them, repeat.
// The oracle for backoff() (tests), and the thesis's algorithm as written.
OverlapReport backoff_reference(const AgentTable& t, NextState& next, const StaticScene& scene,
                                CollisionPath& path, Executor& ex, QueryStats& stats,
                                std::size_t& iterations);

// Hash of the committed state: tick and row count, then per row id, position, velocity and
// state bits. The rows are hashed in blocks of kHashBlock, each block in kHashLanes interleaved
// chains (row r in lane r mod kHashLanes) whose digests fold into the block's; the blocks'
// digests fold in row order. The blocks are fixed, so the hash is the same on any thread count;
// the lanes let one core overlap the chains' multiplies, the blocks let several cores share the
// work (one chain over every row cost 0.2 ms a tick at 2 * 10^4 rows, serial on any thread
// count).
inline constexpr std::size_t kHashBlock = 4096;
inline constexpr std::size_t kHashLanes = 4;
uint64_t state_hash(const AgentTable& t, uint64_t tick, Executor* ex = nullptr);

}  // namespace crowddb::sim
