// Access paths: the interchangeable operators behind each steering query. A stage of the tick
// asks the plan for the access path of its query and calls run(); it never knows whether the
// rows come from a nested loop or an index. New methods register in registry.cpp only.
//
// An access path object holds per-run state (index storage, scratch buffers) reused from tick
// to tick; it is used by one tick at a time. run() may use the executor's threads but must give
// the same output whatever the thread count.
#pragma once

#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "crowddb/query.hpp"
#include "util/executor.hpp"

namespace crowddb {

namespace index {
class DiscGrid;
}

class FtcPath {
 public:
  virtual ~FtcPath() = default;
  // out[i] = the first collider of disc i within `horizon` (DESIGN.md §5), for every disc.
  virtual void run(const DiscView& discs, const StaticScene& scene, double horizon,
                   std::span<FtcHit> out, Executor& ex, QueryStats& stats) = 0;
  // A hint for the runs that follow, until withdrawn: no two discs overlap at t = 0 (closer than
  // the sum of their radii), as the engine knows at the start of a tick after one whose backoff
  // left no overlapping pair (and no insert since). A method may then skip work that only pays
  // where many overlap. It changes the cost only: the answers are the same with or without it,
  // true or not. Off by default. Returns whether the method acts on the hint (EXPLAIN ANALYZE
  // counts the ticks on which it did).
  virtual bool assume_no_overlaps(bool /*yes*/) { return false; }
};

class FieldPath {
 public:
  virtual ~FieldPath() = default;
  // Potential and gradient at every disc over the other discs and the scene's charged points.
  virtual void run(const DiscView& discs, const StaticScene& scene, const PotentialSpec& spec,
                   FieldColumns& out, Executor& ex, QueryStats& stats) = 0;
  // The field of `sources` and the scene at arbitrary points (unit probe charge, no exclusion:
  // see crowddb::field_at). Methods that cannot probe keep this default, which throws Error(usage).
  virtual void probe(std::span<const Vec2> points, const DiscView& sources,
                     const StaticScene& scene, const PotentialSpec& spec, FieldColumns& out,
                     Executor& ex, QueryStats& stats);
};

class CollisionPath {
 public:
  virtual ~CollisionPath() = default;
  // All overlapping pairs among the discs and between discs and obstacles (exact methods), or
  // the pairs the method finds (heuristics, which may miss some but never invent one).
  virtual void run(const DiscView& discs, const StaticScene& scene, CollisionPairs& out,
                   Executor& ex, QueryStats& stats) = 0;
  // The index the last run built over its discs, when the method keeps one that answers
  // DiscGrid's overlap probes (the freeze loop then probes it rather than build its own);
  // nullptr otherwise. Valid until the next run; it holds the discs as they were then.
  virtual const index::DiscGrid* disc_grid() const { return nullptr; }
};

class NeighbourPath {
 public:
  virtual ~NeighbourPath() = default;
  // out = the neighbour lists of the query rows (all rows when `queries` is empty): the k
  // nearest other discs strictly within `range` (all when k = 0), nearest first, ties by id.
  virtual void run(const DiscView& discs, std::span<const uint32_t> queries, double range,
                   uint32_t k, NeighbourLists& out, Executor& ex, QueryStats& stats) = 0;
  // The table's rows were permuted (order[new row] = old row) since the last run: a method that
  // keeps per-row state across runs (the grid's hints) carries it along, on `ex`'s threads when
  // given. Never changes a result. Runs beside the table's own permutation: reads nothing of it.
  virtual void rows_permuted(std::span<const uint32_t> /*order*/, Executor* /*ex*/ = nullptr) {}
};

// Lists a NeighbourPath returned, with what it was asked: for every row of the table it ran over,
// the `k` nearest other rows (all when k = 0) whose centres lie strictly closer than `range`,
// nearest first. So a row's list holds every row strictly closer than its bound: `range` when
// the list is shorter than k (or k = 0), else the distance of its k-th. A steering model offers
// its tick's lists (steer::Model::near_lists) to the backoff, which can rule overlaps out from
// them without a collision query (sim/backoff.cpp).
struct NearLists {
  const NeighbourLists* lists = nullptr;  // null: none this tick
  double range = 0;
  uint32_t k = 0;
};

class FeaturePath {
 public:
  virtual ~FeaturePath() = default;
  // out = per point of `points`, the scene's obstacle features closer than reach[i], ascending.
  virtual void run(const DiscView& points, std::span<const double> reach, const StaticScene& scene,
                   FeatureLists& out, Executor& ex, QueryStats& stats) = 0;
};

// What the planner knows about a registered method.
struct MethodInfo {
  std::string name;
  std::string description;  // shown by EXPLAIN
  bool exact = true;        // returns exactly the naive result (within tolerance for fields)
  // The planner picks, among the exact methods whose `supports` accepts the query, the one with
  // the highest rank whose auto_min_rows <= rows. Naive has rank 0 and min 0.
  int auto_rank = 0;
  std::size_t auto_min_rows = 0;
  bool in_auto = true;  // false: only when forced by name
};

struct FtcMethod {
  MethodInfo info;
  std::function<std::unique_ptr<FtcPath>()> make;
};

struct FieldMethod {
  MethodInfo info;
  std::function<bool(const PotentialSpec&)> supports;
  std::function<std::unique_ptr<FieldPath>()> make;
};

// Facts about the discs a collision method may depend on.
struct CollisionQueryShape {
  std::size_t rows = 0;
  bool equal_radii = false;
  // The consumer needs every overlapping pair, not just the collision set: overlap counts, or a
  // backoff that must tell new overlaps from pairs that already overlapped at the start of the
  // tick. Methods that return only the set exactly (nn) do not support such queries.
  bool need_all_pairs = false;
};

struct CollisionMethod {
  MethodInfo info;
  std::function<bool(const CollisionQueryShape&)> supports;
  std::function<std::unique_ptr<CollisionPath>()> make;
};

struct NeighbourMethod {
  MethodInfo info;
  std::function<std::unique_ptr<NeighbourPath>()> make;
};

struct FeatureMethod {
  MethodInfo info;
  std::function<std::unique_ptr<FeaturePath>()> make;
};

const std::vector<FtcMethod>& ftc_registry();
const std::vector<FieldMethod>& field_registry();
const std::vector<CollisionMethod>& collision_registry();
const std::vector<NeighbourMethod>& neighbour_registry();
const std::vector<FeatureMethod>& feature_registry();

// Lookup by name; throws Error(usage) naming the valid choices when unknown.
const FtcMethod& find_ftc_method(std::string_view name);
const FieldMethod& find_field_method(std::string_view name, const PotentialSpec& spec);
const CollisionMethod& find_collision_method(std::string_view name,
                                             const CollisionQueryShape& shape);
const NeighbourMethod& find_neighbour_method(std::string_view name);
const FeatureMethod& find_feature_method(std::string_view name);

// The planner's choice for "auto".
const FtcMethod& choose_ftc_method(std::size_t rows);
const FieldMethod& choose_field_method(std::size_t rows, const PotentialSpec& spec);
const CollisionMethod& choose_collision_method(const CollisionQueryShape& shape);
const NeighbourMethod& choose_neighbour_method(std::size_t rows);
const FeatureMethod& choose_feature_method(std::size_t features);
// "auto" or a name -> the method (throws Error(usage) for an unknown name).
const NeighbourMethod& neighbour_method(std::string_view name, std::size_t rows);
const FeatureMethod& feature_method(std::string_view name, std::size_t features);

}  // namespace crowddb
