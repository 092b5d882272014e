// Benchmarks of the sdf library: the repetitions vector (in memory and from a file), and the
// static, online and online-bounded schedulers on chains, trees and random cyclic graphs of 10^3
// to 10^6 actors. Fixed seeds; each benchmark reports a checksum counter of its result so that a
// fast wrong change shows.
//
//   build/bench/sdf/sdf_bench                         run everything
//   build/bench/sdf/sdf_bench --write-graphs DIR      write the 10^6-actor graphs (JSON, SDF3)
//                                                     for timing `sdfsched repetitions` by hand
#include <benchmark/benchmark.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>

#include "sdf/generate.hpp"
#include "sdf/io.hpp"
#include "sdf/naive.hpp"
#include "sdf/online.hpp"
#include "sdf/repetitions.hpp"
#include "sdf/schedule.hpp"

namespace {

using sdf::gen::Shape;

const char* kShapeNames[] = {"chain", "tree", "random"};

sdf::gen::Spec spec_for(int shape, uint32_t n) {
  sdf::gen::Spec s;
  s.actors = n;
  s.shape = shape == 0 ? Shape::chain : (shape == 1 ? Shape::fan_out : Shape::cyclic);
  s.extra_percent = 50;
  s.back_percent = 10;
  return s;
}

// Graphs are built once per (shape, size) and shared by the benchmarks.
const sdf::gen::Generated& graph(int shape, uint32_t n) {
  static std::map<std::pair<int, uint32_t>, sdf::gen::Generated> cache;
  auto it = cache.find({shape, n});
  if (it == cache.end()) {
    crowddb::Rng rng(1000 + static_cast<uint64_t>(shape));
    it = cache.emplace(std::pair{shape, n}, sdf::gen::generate(spec_for(shape, n), rng)).first;
  }
  return it->second;
}

uint64_t checksum(const std::vector<uint64_t>& v) {
  uint64_t h = 0;
  for (uint64_t x : v) h = h * 1000003 + x;
  return h;
}

void set_label(benchmark::State& state, int shape) {
  state.SetLabel(std::string(kShapeNames[shape]) + " " + std::to_string(state.range(1)) +
                 " actors");
}

void BM_Repetitions(benchmark::State& state) {
  const int shape = static_cast<int>(state.range(0));
  const auto& gg = graph(shape, static_cast<uint32_t>(state.range(1)));
  uint64_t sum = 0;
  for (auto _ : state) {
    const sdf::Repetitions r = sdf::compute_repetitions(gg.graph);
    if (!r.consistent || r.q != gg.q) state.SkipWithError("wrong repetitions vector");
    sum = checksum(r.q);
    benchmark::DoNotOptimize(sum);
  }
  state.counters["checksum"] = static_cast<double>(sum % 1000000);
  state.SetItemsProcessed(state.iterations() * state.range(1));
  set_label(state, shape);
}

// The plain walk (naive::repetitions, the first implementation), for the ratio in one run.
void BM_RepetitionsPlainWalk(benchmark::State& state) {
  const int shape = static_cast<int>(state.range(0));
  const auto& gg = graph(shape, static_cast<uint32_t>(state.range(1)));
  uint64_t sum = 0;
  for (auto _ : state) {
    const sdf::Repetitions r = sdf::naive::repetitions(gg.graph);
    if (!r.consistent || r.q != gg.q) state.SkipWithError("wrong repetitions vector");
    sum = checksum(r.q);
    benchmark::DoNotOptimize(sum);
  }
  state.counters["checksum"] = static_cast<double>(sum % 1000000);
  state.SetItemsProcessed(state.iterations() * state.range(1));
  set_label(state, shape);
}

std::string temp_file(int shape, uint32_t n, const char* ext) {
  return (std::filesystem::temp_directory_path() /
          ("sdf_bench_" + std::string(kShapeNames[shape]) + "_" + std::to_string(n) + ext))
      .string();
}

// Loading included: read the file, parse, build the graph, compute the vector.
void BM_LoadAndRepetitions(benchmark::State& state) {
  const int shape = static_cast<int>(state.range(0));
  const auto n = static_cast<uint32_t>(state.range(1));
  const bool xml = state.range(2) == 1;
  const std::string path = temp_file(shape, n, xml ? ".xml" : ".json");
  {
    const auto& gg = graph(shape, n);
    std::ofstream(path) << (xml ? sdf::write_sdf3(gg.graph) : sdf::write_json(gg.graph));
  }
  uint64_t sum = 0;
  for (auto _ : state) {
    const sdf::Graph g = sdf::read_graph_file(path);
    const sdf::Repetitions r = sdf::compute_repetitions(g);
    sum = checksum(r.q);
    benchmark::DoNotOptimize(sum);
  }
  if (sum != checksum(graph(shape, n).q)) state.SkipWithError("wrong repetitions vector");
  state.counters["checksum"] = static_cast<double>(sum % 1000000);
  state.counters["MB"] = static_cast<double>(std::filesystem::file_size(path)) / 1e6;
  state.SetLabel(std::string(kShapeNames[shape]) + " " + std::to_string(n) +
                 (xml ? " SDF3" : " JSON"));
  std::filesystem::remove(path);
}

void BM_Static(benchmark::State& state) {
  const int shape = static_cast<int>(state.range(0));
  const auto& gg = graph(shape, static_cast<uint32_t>(state.range(1)));
  size_t runs = 0;
  for (auto _ : state) {
    const sdf::StaticSchedule s = sdf::static_schedule(gg.graph, gg.q);
    if (!s.complete) state.SkipWithError("deadlock");
    runs = s.runs.size();
    benchmark::DoNotOptimize(runs);
  }
  state.counters["decisions"] = static_cast<double>(runs);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(runs));
  set_label(state, shape);
}

// Raw decision throughput of the online rule: OnlineScheduler::step, one decision per call.
void BM_OnlineDecisions(benchmark::State& state) {
  const int shape = static_cast<int>(state.range(0));
  const auto& gg = graph(shape, static_cast<uint32_t>(state.range(1)));
  const bool bounded = state.range(2) == 1;
  const sdf::OnlineScheduler start(gg.graph, gg.q, {sdf::FiringRule::floor_key, bounded});
  sdf::OnlineScheduler s = start;
  uint64_t fired = 0;
  for (auto _ : state) {
    const auto r = s.step();
    if (!r) {
      state.SkipWithError("deadlock");
      break;
    }
    fired += r->count;
    // Unbounded growth would end in a token overflow after ~10^18 firings; restart long before.
    if (s.decisions() == 50'000'000) s = start;
  }
  state.counters["checksum"] = static_cast<double>(fired % 1000000);
  state.SetItemsProcessed(state.iterations());
  set_label(state, shape);
  state.SetLabel(std::string(kShapeNames[shape]) + " " + std::to_string(state.range(1)) +
                 (bounded ? " actors, bounded" : " actors"));
}

// The whole online driver: detection (Brent), transient location and the metrics replay.
void BM_OnlineRun(benchmark::State& state) {
  const int shape = static_cast<int>(state.range(0));
  const auto& gg = graph(shape, static_cast<uint32_t>(state.range(1)));
  sdf::OnlineRunOptions o;
  o.scheduler.bounded = state.range(2) == 1;
  o.max_decisions = 20'000'000;
  o.max_listed_runs = 0;
  sdf::OnlineRun r;
  for (auto _ : state) {
    r = sdf::run_online(gg.graph, gg.q, o);
    benchmark::DoNotOptimize(r.decisions_explored);
  }
  state.counters["outcome"] = static_cast<double>(r.outcome);
  state.counters["decisions"] = static_cast<double>(r.decisions_explored);
  state.counters["fairness_max"] = static_cast<double>(r.metrics.fairness.max);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(r.decisions_explored));
  state.SetLabel(std::string(kShapeNames[shape]) + " " + std::to_string(state.range(1)) +
                 (o.scheduler.bounded ? " online-bounded" : " online") + " -> " +
                 sdf::outcome_name(r.outcome));
}

void sizes(benchmark::internal::Benchmark* b, std::initializer_list<int64_t> ns,
           std::initializer_list<int64_t> extra = {0}) {
  for (int64_t shape = 0; shape < 3; ++shape)
    for (int64_t n : ns)
      for (int64_t e : extra) b->Args({shape, n, e});
}

BENCHMARK(BM_Repetitions)->Apply([](auto* b) {
                           sizes(b, {1000, 10000, 100000, 1000000});
                         }) -> Unit(benchmark::kMillisecond);
BENCHMARK(BM_RepetitionsPlainWalk)
    ->Apply([](auto* b) { sizes(b, {1000000}); }) -> Unit(benchmark::kMillisecond);
BENCHMARK(BM_LoadAndRepetitions)
    ->Apply([](auto* b) {
      for (int64_t shape : {0, 2})
        for (int64_t xml : {0, 1}) b->Args({shape, 1000000, xml});
    })
    // The SDF3 reader scans on a second thread: Time is elapsed time, CPU the whole process's.
    -> MeasureProcessCPUTime() -> UseRealTime() -> Unit(benchmark::kMillisecond) -> Iterations(3);
BENCHMARK(BM_Static)->Apply([](auto* b) {
                      sizes(b, {1000, 10000, 100000, 1000000});
                    }) -> Unit(benchmark::kMillisecond);
BENCHMARK(BM_OnlineDecisions)->Apply([](auto* b) { sizes(b, {1000, 1000000}, {0, 1}); });
BENCHMARK(BM_OnlineRun)->Apply([](auto* b) {
                         sizes(b, {1000, 10000, 100000, 1000000}, {0, 1});
                       }) -> Unit(benchmark::kMillisecond) -> Iterations(1);

}  // namespace

int main(int argc, char** argv) {
  if (argc == 3 && std::strcmp(argv[1], "--write-graphs") == 0) {
    std::filesystem::create_directories(argv[2]);
    for (int shape : {0, 1, 2}) {
      const auto& gg = graph(shape, 1000000);
      const std::string base = std::string(argv[2]) + "/" + kShapeNames[shape] + "_1e6";
      std::ofstream(base + ".json") << sdf::write_json(gg.graph);
      std::ofstream(base + ".xml") << sdf::write_sdf3(gg.graph);
    }
    return 0;
  }
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
