// Potential field, E5 setup (DESIGN.md §7): n agents on an n x n board, 3 obstacles per 125
// agents (charged points at their centres), A = 0.929328, k = 0.272194, potential + gradient
// for every agent, single-threaded. Counters: `checksum` (sum of potentials: a fast wrong change
// shows), `s_per_Magent` (= microseconds per agent).
//
//   build/bench/field_bench --benchmark_filter='Index'            # 10^3 .. 10^6
//   build/bench/field_bench --benchmark_filter='Crossover'        # small n: index vs naive
//   build/bench/field_bench --benchmark_filter='L2'               # exp-l2: cutoff vs naive
//   build/bench/field_bench --benchmark_filter='InvL2'            # inv-l2: Barnes-Hut vs naive
#include <benchmark/benchmark.h>

#include <map>
#include <memory>

#include "crowddb/query.hpp"
#include "scenario/builders.hpp"

namespace crowddb {
namespace {

struct Fixture {
  build::FieldWorld world;
  StaticScene scene;
};

const Fixture& fixture(std::size_t n) {
  static std::map<std::size_t, std::unique_ptr<Fixture>> cache;
  auto& f = cache[n];
  if (!f) {
    f = std::make_unique<Fixture>();
    f->world = build::e5_world(n, 2024);
    f->scene = StaticScene(f->world.obstacles, {}, 1.0, ObstacleCharges::centres);
  }
  return *f;
}

PotentialSpec spec(Metric metric, Kernel kernel) {
  PotentialSpec s;
  s.metric = metric;
  s.kernel = kernel;
  if (kernel == Kernel::inv) s.A = 1;
  return s;
}

void run(benchmark::State& state, const char* method, Metric metric, Kernel kernel = Kernel::exp) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const Fixture& f = fixture(n);
  const PotentialSpec s = spec(metric, kernel);
  double checksum = 0;
  for (auto _ : state) {
    const FieldColumns out = potential_field(f.world.agents.view(), f.scene, s, method, 1);
    checksum = 0;
    for (double p : out.potential) checksum += p;
    benchmark::DoNotOptimize(checksum);
  }
  state.counters["checksum"] = checksum;
  // Seconds per million agents (benchmark prints it with an "s" suffix) = microseconds per agent.
  state.counters["s_per_Magent"] =
      benchmark::Counter(static_cast<double>(state.iterations()) * static_cast<double>(n) / 1e6,
                         benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
}

void BM_FieldIndexL1(benchmark::State& s) {
  run(s, "index", Metric::l1);
}
void BM_FieldIndexRadial(benchmark::State& s) {
  run(s, "index", Metric::radial);
}
void BM_FieldNaiveL1(benchmark::State& s) {
  run(s, "naive", Metric::l1);
}
void BM_FieldCrossoverIndex(benchmark::State& s) {
  run(s, "index", Metric::l1);
}
void BM_FieldCrossoverNaive(benchmark::State& s) {
  run(s, "naive", Metric::l1);
}

void BM_FieldCutoffL2(benchmark::State& s) {
  run(s, "cutoff", Metric::l2);
}
void BM_FieldNaiveL2(benchmark::State& s) {
  run(s, "naive", Metric::l2);
}
void BM_FieldCutoffCrossoverCutoff(benchmark::State& s) {
  run(s, "cutoff", Metric::l2);
}
void BM_FieldCutoffCrossoverNaive(benchmark::State& s) {
  run(s, "naive", Metric::l2);
}

// Small to medium n for the cutoff's planner threshold: below a board of ~2 halos (n ~ 300 for
// the thesis's k) the cutoff is one tile, i.e. the naive loop plus its overhead.
void cutoff_sizes(benchmark::internal::Benchmark* b) {
  for (int n : {16, 32, 64, 128, 256, 384, 512, 768, 1000, 2000}) b->Arg(n);
}

void BM_FieldBhInvL2(benchmark::State& s) {
  run(s, "bh", Metric::l2, Kernel::inv);
}
void BM_FieldNaiveInvL2(benchmark::State& s) {
  run(s, "naive", Metric::l2, Kernel::inv);
}

BENCHMARK(BM_FieldIndexL1)
    ->RangeMultiplier(10)
    ->Range(1000, 1000000)
    ->Arg(20000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FieldIndexRadial)
    ->RangeMultiplier(10)
    ->Range(1000, 1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FieldNaiveL1)->Arg(1000)->Arg(10000)->Arg(20000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FieldCrossoverIndex)
    ->Arg(4)
    ->Arg(8)
    ->Arg(12)
    ->Arg(16)
    ->Arg(24)
    ->Arg(32)
    ->Arg(64)
    ->Arg(128)
    ->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FieldCrossoverNaive)
    ->Arg(4)
    ->Arg(8)
    ->Arg(12)
    ->Arg(16)
    ->Arg(24)
    ->Arg(32)
    ->Arg(64)
    ->Arg(128)
    ->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_FieldCutoffL2)
    ->RangeMultiplier(10)
    ->Range(1000, 1000000)
    ->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FieldNaiveL2)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FieldCutoffCrossoverCutoff)->Apply(cutoff_sizes)->Unit(benchmark::kMicrosecond);
BENCHMARK(BM_FieldCutoffCrossoverNaive)->Apply(cutoff_sizes)->Unit(benchmark::kMicrosecond);

BENCHMARK(BM_FieldBhInvL2)->RangeMultiplier(10)->Range(1000, 100000)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_FieldNaiveInvL2)->Arg(1000)->Arg(10000)->Unit(benchmark::kMillisecond);

}  // namespace
}  // namespace crowddb

BENCHMARK_MAIN();
