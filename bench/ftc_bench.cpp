// First-to-collide: index build and query against the naive nested loop (issue 3).
//
//   build/bench/ftc_bench [--benchmark_filter=...]
//
// Worlds: uniform at the E1 density (15,000 agents on 640 x 480; the plane grows with n so the
// density stays), the Big Crunch and the perturbed Big Crunch at the same density, |v| <= 50,
// radius in [1, 3], horizon 30. Single thread. Counters per query: nodes visited, queue pops and
// pushes, exact pair tests; `hash` is a checksum of the answers so a fast wrong change shows.
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstring>
#include <map>
#include <tuple>
#include <vector>

#include "index/ftc_tree.hpp"
#include "query/naive_paths.hpp"
#include "scenario/builders.hpp"

namespace crowddb {
namespace {

constexpr double kHorizon = 30;

enum World { uniform_w = 0, crunch_w = 1, perturbed_w = 2, plane_w = 3 };

build::Box e1_box(std::size_t n) {
  const double s = std::sqrt(static_cast<double>(n) / 15000.0);
  return {0, 0, 640 * s, 480 * s};
}

const DiscTable& world(int kind, std::size_t n) {
  static std::map<std::pair<int, std::size_t>, DiscTable> cache;
  auto it = cache.find({kind, n});
  if (it != cache.end()) return it->second;
  DiscTable t;
  switch (kind) {
    case uniform_w:
      t = build::uniform(n, e1_box(n), 50, 1, 3, 1);
      break;
    case crunch_w:
      t = build::big_crunch(n, e1_box(n), 20, 1, 3, 0, 1);
      break;
    default:
      t = build::big_crunch(n, e1_box(n), 20, 1, 3, 1, 1);
      break;
  }
  return cache.emplace(std::pair{kind, n}, std::move(t)).first->second;
}

uint64_t checksum(const std::vector<FtcHit>& hits) {
  uint64_t h = 1469598103934665603ull;
  for (const FtcHit& x : hits) {
    uint64_t bits;
    std::memcpy(&bits, &x.time, sizeof bits);
    h = (h ^ (bits + x.with.row * 4 + static_cast<uint64_t>(x.with.kind))) * 1099511628211ull;
  }
  return h;
}

FtcIndexOptions options_for(int variant) {
  using O = FtcIndexOptions;
  O o;
  switch (variant) {
    case 1:
      o.bound = O::Bound::frustum;
      break;
    case 2:
      o.order = O::Order::best_first;
      break;
    case 3:
      o.slices = 1;
      break;
    case 4:
      o.slices = 2;
      break;
    case 5:
      o.order = O::Order::nearer_first;
      break;
    case 6:
      o.order = O::Order::bottom_up;
      break;
    case 7:
      o.overlaps_first = false;
      break;
    case 9:
      o.overlap_join = false;
      break;  // overlaps by the tree search (before the join)
    case 8:   // the thesis's search made exact
      o = {.leaf_size = 1,
           .bound = O::Bound::frustum,
           .slices = 1,
           .order = O::Order::best_first,
           .seed_own_leaf = false,
           .overlaps_first = false};
      break;
    default:
      if (variant >= 100) o.leaf_size = static_cast<std::size_t>(variant - 100);  // leaf sweeps
      break;
  }
  // Built on every run: the same table again and again is no tick sequence, and BM_Build
  // measures builds (a refit, rebuild_every, is the tick's business: bench/tick_speed).
  o.rebuild_every = 1;
  return o;
}

void report(benchmark::State& state, const QueryStats& st, std::size_t n, uint64_t hash,
            double iters) {
  const double q = static_cast<double>(n) * iters;
  state.counters["nodes/q"] = static_cast<double>(st.nodes_visited) / q;
  state.counters["pops/q"] = static_cast<double>(st.queue_pops) / q;
  state.counters["pushes/q"] = static_cast<double>(st.queue_pushes) / q;
  state.counters["pairs/q"] = static_cast<double>(st.pair_tests) / q;
  state.counters["hash"] = static_cast<double>(hash % 1000000007ull);
}

// Build only, on one thread.
void BM_Build(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const DiscTable& t = world(static_cast<int>(state.range(1)), n);
  const StaticScene scene;
  FtcIndex index(options_for(static_cast<int>(state.range(2))));
  for (auto _ : state) {
    index.build(t.view(), scene, kHorizon);
    benchmark::DoNotOptimize(index.node_count());
  }
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}

// All queries on a built index.
void BM_Query(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const DiscTable& t = world(static_cast<int>(state.range(1)), n);
  const StaticScene scene;
  FtcIndex index(options_for(static_cast<int>(state.range(2))));
  index.build(t.view(), scene, kHorizon);
  Executor ex(1);
  std::vector<FtcHit> out(n);
  QueryStats st;
  for (auto _ : state) {
    index.query_all(out, ex, st);
    benchmark::DoNotOptimize(out.data());
  }
  report(state, st, n, checksum(out), static_cast<double>(state.iterations()));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}

// One tick's worth: build + all queries (the figure the targets are about).
void BM_BuildQuery(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const DiscTable& t = world(static_cast<int>(state.range(1)), n);
  const StaticScene scene;
  FtcIndex index(options_for(static_cast<int>(state.range(2))));
  Executor ex(1);
  std::vector<FtcHit> out(n);
  QueryStats st;
  for (auto _ : state) {
    index.run(t.view(), scene, kHorizon, out, ex, st);
    benchmark::DoNotOptimize(out.data());
  }
  report(state, st, n, checksum(out), static_cast<double>(state.iterations()));
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}

void BM_Naive(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const DiscTable& t = world(static_cast<int>(state.range(1)), n);
  const StaticScene scene;
  FtcNaive naive;
  Executor ex(1);
  std::vector<FtcHit> out(n);
  QueryStats st;
  for (auto _ : state) {
    naive.run(t.view(), scene, kHorizon, out, ex, st);
    benchmark::DoNotOptimize(out.data());
  }
  state.counters["hash"] = static_cast<double>(checksum(out) % 1000000007ull);
  state.SetItemsProcessed(static_cast<int64_t>(state.iterations() * n));
}

// Args: n, world (0 uniform, 1 Big Crunch, 2 perturbed: all at the E1 density; 3 uniform on the
// fixed 640 x 480 plane), variant (0 default: chord K = 4, leaf_queue, leaf 16; 1 frustum bound;
// 2 best-first order from the root; 3 K = 1; 4 K = 2; 5 nearer-first from the root; 6 bottom-up;
// 7 no overlap-first phase; 8 the thesis's search (frustum, best-first, one agent per leaf);
// 9 the overlap phase by the tree search instead of the leaf join;
// 100 + L: leaf size L).
void sizes(benchmark::internal::Benchmark* b) {
  for (int w : {uniform_w, crunch_w, perturbed_w})
    for (int64_t n : {1000, 15000, 100000, 1000000}) b->Args({n, w, 0});
  for (int v : {1, 2, 3, 4, 5, 6, 7, 8, 9})
    for (int w : {uniform_w, crunch_w, perturbed_w}) b->Args({15000, w, v});
  b->Unit(benchmark::kMillisecond);
}

BENCHMARK(BM_Build)->Apply(sizes);
BENCHMARK(BM_Query)->Apply(sizes);
BENCHMARK(BM_BuildQuery)->Apply(sizes);
// Small n, index against naive: where the planner's threshold (auto_min_rows) comes from.
BENCHMARK(BM_BuildQuery)
    ->ArgsProduct({{16, 32, 64, 128, 256, 512}, {uniform_w, plane_w}, {0}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_Naive)
    ->ArgsProduct({{16, 32, 64, 128, 256, 512}, {uniform_w, plane_w}})
    ->Unit(benchmark::kMicrosecond);

// Leaf-size sweep (variant 100 + leaf size) at n = 15,000: how the default leaf size was chosen.
BENCHMARK(BM_BuildQuery)
    ->ArgsProduct({{15000}, {uniform_w, crunch_w, perturbed_w}, {104, 108, 116, 124, 132, 148}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_Naive)
    ->ArgsProduct({{1000, 5000, 15000}, {uniform_w, crunch_w, perturbed_w}})
    ->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace crowddb

BENCHMARK_MAIN();
