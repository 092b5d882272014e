// The steering queries of one tick, callable on their own (DESIGN.md §3-§5, §9).
//
// Each query has a naive access path (nested loops: the oracle) and, as the index issues land,
// indexed access paths behind the same interface. Methods are chosen by name ("naive", "index",
// "grid", ...) or left to the planner ("auto"). Results are identical across methods where
// DESIGN.md says exact (first-to-collide, collision sets) and within its tolerance for fields.
//
// Thread-safety: the free functions are re-entrant; they use `threads` threads internally.
#pragma once

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "crowddb/world.hpp"

namespace crowddb {

// Read-only view of moving discs (the agents) as columns. Indices read rows only through it
// and keep orderings and aggregates of their own, never copies of the table.
struct DiscView {
  std::size_t n = 0;
  const double* x = nullptr;
  const double* y = nullptr;
  const double* vx = nullptr;  // [length/tick]
  const double* vy = nullptr;
  const double* radius = nullptr;
  const double* charge = nullptr;
  const uint64_t* id = nullptr;  // public ids: tie-breaks and output order

  std::size_t count() const { return n; }
  static DiscView of(const AgentTable& t) {
    return {t.size(),    t.x.data(),      t.y.data(),      t.vx.data(),
            t.vy.data(), t.radius.data(), t.charge.data(), t.id.data()};
  }
};

// Owned disc columns, for callers that do not keep a World (the CLI's CSV input, tests,
// benchmarks, experiments). view() borrows them.
struct DiscTable {
  std::vector<double> x, y, vx, vy, radius, charge;
  std::vector<uint64_t> id;

  std::size_t size() const { return x.size(); }
  void push_back(uint64_t row_id, double px, double py, double pvx, double pvy, double r,
                 double c = 1) {
    id.push_back(row_id);
    x.push_back(px);
    y.push_back(py);
    vx.push_back(pvx);
    vy.push_back(pvy);
    radius.push_back(r);
    charge.push_back(c);
  }
  DiscView view() const {
    return {x.size(),  x.data(),      y.data(),      vx.data(),
            vy.data(), radius.data(), charge.data(), id.data()};
  }
};

// How static obstacles contribute charged points to the potential field.
enum class ObstacleCharges {
  centres,   // one charged point per circle at its centre (the thesis's model; `crowddb query
             // field`)
  boundary,  // circles and polygons sampled along their boundary
  none,      // no charged points: obstacles repel by their nearest geometry instead (thesis
             // model's default, ThesisParams::obstacle_repulsion)
};

class RingGrid;  // src/world/ring_grid.hpp

// Static obstacles in the form the queries use, with derived data (bounding boxes, charged
// points) computed once. Polygons are stored counter-clockwise.
class StaticScene {
 public:
  StaticScene() = default;
  // `spacing`: largest gap between charged points sampled along polygon edges (and circle
  // boundaries with ObstacleCharges::boundary); DESIGN.md: no larger than the smallest agent
  // radius.
  //
  // `walls`: the world's bounds as solid walls, appended to the polygons as four rectangles
  // outside the bounds (as thick as the world is wide, so nothing tunnels through them); their
  // charged points lie on the bounds only.
  StaticScene(std::vector<CircleObstacle> circles, std::vector<PolygonObstacle> polygons,
              double spacing, ObstacleCharges charges = ObstacleCharges::boundary,
              const Bounds* walls = nullptr);

  std::span<const CircleObstacle> circles() const { return circles_; }
  // The obstacle polygons followed by the wall polygons (rows >= wall_begin() are walls).
  std::span<const PolygonObstacle> polygons() const { return polygons_; }
  std::size_t wall_begin() const { return wall_begin_; }
  struct Box {
    double xmin, ymin, xmax, ymax;
  };
  std::span<const Box> polygon_boxes() const { return boxes_; }
  // Charged points for the potential field: obstacle circles and polygon edge samples.
  std::span<const double> point_x() const { return px_; }
  std::span<const double> point_y() const { return py_; }
  std::span<const double> point_charge() const { return pc_; }
  std::size_t point_count() const { return px_.size(); }
  bool empty() const { return circles_.empty() && polygons_.empty(); }
  // Obstacle features (circles, then every polygon edge): feature f < circles().size() is a
  // circle, the others are edges numbered polygon by polygon (first_edge(p) + e).
  std::size_t feature_count() const { return circles_.size() + edge_start_.back(); }
  std::size_t first_edge(std::size_t polygon) const {
    return circles_.size() + edge_start_[polygon];
  }
  // The polygon row and edge index of an edge feature (f >= circles().size()). O(1).
  std::pair<std::size_t, std::size_t> edge_of(std::size_t f) const {
    const std::size_t e = f - circles_.size(), p = edge_polygon_[e];
    return {p, e - edge_start_[p]};
  }
  // The endpoints of an edge feature (f >= circles().size()), in its polygon's order: the queries'
  // inner loops read them from one table instead of through the polygon's vertex list.
  struct Edge {
    Vec2 a, b;
  };
  const Edge& edge(std::size_t f) const { return edges_[f - circles_.size()]; }
  // Polygon p's edge grid (src/world/ring_grid.hpp) where it has many edges, else null: the
  // exact polygon tests through it (src/query/scene_polygons.hpp) read the edges near the
  // question. A walkable hall drawn with 20,000 vertices made its blocked pieces' tests loop over
  // every edge for every agent each tick.
  const RingGrid* ring_grid(std::size_t p) const { return grids_[p].get(); }
  // A distinct number for every scene built in this process: caches keyed by it (an index over
  // the features) never outlive the scene they were built for.
  uint64_t generation() const { return generation_; }

 private:
  std::vector<CircleObstacle> circles_;
  std::vector<PolygonObstacle> polygons_;
  std::vector<Box> boxes_;
  std::vector<double> px_, py_, pc_;
  std::size_t wall_begin_ = 0;
  std::vector<uint32_t> edge_start_ = {0};  // polygons().size() + 1 prefix sums of edge counts
  std::vector<uint32_t> edge_polygon_;      // per edge feature: its polygon row
  std::vector<Edge> edges_;                 // per edge feature: its endpoints
  std::vector<std::shared_ptr<const RingGrid>> grids_;  // per polygon (immutable: copies share)
  uint64_t generation_ = 0;
};

// Per-query counters; the experiments plot them. Methods fill what applies to them.
struct QueryStats {
  uint64_t rows = 0;           // query rows (agents probed)
  uint64_t pair_tests = 0;     // exact pair computations
  uint64_t nodes_visited = 0;  // index nodes expanded
  uint64_t queue_pushes = 0;
  uint64_t queue_pops = 0;
  double build_seconds = 0;  // index construction
  double query_seconds = 0;  // probes
  QueryStats& operator+=(const QueryStats& o);
};

// ---------------------------------------------------------------- first-to-collide (§5)

// Who a disc meets first. Agents by row of the DiscView, obstacles by row of their table.
struct Collider {
  enum class Kind : uint8_t { none = 0, agent = 1, circle = 2, polygon = 3 };
  Kind kind = Kind::none;
  uint32_t row = 0;
  friend bool operator==(Collider, Collider) = default;
};

// The ranges first-to-collide and the collision set accept. Inside them the pair arithmetic
// (squared distances, |v|^2 t^2) stays far from overflow, so every method is exact; outside, a
// product such as (2e160)^2 would overflow to infinity and a collision be missed, so such inputs
// are refused (Error::Kind::input naming the row and field) rather than answered wrongly.
// Coordinates and radii: |value| <= kMaxCoordinate (10^9 length units).
inline constexpr double kMaxQuerySpeed = 1e9;    // |vx|, |vy| [length/tick]
inline constexpr double kMaxQueryHorizon = 1e9;  // [ticks]

struct FtcHit {
  Collider with;           // kind none: no collision within the horizon
  double time = INFINITY;  // [ticks], in [0, horizon]; 0 when already overlapping
  friend bool operator==(const FtcHit&, const FtcHit&) = default;
};

// For each disc, the first agent or obstacle it collides with within `horizon` ticks, moving on
// rays p + v t. Ties in time go to agents before obstacles, then the smaller id (agents) or row
// (obstacles). Exact: every method returns the same hits. Inputs outside the ranges above (and a
// horizon outside [0, kMaxQueryHorizon]) throw Error::Kind::input.
std::vector<FtcHit> first_to_collide(const DiscView& discs, const StaticScene& scene,
                                     double horizon, std::string_view method = "auto",
                                     int threads = 1, QueryStats* stats = nullptr);

// ---------------------------------------------------------------- potential field (§4)

enum class Kernel { exp, inv };
enum class Metric { l1, l2, radial };

struct PotentialSpec {
  Kernel kernel = Kernel::exp;
  Metric metric = Metric::l1;
  double A = 0.929328;  // thesis values: A e^{-k x} fitted to 1/x
  double k = 0.272194;
  int radial_frames = 2;  // m rotated frames for the radial metric
  double inv_floor =
      0.1;  // inv kernel: distance floored here (> 0) so coincident points stay finite
  // The thesis's finite-difference gradient (§1.2) instead of the analytic one:
  // grad_x = (P(x + h, y) - P(x, y)) / h with h = fd_step, and likewise in y.
  bool finite_difference = false;
  double fd_step = 1e-3;
};

// Potential and its gradient with respect to the probe's position, per disc.
struct FieldColumns {
  std::vector<double> potential, grad_x, grad_y;
  void resize(std::size_t n) {
    potential.assign(n, 0.0);
    grad_x.assign(n, 0.0);
    grad_y.assign(n, 0.0);
  }
};

// P(p) = sum over q != p of A c_p c_q K(d(p, q)), over the other discs and the scene's charged
// points, with its analytic gradient (sign(0) = 0 for L1 terms, 0 at coincident points for L2).
FieldColumns potential_field(const DiscView& discs, const StaticScene& scene,
                             const PotentialSpec& spec, std::string_view method = "auto",
                             int threads = 1, QueryStats* stats = nullptr);

// The field that `sources` and the scene's charged points create, evaluated at arbitrary points
// (to draw it): potential[i] = sum over all sources q of A c_q K(d(points[i], q)) — a probe has
// unit charge and excludes nothing, so a probe on top of a source gets that source's K(0) term —
// with its gradient with respect to the probe's position (the same sign(0) = 0 conventions).
// Methods as potential_field ("naive", "index", "auto"); spec.finite_difference is honoured.
// Throws Error(input) when a point is not finite, Error(usage) for an unknown method or one that
// does not support the spec.
FieldColumns field_at(std::span<const Vec2> points, const DiscView& sources,
                      const StaticScene& scene, const PotentialSpec& spec,
                      std::string_view method = "auto", int threads = 1,
                      QueryStats* stats = nullptr);

// Least-squares fit of A e^{-k x} to alpha / x on [from, to] (DESIGN.md §4), so users can pick
// their own kernel constants. samples = 0: the continuous L2 norm, the integral over [from, to]
// of (A e^{-k x} - alpha / x)^2 dx by composite Gauss-Legendre quadrature; samples >= 2: the sum
// over that many equally spaced points (both ends included). For fixed k the best A is linear
// (closed form), so k alone is searched: a log-spaced bracketing scan, golden-section search,
// then bisection on the sign of the derivative of the reduced objective.
// Throws Error(usage) unless 0 < from < to, both finite, alpha > 0 finite, samples 0 or >= 2.
struct KernelFit {
  double A = 0, k = 0;
  double max_abs_error = 0;  // max |A e^{-k x} - alpha/x| on a dense grid of [from, to]
  double max_rel_error = 0;  // max of |A e^{-k x} - alpha/x| / (alpha/x) on that grid
  double rms_error = 0;  // root mean square error in the fitted norm (per unit length or sample)
};
KernelFit fit_exp_kernel(double from, double to, double alpha = 1.0, int samples = 0);

// ---------------------------------------------------------------- collision sets (§3.2)

// Overlapping pairs: discs overlap when the distance of centres is < the sum of radii; a disc
// overlaps a circle obstacle likewise and a polygon when its centre is inside or its boundary
// is closer than the radius.
struct CollisionPairs {
  std::vector<std::pair<uint32_t, uint32_t>> agents;     // (i, j) rows, i < j, sorted
  std::vector<std::pair<uint32_t, Collider>> obstacles;  // (agent row, obstacle), sorted
  void clear() {
    agents.clear();
    obstacles.clear();
  }
};

// The rows of discs that overlap another disc or an obstacle, sorted. Inputs outside the ranges of
// first-to-collide throw Error::Kind::input.
std::vector<uint32_t> collision_set(const DiscView& discs, const StaticScene& scene,
                                    std::string_view method = "auto", int threads = 1,
                                    QueryStats* stats = nullptr);

// ---------------------------------------------------------------- neighbours (steering models)

// Lists per query row, nearest first: the neighbours of query q are entries
// [offset[q], offset[q + 1]).
struct NeighbourLists {
  std::vector<uint32_t> offset;  // queries + 1
  std::vector<uint32_t> row;     // rows of the DiscView
  std::vector<double> dist2;     // squared distance of centres [m^2]; empty if !with_dist2
  // Set by the caller before a run: false leaves dist2 empty, for a caller that recomputes the
  // distances it needs from the positions (the k-nearest lists of 10^6 agents with k = 10 hold
  // 80 MB of them).
  bool with_dist2 = true;
  std::size_t queries() const { return offset.empty() ? 0 : offset.size() - 1; }
  std::span<const uint32_t> rows_of(std::size_t q) const {
    return {row.data() + offset[q], row.data() + offset[q + 1]};
  }
};

// For each query disc (the rows in `queries`, or every row when it is empty), the other discs
// whose centres lie strictly closer than `range`: the k nearest of them (all when k = 0), nearest
// first, ties in distance by the smaller id. Exact: every method returns the same lists.
NeighbourLists neighbours(const DiscView& discs, double range, uint32_t k,
                          std::span<const uint32_t> queries = {}, std::string_view method = "auto",
                          int threads = 1, QueryStats* stats = nullptr);

// ---------------------------------------------------------------- obstacle features

// Per query point, the obstacle features (StaticScene::feature_count numbering) strictly closer
// than its reach, in feature order, with their squared distances (feature_dist2).
struct FeatureLists {
  std::vector<uint32_t> offset;   // queries + 1
  std::vector<uint32_t> feature;  // feature numbers, ascending per query
  std::vector<double> dist2;      // [m^2]
  std::size_t queries() const { return offset.empty() ? 0 : offset.size() - 1; }
};

// Squared distance from (px, py) to feature f: to a circle's disc (0 inside), to an edge's
// segment. The one primitive every method calls, so "exact" comparisons are meaningful.
double feature_dist2(const StaticScene& scene, std::size_t f, double px, double py);
// The closest point of feature f to (px, py) (a circle's boundary point; the point itself at its
// centre).
Vec2 feature_closest(const StaticScene& scene, std::size_t f, double px, double py);

// For each point (the centres of `points`), the features closer than reach[i] (reach has one
// entry per point, each >= 0). Exact: every method returns the same lists.
FeatureLists obstacle_features(const DiscView& points, std::span<const double> reach,
                               const StaticScene& scene, std::string_view method = "auto",
                               int threads = 1, QueryStats* stats = nullptr);

// Names of the registered methods of each query, naive first.
std::vector<std::string> ftc_methods();
std::vector<std::string> field_methods();
std::vector<std::string> collision_methods();
std::vector<std::string> neighbour_methods();
std::vector<std::string> feature_methods();

}  // namespace crowddb
