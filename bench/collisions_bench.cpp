// Collision-set methods (DESIGN.md §3.2) at n = 10^3 ... 10^6 on fixed-seed inputs:
//   uniform   radii 1-3, square side chosen for ~10% of the discs in collision (the target)
//   equal     radius 2, ~10% in collision (the only input nn accepts)
//   clustered radii 1-3, 1 cluster per 2,000 discs (spread 500), dense cores
//   mixed     radii 0.5-50, ~10% in collision
//   giants    uniform radii 1-3 plus one disc in 10^4 of radius 100-1000
//   dense, densemixed  radii 1-3 / 0.5-50 with ~50% in collision (Delaunay miss rates)
// Counters: pairs and a pair checksum (a fast wrong change shows), in_collision (fraction of
// discs in the set), and for delaunay its misses against the exact answer (missed_pairs,
// missed_agents: fractions of the exact pairs / set; computed outside the timed loop).
//
//   build/bench/collisions_bench --benchmark_filter='uniform/1000000' --benchmark_repetitions=5
//   build/bench/collisions_bench --benchmark_filter='^small/'   (naive-to-index crossover)
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <numbers>
#include <string>

#include "index/obstacle_index.hpp"
#include "plan/access_path.hpp"
#include "query/naive_paths.hpp"
#include "scenario/builders.hpp"
#include "util/executor.hpp"

namespace {

using namespace crowddb;

// Side of the square in which n discs with radii uniform in [a, b] have about `frac` of them
// overlapping another: P(collide) = 1 - exp(-n pi E[(ri + rj)^2] / side^2).
double side_for(std::size_t n, double a, double b, double frac) {
  const double e2 = 2 * (b - a) * (b - a) / 12 + (a + b) * (a + b);
  return std::sqrt(static_cast<double>(n) * std::numbers::pi * e2 / -std::log1p(-frac));
}

DiscTable make(const std::string& dist, std::size_t n) {
  const uint64_t seed = 20240501 + n;
  if (dist == "uniform") {
    const double s = side_for(n, 1, 3, 0.10);
    return build::uniform(n, build::Box{0, 0, s, s}, 1, 1, 3, seed);
  }
  if (dist == "equal") {
    const double s = side_for(n, 2, 2, 0.10);
    return build::uniform(n, build::Box{0, 0, s, s}, 1, 2, 2, seed);
  }
  if (dist == "clustered") {  // 2,000 discs per cluster, spread 500: dense cores, empty between
    const double s = side_for(n, 1, 3, 0.02);
    return build::clustered(n, build::Box{0, 0, s, s}, std::max<std::size_t>(1, n / 2000), 500, 1,
                            1, 3, seed);
  }
  if (dist == "mixed") {
    const double s = side_for(n, 0.5, 50, 0.10);
    return build::uniform(n, build::Box{0, 0, s, s}, 1, 0.5, 50, seed);
  }
  if (dist == "dense") {  // radii 1-3, about half the discs in collision
    const double s = side_for(n, 1, 3, 0.50);
    return build::uniform(n, build::Box{0, 0, s, s}, 1, 1, 3, seed);
  }
  if (dist == "densemixed") {  // radii 0.5-50, about half in collision
    const double s = side_for(n, 0.5, 50, 0.50);
    return build::uniform(n, build::Box{0, 0, s, s}, 1, 0.5, 50, seed);
  }
  // giants
  const double s = side_for(n, 1, 3, 0.10);
  DiscTable t = build::uniform(n - n / 10000, build::Box{0, 0, s, s}, 1, 1, 3, seed);
  build::add_giants(t, n / 10000, build::Box{0, 0, s, s}, 100, 1000, seed + 1);
  return t;
}

const DiscTable& data(const std::string& dist, std::size_t n) {
  static std::map<std::pair<std::string, std::size_t>, std::unique_ptr<DiscTable>> cache;
  auto& slot = cache[{dist, n}];
  if (!slot) slot = std::make_unique<DiscTable>(make(dist, n));
  return *slot;
}

struct Exact {
  CollisionPairs pairs;
  std::vector<uint32_t> set;
};

std::vector<uint32_t> set_of(const CollisionPairs& p) {
  std::vector<uint32_t> rows;
  for (auto [i, j] : p.agents) {
    rows.push_back(i);
    rows.push_back(j);
  }
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  return rows;
}

const Exact& exact(const std::string& dist, std::size_t n) {
  static std::map<std::pair<std::string, std::size_t>, std::unique_ptr<Exact>> cache;
  auto& slot = cache[{dist, n}];
  if (!slot) {
    slot = std::make_unique<Exact>();
    Executor ex(1);
    QueryStats st;
    find_collision_method("grid", {})
        .make()
        ->run(data(dist, n).view(), StaticScene(), slot->pairs, ex, st);
    slot->set = set_of(slot->pairs);
  }
  return *slot;
}

void run(benchmark::State& state, const std::string& method, const std::string& dist,
         std::size_t n) {
  const DiscTable& t = data(dist, n);
  const DiscView d = t.view();
  CollisionQueryShape shape;
  shape.rows = n;
  shape.equal_radii = dist == "equal";
  auto path = find_collision_method(method, shape).make();
  const StaticScene scene;
  Executor ex(1);
  CollisionPairs out;
  for (auto _ : state) {
    QueryStats st;
    path->run(d, scene, out, ex, st);
    benchmark::DoNotOptimize(out.agents.data());
    benchmark::ClobberMemory();
  }
  uint64_t sum = 0;
  for (auto [i, j] : out.agents) sum = sum * 1000003 + (static_cast<uint64_t>(i) << 32 | j);
  state.counters["pairs"] = static_cast<double>(out.agents.size());
  state.counters["checksum"] = static_cast<double>(sum % 1000000007);
  const std::vector<uint32_t> set = set_of(out);
  state.counters["in_collision"] = static_cast<double>(set.size()) / static_cast<double>(n);
  if (method == "delaunay") {
    const Exact& e = exact(dist, n);
    state.counters["missed_pairs"] =
        1 - static_cast<double>(out.agents.size()) /
                static_cast<double>(std::max<std::size_t>(1, e.pairs.agents.size()));
    state.counters["missed_agents"] =
        1 - static_cast<double>(set.size()) /
                static_cast<double>(std::max<std::size_t>(1, e.set.size()));
  }
}

// The obstacle half alone: the oracle's loop over every obstacle against ObstacleIndex, on the
// uniform table with an airport-like scene scaled to its box (24 pillars, 5 boxes, 4 walls).
void obstacles(benchmark::State& state, bool indexed, std::size_t n) {
  const DiscTable& t = data("uniform", n);
  const DiscView d = t.view();
  const double side = side_for(n, 1, 3, 0.10);
  std::vector<CircleObstacle> circles;
  std::vector<PolygonObstacle> polys;
  for (int i = 0; i < 24; ++i)
    circles.push_back(
        {side * (0.1 + 0.15 * (i % 6)), side * (0.15 + 0.2 * (i / 6)), side * 0.03, 1});
  for (int i = 0; i < 5; ++i) {
    const double x = side * (0.05 + 0.18 * i), y = side * 0.92, w = side * 0.05;
    polys.push_back({{{x, y}, {x + w, y}, {x + w, y + w / 4}, {x, y + w / 4}}, 1});
  }
  const Bounds walls{side * 0.01, side * 0.01, side * 0.99, side * 0.99};
  const StaticScene scene(circles, polys, side, ObstacleCharges::centres, &walls);
  std::vector<std::pair<uint32_t, Collider>> hits;
  for (auto _ : state) {
    hits.clear();
    QueryStats st;
    if (indexed)
      index::obstacle_overlaps(d, scene, index::Frame::of(d), hits, st);
    else
      disc_obstacle_overlaps(d, scene, 0, d.n, hits);
    benchmark::DoNotOptimize(hits.data());
  }
  state.counters["hits"] = static_cast<double>(hits.size());
}

std::string loadavg() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

}  // namespace

int main(int argc, char** argv) {
  const std::size_t sizes[] = {1000, 10000, 100000, 1000000};
  // Small tables, for the planner's crossover from naive to an index (auto_min_rows).
  for (const std::string dist : {"uniform", "equal"})
    for (const std::string method : {"naive", "grid", "sweep", "nn"})
      for (std::size_t n : {16, 32, 64, 128, 256, 512}) {
        if (method == "nn" && dist != "equal") continue;
        benchmark::RegisterBenchmark(
            ("small/" + method + "/" + dist + "/" + std::to_string(n)).c_str(),
            [=](benchmark::State& s) { run(s, method, dist, n); })
            ->Unit(benchmark::kMicrosecond);
      }
  for (const std::string dist :
       {"uniform", "equal", "clustered", "mixed", "giants", "dense", "densemixed"})
    for (const std::string method : {"naive", "grid", "sweep", "nn", "delaunay"})
      for (std::size_t n : sizes) {
        if (method == "naive" && n > 10000) continue;     // O(n^2): 10^5 takes seconds per run
        if (method == "nn" && dist != "equal") continue;  // equal radii only
        auto* b =
            benchmark::RegisterBenchmark((method + "/" + dist + "/" + std::to_string(n)).c_str(),
                                         [=](benchmark::State& s) { run(s, method, dist, n); });
        b->Unit(benchmark::kMillisecond);
        if (n >= 1000000) b->Iterations(method == "delaunay" ? 2 : 10);
      }
  for (std::size_t n : sizes)
    for (bool indexed : {false, true})
      benchmark::RegisterBenchmark(
          ((indexed ? "obstacles/index/" : "obstacles/loop/") + std::to_string(n)).c_str(),
          [=](benchmark::State& s) { obstacles(s, indexed, n); })
          ->Unit(benchmark::kMillisecond);
  benchmark::Initialize(&argc, argv);
  benchmark::AddCustomContext("loadavg_at_start", loadavg());
  benchmark::RunSpecifiedBenchmarks();
  std::fprintf(stderr, "loadavg at end: %s\n", loadavg().c_str());
  benchmark::Shutdown();
  return 0;
}
