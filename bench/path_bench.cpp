// Pathfinding benchmarks (issue 6): navmesh build time for a 1 km x 1 km world with 1,000
// obstacles; path queries per second; the tick-time overhead of the path service while 10^4
// agents re-plan. Fixed seeds; counters carry result checksums so a fast wrong change shows.
// The machine's load average is recorded in the context (2 shared cores: compare runs only
// with similar load, and prefer the ratios measured within one run).
//
//   build/bench/path_bench --benchmark_filter=Build
//   build/bench/path_bench --benchmark_filter='Query|Sight'
//   build/bench/path_bench --benchmark_filter=Overhead
#include <benchmark/benchmark.h>

#include <cmath>
#include <fstream>
#include <memory>
#include <string>

#include "crowddb/simulation.hpp"
#include "path/navigation.hpp"
#include "path/navmesh.hpp"
#include "sim/stages.hpp"
#include "support/configs.hpp"
#include "util/executor.hpp"
#include "util/rng.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb {
namespace {

constexpr double kSide = 1000;   // the world: 1 km x 1 km (1 length unit = 1 m)
constexpr double kRadius = 0.5;  // agents (and the mesh's radius class)

// 1,000 obstacles: rectangles (walls and boxes), circles (pillars) and non-convex L-shapes,
// 2-25 m across, at uniform positions. Overlaps are allowed (they merge into bigger blocks).
path::NavGeometry city(uint64_t seed = 42) {
  Rng rng(seed);
  path::NavGeometry g{{0, 0, kSide, kSide}, {}, {}};
  for (int i = 0; i < 1000; ++i) {
    const double x = rng.uniform(10, kSide - 30), y = rng.uniform(10, kSide - 30);
    const double w = rng.uniform(2, 25), h = rng.uniform(2, 25);
    switch (rng.below(3)) {
      case 0:
        g.polygons.push_back({{{x, y}, {x + w, y}, {x + w, y + h}, {x, y + h}}, 1});
        break;
      case 1:
        g.circles.push_back({x, y, rng.uniform(1, 8), 1});
        break;
      default: {  // an L: counter-clockwise, non-convex
        const double t = std::min(w, h) / 3;
        g.polygons.push_back(
            {{{x, y}, {x + w, y}, {x + w, y + t}, {x + t, y + t}, {x + t, y + h}, {x, y + h}}, 1});
      }
    }
  }
  return g;
}

bool blocked(const path::NavGeometry& g, Vec2 p, double r) {
  for (const CircleObstacle& c : g.circles)
    if (std::hypot(p.x - c.x, p.y - c.y) < c.radius + r) return true;
  for (const PolygonObstacle& poly : g.polygons)
    if (disc_overlaps_polygon(poly.vertices, p.x, p.y, r)) return true;
  return false;
}

Vec2 free_point(const path::NavGeometry& g, Rng& rng, double r) {
  for (;;) {
    const Vec2 p{rng.uniform(r + 2, kSide - r - 2), rng.uniform(r + 2, kSide - r - 2)};
    if (!blocked(g, p, 3 * r)) return p;
  }
}

std::string load_average() {
  std::ifstream f("/proc/loadavg");
  std::string a, b, c;
  f >> a >> b >> c;
  return a + " " + b + " " + c;
}

// ---------------------------------------------------------------- build

// Args: cell size in centimetres, threads.
void BM_NavMeshBuild(benchmark::State& state) {
  const path::NavGeometry g = city();
  path::NavMeshParams p;
  p.radius = kRadius;
  p.cell_size = static_cast<double>(state.range(0)) / 100;
  p.tile_size = 256;
  Executor ex(static_cast<int>(state.range(1)));
  int polygons = 0, tiles = 0;
  for (auto _ : state) {
    auto mesh = path::NavMesh::build(g, p, &ex);
    polygons = mesh->stats().polygons;
    tiles = mesh->stats().tiles;
    benchmark::DoNotOptimize(mesh.get());
  }
  state.counters["polygons"] = polygons;  // checksum: a different mesh shows here
  state.counters["tiles"] = tiles;
  state.counters["cells_M"] = std::pow(kSide / p.cell_size, 2) / 1e6;
}
BENCHMARK(BM_NavMeshBuild)
    ->ArgNames({"cell_cm", "threads"})
    ->Args({50, 1})
    ->Args({50, 2})
    ->Args({25, 1})
    ->Args({25, 2})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true)
    ->UseRealTime();

// ---------------------------------------------------------------- queries

const path::NavMesh& shared_mesh() {
  static const std::unique_ptr<path::NavMesh> mesh = [] {
    path::NavMeshParams p;
    p.radius = kRadius;
    p.cell_size = 0.25;
    return path::NavMesh::build(city(), p);
  }();
  return *mesh;
}

// Arg: the longest start-goal distance [m] (pairs drawn uniformly, kept if within it).
void BM_PathQuery(benchmark::State& state) {
  const path::NavGeometry g = city();
  const path::NavMesh& mesh = shared_mesh();
  path::PathFinder finder(mesh, 65535);
  Rng rng(7);
  const double reach = static_cast<double>(state.range(0));
  std::vector<std::pair<Vec2, Vec2>> pairs;
  while (pairs.size() < 256) {
    const Vec2 a = free_point(g, rng, kRadius), b = free_point(g, rng, kRadius);
    if (std::hypot(a.x - b.x, a.y - b.y) <= reach) pairs.push_back({a, b});
  }
  std::size_t k = 0, ok = 0, corners = 0, n = 0;
  double length = 0;
  for (auto _ : state) {
    const auto& [a, b] = pairs[k++ % pairs.size()];
    const path::PathResult r = finder.find(a, b);
    ok += r.status == path::PathStatus::ok;
    corners += r.corners.size();
    length += r.length;
    ++n;
  }
  state.SetItemsProcessed(static_cast<int64_t>(n));
  state.counters["ok_frac"] = static_cast<double>(ok) / static_cast<double>(n);
  state.counters["corners"] = static_cast<double>(corners) / static_cast<double>(n);
  state.counters["mean_len"] = length / static_cast<double>(n);  // checksum
}
BENCHMARK(BM_PathQuery)->ArgName("max_dist_m")->Arg(100)->Arg(1500)->Unit(benchmark::kMicrosecond);

void BM_SightLine(benchmark::State& state) {
  const path::NavGeometry g = city();
  const path::NavMesh& mesh = shared_mesh();
  Rng rng(9);
  std::vector<std::pair<Vec2, Vec2>> pairs;
  while (pairs.size() < 1024) {
    const Vec2 a = free_point(g, rng, kRadius);
    const double t = rng.uniform(0, 2 * 3.14159265358979), d = rng.uniform(1, 30);
    pairs.push_back({a, {a.x + d * std::cos(t), a.y + d * std::sin(t)}});
  }
  std::size_t k = 0, seen = 0;
  for (auto _ : state) {
    const auto& [a, b] = pairs[k++ % pairs.size()];
    seen += mesh.visible(a, b);
  }
  state.SetItemsProcessed(static_cast<int64_t>(k));
  state.counters["visible_frac"] = static_cast<double>(seen) / static_cast<double>(k);  // checksum
}
BENCHMARK(BM_SightLine)->Unit(benchmark::kMicrosecond);

// ---------------------------------------------------------------- tick overhead

// 10^4 agents at free points of the city, 50 goals. Every `period` ticks all agents get a new
// goal (World::retarget, applied as the tick's batch): each must re-plan. Per tick the service's
// operators run exactly as in Simulation::step — path results, Q1 attraction with waypoint
// skipping, path requests — and the agents stand still (no steering), so only the service's
// own cost is timed. Args: navigation off (Q1 only, the baseline) or on; budget; threads;
// sight_interval (ticks between an agent's line-of-sight checks).
struct Crowd {
  World world;
  std::vector<AgentId> ids;
};

Crowd crowd(const path::NavGeometry& g, std::size_t n) {
  Crowd c{World(g.bounds), {}};
  for (const CircleObstacle& o : g.circles) c.world.add_obstacle(o);
  for (const PolygonObstacle& o : g.polygons) c.world.add_obstacle(o);
  Rng rng(11);
  for (int k = 0; k < 50; ++k) {
    const Vec2 p = free_point(g, rng, kRadius);
    c.world.add_goal({"g" + std::to_string(k), p.x, p.y, 1, 2, {}});
  }
  for (std::size_t i = 0; i < n; ++i) {
    AgentSpec s;
    const Vec2 p = free_point(g, rng, kRadius);
    s.x = p.x;
    s.y = p.y;
    s.radius = kRadius;
    s.max_speed = 1.3;
    s.pref_speed = s.max_speed;
    s.goal = static_cast<uint32_t>(rng.below(50));
    c.ids.push_back(c.world.insert(s));
  }
  c.world.apply_pending();
  return c;
}

void BM_ServiceOverhead(benchmark::State& state) {
  static const path::NavGeometry g = city();
  const bool nav_on = state.range(0) != 0;
  const std::size_t n = 10'000;
  constexpr uint64_t kPeriod = 20;
  Crowd c = crowd(g, n);
  SimConfig cfg = test::thesis_config();
  cfg.navigation.enabled = nav_on;
  cfg.navigation.latency = 2;
  cfg.navigation.budget = static_cast<uint32_t>(std::max<int64_t>(1, state.range(1)));
  cfg.navigation.cell_size = 0.25;
  cfg.navigation.replan_after = 0;
  cfg.navigation.sight_interval = static_cast<double>(state.range(3));  // dt = 1: ticks
  Executor ex(static_cast<int>(state.range(2)));
  std::unique_ptr<path::Navigation> nav;
  if (nav_on) {
    nav = std::make_unique<path::Navigation>(c.world, cfg, ex);  // mesh build: not timed
    nav->request_paths(c.world, 0);
  }
  sim::Preferred fx;
  Rng rng(5);
  uint64_t tick = 0;
  double apply_s = 0, q1_s = 0, request_s = 0;
  for (auto _ : state) {
    ++tick;
    state.PauseTiming();
    if (tick % kPeriod == 0)
      for (const AgentId& id : c.ids) c.world.retarget(id, static_cast<uint32_t>(rng.below(50)));
    c.world.apply_pending();
    fx.reset(n);
    state.ResumeTiming();
    Stopwatch sw;
    if (nav) nav->apply_results(c.world, tick);
    apply_s += sw.seconds();
    sw.restart();
    sim::goal_stage(c.world.agents(), c.world.goals(), cfg, tick, {}, fx, ex, nav.get());
    q1_s += sw.seconds();
    sw.restart();
    if (nav) nav->request_paths(c.world, tick);
    request_s += sw.seconds();
  }
  const double per_tick = 1e3 / static_cast<double>(tick);
  state.counters["q1_ms"] = q1_s * per_tick;  // goal stage, with the line-of-sight checks
  if (nav) {
    const auto s = nav->stats();
    const auto w = nav->service_stats();
    state.counters["apply_ms"] = (apply_s - w.wait_seconds) * per_tick;
    state.counters["wait_ms"] = w.wait_seconds * per_tick;  // the tick waiting for the worker
    state.counters["request_ms"] = request_s * per_tick;
    state.counters["requests"] = static_cast<double>(s.requests);
    state.counters["applied"] = static_cast<double>(s.applied);
    state.counters["queued_end"] = static_cast<double>(s.queued);
    state.counters["search_us"] =
        w.jobs_done ? w.work_seconds * 1e6 / static_cast<double>(w.jobs_done) : 0;
  }
}
BENCHMARK(BM_ServiceOverhead)
    ->ArgNames({"nav", "budget", "threads", "sight"})
    ->Args({0, 0, 1, 1})
    ->Args({1, 500, 1, 1})
    ->Args({1, 2000, 1, 1})
    ->Args({1, 2000, 2, 1})
    ->Args({1, 2000, 1, 4})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(100)
    ->UseRealTime();

// The whole tick (Simulation::step) with 10^4 walking agents, navigation off and on, so the
// worker's searches overlap the tick's other work as they do in a run. The steering queries are
// off (w_apf = w_ftc = 0, backoff off) so that the service's share is not hidden behind them; what
// remains is Q1, integrate, the overlap count and commit. Every 20 ticks
// all agents get new goals (arrivals re-target too). Args: navigation, budget.
void BM_TickOverhead(benchmark::State& state) {
  static const path::NavGeometry g = city();
  Crowd c = crowd(g, 10'000);
  SimConfig cfg = test::thesis_config();
  cfg.steering.thesis.w_apf = 0;
  cfg.steering.thesis.w_ftc = 0;
  cfg.backoff = false;
  cfg.arrival = ArrivalPolicy::retarget;
  cfg.navigation.enabled = state.range(0) != 0;
  cfg.navigation.budget = static_cast<uint32_t>(std::max<int64_t>(1, state.range(1)));
  cfg.navigation.cell_size = 0.25;
  Simulation sim(std::move(c.world), cfg);
  Rng rng(5);
  uint64_t tick = 0;
  for (auto _ : state) {
    if (++tick % 20 == 0) {
      state.PauseTiming();
      for (const AgentId& id : c.ids)
        sim.world().retarget(id, static_cast<uint32_t>(rng.below(50)));
      state.ResumeTiming();
    }
    sim.step();
  }
  state.counters["arrived"] = static_cast<double>(sim.arrived_total());
  // The path service's own rows of EXPLAIN ANALYZE: waits and the queue left at the end.
  const std::string ea = sim.explain_analyze();
  if (const auto at = ea.find("the tick waited for it "); at != std::string::npos)
    state.counters["waits"] = std::stod(ea.substr(at + 23));
  if (const auto at = ea.find(" superseded, "); at != std::string::npos)
    state.counters["queued_end"] = std::stod(ea.substr(at + 13));
  state.counters["hash_lo"] = static_cast<double>(sim.state_hash() & 0xffff);  // checksum
}
BENCHMARK(BM_TickOverhead)
    ->ArgNames({"nav", "budget"})
    ->Args({0, 0})
    ->Args({1, 2000})
    ->Args({1, 200})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(40)
    ->UseRealTime();

}  // namespace
}  // namespace crowddb

int main(int argc, char** argv) {
  benchmark::Initialize(&argc, argv);
  benchmark::AddCustomContext("loadavg_at_start", crowddb::load_average());
  benchmark::RunSpecifiedBenchmarks();
  benchmark::AddCustomContext("loadavg_at_end", crowddb::load_average());
  benchmark::Shutdown();
  return 0;
}
