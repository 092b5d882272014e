// The neighbour query of the steering models (k nearest within a range; all within a range), the
// grid index against the naive scan, on uniform pedestrian crowds (radius 0.25 m) at densities of
// 0.5 and 2 people per square metre. Counters: neighbours found and a checksum of the lists (a
// fast wrong change shows).
//
//   build/bench/neighbour_bench --benchmark_filter='grid/knn/20000' --benchmark_repetitions=5
//   build/bench/neighbour_bench --benchmark_filter='/small/'   (naive-to-grid crossover)
#include <benchmark/benchmark.h>

#include <cmath>
#include <string>

#include "index/neighbour_grid.hpp"
#include "query/naive_paths.hpp"
#include "scenario/builders.hpp"
#include "util/executor.hpp"

namespace {

using namespace crowddb;

DiscTable crowd(std::size_t n, double density) {
  const double side = std::sqrt(static_cast<double>(n) / density);
  return build::uniform(n, build::Box{0, 0, side, side}, 1.3, 0.25, 0.25, 7 + n);
}

// kind 0: k nearest (k = 10 within 5 m, orca's defaults); kind 1: all within 3 m (cfsm's).
void run(benchmark::State& state, NeighbourPath& path, int kind) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const double density = static_cast<double>(state.range(1)) / 10;
  const DiscTable t = crowd(n, density);
  Executor ex(static_cast<int>(state.range(2)));
  NeighbourLists out;
  QueryStats st;
  for (auto _ : state) {
    path.run(t.view(), {}, kind == 0 ? 5.0 : 3.0, kind == 0 ? 10 : 0, out, ex, st);
    benchmark::DoNotOptimize(out.row.data());
  }
  uint64_t sum = 0;
  for (std::size_t a = 0; a < out.row.size(); ++a) sum = sum * 31 + out.row[a];
  state.counters["neighbours"] = static_cast<double>(out.row.size());
  state.counters["checksum"] = static_cast<double>(sum % 1000003);
}

void BM_Grid(benchmark::State& s, int kind) {
  index::NeighbourGrid g;
  run(s, g, kind);
}
void BM_Naive(benchmark::State& s, int kind) {
  NeighbourNaive g;
  run(s, g, kind);
}

}  // namespace

// Args: n, density x 10 (people per m^2), threads.
BENCHMARK_CAPTURE(BM_Grid, knn, 0)
    ->Name("grid/knn")
    ->ArgsProduct({{1000, 20000, 100000}, {5, 20}, {1, 2}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Grid, all, 1)
    ->Name("grid/all")
    ->ArgsProduct({{1000, 20000}, {5, 20}, {1}})
    ->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Naive, knn, 0)
    ->Name("naive/knn")
    ->Args({1000, 5, 1})
    ->Unit(benchmark::kMillisecond);
// The crossover the planner's auto_min_rows comes from.
BENCHMARK_CAPTURE(BM_Grid, small, 0)
    ->Name("grid/small")
    ->ArgsProduct({{16, 32, 48, 64, 96, 128}, {5}, {1}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Naive, small, 0)
    ->Name("naive/small")
    ->ArgsProduct({{16, 32, 48, 64, 96, 128}, {5}, {1}})
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_MAIN();
