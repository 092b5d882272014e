// First-to-collide index (DESIGN.md §5, thesis §2.1): a kinetic k-d tree with exact best-first
// search. Registered as the "index" access path of the first-to-collide query.
//
// QUERY. For every disc a: the b != a (agent, circle or polygon) with the smallest t in
// [0, horizon] at which a and b, moving on rays, come closer than r_a + r_b; ties go to agents,
// then circles, then polygons, then the smaller id / row. The answer must equal the naive loop's
// bit for bit, so pair times are computed by ray_disc_time / ray_polygon_time on exactly the
// naive path's inputs, and the index only decides which pairs need computing.
//
// STRUCTURE. A k-d tree over the positions at t = 0: median split of the wider side of the cell,
// leaves of at most leaf_size members (leaf_size_apart once told that no discs overlap,
// assume_no_overlaps), members of a leaf sorted by key (id). The index reads the
// rows through the DiscView and keeps a copy of each member's columns (x, y, v, r, id, row) in
// tree order, so a leaf's members lie together in memory and queries, run in tree order, read
// memory in order; the copies are the rows' own values, so pair times are unchanged. It also
// keeps orderings (tree order, row -> position, position -> leaf) and per-node aggregates:
// kinetic bounds (below), the largest radius, the smallest key, the node's cell (its ancestors'
// split half-planes) and its parent. Built anew every rebuild_every-th tick, and refitted on the
// ticks between (REFIT below).
// Static circles get a tree of their own (zero velocities); polygons are tested one by one
// through their boxes (the naive path's box filter, then the box bound, then ray_polygon_time,
// through the polygon's edge grid where it has many edges); among many polygons, only those in
// the cells of a grid over their boxes that the query's sweep box meets (then the walls).
//
// INVARIANT (kinetic bounds). For every node, every member b and every t in [0, horizon]:
// p_b + v_b t lies in the node's box B(t), inflated by delta(t) = delta0 + delta1 t.
//   chord (default): the members' bounding boxes at K + 1 knots t_j = j horizon / K, linearly
//     interpolated on each slice [t_j, t_j+1]. It holds because each member moves linearly: on a
//     slice its position is the same interpolation of its knot positions, which lie in the knot
//     boxes. Internal nodes take min/max of their children's knot boxes.
//   frustum (the thesis's, used when the horizon is 0 or infinite): the t = 0 box whose edges
//     move at the members' velocity bounds, [lo + vx_min t, hi + vx_max t]; valid for all t >= 0.
// The chord box is never wider than the frustum (min of sums >= sum of mins) and is exact at the
// knots.
//
// BOUND. A member can touch a at time t only if the centre distance is < r_a + r_b <= R =
// r_a + r_max (node), so the Chebyshev distance of B(t) to a's centre p_a + v_a t must be <= R.
// In a's frame every edge of B(t) is a line in t on each slice (a's velocity subtracted from the
// edge's slope): four linear inequalities give an interval of t per slice, and the earliest t of
// the first non-empty interval in [0, min(horizon, best)] is the node's bound: a true lower bound
// on every member's pair time. Rejection needs only multiplications; within reach at the slice
// start (the common case near the query) costs four comparisons. The four edges are computed two
// at a time, x and y in the lanes of a vector, and an agent leaf's pair times several at a time
// (`lanes`; the scalar versions are kept as the reference, and the tests check that the two give
// the same bounds, times and search bit for bit).
//
// FLOATING POINT. The bound must stay below the pair time that ray_disc_time computes, rounding
// included. For near-grazing pairs that time carries a position error of order sqrt(eps) M,
// M = |d| + |w| t + R; the boxes are inflated by delta(t) = kappa (M0 + V t), kappa = 1e-6,
// with M0 >= 2 (extent of all positions) + 2 (largest radii) and V >= every |v_b - v_a|. That
// also covers the rounding of the knot positions, slopes and bound arithmetic, all relative to
// these magnitudes because boxes are stored relative to a local origin (so 10^6 offsets cost
// nothing). validate() checks the containment at the knots and mid-slices.
//
// SEARCH AND TIES. The answer so far is ordered by (time, kind, key, row). A node is skipped only
// when the answer STRICTLY precedes (bound, kind, min_key) of the node: a node whose bound equals
// the best time may still hold an equal-time member with a smaller id. The queue is ordered by
// (bound, min_key) and the search stops when its smallest entry is skipped (nothing later can
// win). Order (leaf_queue, default): (1) overlaps first (skipped once told that no discs overlap):
// an agent overlapping a now wins outright (time 0, agents first), and finding the smallest such
// (id, row) needs only t = 0 tests: at the E1 density ~90% of agents end here. It runs
// set-at-a-time, leaf by leaf (overlap_join): a walk from the root collects the members of every
// leaf whose t = 0 box lies within Chebyshev distance r_max(leaf) + r_max(other) of the leaf's box,
// keeping those within r_max(leaf) + r_b of it (the boxes carry the delta0 inflation, so rounding
// cannot drop an overlapping member); then every member of the leaf is tested against all of them
// with ray_disc_time's own overlap term (c = |d|^2 - R^2 < 0, the same expression, so the same
// bits) in a loop the compiler vectorizes, and the overlapping ones (a few) are compared by (id,
// row). Queries run in tree order, so the join runs once per leaf (~37 tests per agent at the E1
// density, no queue, no unpredictable branches). With overlap_join off, the same answer comes from
// the tree search below with t = 0 bounds. (2) otherwise a's own leaf is scanned (its neighbours
// give an early best time), then the path is walked up to the root: each sibling's bound goes into
// the queue; the walk stops once every position from which a member could still reach a before the
// best time (a's centre
// +- R_max + (|v_a| + v_max) cap per axis) lies strictly inside the cell below: all other members
// lie outside that cell. (3) The queue is searched in bound order, descending into the child with
// the smaller bound and queueing the other. Any visiting order is exact; the order only changes
// the work. Leaves stop scanning at the first key that cannot win any more.
//
// COMPLEXITY. Build O(n log n): a median split per level; large ranges are first cut by two
// sample quantiles bracketing the median in one branch-free pass, and only the middle part goes to
// nth_element (whose comparisons are unpredictable branches); plus O(n K) for the kinetic
// bounds. On several threads (from 4,096 members) the top levels are split on the calling thread
// and the subtrees below them built at once: every node's number is known in advance (preorder,
// and the shape depends only on the sizes), so the tree is the one a single thread builds
// (test: FtcIndex.TreeBuiltOnThreadsIsTheSame). Memory O(n / leaf * K) aggregates, the members'
// copy (56 bytes each) and three arrays of n ints. The overlap join costs O(leaf) tests per agent
// at a fixed density. A query costs O(log n) node visits when a collision is found nearby (the
// usual case); in the worst case (no collision within the horizon and bounds that cannot prune,
// e.g. sparse worlds with fast random velocities, whose nodes all carry the full velocity spread)
// it is O(n), as the naive loop. Splitting velocities as well as positions (a 4-d tree) was tried
// and measured, and dropped: on uniform worlds with radius 0.1-0.3, n = 1,000 on 640 x 480, it cut
// pair tests per query from 524 to 332 at best, but at the E1 density (n = 15,000, radius 1-3) it
// raised them from 18 to 53-580 (position locality is what finds the overlapping neighbours).
//
// REFIT. Between builds the agent tree keeps its nodes and the rows in them and recomputes the
// members' copies and every node's kinetic bounds from the rows as they are now: O(n K), in
// chunks of leaves on every thread, then the parents. The invariant and the bound hold as after
// a build (they only ask that the boxes contain the members). The cells do not: a member of
// another subtree may have walked into a cell since the build, by at most the largest move of
// any member since then (per axis, drift_x and drift_y), so the bottom-up walk stops only where
// the reach box lies inside the cell shrunk by that much. The frame keeps the build's origin
// (the boxes and cells are relative to it), with M0 grown by four times its distance from the
// new centre. Only the search's cost changes with the tree's shape: the answers are the same,
// refitted or built. A table whose rows are not the build's (another count, another id in a
// member's place: inserts, removals, reordered rows), another leaf size, another number of knots
// or another kind of bound (chord or frustum) gets a build; a new horizon with as many knots is
// refitted (the bounds are recomputed at the new knots).
//
// THE BIG CRUNCH (thesis §4.1: its index was worse than naive there). Every agent heads for the
// centre c and arrives at t = A: v_b = (c - p_b) / A, so relative to a every other agent moves
// as d_b (1 - t / A) and the first collision time A (1 - (r_a + r_b) / |d_b|) is close to A for
// everyone when radii are small against the spacing. A node at relative distance D with extent W
// (along the approach) has relative velocities in [-(D + W) / A, -D / A]: the frustum moves its
// near edge at the FASTEST member's speed while the node itself shrinks, so its bound is
// A (D - R) / (D + W), below the best time A (1 - R / d_nn) for nearly every node with W / D above
// R / d_nn: large nodes near and far are all opened, and best-first from the root with a loose
// bound pops every node (O(n) per query, O(n^2 log n) in all). The chord bound is exact at the
// knots: in the Big Crunch each node's member box at time t is exactly its t = 0 box shrunk
// towards c (positions are affine in t for the whole node), so with knots the bound is close to
// A (1 - R / dist(box)): a nearest-neighbour search in disguise, pruning as well as a k-d tree
// does. Starting at a's own leaf gives a near-final best time at once, so the far nodes are cut
// at the top. The perturbed crunch (±1 per velocity component) only adds the perturbation's
// spread (|dv| t) to the boxes. More slices tighten the bound between knots (K = 4 by default).
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "plan/access_path.hpp"

namespace crowddb {

struct FtcIndexOptions {
  std::size_t leaf_size = 16;  // most members in a leaf (>= 1)
  // How a node bounds where its members can be at a time t in [0, horizon].
  enum class Bound : uint8_t {
    frustum,  // the thesis's: the t = 0 box, its edges moving at the members' velocity bounds
    chord,    // boxes of the members' positions at K + 1 knot times, linearly interpolated
  };
  Bound bound = Bound::chord;
  int slices = 4;  // chord: K, the number of equal time slices over [0, horizon] (>= 1)
  // Search order. All are exact; they differ in the work done before the answer is certain.
  enum class Order : uint8_t {
    best_first,    // from the root, every child through the queue (the thesis's algorithm)
    nearer_first,  // from the root, descend into the child with the smaller bound, queue the other
    bottom_up,     // from the query's own leaf up: each sibling of the path, nearest first,
                   // searched nearer-first (the query's neighbours fix an early best time)
    leaf_queue,    // from the query's own leaf up: the siblings of the path go into the queue,
                   // which is then searched nearer-first in bound order
  };
  Order order = Order::leaf_queue;
  bool seed_own_leaf = true;   // top-down orders: scan the query's own leaf first
  bool overlaps_first = true;  // first look only for agents overlapping the query now (t = 0)
  // overlaps_first: find them leaf by leaf, all members of a leaf against the members of the
  // leaves within reach (set-at-a-time); false: by the tree search in `order` (t = 0 bounds).
  bool overlap_join = true;
  // The bounds' edges two at a time and an agent leaf's pair times several at a time, in the
  // lanes of a vector; false: one by one (the reference the tests compare with: the same bounds
  // and times bit for bit, so the same search).
  bool lanes = true;
  // Most members in an agent leaf when told that no discs overlap (assume_no_overlaps): then the
  // overlap join, whose cost grows with the leaf, does not run, and larger leaves trade node
  // bounds (branchy, one at a time) for pair times (in lanes, several at a time). The thesis
  // model's first-to-collide query on ticks without overlaps, airport at 2,000 / 5,000 /
  // 20,000 / 100,000 agents, ms per tick against leaf_size 16: 32 -12 / -15 / -18 / -13 %,
  // 48 -11 / -18 / -21 / -11 %, 64 -5 / -13 / -19 / -11 % (docs/bench/journal.md).
  std::size_t leaf_size_apart = 48;
  // The agent tree is built anew on every rebuild_every-th build (run), and in between refitted:
  // the same nodes over the same rows, their bounds recomputed from where the rows are now, no
  // median splits. Only while the table holds the same rows with the same ids, and the leaf size,
  // the number of knots and the kind of bound stay (else it is built); 1: built every time. The
  // tree drifts from the positions' medians, so the searches open a little more (pair tests +1 % at
  // 5, +3 % at 10) while the builds cost a third. Thesis model, airport-20k, first-to-collide
  // against 1: 30 ticks -6 % at 5 and at 10, -4 % at 20; 100 ticks -3 % at 5 and at 10 (within the
  // noise of each other); airport-2k, 100 ticks, -7 % at 10 (docs/bench/journal.md).
  uint64_t rebuild_every = 10;
};

// Thread-safety: build() and query() change the index (one caller at a time); query_all() may
// run on many threads of the executor and gives the same answer on any number of them.
class FtcIndex final : public FtcPath {
 public:
  explicit FtcIndex(FtcIndexOptions options = {});
  ~FtcIndex() override;
  FtcIndex(const FtcIndex&) = delete;
  FtcIndex& operator=(const FtcIndex&) = delete;

  // build() then query_all(); fills stats.build_seconds and stats.query_seconds.
  void run(const DiscView& discs, const StaticScene& scene, double horizon, std::span<FtcHit> out,
           Executor& ex, QueryStats& stats) override;
  // With the hint (FtcPath::assume_no_overlaps), the trees built from then on have agent leaves
  // of up to leaf_size_apart members, and the queries skip `overlaps_first`, which would find
  // nothing (every option is exact, so a wrong hint costs time only). The thesis model gives
  // it on ticks that start without overlaps (airport-20k: the overlap join was 3-4 % of the
  // query's time there).
  bool assume_no_overlaps(bool yes) override;

  // The two halves of run(), for tests, benchmarks and experiments. The index keeps pointers
  // into `discs` and `scene`: they must stay alive and unchanged while it is queried.
  // Throws Error(input) naming the row and column when a disc has a non-finite value.
  // With `ex`, large trees are built on its threads (the same tree, node for node); one build
  // per index at a time, which may run inside a task of Executor::both or a loop's body.
  void build(const DiscView& discs, const StaticScene& scene, double horizon,
             Executor* ex = nullptr);
  // out[i] for every disc i; deterministic whatever the executor's thread count.
  void query_all(std::span<FtcHit> out, Executor& ex, QueryStats& stats) const;
  // One disc's answer; adds its counters (rows, pair_tests, nodes_visited, queue pushes and
  // pops) to *stats. Not thread-safe (uses the index's own scratch space).
  FtcHit query(std::size_t row, QueryStats* stats = nullptr) const;

  // Whole-structure check: ranges partition the rows, every member lies inside its node's
  // bounds at every knot time, radii and keys are bounded. "" when all hold, else the first
  // violation.
  std::string validate() const;
  std::size_t node_count() const;  // agent tree
  bool refitted() const;           // the last build refitted the agent tree (rebuild_every)
  bool uses_chord_bound() const;   // false: fell back to frustum (horizon 0 or infinite)
  const FtcIndexOptions& options() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace crowddb
