// The catalogue of access paths, and the planner's rule for "auto". Adding an index means adding
// one entry here; no stage of the tick changes.
#include <algorithm>

#include "index/collisions_delaunay.hpp"
#include "index/collisions_grid.hpp"
#include "index/collisions_nn.hpp"
#include "index/collisions_sweep.hpp"
#include "index/feature_grid.hpp"
#include "index/field_bh.hpp"
#include "index/field_index.hpp"
#include "index/ftc_tree.hpp"
#include "index/neighbour_grid.hpp"
#include "plan/access_path.hpp"
#include "query/naive_paths.hpp"

namespace crowddb {
namespace {

template <class M>
std::string choices(const std::vector<M>& registry) {
  std::string s;
  for (const auto& m : registry) s += (s.empty() ? "" : ", ") + m.info.name;
  return s + (s.empty() ? "" : ", ") + "auto";
}

template <class M>
const M* by_name(const std::vector<M>& registry, std::string_view name) {
  for (const auto& m : registry)
    if (m.info.name == name) return &m;
  return nullptr;
}

// Highest auto_rank among the applicable methods; naive (rank 0, min 0) always applies.
template <class M, class Ok>
const M& pick(const std::vector<M>& registry, std::size_t rows, Ok ok) {
  const M* best = &registry.front();
  for (const auto& m : registry)
    if (m.info.in_auto && m.info.exact && rows >= m.info.auto_min_rows && ok(m) &&
        m.info.auto_rank > best->info.auto_rank)
      best = &m;
  return *best;
}

}  // namespace

const std::vector<FtcMethod>& ftc_registry() {
  static const std::vector<FtcMethod> methods = {
      {{"naive", "nested loop over all pairs, O(n^2)"},
       [] { return std::make_unique<FtcNaive>(); }},
      // auto_min_rows = 64, measured with build/bench/ftc_bench (BM_BuildQuery vs BM_Naive,
      // single thread, medians of 5, load ~7.5 on 2 cores): build + all queries against the nested
      // loop at n = 16 / 32 / 64 / 128 agents: 1.6 / 3.8 / 11.4 / 26 us vs 1.0 / 5.0 / 18.6 / 137
      // us at the E1 density, 2.0 / 5.4 / 12.8 / 31 us vs 1.2 / 4.7 / 17.8 / 133 us on the 640 x
      // 480 plane. The index wins from about 32 rows; 64 leaves a margin for noise.
      {{"index", "kinetic k-d tree, exact best-first search (src/index/ftc_tree.hpp)", true, 1, 64},
       [] { return std::make_unique<FtcIndex>(); }},
  };
  return methods;
}

const std::vector<FieldMethod>& field_registry() {
  static const std::vector<FieldMethod> methods = {
      {{"naive", "nested loop over all pairs, O(n^2)"},
       [](const PotentialSpec&) { return true; },
       [] { return std::make_unique<FieldNaive>(); }},
      // auto_min_rows 20: the index overtakes the naive loop between 16 and 24 rows (medians of
      // 3 repetitions of bench/field_bench BM_FieldCrossover*, exp-l1, n agents on an n x n
      // board: 16 rows 4.0 vs 3.4 us, 24 rows 5.3 vs 8.3 us, single-threaded, load ~8).
      {{"index", "exact separable aggregate index (exp-l1, exp-radial m <= 2), O(n log n)", true, 2,
        20},
       [](const PotentialSpec& s) { return field_index_supports(s); },
       [] { return std::make_unique<FieldIndex>(); }},
      // cutoff: any exp kernel; direct pairs within the halo beyond which all terms together stay
      // below 2.4e-16 A c_max^2 (exact within tolerance). While the world is smaller than two
      // halos it is one tile: the naive loop plus overhead. auto_min_rows 400: bench/field_bench
      // BM_FieldCutoffCrossover* (exp-l2, thesis k, n on n x n), medians of 3: 256 rows 1.00 vs
      // 0.83 ms, 384 rows 1.6 vs 1.8 ms, 512 rows 1.8 vs 3.4 ms (single-threaded, load ~9).
      {{"cutoff", "exp kernels: direct pairs within the negligible-tail halo, O(n * neighbours)",
        true, 1, 400},
       [](const PotentialSpec& s) { return field_cutoff_supports(s); },
       [] { return std::make_unique<FieldIndex>(FieldIndex::Mode::cutoff); }},
      // bh: approximate (worst case 22% of S_abs on the potential, see field_bh.cpp): only by name.
      {{"bh", "inv kernels: Barnes-Hut monopoles, theta 0.1, approximate with a stated bound",
        false, 0, 0, false},
       [](const PotentialSpec& s) { return field_bh_supports(s); },
       [] { return std::make_unique<FieldBarnesHut>(); }},
  };
  return methods;
}

const std::vector<CollisionMethod>& collision_registry() {
  static const std::vector<CollisionMethod> methods = {
      {{"naive", "nested loop over all pairs, O(n^2)"},
       [](const CollisionQueryShape&) { return true; },
       [] { return std::make_unique<CollisionNaive>(); }},
      // auto_min_rows: where each overtakes the nested loop (bench/collisions_bench, small/*:
      // grid and nn from ~64 rows, sweep from ~128). nn ranks first on request of the design
      // (thesis §3.2) although it measures 1.0-1.4x slower than grid: it only ever serves where
      // it is exact (equal radii, and a tick that starts overlap-free: need_all_pairs false).
      {{"grid", "uniform grid, cell = 2 x max radius per radius class, O(n + k)", true, 2, 64},
       [](const CollisionQueryShape&) { return true; },
       [] { return std::make_unique<index::CollisionGrid>(); }},
      {{"sweep", "plane sweep over bounding boxes with exact check, O(n log n + k)", true, 1, 128},
       [](const CollisionQueryShape&) { return true; },
       [] { return std::make_unique<index::CollisionSweep>(); }},
      {{"nn", "nearest neighbour per agent, equal radii only; gives the set, not every pair", true,
        3, 64},
       [](const CollisionQueryShape& s) { return s.equal_radii && !s.need_all_pairs; },
       [] { return std::make_unique<index::CollisionNn>(); }},
      {{"delaunay", "Delaunay edges plus diagonals (CGAL), heuristic: may miss pairs", false, 0, 0,
        false},
       [](const CollisionQueryShape&) { return true; },
       [] { return std::make_unique<index::CollisionDelaunay>(); }},
  };
  return methods;
}

const std::vector<NeighbourMethod>& neighbour_registry() {
  static const std::vector<NeighbourMethod> methods = {
      {{"naive", "scan of all rows per query, O(n) each"},
       [] { return std::make_unique<NeighbourNaive>(); }},
      // auto_min_rows 64: see bench/neighbour_bench.cpp (the grid's build pays off from a few
      // dozen rows).
      {{"grid", "uniform grid, ring-by-ring k-nearest search with pruning, O(n + k) per tick", true,
        1, 64},
       [] { return std::make_unique<index::NeighbourGrid>(); }},
  };
  return methods;
}

const std::vector<FeatureMethod>& feature_registry() {
  static const std::vector<FeatureMethod> methods = {
      {{"naive", "every obstacle feature per query"},
       [] { return std::make_unique<FeatureNaive>(); }},
      {{"grid", "features bucketed into a uniform grid once per scene", true, 1, 16},
       [] { return std::make_unique<index::FeatureGrid>(); }},
  };
  return methods;
}

const FtcMethod& find_ftc_method(std::string_view name) {
  if (const auto* m = by_name(ftc_registry(), name)) return *m;
  throw Error(Error::Kind::usage, "unknown first-to-collide method '" + std::string(name) +
                                      "' (choose from " + choices(ftc_registry()) + ")");
}

const FieldMethod& find_field_method(std::string_view name, const PotentialSpec& spec) {
  const auto* m = by_name(field_registry(), name);
  if (!m)
    throw Error(Error::Kind::usage, "unknown field method '" + std::string(name) +
                                        "' (choose from " + choices(field_registry()) + ")");
  if (!m->supports(spec))
    throw Error(Error::Kind::usage,
                "field method '" + std::string(name) + "' does not support this kernel and metric");
  return *m;
}

const CollisionMethod& find_collision_method(std::string_view name,
                                             const CollisionQueryShape& shape) {
  const auto* m = by_name(collision_registry(), name);
  if (!m)
    throw Error(Error::Kind::usage, "unknown collision method '" + std::string(name) +
                                        "' (choose from " + choices(collision_registry()) + ")");
  if (!m->supports(shape)) {
    // Name the fact that rules it out, by asking the method about the query without it.
    CollisionQueryShape relaxed = shape;
    relaxed.equal_radii = true;
    std::string why;
    if (!shape.equal_radii && m->supports(relaxed))
      why = "it needs all agents to have the same radius";
    relaxed = shape;
    relaxed.need_all_pairs = false;
    if (why.empty() && shape.need_all_pairs && m->supports(relaxed))
      why = "it finds the collision set, not every overlapping pair, and this use needs every pair";
    if (why.empty()) why = m->info.description;
    throw Error(Error::Kind::usage, "collision method '" + std::string(name) +
                                        "' does not apply here: " + why + " (choose from " +
                                        choices(collision_registry()) + ")");
  }
  return *m;
}

const NeighbourMethod& find_neighbour_method(std::string_view name) {
  if (const auto* m = by_name(neighbour_registry(), name)) return *m;
  throw Error(Error::Kind::usage, "unknown neighbours method '" + std::string(name) +
                                      "' (choose from " + choices(neighbour_registry()) + ")");
}

const FeatureMethod& find_feature_method(std::string_view name) {
  if (const auto* m = by_name(feature_registry(), name)) return *m;
  throw Error(Error::Kind::usage, "unknown obstacle-features method '" + std::string(name) +
                                      "' (choose from " + choices(feature_registry()) + ")");
}

const NeighbourMethod& choose_neighbour_method(std::size_t rows) {
  return pick(neighbour_registry(), rows, [](const NeighbourMethod&) { return true; });
}

const FeatureMethod& choose_feature_method(std::size_t features) {
  return pick(feature_registry(), features, [](const FeatureMethod&) { return true; });
}

const NeighbourMethod& neighbour_method(std::string_view name, std::size_t rows) {
  return name == "auto" ? choose_neighbour_method(rows) : find_neighbour_method(name);
}

const FeatureMethod& feature_method(std::string_view name, std::size_t features) {
  return name == "auto" ? choose_feature_method(features) : find_feature_method(name);
}

const FtcMethod& choose_ftc_method(std::size_t rows) {
  return pick(ftc_registry(), rows, [](const FtcMethod&) { return true; });
}

const FieldMethod& choose_field_method(std::size_t rows, const PotentialSpec& spec) {
  return pick(field_registry(), rows, [&](const FieldMethod& m) { return m.supports(spec); });
}

const CollisionMethod& choose_collision_method(const CollisionQueryShape& shape) {
  return pick(collision_registry(), shape.rows,
              [&](const CollisionMethod& m) { return m.supports(shape); });
}

}  // namespace crowddb
