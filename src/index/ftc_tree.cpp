// The kinetic k-d tree of first-to-collide. The design (invariant, bound, complexity, why the
// Big Crunch does not degrade) is in ftc_tree.hpp.
#include "index/ftc_tree.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>
#include <mutex>
#include <numeric>
#include <type_traits>
#include <vector>
#include <xsimd/xsimd.hpp>

#include "crowddb/error.hpp"
#include "index/ftc_pair_lanes.hpp"
#include "query/ftc_geometry.hpp"
#include "util/cpu.hpp"
#include "util/executor.hpp"
#include "util/stopwatch.hpp"
#include "world/box_grid.hpp"

namespace crowddb {

namespace ftc {
#if CROWDDB_FTC_AVX2 && !XSIMD_WITH_AVX2
#define CROWDDB_FTC_DISPATCH 1
// ftc_pair_lanes_avx2.cpp: the lanes of AVX2, for a build whose own instruction set is narrower.
uint32_t pair_times_lanes_avx2(const Columns& m, uint32_t n, const Query& q, double horizon,
                               double* out, double& earliest);
#endif

bool pair_times_avx2() {
#if CROWDDB_FTC_DISPATCH
  return cpu_has_avx2();
#else
  return false;
#endif
}

double pair_times(const Columns& m, uint32_t n, const Query& q, double horizon, double* out,
                  Lanes lanes) {
  double earliest = INFINITY;
#if CROWDDB_FTC_DISPATCH
  uint32_t k = pair_times_avx2() && lanes == Lanes::widest
                   ? pair_times_lanes_avx2(m, n, q, horizon, out, earliest)
                   : pair_times_lanes<xsimd::default_arch>(m, n, q, horizon, out, earliest);
#else
  (void)lanes;  // the build's lanes are the widest there are
  uint32_t k = pair_times_lanes<xsimd::default_arch>(m, n, q, horizon, out, earliest);
#endif
  for (; k < n; ++k) {  // the tail, one at a time (AgentSource::time's expression)
    out[k] = ray_disc_time(m.x[k] - q.x, m.y[k] - q.y, m.vx[k] - q.vx, m.vy[k] - q.vy, q.r + m.r[k],
                           horizon);
    earliest = std::min(earliest, out[k]);
  }
  return earliest;
}
}  // namespace ftc

namespace {

using Kind = Collider::Kind;

// Relative slack of the bounds against rounding (see "Floating point" in ftc_tree.hpp). The pair
// times carry errors of order sqrt(eps) * M in position for near-grazing pairs; 1e-6 leaves a
// margin of more than ten.
constexpr double kSlack = 1e-6;
constexpr uint32_t kNoRow = std::numeric_limits<uint32_t>::max();
// From this many members a tree's subtrees are built on every thread (below, the threads'
// start-up costs more than they save).
constexpr uint32_t kParallelBuild = 4096;

// The time axis every tree of one build shares.
struct Frame {
  double ox = 0, oy = 0;      // local origin: node boxes are stored relative to it
  std::vector<double> knots;  // chord: 0 = t_0 < ... < t_K = horizon; frustum: {0, +inf}
  bool chord = true;
  double delta0 = 0, delta1 = 0;  // every node box is inflated by delta0 + delta1 * t
  bool lanes = true;  // slice_bound_lanes and lanes_pair_times (else the scalar references)
  int slices() const { return static_cast<int>(knots.size()) - 1; }
};

// A node's bounds on one time slice [t_j, t_j+1]: its members lie in
// [lo + slo (t - t_j), hi + shi (t - t_j)] per axis (frame coordinates, inflated).
struct Slice {
  double lo_x, lo_y, hi_x, hi_y;
  double slo_x, slo_y, shi_x, shi_y;
};

struct TreeNode {
  double rmax;          // largest member radius
  uint64_t min_key;     // smallest member key (agent id or obstacle row)
  uint32_t begin, end;  // members: perm[begin, end)
  uint32_t right;       // right child; the left child is this node + 1; 0 for a leaf
  uint32_t parent;      // kNoRow for the root
  bool leaf() const { return right == 0; }
};

// A node's cell: the split half-planes of its ancestors, cut down to the root's bounding box
// (frame coordinates, at t = 0). Every member outside the subtree lies outside its interior.
struct Cell {
  double x0, y0, x1, y1;
};

// The probe: the query disc, raw (for the exact pair times) and in frame coordinates (bounds).
struct Probe {
  double ax, ay, avx, avy, ar;  // the query row's columns, untouched
  double fx, fy;                // position in the frame
  uint32_t self;                // own row in the agent tree, or kNoRow
};

// The running answer, ordered lexicographically by (time, kind, key, row): the naive loop keeps
// the first of equal (time, kind, key) in row order, i.e. the smallest row.
struct Best {
  double t = INFINITY;
  Kind kind = Kind::none;
  uint64_t key = 0;
  uint32_t row = 0;

  void offer(double time, Kind k, uint64_t key2, uint32_t row2) {
    if (time == INFINITY) return;
    if (kind == Kind::none || precedes(time, k, key2, t, kind, key) ||
        (time == t && k == kind && key2 == key && row2 < row))
      *this = {time, k, key2, row2};
  }
  // True when every candidate (time >= b, kind k, key >= min_key) loses to the answer so far.
  bool beats(double b, Kind k, uint64_t min_key) const {
    return kind != Kind::none && precedes(t, kind, key, b, k, min_key);
  }
};

struct Counters {
  uint64_t pair_tests = 0, visited = 0, pushes = 0, pops = 0;
};

struct Entry {
  double bound;
  uint64_t key;
  uint32_t node;
};
// std heap functions build a max-heap: "less" means "later".
struct Later {
  bool operator()(const Entry& a, const Entry& b) const {
    return a.bound != b.bound ? a.bound > b.bound : a.key > b.key;
  }
};

// The bound on one slice: the first t in [t0, t0 + span] at which the box comes within
// Chebyshev distance R of the probe's centre, or +inf. (qx, qy): the probe's centre at t0. The
// four edges are lines in t in the probe's frame; an edge outside reach must close its gap within
// the slice, an edge inside must not leave before the others arrive. Rejection needs no division.
inline double slice_bound(const Slice& b, double qx, double qy, const Probe& q, double R, double t0,
                          double span) {
  const double p[4] = {b.lo_x - qx, qx - b.hi_x, b.lo_y - qy, qy - b.hi_y};
  // Common case first: within reach already at the slice start.
  if (p[0] <= R && p[1] <= R && p[2] <= R && p[3] <= R) return t0;
  const double v[4] = {b.slo_x - q.avx, q.avx - b.shi_x, b.slo_y - q.avy, q.avy - b.shi_y};
  bool ok = true;
  for (int e = 0; e < 4; ++e)
    if (p[e] > R && (!(v[e] < 0) || p[e] - R > span * -v[e])) ok = false;
  if (!ok) return INFINITY;
  double lo = 0;
  for (int e = 0; e < 4; ++e)
    if (p[e] > R) lo = std::max(lo, (p[e] - R) / -v[e]);
  for (int e = 0; e < 4; ++e)
    if (p[e] <= R && v[e] > 0 && p[e] + v[e] * lo > R) ok = false;
  return ok && lo <= span ? t0 + lo : INFINITY;
}

// Two doubles, and two lane masks, in one register (GCC's and clang's vector extensions; SSE2 on
// x86-64).
typedef double V2d __attribute__((vector_size(16)));
typedef int64_t V2m __attribute__((vector_size(16)));

// slice_bound with the x and the y edges side by side in the lanes of a vector: the same
// operations on the same operands, so the same bound bit for bit, without a branch per edge
// (whether an edge is within reach is a coin toss to the predictor). The lanes of `lo`: edges
// 0 and 2 (the box's low sides), of `hi`: edges 1 and 3.
inline double slice_bound_lanes(const Slice& b, double qx, double qy, const Probe& q, double R,
                                double t0, double span) {
  V2d lo, hi, slo, shi;
  __builtin_memcpy(&lo, &b.lo_x, sizeof lo);  // lo_x, lo_y
  __builtin_memcpy(&hi, &b.hi_x, sizeof hi);  // hi_x, hi_y
  __builtin_memcpy(&slo, &b.slo_x, sizeof slo);
  __builtin_memcpy(&shi, &b.shi_x, sizeof shi);
  const V2d at = {qx, qy}, av = {q.avx, q.avy};
  const V2d pl = lo - at, ph = at - hi;
  const V2m out_l = pl > R, out_h = ph > R;
  const V2m out = out_l | out_h;
  if (!(out[0] | out[1])) return t0;
  const V2d vl = slo - av, vh = av - shi;
  const V2m bad =
      (out_l & (~(vl < 0) | (pl - R > span * -vl))) | (out_h & (~(vh < 0) | (ph - R > span * -vh)));
  if (bad[0] | bad[1]) return INFINITY;
  const V2d zero = {0, 0};
  const V2d tl = out_l ? (pl - R) / -vl : zero, th = out_h ? (ph - R) / -vh : zero;
  // In edge order from 0, as slice_bound takes it (a NaN quotient, of infinities, is passed
  // over the same way; a lane within reach holds 0, which changes nothing).
  const double t = std::max(std::max(std::max(std::max(0.0, tl[0]), th[0]), tl[1]), th[1]);
  const V2m leave =
      ((pl <= R) & (vl > 0) & (pl + vl * t > R)) | ((ph <= R) & (vh > 0) & (ph + vh * t > R));
  return !(leave[0] | leave[1]) && t <= span ? t0 + t : INFINITY;
}

// Earliest t in [0, tcap] at which the node's box comes within reach of the probe, or +inf: a
// lower bound on every member's pair time with radius sum <= R. s[j * stride]: the slice j.
template <bool Lanes>
double node_bound(const Slice* s, std::size_t stride, const Frame& f, const Probe& q, double R,
                  double tcap) {
  const auto bound = [&](const Slice& b, double qx, double qy, double t0, double span) {
    if constexpr (Lanes)
      return slice_bound_lanes(b, qx, qy, q, R, t0, span);
    else
      return slice_bound(b, qx, qy, q, R, t0, span);
  };
  const int K = f.slices();
  if (K == 1) return bound(s[0], q.fx, q.fy, 0, std::min(f.knots[1], tcap));
  for (int j = 0; j < K; ++j) {
    const double t0 = f.knots[j];
    if (t0 > tcap) break;
    const double qx = j == 0 ? q.fx : q.fx + q.avx * t0;
    const double qy = j == 0 ? q.fy : q.fy + q.avy * t0;
    const double t = bound(s[static_cast<std::size_t>(j) * stride], qx, qy, t0,
                           std::min(f.knots[j + 1], tcap) - t0);
    if (t != INFINITY) return t;
  }
  return INFINITY;
}

inline double node_bound(const Slice* s, std::size_t stride, const Frame& f, const Probe& q,
                         double R, double tcap) {
  return f.lanes ? node_bound<true>(s, stride, f, q, R, tcap)
                 : node_bound<false>(s, stride, f, q, R, tcap);
}

// ------------------------------------------------------------------- member sources

using Member = ftc::Member;  // (index/ftc_pair_lanes.hpp)

// An agent leaf's pair times several at a time (scan below), up to this many members; larger
// leaves (leaf_size and leaf_size_apart are options) are scanned one by one.
constexpr uint32_t kLaneLeaf = 64;

struct ProbeScratch {
  std::vector<Entry> heap;
  // The overlap phase of one leaf of the agent tree (see leaf_overlaps()): its candidates'
  // columns, a per-candidate buffer, and each member's answer (a row, or kNoRow).
  std::vector<double> cx, cy, cr, cc;
  std::vector<uint32_t> cpos, pick, hit;  // candidates' positions in tree order
  uint32_t leaf = kNoRow;
  std::size_t ncand = 0;           // candidates of that leaf (the member itself included)
  bool crowded = false;            // more than the join's cap: that leaf uses the tree search
  uint64_t join_visited = 0;       // nodes its walk visited
  std::vector<uint32_t> polygons;  // the polygons whose box may meet the query's sweep
};

struct AgentSource {
  static constexpr Kind kind = Kind::agent;
  const DiscView* d = nullptr;
  std::size_t size() const { return d->n; }
  double x(uint32_t i) const { return d->x[i]; }
  double y(uint32_t i) const { return d->y[i]; }
  double vx(uint32_t i) const { return d->vx[i]; }
  double vy(uint32_t i) const { return d->vy[i]; }
  double r(uint32_t i) const { return d->radius[i]; }
  uint64_t key(uint32_t i) const { return d->id[i]; }
  // Exactly the naive path's expressions (ftc_naive.cpp, ray_disc_time), so times are
  // bit-identical: overlaps() is ray_disc_time's own test for time 0.
  static bool overlaps(const Probe& a, const Member& b) {
    const double dx = b.x - a.ax, dy = b.y - a.ay, R = a.ar + b.r;
    return dx * dx + dy * dy - R * R < 0;
  }
  static double time(const Probe& a, const Member& b, double horizon) {
    return ray_disc_time(b.x - a.ax, b.y - a.ay, b.vx - a.avx, b.vy - a.avy, a.ar + b.r, horizon);
  }
};

// ray_disc_time of the query against members m[0, n), several at a time in lanes (AVX2's four
// where the CPU has them and the build's own set is narrower, else the build's): the same bits as
// AgentSource::time (index/ftc_pair_lanes.hpp).
double lanes_pair_times(const ftc::Columns& m, uint32_t n, const Probe& q, double horizon,
                        double* out) {
  return ftc::pair_times(m, n, {q.ax, q.ay, q.avx, q.avy, q.ar}, horizon, out);
}

struct CircleSource {
  static constexpr Kind kind = Kind::circle;
  std::span<const CircleObstacle> c;
  std::size_t size() const { return c.size(); }
  double x(uint32_t i) const { return c[i].x; }
  double y(uint32_t i) const { return c[i].y; }
  double vx(uint32_t) const { return 0; }
  double vy(uint32_t) const { return 0; }
  double r(uint32_t i) const { return c[i].radius; }
  uint64_t key(uint32_t i) const { return i; }
  static bool overlaps(const Probe& a, const Member& b) {
    const double dx = b.x - a.ax, dy = b.y - a.ay, R = a.ar + b.r;
    return dx * dx + dy * dy - R * R < 0;
  }
  static double time(const Probe& a, const Member& b, double horizon) {
    return ray_disc_time(b.x - a.ax, b.y - a.ay, -a.avx, -a.avy, a.ar + b.r, horizon);
  }
};

// c[j] = ray_disc_time's overlap term for the query (ax, ay, ar) against candidate j, exactly
// the naive path's expression, in a loop the compiler vectorizes (IEEE operations lane by lane
// give the same bits; -ffp-contract=off keeps them unfused). Returns how many are < 0.
double overlap_terms(const double* __restrict x, const double* __restrict y,
                     const double* __restrict r, double* __restrict c, std::size_t n, double ax,
                     double ay, double ar) {
  double hits = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const double dx = x[j] - ax, dy = y[j] - ay, R = ar + r[j];
    c[j] = dx * dx + dy * dy - R * R;
    hits += c[j] < 0 ? 1.0 : 0.0;
  }
  return hits;
}

// ------------------------------------------------------------------- the tree

template <class Src>
class KineticTree {
 public:
  // With `ex` (more than one thread, kParallelBuild members or more), the subtrees below the top
  // levels are built on its threads: the same tree, node for node.
  void build(const Src& src, const Frame& f, std::size_t leaf_size, Executor* ex = nullptr);
  // The tree of the last build over `src` as it is now: the same members in the same nodes,
  // their columns copied anew and every node's bounds recomputed (O(n K), no splits). Only when
  // `src` holds the same rows with the same keys, the leaf size, the frame's number of knots and
  // its kind of bound are the build's, and the frame keeps the build's origin; else false, nothing
  // changed, and the caller builds. The cells are the build's: members have moved off them since by
  // at most drift_x_ / drift_y_, which the walk's stop test allows for.
  bool refit(const Src& src, const Frame& f, std::size_t leaf_size, Executor* ex = nullptr);
  using Order = FtcIndexOptions::Order;
  // Adds this tree's members to `best`. self_pos: the query's position in tree order (it is
  // skipped as a member, and its leaf is scanned first), or kNoRow.
  // OverlapOnly: only the members that overlap the query now (pair time 0) count; the bounds
  // and the pair tests shrink to the t = 0 checks (see "Overlaps first" in ftc_tree.hpp).
  template <bool OverlapOnly>
  void search(const Probe& q, double horizon, Best& best, ProbeScratch& sc, Counters& c,
              Order order, uint32_t self_pos, bool seed) const;
  std::string validate(const Frame& f) const;
  // The overlap phase for all members of `leaf` at once: sc.hit[i] is the row of the smallest
  // (key, row) member overlapping member begin + i at t = 0, or kNoRow. The candidates are the
  // members of every leaf whose t = 0 box comes within reach of `leaf`'s (Chebyshev gap <= the
  // two leaves' largest radii summed): every member that can overlap is among them.
  void leaf_overlaps(uint32_t leaf, ProbeScratch& sc) const;

  bool empty() const { return nodes_.empty(); }
  double built_ox() const { return built_ox_; }
  double built_oy() const { return built_oy_; }
  std::size_t node_count() const { return nodes_.size(); }
  const std::vector<uint32_t>& perm() const { return perm_; }
  uint32_t pos_of(uint32_t row) const { return pos_of_[row]; }
  uint32_t leaf_at(uint32_t pos) const { return leaf_at_[pos]; }
  const Member& member(uint32_t pos) const { return items_[pos]; }
  uint32_t leaf_begin(uint32_t leaf) const { return nodes_[leaf].begin; }

 private:
  using Item = Member;
  // Raw (uninflated) bounds during the build: K + 1 knot boxes, or box + velocity bounds.
  struct Raw {
    double lo_x, lo_y, hi_x, hi_y;
  };
  // A median split's scratch (select_median): one per thread building.
  struct Split;
  // Builds the subtree of pts_[b, e) rooted at node idx, its nodes numbered in preorder from
  // idx (the left child is idx + 1); returns the number after its last node.
  uint32_t build_node(uint32_t idx, uint32_t b, uint32_t e, uint32_t parent, Cell cell, Split& sc);
  // A subtree left to build_node on some thread.
  struct Subtree {
    uint32_t idx, b, e, parent;
    Cell cell;
  };
  // The top `depth` levels of the subtree of pts_[b, e) rooted at idx, on the calling thread:
  // the splits go to `top` (their bounds are merged once the subtrees below are built), the
  // subtrees below them to `below`.
  void build_top(uint32_t idx, uint32_t b, uint32_t e, uint32_t parent, Cell cell, int depth,
                 std::vector<Subtree>& below, std::vector<uint32_t>& top);
  // Splits pts_[b, e) at its median along the wider side of `cell`: returns the first member of
  // the right half; the two halves' cells.
  uint32_t split(uint32_t b, uint32_t e, const Cell& cell, Split& sc, Cell& lc, Cell& rc);
  // Nodes of the tree over n members (median splits until at most leaf_size_ remain).
  std::size_t count_nodes(std::size_t n) const {
    return n <= leaf_size_ ? 1 : 1 + count_nodes(n / 2) + count_nodes(n - n / 2);
  }
  void leaf_bounds(uint32_t node);
  void merge_bounds(uint32_t node, uint32_t l, uint32_t r);
  void finish_bounds(uint32_t node);
  template <bool OverlapOnly>
  void scan(uint32_t node, const Probe& q, double horizon, Best& best, Counters& c) const;

  const Src* src_ = nullptr;
  const Frame* f_ = nullptr;
  std::size_t leaf_size_ = 8;
  std::vector<TreeNode> nodes_;
  // Slice j of node k at [j * nodes + k]: slice 0 of all nodes (the one most searches need)
  // lies together.
  std::vector<Slice> slices_;
  std::size_t stride_ = 0;         // number of nodes
  std::vector<uint32_t> perm_;     // rows in tree order
  std::vector<uint32_t> pos_of_;   // row -> its position in perm_
  std::vector<uint32_t> leaf_at_;  // position in perm_ -> its leaf
  std::vector<Cell> cells_;        // per node
  // Reach of any member: largest radius and speeds per axis (for the bottom-up walk's stop).
  double reach_r_ = 0, reach_vx_ = 0, reach_vy_ = 0;
  // Since the build: the farthest any member moved along x and along y (refit), and the
  // members' positions then (raw coordinates, tree order).
  double drift_x_ = 0, drift_y_ = 0;
  std::vector<double> built_x_, built_y_;
  std::vector<uint32_t> leaves_;  // refit's scratch: the leaves' node numbers
  double built_ox_ = 0, built_oy_ = 0;
  std::size_t built_knots_ = 0;
  bool built_chord_ = false;
  std::vector<Item> items_;  // the members in tree order (copied from the source at the leaves)
  // Their x, y, vx, vy and r again, column by column (n each, in that order), for the lanes.
  std::vector<double> cols_;
  ftc::Columns columns() const {
    const double* p = cols_.data();
    const std::size_t n = items_.size();
    return {p, p + n, p + 2 * n, p + 3 * n, p + 4 * n};
  }
  // build scratch: the positions the median splits partition (small, so they move cheaply)
  struct Pt {
    double x, y;  // the source's values (x - ox is monotone in x: raw order is frame order)
    uint32_t row;
  };
  std::vector<Pt> pts_;
  struct Split {
    std::vector<Pt> lohi, middle;
  };
  std::vector<Split> splits_;  // one per subtree built at once
  // Rearranges pts_[b, e) as std::nth_element does at position k, by coordinate C.
  template <double Pt::*C>
  void select_median(uint32_t b, uint32_t e, uint32_t k, Split& sc);
  // (K + 1) per node (chord) or 2 per node (frustum: box, velocity box). Only the build reads
  // them; kept from build to build, as splits_ is, so that its memory is not touched anew.
  std::vector<Raw> raw_;
};

template <class Src>
void KineticTree<Src>::build(const Src& src, const Frame& f, std::size_t leaf_size, Executor* ex) {
  src_ = &src;
  f_ = &f;
  leaf_size_ = std::max<std::size_t>(leaf_size, 1);
  nodes_.clear();
  slices_.clear();
  raw_.clear();
  const auto n = static_cast<uint32_t>(src.size());
  perm_.resize(n);
  pos_of_.resize(n);
  leaf_at_.resize(n);
  cells_.clear();
  if (n == 0) return;
  items_.resize(n);
  cols_.resize(5 * std::size_t{n});
  pts_.resize(n);
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  for (uint32_t i = 0; i < n; ++i) {
    pts_[i] = {src.x(i), src.y(i), i};
    x0 = std::min(x0, pts_[i].x);
    x1 = std::max(x1, pts_[i].x);
    y0 = std::min(y0, pts_[i].y);
    y1 = std::max(y1, pts_[i].y);
  }
  // Frame coordinates (x - ox is monotone in x, so orders by raw x are orders by frame x).
  const Cell root{x0 - f.ox, y0 - f.oy, x1 - f.ox, y1 - f.oy};
  // Every node has its place before it is built (preorder; the sizes fix the shape), so
  // subtrees can be built at once.
  stride_ = count_nodes(n);
  nodes_.resize(stride_);
  cells_.resize(stride_);
  slices_.resize(stride_ * static_cast<std::size_t>(f.slices()));
  raw_.resize(stride_ * (f.chord ? f.knots.size() : 2));
  const int threads = ex ? ex->threads() : 1;
  if (splits_.empty()) splits_.resize(1);
  if (threads > 1 && n >= kParallelBuild) {
    // The top levels here (the first split alone is a tenth of the work at 2 * 10^4), then
    // at least two subtrees per thread.
    int depth = 1;
    while ((1 << depth) < 2 * threads) ++depth;
    std::vector<Subtree> below;
    std::vector<uint32_t> top;
    build_top(0, 0, n, kNoRow, root, depth, below, top);
    if (splits_.size() < below.size()) splits_.resize(below.size());
    ex->for_each_chunk(below.size(), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t k = b; k < e; ++k) {
        const Subtree& t = below[k];
        [[maybe_unused]] const uint32_t end =
            build_node(t.idx, t.b, t.e, t.parent, t.cell, splits_[k]);
        assert(end == t.idx + count_nodes(t.e - t.b));
      }
    });
    for (auto it = top.rbegin(); it != top.rend(); ++it) {  // children before their parents
      merge_bounds(*it, *it + 1, nodes_[*it].right);
      finish_bounds(*it);
    }
  } else {
    [[maybe_unused]] const uint32_t end = build_node(0, 0, n, kNoRow, root, splits_[0]);
    assert(end == stride_);
  }
  for (uint32_t i = 0; i < n; ++i) perm_[i] = items_[i].row;
  for (uint32_t i = 0; i < n; ++i) pos_of_[perm_[i]] = i;
  built_x_.resize(n);
  built_y_.resize(n);
  for (uint32_t i = 0; i < n; ++i) {
    built_x_[i] = items_[i].x;
    built_y_[i] = items_[i].y;
  }
  drift_x_ = drift_y_ = 0;
  built_ox_ = f.ox;
  built_oy_ = f.oy;
  built_knots_ = f.knots.size();
  built_chord_ = f.chord;
  for (uint32_t k = 0; k < nodes_.size(); ++k)
    if (nodes_[k].leaf())
      for (uint32_t i = nodes_[k].begin; i < nodes_[k].end; ++i) leaf_at_[i] = k;
  reach_r_ = nodes_[0].rmax;
  reach_vx_ = reach_vy_ = 0;
  for (uint32_t i = 0; i < n; ++i) {
    reach_vx_ = std::max(reach_vx_, std::fabs(src.vx(i)));
    reach_vy_ = std::max(reach_vy_, std::fabs(src.vy(i)));
  }
}

template <class Src>
bool KineticTree<Src>::refit(const Src& src, const Frame& f, std::size_t leaf_size, Executor* ex) {
  const auto n = static_cast<uint32_t>(src.size());
  if (nodes_.empty() || n != items_.size() || std::max<std::size_t>(leaf_size, 1) != leaf_size_ ||
      f.chord != built_chord_ || f.knots.size() != built_knots_ || f.ox != built_ox_ ||
      f.oy != built_oy_)
    return false;
  src_ = &src;
  f_ = &f;
  // Leaf by leaf (in chunks, on every thread with `ex`): the members' columns anew, the leaf's
  // bounds; per chunk the largest moves and speeds, and whether every key is still its row's.
  const auto m = static_cast<uint32_t>(nodes_.size());
  leaves_.clear();
  for (uint32_t k = 0; k < m; ++k)
    if (nodes_[k].leaf()) leaves_.push_back(k);
  constexpr std::size_t kLeafGrain = 16;
  const std::size_t chunks = (leaves_.size() + kLeafGrain - 1) / kLeafGrain;
  std::vector<double> part(4 * chunks, 0);
  std::vector<uint8_t> same(chunks, 1);
  const std::size_t stride = items_.size();
  const auto refit_leaves = [&](std::size_t b, std::size_t e) {
    double dx = 0, dy = 0, vx = 0, vy = 0;
    bool ok = true;
    for (std::size_t l = b; l < e; ++l) {
      const TreeNode& nd = nodes_[leaves_[l]];
      for (uint32_t i = nd.begin; i < nd.end; ++i) {
        Item& it = items_[i];
        const uint32_t row = it.row;
        ok = ok && src.key(row) == it.key;
        it.x = src.x(row);
        it.y = src.y(row);
        it.vx = src.vx(row);
        it.vy = src.vy(row);
        it.r = src.r(row);
        double* const c = cols_.data() + i;
        c[0] = it.x;
        c[stride] = it.y;
        c[2 * stride] = it.vx;
        c[3 * stride] = it.vy;
        c[4 * stride] = it.r;
        dx = std::max(dx, std::fabs(it.x - built_x_[i]));
        dy = std::max(dy, std::fabs(it.y - built_y_[i]));
        vx = std::max(vx, std::fabs(it.vx));
        vy = std::max(vy, std::fabs(it.vy));
      }
      leaf_bounds(leaves_[l]);
      finish_bounds(leaves_[l]);
    }
    const std::size_t k = b / kLeafGrain;
    part[4 * k] = dx;
    part[4 * k + 1] = dy;
    part[4 * k + 2] = vx;
    part[4 * k + 3] = vy;
    same[k] = ok;
  };
  if (ex && ex->threads() > 1 && n >= kParallelBuild)
    ex->for_each_chunk(leaves_.size(), kLeafGrain, refit_leaves);
  else
    refit_leaves(0, leaves_.size());
  double dx = 0, dy = 0;
  reach_vx_ = reach_vy_ = 0;
  bool ok = true;
  for (std::size_t k = 0; k < chunks; ++k) {
    dx = std::max(dx, part[4 * k]);
    dy = std::max(dy, part[4 * k + 1]);
    reach_vx_ = std::max(reach_vx_, part[4 * k + 2]);
    reach_vy_ = std::max(reach_vy_, part[4 * k + 3]);
    ok = ok && same[k];
  }
  if (!ok) {  // another row in a member's place: the tree must be built (the copies are moot)
    nodes_.clear();
    return false;
  }
  // (Rounding of the differences: a relative 1e-9 more.)
  drift_x_ = dx * (1 + 1e-9);
  drift_y_ = dy * (1 + 1e-9);
  // The parents from their children (preorder: every child comes after its parent).
  for (uint32_t k = m; k-- > 0;)
    if (!nodes_[k].leaf()) {
      merge_bounds(k, k + 1, nodes_[k].right);
      finish_bounds(k);
    }
  reach_r_ = nodes_[0].rmax;
  return true;
}

template <class Src>
uint32_t KineticTree<Src>::split(uint32_t b, uint32_t e, const Cell& cell, Split& sc, Cell& lc,
                                 Cell& rc) {
  // Split the cell's wider side at the median: balanced, depth ceil(log2(n / leaf)).
  const bool by_x = cell.x1 - cell.x0 >= cell.y1 - cell.y0;
  const uint32_t mid = b + (e - b) / 2;
  if (by_x)
    select_median<&Pt::x>(b, e, mid, sc);
  else
    select_median<&Pt::y>(b, e, mid, sc);
  // Left members have coordinate <= cut, right ones >= cut (ties may fall either side).
  // (x - ox rounds monotonically: raw order is frame order, and the cut bounds both sides.)
  const double cut = by_x ? pts_[mid].x - f_->ox : pts_[mid].y - f_->oy;
  lc = cell;
  rc = cell;
  (by_x ? lc.x1 : lc.y1) = cut;
  (by_x ? rc.x0 : rc.y0) = cut;
  return mid;
}

template <class Src>
void KineticTree<Src>::build_top(uint32_t idx, uint32_t b, uint32_t e, uint32_t parent, Cell cell,
                                 int depth, std::vector<Subtree>& below,
                                 std::vector<uint32_t>& top) {
  if (depth == 0 || e - b <= leaf_size_) {
    below.push_back({idx, b, e, parent, cell});
    return;
  }
  Cell lc, rc;
  const uint32_t mid = split(b, e, cell, splits_[0], lc, rc);
  const auto r = static_cast<uint32_t>(idx + 1 + count_nodes(mid - b));
  nodes_[idx] = {0, 0, b, e, r, parent};
  cells_[idx] = cell;
  top.push_back(idx);
  build_top(idx + 1, b, mid, idx, lc, depth - 1, below, top);
  build_top(r, mid, e, idx, rc, depth - 1, below, top);
}

template <class Src>
uint32_t KineticTree<Src>::build_node(uint32_t idx, uint32_t b, uint32_t e, uint32_t parent,
                                      Cell cell, Split& sc) {
  nodes_[idx] = {0, 0, b, e, 0, parent};
  cells_[idx] = cell;
  uint32_t next = idx + 1;
  if (e - b <= leaf_size_) {
    // The leaf's members, copied from the source, by key: a scan can stop at the first key
    // that can no longer win.
    const Src& src = *src_;
    for (uint32_t i = b; i < e; ++i) {
      const uint32_t row = pts_[i].row;
      items_[i] = {src.x(row), src.y(row), src.vx(row), src.vy(row), src.r(row), src.key(row), row};
    }
    std::sort(items_.begin() + b, items_.begin() + e, [](const Item& p, const Item& q) {
      return p.key != q.key ? p.key < q.key : p.row < q.row;
    });
    const std::size_t n = items_.size();
    for (uint32_t i = b; i < e; ++i) {
      const Item& it = items_[i];
      double* const c = cols_.data() + i;
      c[0] = it.x;
      c[n] = it.y;
      c[2 * n] = it.vx;
      c[3 * n] = it.vy;
      c[4 * n] = it.r;
    }
    leaf_bounds(idx);
  } else {
    Cell lc, rc;
    const uint32_t mid = split(b, e, cell, sc, lc, rc);
    const uint32_t r = build_node(idx + 1, b, mid, idx, lc, sc);
    next = build_node(r, mid, e, idx, rc, sc);
    nodes_[idx].right = r;
    merge_bounds(idx, idx + 1, r);
  }
  finish_bounds(idx);
  return next;
}

// nth_element's comparisons are unpredictable branches, a pass per level of the tree. Large
// ranges are cut first: two order statistics of a sample bracket the median, one branch-free pass
// sorts the range into below / between / above (out of place), and only the between part is left
// to nth_element. If the bracket misses the median (adversarial orders), nth_element does it all.
template <class Src>
template <double KineticTree<Src>::Pt::*C>
void KineticTree<Src>::select_median(uint32_t b, uint32_t e, uint32_t k, Split& sc) {
  Pt* a = pts_.data() + b;
  const std::size_t n = e - b, kk = k - b;
  const auto less = [](const Pt& p, const Pt& q) { return p.*C < q.*C; };
  if (n <= 256) {
    std::nth_element(a, a + kk, a + n, less);
    return;
  }
  double s[31];
  for (std::size_t i = 0; i < 31; ++i) s[i] = a[(2 * i + 1) * n / 62].*C;
  std::sort(s, s + 31);
  const double p1 = s[11], p2 = s[19];
  if (sc.lohi.size() < n) {
    sc.lohi.resize(n);
    sc.middle.resize(n);
  }
  Pt* t = sc.lohi.data();  // below p1 from the front, above p2 from the back
  Pt* m = sc.middle.data();
  std::size_t lo = 0, hi = 0, mi = 0;
  for (std::size_t i = 0; i < n; ++i) {
    // Every slot written to is either kept (its counter advances) or unused: the front and the
    // back never meet before the last element.
    const Pt x = a[i];
    const bool l = x.*C<p1, h = x.*C> p2;
    t[lo] = x;
    t[n - 1 - hi] = x;
    m[mi] = x;
    lo += l;
    hi += h;
    mi += !(l | h);
  }
  if (kk < lo || kk >= lo + mi) {
    std::nth_element(a, a + kk, a + n, less);
    return;
  }
  std::copy(t, t + lo, a);
  std::copy(m, m + mi, a + lo);
  std::copy(t + n - hi, t + n, a + lo + mi);
  std::nth_element(a + lo, a + kk, a + lo + mi, less);
}

template <class Src>
void KineticTree<Src>::leaf_bounds(uint32_t node) {
  TreeNode& nd = nodes_[node];
  const Frame& f = *f_;
  const std::size_t per = f.chord ? f.knots.size() : 2;
  Raw* raw = &raw_[node * per];
  for (std::size_t j = 0; j < per; ++j) raw[j] = {INFINITY, INFINITY, -INFINITY, -INFINITY};
  nd.rmax = 0;
  nd.min_key = std::numeric_limits<uint64_t>::max();
  for (uint32_t i = nd.begin; i < nd.end; ++i) {
    const Item& it = items_[i];
    const double x = it.x - f.ox, y = it.y - f.oy, vx = it.vx, vy = it.vy;
    nd.rmax = std::max(nd.rmax, it.r);
    nd.min_key = std::min(nd.min_key, it.key);
    if (f.chord) {
      for (std::size_t j = 0; j < per; ++j) {
        const double t = f.knots[j];
        const double px = x + vx * t, py = y + vy * t;
        raw[j] = {std::min(raw[j].lo_x, px), std::min(raw[j].lo_y, py), std::max(raw[j].hi_x, px),
                  std::max(raw[j].hi_y, py)};
      }
    } else {
      raw[0] = {std::min(raw[0].lo_x, x), std::min(raw[0].lo_y, y), std::max(raw[0].hi_x, x),
                std::max(raw[0].hi_y, y)};
      raw[1] = {std::min(raw[1].lo_x, vx), std::min(raw[1].lo_y, vy), std::max(raw[1].hi_x, vx),
                std::max(raw[1].hi_y, vy)};
    }
  }
}

template <class Src>
void KineticTree<Src>::merge_bounds(uint32_t node, uint32_t l, uint32_t r) {
  const std::size_t per = f_->chord ? f_->knots.size() : 2;
  Raw* out = &raw_[node * per];
  const Raw* a = &raw_[l * per];
  const Raw* b = &raw_[r * per];
  for (std::size_t j = 0; j < per; ++j)
    out[j] = {std::min(a[j].lo_x, b[j].lo_x), std::min(a[j].lo_y, b[j].lo_y),
              std::max(a[j].hi_x, b[j].hi_x), std::max(a[j].hi_y, b[j].hi_y)};
  nodes_[node].rmax = std::max(nodes_[l].rmax, nodes_[r].rmax);
  nodes_[node].min_key = std::min(nodes_[l].min_key, nodes_[r].min_key);
}

// Inflates the raw bounds by delta0 + delta1 t and turns them into per-slice lines.
template <class Src>
void KineticTree<Src>::finish_bounds(uint32_t node) {
  const Frame& f = *f_;
  const int K = f.slices();
  auto at = [&](int j) -> Slice& { return slices_[static_cast<std::size_t>(j) * stride_ + node]; };
  if (!f.chord) {
    const Raw& box = raw_[node * 2];
    const Raw& vel = raw_[node * 2 + 1];
    at(0) = {box.lo_x - f.delta0, box.lo_y - f.delta0, box.hi_x + f.delta0, box.hi_y + f.delta0,
             vel.lo_x - f.delta1, vel.lo_y - f.delta1, vel.hi_x + f.delta1, vel.hi_y + f.delta1};
    return;
  }
  const Raw* raw = &raw_[node * f.knots.size()];
  auto inflated = [&](int j) {
    const double d = f.delta0 + f.delta1 * f.knots[j];
    return Raw{raw[j].lo_x - d, raw[j].lo_y - d, raw[j].hi_x + d, raw[j].hi_y + d};
  };
  Raw a = inflated(0);
  for (int j = 0; j < K; ++j) {
    const Raw b = inflated(j + 1);
    // Rounding of the slopes moves the lines by far less than the inflation (see the header).
    const double inv = 1 / (f.knots[j + 1] - f.knots[j]);
    at(j) = {a.lo_x,
             a.lo_y,
             a.hi_x,
             a.hi_y,
             (b.lo_x - a.lo_x) * inv,
             (b.lo_y - a.lo_y) * inv,
             (b.hi_x - a.hi_x) * inv,
             (b.hi_y - a.hi_y) * inv};
    a = b;
  }
}

template <class Src>
template <bool OverlapOnly>
void KineticTree<Src>::scan(uint32_t node, const Probe& q, double horizon, Best& best,
                            Counters& c) const {
  const TreeNode& nd = nodes_[node];
  if constexpr (!OverlapOnly && std::is_same_v<Src, AgentSource>) {
    // The pair times first, all of the leaf's in lanes (those after a break are wasted work,
    // not a different answer), then offered in key order as below.
    const uint32_t n = nd.end - nd.begin;
    if (f_->lanes && n <= kLaneLeaf) {
      double times[kLaneLeaf];
      const double earliest = lanes_pair_times(columns().from(nd.begin), n, q, horizon, times);
      // Usually no member can win (most never collide within the horizon, or later than the
      // answer so far): the loop below would then offer only losers and never break (it breaks
      // only once the answer has time 0), so only its count is needed. (The query's own row,
      // at time 0 with itself unless its radius is 0, keeps its leaf in the loop.)
      if (best.kind == Kind::none ? earliest == INFINITY : best.t > 0 && earliest > best.t) {
        const bool self =
            q.self != kNoRow && pos_of_[q.self] >= nd.begin && pos_of_[q.self] < nd.end;
        c.pair_tests += n - (self ? 1 : 0);
        return;
      }
      for (uint32_t k = 0; k < n; ++k) {
        const Member& m = items_[nd.begin + k];
        if (best.beats(0, Src::kind, m.key)) break;
        if (m.row == q.self) continue;
        ++c.pair_tests;
        best.offer(times[k], Src::kind, m.key, m.row);
      }
      return;
    }
  }
  for (uint32_t i = nd.begin; i < nd.end; ++i) {
    const Member& m = items_[i];
    // Leaves are sorted by key: once the answer beats (t = 0, key), it beats the rest too.
    if (best.beats(0, Src::kind, m.key)) break;
    if (m.row == q.self) continue;
    ++c.pair_tests;
    if constexpr (OverlapOnly) {
      if (Src::overlaps(q, m)) best.offer(0.0, Src::kind, m.key, m.row);
    } else {
      best.offer(Src::time(q, m, horizon), Src::kind, m.key, m.row);
    }
  }
}

template <class Src>
template <bool OverlapOnly>
void KineticTree<Src>::search(const Probe& q, double horizon, Best& best, ProbeScratch& sc,
                              Counters& c, Order order, uint32_t self_pos, bool seed) const {
  if (nodes_.empty()) return;
  const Frame& f = *f_;
  constexpr Kind kind = Src::kind;
  if constexpr (OverlapOnly) horizon = 0;
  auto bound_of = [&](uint32_t k) {
    const double R = q.ar + nodes_[k].rmax;
    if constexpr (OverlapOnly) {  // within reach at t = 0, or out
      const Slice& b = slices_[k];
      return b.lo_x - q.fx <= R && q.fx - b.hi_x <= R && b.lo_y - q.fy <= R && q.fy - b.hi_y <= R
                 ? 0.0
                 : INFINITY;
    } else {
      const double cap = best.kind == Kind::none ? horizon : std::min(horizon, best.t);
      return node_bound(&slices_[k], stride_, f, q, R, cap);
    }
  };
  auto pruned = [&](double b, uint64_t min_key) {
    return b == INFINITY || best.beats(b, kind, min_key);
  };
  auto push = [&](double b, uint32_t k) {
    sc.heap.push_back({b, nodes_[k].min_key, k});
    std::push_heap(sc.heap.begin(), sc.heap.end(), Later{});
    ++c.pushes;
  };
  // Searches the subtree at `start` (not pruned when called). Any visiting order is exact: a
  // node is skipped only when the answer so far beats its bound, and the answer only improves.
  // start == kNoRow: continue with the queue as it is.
  auto explore = [&](uint32_t start, double start_bound, uint32_t skip_leaf) {
    if (start != kNoRow) sc.heap.clear();
    uint32_t node = start;
    if (order == Order::best_first) {
      push(start_bound, start);
      node = kNoRow;
    }
    for (;;) {
      if (node == kNoRow) {
        if (sc.heap.empty()) return;
        std::pop_heap(sc.heap.begin(), sc.heap.end(), Later{});
        const Entry e = sc.heap.back();
        sc.heap.pop_back();
        ++c.pops;
        if (pruned(e.bound, e.key)) return;  // the smallest bound left cannot win: nothing can
        node = e.node;
      }
      const TreeNode& nd = nodes_[node];
      if (nd.leaf()) {
        if (node != skip_leaf) {
          ++c.visited;
          scan<OverlapOnly>(node, q, horizon, best, c);
        }
        node = kNoRow;
        continue;
      }
      ++c.visited;
      const uint32_t l = node + 1, r = nd.right;
      const double bl = bound_of(l), br = bound_of(r);
      const bool keep_l = !pruned(bl, nodes_[l].min_key), keep_r = !pruned(br, nodes_[r].min_key);
      node = kNoRow;
      if (order == Order::best_first) {
        if (keep_l) push(bl, l);
        if (keep_r) push(br, r);
      } else if (keep_l && keep_r) {
        const bool l_first = bl != br ? bl < br : nodes_[l].min_key <= nodes_[r].min_key;
        push(l_first ? br : bl, l_first ? r : l);
        node = l_first ? l : r;
      } else if (keep_l) {
        node = l;
      } else if (keep_r) {
        node = r;
      }
    }
  };

  // The query's own leaf first: its neighbours give an early best time.
  sc.heap.clear();
  uint32_t leaf = kNoRow;
  if (self_pos != kNoRow && (seed || order == Order::bottom_up || order == Order::leaf_queue)) {
    leaf = leaf_at_[self_pos];
    ++c.visited;
    scan<OverlapOnly>(leaf, q, horizon, best, c);
  }
  if ((order == Order::bottom_up || order == Order::leaf_queue) && leaf != kNoRow) {
    // Then the siblings of the path to the root, nearest (deepest) first. Once every position
    // from which a member could still reach the query before the answer so far lies strictly
    // inside the cell below, no sibling further up can hold a winner: stop.
    for (uint32_t below = leaf; below != 0; below = nodes_[below].parent) {
      // (Overlaps count at t = 0 even when the horizon is negative: the reach is at least R.)
      const double cap =
          std::max(0.0, best.kind == Kind::none ? horizon : std::min(horizon, best.t));
      const double hx =
          reach_r_ + q.ar + f.delta0 + (std::fabs(q.avx) + reach_vx_ + f.delta1) * cap;
      const double hy =
          reach_r_ + q.ar + f.delta0 + (std::fabs(q.avy) + reach_vy_ + f.delta1) * cap;
      // (Shrunk by the drift since the build: a member outside the subtree was outside the cell
      // then, and has moved at most that far.)
      const Cell& cell = cells_[below];
      if (q.fx - hx > cell.x0 + drift_x_ && q.fx + hx < cell.x1 - drift_x_ &&
          q.fy - hy > cell.y0 + drift_y_ && q.fy + hy < cell.y1 - drift_y_)
        break;
      const uint32_t p = nodes_[below].parent;
      const uint32_t sib = below == p + 1 ? nodes_[p].right : p + 1;
      const double b = bound_of(sib);
      if (pruned(b, nodes_[sib].min_key)) continue;
      if (order == Order::bottom_up)
        explore(sib, b, kNoRow);  // searched at once, deepest sibling first
      else
        push(b, sib);  // searched below in bound order
    }
    if (order == Order::leaf_queue) explore(kNoRow, 0, kNoRow);
    return;
  }
  const double b0 = bound_of(0);
  if (!pruned(b0, nodes_[0].min_key)) explore(0, b0, leaf);
}

template <class Src>
void KineticTree<Src>::leaf_overlaps(uint32_t leaf, ProbeScratch& sc) const {
  std::size_t n = 0;  // candidates so far, in sc.cx[0, n) etc.
  sc.join_visited = 0;
  sc.crowded = false;
  // In a crowd (everyone within reach of everyone) the join would cost O(n) per agent, while the
  // tree search, pruning by smallest key, stays cheap: past the cap, the leaf falls back to it.
  const std::size_t cap = std::max<std::size_t>(256, 16 * leaf_size_);
  // Slice 0 of every node starts with its inflated box at t = 0 (chord and frustum alike).
  const Slice& L = slices_[leaf];
  const double rl = nodes_[leaf].rmax;
  const double ox = f_->ox, oy = f_->oy;
  const double lx0 = L.lo_x - rl, lx1 = L.hi_x + rl, ly0 = L.lo_y - rl, ly1 = L.hi_y + rl;
  // A depth-first walk; the heap's storage serves as the stack (it is empty between searches).
  std::vector<Entry>& stack = sc.heap;
  stack.clear();
  stack.push_back({0, 0, 0});
  while (!stack.empty()) {
    const uint32_t k = stack.back().node;
    stack.pop_back();
    const Slice& b = slices_[k];
    const double R = rl + nodes_[k].rmax;
    ++sc.join_visited;
    if (b.lo_x - L.hi_x > R || L.lo_x - b.hi_x > R || b.lo_y - L.hi_y > R || L.lo_y - b.hi_y > R)
      continue;
    const TreeNode& nd = nodes_[k];
    if (!nd.leaf()) {
      stack.push_back({0, 0, nd.right});
      stack.push_back({0, 0, k + 1});
      continue;
    }
    // Only the members within reach of the leaf's box (Chebyshev, frame coordinates): the box is
    // inflated by delta0, far more than the rounding of the overlap test. Branch-free: each
    // member's position is written, and kept by advancing n.
    if (sc.cpos.size() < n + (nd.end - nd.begin)) sc.cpos.resize(2 * (n + (nd.end - nd.begin)));
    uint32_t* cpos = sc.cpos.data();
    for (uint32_t i = nd.begin; i < nd.end; ++i) {
      const Member& m = items_[i];
      const double fx = m.x - ox, fy = m.y - oy, rb = m.r;
      cpos[n] = i;
      n += (fx >= lx0 - rb) & (fx <= lx1 + rb) & (fy >= ly0 - rb) & (fy <= ly1 + rb);
    }
    if (n > cap) {
      sc.crowded = true;
      sc.ncand = 0;
      return;
    }
  }
  sc.ncand = n;
  if (sc.cx.size() < n) {
    sc.cx.resize(n);
    sc.cy.resize(n);
    sc.cr.resize(n);
    sc.cc.resize(n);
    sc.pick.resize(n);
  }
  for (std::size_t j = 0; j < n; ++j) {
    const Member& m = items_[sc.cpos[j]];
    sc.cx[j] = m.x;
    sc.cy[j] = m.y;
    sc.cr[j] = m.r;
  }
  const TreeNode& nl = nodes_[leaf];
  sc.hit.assign(nl.end - nl.begin, kNoRow);
  const double* cx = sc.cx.data();  // (the member itself is among the candidates)
  const double* cy = sc.cy.data();
  const double* cr = sc.cr.data();
  double* cc = sc.cc.data();
  for (uint32_t i = nl.begin; i < nl.end; ++i) {
    const Member& a = items_[i];
    if (overlap_terms(cx, cy, cr, cc, n, a.x, a.y, a.r) < 2) continue;  // only itself
    // The few overlapping candidates, gathered without branches, then the smallest (key, row).
    uint32_t* pick = sc.pick.data();
    std::size_t m = 0;
    for (std::size_t j = 0; j < n; ++j) {
      pick[m] = static_cast<uint32_t>(j);
      m += cc[j] < 0;
    }
    uint32_t best = kNoRow;
    for (std::size_t h = 0; h < m; ++h) {
      const uint32_t j = sc.cpos[pick[h]];  // a position in tree order
      if (j == i) continue;                 // the member itself
      if (best == kNoRow || items_[j].key < items_[best].key ||
          (items_[j].key == items_[best].key && items_[j].row < items_[best].row))
        best = j;
    }
    if (best != kNoRow) sc.hit[i - nl.begin] = items_[best].row;
  }
}

template <class Src>
std::string KineticTree<Src>::validate(const Frame& f) const {
  const Src& s = *src_;
  const std::size_t K = static_cast<std::size_t>(f.slices());
  std::vector<uint32_t> seen(perm_.size(), 0);
  for (uint32_t row : perm_) {
    if (row >= seen.size() || seen[row]++) return "perm is not a permutation";
  }
  for (uint32_t k = 0; k < nodes_.size(); ++k) {
    const TreeNode& nd = nodes_[k];
    if (nd.begin >= nd.end || nd.end > perm_.size())
      return "node " + std::to_string(k) + ": bad range";
    if (!nd.leaf()) {
      const TreeNode& l = nodes_[k + 1];
      const TreeNode& r = nodes_[nd.right];
      if (l.parent != k || r.parent != k)
        return "node " + std::to_string(k) + ": wrong parent links";
      if (l.begin != nd.begin || l.end != r.begin || r.end != nd.end)
        return "node " + std::to_string(k) + ": children do not partition its range";
    } else if (nd.end - nd.begin > leaf_size_) {
      return "leaf " + std::to_string(k) + ": too many members";
    }
    auto sl = [&](std::size_t j) -> const Slice& { return slices_[j * stride_ + k]; };
    for (uint32_t i = nd.begin; i < nd.end; ++i) {
      const uint32_t row = perm_[i];
      if (s.r(row) > nd.rmax) return "node " + std::to_string(k) + ": rmax below a member's radius";
      if (s.key(row) < nd.min_key)
        return "node " + std::to_string(k) + ": min_key above a member's key";
      if (pos_of_[row] != i) return "row " + std::to_string(row) + ": pos_of is wrong";
      if (nd.leaf() && leaf_at_[i] != k)
        return "position " + std::to_string(i) + ": leaf_at is wrong";
      const double fx = s.x(row) - f.ox, fy = s.y(row) - f.oy;
      const Cell& cl = cells_[k];
      const double mx = drift_x_ + f.delta0, my = drift_y_ + f.delta0;  // (and rounding)
      if (fx < cl.x0 - mx || fx > cl.x1 + mx || fy < cl.y0 - my || fy > cl.y1 + my)
        return "node " + std::to_string(k) + ": row " + std::to_string(row) + " outside its cell";
      // Each member at each slice's two ends (and its middle) lies inside the slice's box.
      for (std::size_t j = 0; j < K; ++j) {
        const double t0 = f.knots[j];
        const double len = std::isfinite(f.knots[j + 1]) ? f.knots[j + 1] - t0 : 1e3;
        for (double u : {0.0, len / 2, len}) {
          const double t = t0 + u;
          const double px = (s.x(row) - f.ox) + s.vx(row) * t,
                       py = (s.y(row) - f.oy) + s.vy(row) * t;
          const Slice& b = sl(j);
          if (px < b.lo_x + b.slo_x * u || px > b.hi_x + b.shi_x * u || py < b.lo_y + b.slo_y * u ||
              py > b.hi_y + b.shi_y * u)
            return "node " + std::to_string(k) + ": row " + std::to_string(row) +
                   " leaves the box at t=" + std::to_string(t);
        }
      }
    }
  }
  return "";
}

}  // namespace

// ------------------------------------------------------------------- FtcIndex

struct FtcIndex::Impl {
  FtcIndexOptions opt;
  DiscView discs;
  const StaticScene* scene = nullptr;
  double horizon = 0;
  Frame frame;
  AgentSource agents;
  CircleSource circles;
  KineticTree<AgentSource> agent_tree;
  KineticTree<CircleSource> circle_tree;
  std::vector<Slice> polygon_boxes;  // one static slice per polygon (frustum form)
  // Among many polygons, their boxes in a grid (kept while the scene is the same): a query reads
  // those whose box meets its sweep, not every polygon (SteerSuite's 5,000 boxes).
  static constexpr std::size_t kPolygonsForAGrid = 16;
  BoxGrid polygon_grid;
  uint64_t polygon_grid_scene = 0;  // the scene's generation() it was built for
  mutable ProbeScratch scratch;     // for query()
  bool no_overlaps = false;         // FtcPath::assume_no_overlaps
  uint64_t refits = 0;              // agent tree refits since its last build
  bool refitted = false;            // the last build refitted it

  void make_frame();
  // The answer for one row; pos: its position in the agent tree's order.
  FtcHit probe(uint32_t row, uint32_t pos, ProbeScratch& sc, Counters& c) const;
};

void FtcIndex::Impl::make_frame() {
  const DiscView& d = discs;
  const auto circ = scene->circles();
  const auto boxes = scene->polygon_boxes();
  double x0 = INFINITY, y0 = INFINITY, x1 = -INFINITY, y1 = -INFINITY;
  double ra = 0, rc = 0, v = 0;
  auto take = [&](double x, double y) {
    x0 = std::min(x0, x);
    x1 = std::max(x1, x);
    y0 = std::min(y0, y);
    y1 = std::max(y1, y);
  };
  for (std::size_t i = 0; i < d.n; ++i) {
    take(d.x[i], d.y[i]);
    ra = std::max(ra, d.radius[i]);
    v = std::max(v, std::fabs(d.vx[i]) + std::fabs(d.vy[i]));
  }
  for (const auto& c : circ) {
    take(c.x, c.y);
    rc = std::max(rc, c.radius);
  }
  for (const auto& b : boxes) {
    take(b.xmin, b.ymin);
    take(b.xmax, b.ymax);
  }
  Frame& f = frame;
  f = Frame{};
  if (x0 <= x1) {
    f.ox = x0 + (x1 - x0) / 2;
    f.oy = y0 + (y1 - y0) / 2;
  }
  // M0 bounds |d| + R for every pair (agents, circles, polygon corners); V bounds |w|.
  const double extent = (x1 - x0) + (y1 - y0);
  const double m0 = (x0 <= x1 ? 2 * extent : 0) + 2 * (ra + rc);
  const double vmax = 2 * v;
  f.delta0 = kSlack * m0;
  f.delta1 = kSlack * vmax;
  f.lanes = opt.lanes;
  const int K = std::max(opt.slices, 1);
  f.chord = opt.bound == FtcIndexOptions::Bound::chord && horizon > 0 && std::isfinite(horizon) &&
            std::isfinite(m0 + vmax * horizon) && m0 + vmax * horizon < 1e300;
  if (f.chord) {
    f.knots.resize(static_cast<std::size_t>(K) + 1);
    for (int j = 0; j <= K; ++j) f.knots[static_cast<std::size_t>(j)] = horizon * j / K;
    f.knots.back() = horizon;
  } else {
    f.knots = {0.0, INFINITY};
  }
}

FtcHit FtcIndex::Impl::probe(uint32_t row, uint32_t pos, ProbeScratch& sc, Counters& c) const {
  const Member& a = agent_tree.member(pos);  // the row's own values, in tree order
  Probe q{a.x, a.y, a.vx, a.vy, a.r, a.x - frame.ox, a.y - frame.oy, row};
  Best best;
  const bool overlaps_first = opt.overlaps_first && !no_overlaps;
  if (overlaps_first && opt.overlap_join) {
    // An agent overlapping the query now wins outright (time 0, agents before obstacles); only
    // the smallest (id, row) is wanted, and only t = 0 checks are needed to find it. The join
    // answers the whole leaf at once (queries run in tree order, so once per leaf). Counters:
    // each member its own pair tests, the leaf's first member the walk's nodes, so the sums do
    // not depend on how the rows are split between threads.
    const uint32_t leaf = agent_tree.leaf_at(pos);
    if (sc.leaf != leaf) {
      agent_tree.leaf_overlaps(leaf, sc);
      sc.leaf = leaf;
    }
    const uint32_t begin = agent_tree.leaf_begin(leaf);
    if (pos == begin) c.visited += sc.join_visited;
    if (sc.crowded) {  // a crowd: the tree search below instead
      agent_tree.search<true>(q, horizon, best, sc, c, opt.order, pos, opt.seed_own_leaf);
      if (best.kind != Kind::none) return {{best.kind, best.row}, best.t};
    } else {
      c.pair_tests += sc.ncand - 1;
      const uint32_t hit = sc.hit[pos - begin];
      if (hit != kNoRow) return {{Kind::agent, hit}, 0.0};
    }
  } else if (overlaps_first) {
    // The same answer through the tree search in the chosen order, t = 0 checks only.
    agent_tree.search<true>(q, horizon, best, sc, c, opt.order, pos, opt.seed_own_leaf);
    if (best.kind != Kind::none) return {{best.kind, best.row}, best.t};
  }
  agent_tree.search<false>(q, horizon, best, sc, c, opt.order, pos, opt.seed_own_leaf);
  q.self = kNoRow;
  circle_tree.search<false>(q, horizon, best, sc, c, opt.order, kNoRow, false);
  const auto polys = scene->polygons();
  const auto boxes = scene->polygon_boxes();
  // The naive path's filter first (same inputs, so the same polygons reach ray_polygon_time):
  // the sweep's box against the polygon's.
  const double ax = q.ax, ay = q.ay, avx = q.avx, avy = q.avy, ar = q.ar;
  const double ex0 = ax + std::fmin(0.0, avx * horizon) - ar,
               ex1 = ax + std::fmax(0.0, avx * horizon) + ar;
  const double ey0 = ay + std::fmin(0.0, avy * horizon) - ar,
               ey1 = ay + std::fmax(0.0, avy * horizon) + ar;
  auto offer_polygon = [&](std::size_t p) {
    const auto& bx = boxes[p];
    if (ex1 < bx.xmin || ex0 > bx.xmax || ey1 < bx.ymin || ey0 > bx.ymax) return;
    const double cap = best.kind == Kind::none ? horizon : std::min(horizon, best.t);
    static const Frame static_frames[2] = {{0, 0, {0.0, INFINITY}, false, 0, 0, false},
                                           {0, 0, {0.0, INFINITY}, false, 0, 0, true}};
    const double b = node_bound(&polygon_boxes[p], 1, static_frames[opt.lanes], q, ar, cap);
    if (b == INFINITY || best.beats(b, Kind::polygon, p)) return;
    ++c.pair_tests;
    best.offer(ray_polygon_time(*scene, p, ax, ay, avx, avy, ar, horizon, cap), Kind::polygon, p,
               static_cast<uint32_t>(p));
  };
  const std::size_t walls = scene->wall_begin();
  if (walls >= kPolygonsForAGrid && ex0 <= ex1 && ey0 <= ey1) {  // (not NaN, nor a negative radius)
    // Every box meeting [ex0, ex1] x [ey0, ey1] has a cell in that window's cells (cell_x is
    // monotone), listed in ascending order: the loop's polygons that pass the filter, in its order;
    // then the walls (the last rows, kept out of the grid: they reach a world's width beyond it).
    polygon_grid.collect(polygon_grid.cell_x(ex0), polygon_grid.cell_x(ex1),
                         polygon_grid.cell_y(ey0), polygon_grid.cell_y(ey1), sc.polygons);
    for (const uint32_t p : sc.polygons) offer_polygon(p);
    for (std::size_t p = walls; p < polys.size(); ++p) offer_polygon(p);
  } else {
    for (std::size_t p = 0; p < polys.size(); ++p) offer_polygon(p);
  }
  return best.kind == Kind::none ? FtcHit{} : FtcHit{{best.kind, best.row}, best.t};
}

FtcIndex::FtcIndex(FtcIndexOptions options) : impl_(std::make_unique<Impl>()) {
  if (options.leaf_size < 1) options.leaf_size = 1;
  if (options.leaf_size_apart < 1) options.leaf_size_apart = 1;
  if (options.slices < 1) options.slices = 1;
  impl_->opt = options;
}

FtcIndex::~FtcIndex() = default;

void FtcIndex::build(const DiscView& discs, const StaticScene& scene, double horizon,
                     Executor* ex) {
  Impl& m = *impl_;
  if (discs.n >= kNoRow) throw Error(Error::Kind::input, "first-to-collide index: too many discs");
  for (std::size_t i = 0; i < discs.n; ++i) {
    const char* bad = !std::isfinite(discs.x[i])        ? "x"
                      : !std::isfinite(discs.y[i])      ? "y"
                      : !std::isfinite(discs.vx[i])     ? "vx"
                      : !std::isfinite(discs.vy[i])     ? "vy"
                      : !std::isfinite(discs.radius[i]) ? "radius"
                                                        : nullptr;
    if (bad)
      throw InvalidRow(bad, "first-to-collide index: row " + std::to_string(i) + ": field " + bad +
                                " is not a finite number");
  }
  if (std::isnan(horizon))
    throw Error(Error::Kind::input, "first-to-collide index: horizon is NaN");
  m.discs = discs;
  m.scene = &scene;
  m.scratch.leaf = kNoRow;
  m.horizon = horizon;
  m.make_frame();
  m.agents.d = &m.discs;
  m.circles.c = scene.circles();
  const std::size_t leaf = m.no_overlaps ? m.opt.leaf_size_apart : m.opt.leaf_size;
  bool refitted = false;
  if (m.refits + 1 < m.opt.rebuild_every && !m.agent_tree.empty()) {
    // The last build's origin, which its boxes and cells are relative to: every position's
    // distance from it is larger by at most the shift, and so may be the rounding of the
    // coordinates relative to it (M0 grows by twice the shift per axis; see "Floating point").
    Frame& f = m.frame;
    const Frame fresh = f;
    const double shift =
        std::fabs(f.ox - m.agent_tree.built_ox()) + std::fabs(f.oy - m.agent_tree.built_oy());
    f.ox = m.agent_tree.built_ox();
    f.oy = m.agent_tree.built_oy();
    f.delta0 += kSlack * 4 * shift;
    refitted = m.agent_tree.refit(m.agents, m.frame, leaf, ex);
    if (!refitted) f = fresh;
  }
  m.refitted = refitted;
  if (refitted) {
    ++m.refits;
  } else {
    m.agent_tree.build(m.agents, m.frame, leaf, ex);
    m.refits = 0;
  }
  m.circle_tree.build(m.circles, m.frame, m.opt.leaf_size);
  m.polygon_boxes.clear();
  const double d0 = m.frame.delta0, d1 = m.frame.delta1;
  for (const auto& b : scene.polygon_boxes())
    m.polygon_boxes.push_back({b.xmin - m.frame.ox - d0, b.ymin - m.frame.oy - d0,
                               b.xmax - m.frame.ox + d0, b.ymax - m.frame.oy + d0, -d1, -d1, d1,
                               d1});
  if (scene.wall_begin() >= Impl::kPolygonsForAGrid && m.polygon_grid_scene != scene.generation()) {
    std::vector<BoxBounds> boxes;
    for (const auto& b : scene.polygon_boxes().first(scene.wall_begin()))
      boxes.push_back({b.xmin, b.ymin, b.xmax, b.ymax});
    m.polygon_grid = BoxGrid(boxes, 1024);
    m.polygon_grid_scene = scene.generation();
  }
}

void FtcIndex::query_all(std::span<FtcHit> out, Executor& ex, QueryStats& stats) const {
  const Impl& m = *impl_;
  const auto& order = m.agent_tree.perm();
  std::mutex mu;
  Counters total;
  ex.for_each_chunk(order.size(), 256, [&](std::size_t begin, std::size_t end) {
    ProbeScratch sc;
    Counters c;
    for (std::size_t i = begin; i < end; ++i) {
      const auto pos = static_cast<uint32_t>(i);
      out[order[i]] = m.probe(order[i], pos, sc, c);
    }
    std::lock_guard lock(mu);  // integer sums: the total does not depend on the order
    total.pair_tests += c.pair_tests;
    total.visited += c.visited;
    total.pushes += c.pushes;
    total.pops += c.pops;
  });
  stats.rows += order.size();
  stats.pair_tests += total.pair_tests;
  stats.nodes_visited += total.visited;
  stats.queue_pushes += total.pushes;
  stats.queue_pops += total.pops;
}

FtcHit FtcIndex::query(std::size_t row, QueryStats* stats) const {
  Counters c;
  const auto r = static_cast<uint32_t>(row);
  const FtcHit h = impl_->probe(r, impl_->agent_tree.pos_of(r), impl_->scratch, c);
  if (stats) {
    stats->rows += 1;
    stats->pair_tests += c.pair_tests;
    stats->nodes_visited += c.visited;
    stats->queue_pushes += c.pushes;
    stats->queue_pops += c.pops;
  }
  return h;
}

void FtcIndex::run(const DiscView& discs, const StaticScene& scene, double horizon,
                   std::span<FtcHit> out, Executor& ex, QueryStats& stats) {
  Stopwatch sw;
  build(discs, scene, horizon, &ex);
  stats.build_seconds += sw.seconds();
  sw.restart();
  query_all(out, ex, stats);
  stats.query_seconds += sw.seconds();
}

std::string FtcIndex::validate() const {
  const Impl& m = *impl_;
  std::string s = m.agent_tree.validate(m.frame);
  if (s.empty()) s = m.circle_tree.validate(m.frame);
  return s;
}

std::size_t FtcIndex::node_count() const {
  return impl_->agent_tree.node_count();
}
bool FtcIndex::uses_chord_bound() const {
  return impl_->frame.chord;
}
bool FtcIndex::assume_no_overlaps(bool yes) {
  impl_->no_overlaps = yes;
  return true;
}
bool FtcIndex::refitted() const {
  return impl_->refitted;
}
const FtcIndexOptions& FtcIndex::options() const {
  return impl_->opt;
}

}  // namespace crowddb
