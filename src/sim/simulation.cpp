// The tick driver: plans the access paths, runs the operators of stages.hpp in order, commits,
// and keeps the EXPLAIN ANALYZE counters.
#include "crowddb/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "path/navigation.hpp"
#include "sim/stages.hpp"
#include "util/rng.hpp"
#include "util/stopwatch.hpp"

namespace crowddb {
namespace {

void require(bool ok, const char* field, const std::string& what) {
  if (!ok) throw InvalidRow(field, std::string(field) + " " + what);
}

const char* kernel_name(Kernel k) {
  return k == Kernel::exp ? "exp" : "inv";
}
const char* metric_name(Metric m) {
  return m == Metric::l1 ? "l1" : (m == Metric::l2 ? "l2" : "radial");
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

}  // namespace

void SimConfig::validate() const {
  require(std::isfinite(dt) && dt > 0, "dt", "must be > 0");
  require(std::isfinite(steering.tau) && steering.tau > 0, "tau", "must be > 0");
  require(std::isfinite(steering.w_apf) && steering.w_apf >= 0, "w_apf", "must be >= 0");
  require(std::isfinite(steering.w_ftc) && steering.w_ftc >= 0, "w_ftc", "must be >= 0");
  require(std::isfinite(steering.horizon) && steering.horizon > 0, "horizon", "must be > 0");
  const PotentialSpec& p = steering.potential;
  require(std::isfinite(p.A), "A", "must be finite");
  require(std::isfinite(p.k) && p.k >= 0, "k", "must be >= 0");
  require(p.radial_frames >= 1 && p.radial_frames <= 16, "frames", "must be in 1..16");
  require(std::isfinite(p.inv_floor) && p.inv_floor > 0, "inv_floor", "must be > 0");
  require(threads >= 1 && threads <= 256, "threads", "must be in 1..256");
  require(std::isfinite(waypoint_radius) && waypoint_radius >= 0, "waypoint_radius",
          "must be >= 0");
  const NavigationParams& n = navigation;
  require(n.latency >= 1, "navigation/latency", "must be >= 1");
  require(n.budget >= 1, "navigation/budget", "must be >= 1");
  require(std::isfinite(n.radius_step) && n.radius_step > 0, "navigation/radius_step",
          "must be > 0");
  require(std::isfinite(n.cell_size) && n.cell_size >= 0, "navigation/cell_size", "must be >= 0");
  require(std::isfinite(n.clearance) && n.clearance >= 0, "navigation/clearance", "must be >= 0");
  require(n.tile_size >= 16 && n.tile_size <= 4096, "navigation/tile_size", "must be in 16..4096");
  require(n.sight_interval >= 1, "navigation/sight_interval", "must be >= 1");
}

// Per-operator EXPLAIN ANALYZE counters.
struct OperatorStats {
  uint64_t loops = 0;
  uint64_t rows = 0;
  double seconds = 0;
  QueryStats query;
};

// The access paths chosen for one tick.
struct TickPlan {
  std::size_t rows = 0;
  const FtcMethod* ftc = nullptr;      // null: outer avoidance off (w_ftc = 0)
  const FieldMethod* field = nullptr;  // null: inner avoidance off (w_apf = 0)
  const CollisionMethod* collisions = nullptr;
  bool collisions_fallback = false;  // the forced method does not apply to this tick (see plan())
};

struct Simulation::Engine {
  explicit Engine(int threads) : ex(threads) {}

  Executor ex;
  StaticScene scene;
  double scene_spacing = INFINITY;
  sim::Effects fx;
  sim::NextState next;
  FieldColumns field;
  std::vector<FtcHit> hits;
  std::map<std::string, std::unique_ptr<FtcPath>> ftc_paths;
  std::map<std::string, std::unique_ptr<FieldPath>> field_paths;
  std::map<std::string, std::unique_ptr<CollisionPath>> collision_paths;
  std::unique_ptr<path::Navigation> nav;  // null: navigation off
  // EXPLAIN ANALYZE, in operator order.
  enum Op {
    kApply,
    kPathApply,
    kAttraction,
    kInner,
    kOuter,
    kIntegrate,
    kBackoff,
    kCommit,
    kPathRequest,
    kOpCount
  };
  OperatorStats ops[kOpCount];
  std::map<std::string, uint64_t> method_ticks;  // "field=naive" -> ticks it was chosen
  // The agents are known to overlap nowhere at the start of the next tick: the last tick ended
  // (with backoff on) without an overlapping agent pair and no agent was inserted since. Only
  // then is a method that finds the collision set but not every pair (nn) exact for the
  // backoff: every overlap is new, so the set is all the freeze loop needs.
  bool start_clean = false;

  // The access paths for the next tick. A collision method forced by name that does not apply
  // to this tick (nn while agents still overlap from before, or radii that stopped being equal
  // through inserts) is replaced by the planner's exact choice for the tick and EXPLAIN ANALYZE
  // counts it; `strict` (construction) instead rejects a forced method that can never apply:
  // nn with unequal radii or with backoff off (overlap counts need every pair).
  TickPlan plan(const World& w, const SimConfig& cfg, bool strict = false) const {
    return plan(w, cfg, start_clean, strict);
  }
  TickPlan plan(const World& w, const SimConfig& cfg, bool clean, bool strict) const {
    TickPlan p;
    const AgentTable& t = w.agents();
    p.rows = t.size();
    if (cfg.steering.w_ftc > 0)
      p.ftc =
          cfg.access.ftc == "auto" ? &choose_ftc_method(p.rows) : &find_ftc_method(cfg.access.ftc);
    if (cfg.steering.w_apf > 0)
      p.field = cfg.access.field == "auto"
                    ? &choose_field_method(p.rows, cfg.steering.potential)
                    : &find_field_method(cfg.access.field, cfg.steering.potential);
    CollisionQueryShape shape;
    shape.rows = p.rows;
    shape.equal_radii =
        std::all_of(t.radius.begin(), t.radius.end(), [&](double r) { return r == t.radius[0]; });
    shape.need_all_pairs = !(cfg.backoff && clean);
    if (cfg.access.collisions == "auto") {
      p.collisions = &choose_collision_method(shape);
      return p;
    }
    CollisionQueryShape at_best = shape;
    at_best.need_all_pairs = !cfg.backoff;
    if (strict) find_collision_method(cfg.access.collisions, at_best);  // throws Error(usage)
    const CollisionMethod* forced = nullptr;
    for (const auto& m : collision_registry())
      if (m.info.name == cfg.access.collisions) forced = &m;
    if (!forced) {
      p.collisions = &find_collision_method(cfg.access.collisions, shape);  // throws: unknown name
      return p;
    }
    if (forced->supports(shape)) {
      p.collisions = forced;
    } else {
      p.collisions = &choose_collision_method(shape);
      p.collisions_fallback = true;
    }
    return p;
  }

  template <class Map, class Method>
  auto& path(Map& map, const Method& m) {
    auto& slot = map[m.info.name];
    if (!slot) slot = m.make();
    return *slot;
  }

  // The charged points of obstacle boundaries are spaced no wider than the smallest agent
  // radius (DESIGN.md §2); rebuild the scene when a smaller agent appears.
  void refresh_scene(const World& w, const SimConfig& cfg) {
    double rmin = INFINITY;
    for (double r : w.agents().radius) rmin = std::min(rmin, r);
    if (!std::isfinite(rmin)) rmin = 1;
    if (rmin >= scene_spacing) return;
    scene_spacing = rmin;
    scene = StaticScene({w.circles().begin(), w.circles().end()},
                        {w.polygons().begin(), w.polygons().end()}, scene_spacing,
                        cfg.steering.obstacle_charges, cfg.walls ? &w.bounds() : nullptr);
  }
};

Simulation::Simulation(World world, SimConfig config)
    : world_(std::move(world)), config_(std::move(config)) {
  config_.validate();
  engine_ = std::make_unique<Engine>(config_.threads);
  world_.apply_pending();
  engine_->refresh_scene(world_, config_);
  engine_->plan(world_, config_, true);  // reject unknown or unsupported methods now, not mid-run
  if (config_.navigation.enabled) {
    // Meshes for the radius classes present, and the first requests (tick 0: due at `latency`).
    engine_->nav = std::make_unique<path::Navigation>(world_, config_, engine_->ex);
    engine_->nav->request_paths(world_, 0);
  }
  last_.agents = world_.agents().size();
  last_.state_hash = sim::state_hash(world_.agents(), 0);
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

uint64_t Simulation::state_hash() const {
  return sim::state_hash(world_.agents(), last_.tick);
}

const TickMetrics& Simulation::step() {
  Engine& e = *engine_;
  const SimConfig& cfg = config_;
  Stopwatch tick_clock;
  TickMetrics m;
  m.tick = last_.tick + 1;
  auto timed = [&](Engine::Op op, std::size_t rows, auto&& body) {
    Stopwatch sw;
    body();
    e.ops[op].loops += 1;
    e.ops[op].rows += rows;
    e.ops[op].seconds += sw.seconds();
  };

  // 0. apply the buffered inserts, deletes and re-targets as one batch
  std::size_t applied = 0;
  timed(Engine::kApply, world_.pending_changes(), [&] { applied = world_.apply_pending(); });
  if (applied)
    e.start_clean = false;  // an insert may overlap (erases and re-targets cannot, but are rare)
  if (e.nav) {
    std::size_t routes = 0;
    timed(Engine::kPathApply, 0, [&] { routes = e.nav->apply_results(world_, m.tick); });
    e.ops[Engine::kPathApply].rows += routes;
  }
  e.refresh_scene(world_, cfg);
  const TickPlan plan = e.plan(world_, cfg);
  AgentTable& t = world_.agents_for_tick();
  const std::size_t n = t.size();
  const DiscView view = DiscView::of(t);
  e.fx.reset(n);
  e.next.resize(n);

  // 1-3. the steering queries, each into its own effect columns
  if (cfg.nudge_after > 0)
    for (std::size_t i = 0; i < n; ++i)
      m.nudged += t.state[i] != AgentState::arrived && t.frozen_ticks[i] >= cfg.nudge_after;
  timed(Engine::kAttraction, n,
        [&] { sim::attraction(t, world_.goals(), cfg, m.tick, e.fx, e.ex, e.nav.get()); });
  if (plan.field) {
    ++e.method_ticks["field=" + plan.field->info.name];
    timed(Engine::kInner, n, [&] {
      e.path(e.field_paths, *plan.field)
          .run(view, e.scene, cfg.steering.potential, e.field, e.ex, e.ops[Engine::kInner].query);
      sim::inner_avoidance(e.field, cfg, e.fx, e.ex);
    });
  }
  if (plan.ftc) {
    ++e.method_ticks["ftc=" + plan.ftc->info.name];
    timed(Engine::kOuter, n, [&] {
      e.hits.assign(n, FtcHit{});
      e.path(e.ftc_paths, *plan.ftc)
          .run(view, e.scene, cfg.steering.horizon, e.hits, e.ex, e.ops[Engine::kOuter].query);
      sim::outer_avoidance(t, e.scene, e.hits, cfg, e.fx, e.ex);
    });
  }
  // 4. one effect row per agent -> tentative next state
  timed(Engine::kIntegrate, n, [&] { sim::combine_integrate(t, e.fx, cfg, e.next, e.ex); });

  // 5. backoff (or, without it, just measure the overlaps)
  ++e.method_ticks["collisions=" + plan.collisions->info.name +
                   (plan.collisions_fallback ? " (instead of " + cfg.access.collisions + ")" : "")];
  CollisionPath& cpath = e.path(e.collision_paths, *plan.collisions);
  sim::OverlapReport overlaps;
  timed(Engine::kBackoff, n, [&] {
    QueryStats& qs = e.ops[Engine::kBackoff].query;
    if (cfg.backoff) {
      overlaps = sim::backoff(t, e.next, e.scene, cpath, e.ex, qs, m.freeze_iterations);
    } else {
      overlaps = sim::find_overlaps(t, e.next, e.scene, cpath, e.ex, qs);
    }
  });
  m.overlapping_pairs = overlaps.agent_pairs;
  m.obstacle_overlaps = overlaps.obstacle_hits;
  e.start_clean = cfg.backoff && overlaps.agent_pairs == 0;

  // 6. commit: swap in the next state, advance waypoints, arrivals
  timed(Engine::kCommit, n, [&] {
    t.x.swap(e.next.x);
    t.y.swap(e.next.y);
    t.vx.swap(e.next.vx);
    t.vy.swap(e.next.vy);
    std::vector<std::size_t> leaving;
    for (std::size_t i = 0; i < n; ++i) {
      if (t.state[i] == AgentState::arrived) continue;
      if (e.next.frozen[i]) {
        ++m.frozen;
        t.state[i] = AgentState::frozen;
        ++t.frozen_ticks[i];
        if (t.frozen_ticks[i] == cfg.gridlock_ticks) ++m.gridlock_started;
        m.longest_frozen = std::max<std::size_t>(m.longest_frozen, t.frozen_ticks[i]);
      } else {
        t.state[i] = AgentState::active;
        t.frozen_ticks[i] = 0;
      }
      if (t.frozen_ticks[i] >= cfg.gridlock_ticks) ++m.gridlocked;
      if (e.fx.skip[i] && !t.route[i].empty()) {  // Q1 saw the waypoint after the current one
        t.route[i].erase(
            t.route[i].begin(),
            t.route[i].begin() + std::min<std::size_t>(e.fx.skip[i], t.route[i].size()));
        world_.refresh_target(i);
      }
      const double reach = cfg.waypoint_radius > 0 ? cfg.waypoint_radius : t.radius[i];
      while (!t.route[i].empty() &&
             std::hypot(t.route[i].front().x - t.x[i], t.route[i].front().y - t.y[i]) <= reach) {
        t.route[i].erase(t.route[i].begin());
        world_.refresh_target(i);
      }
      const Goal& g = world_.goals()[t.goal[i]];
      if (t.route[i].empty() && std::hypot(g.x - t.x[i], g.y - t.y[i]) <= g.arrival_radius) {
        ++m.arrived;
        if (cfg.arrival == ArrivalPolicy::remove) {
          leaving.push_back(i);
        } else if (cfg.arrival == ArrivalPolicy::retarget && world_.goals().size() > 1) {
          // Another goal, from a stream keyed by seed, id and tick: thread- and order-independent.
          Rng rng = Rng::stream(cfg.seed ^ (m.tick * 0x9e3779b97f4a7c15ull), t.id[i]);
          const auto others = static_cast<uint32_t>(world_.goals().size() - 1);
          const auto pick = static_cast<uint32_t>(rng.below(others));
          t.goal[i] = pick >= t.goal[i] ? pick + 1 : pick;
          t.route[i].clear();
          t.path_goal[i] = AgentTable::kNoPath;  // a new goal: re-plan
          world_.refresh_target(i);
        } else {
          t.state[i] = AgentState::arrived;
          t.vx[i] = t.vy[i] = 0;
        }
      }
    }
    // Descending rows: each swap-remove moves in a row that is staying (or already handled).
    for (auto it = leaving.rbegin(); it != leaving.rend(); ++it) world_.remove_row(*it);
  });
  // 7. path requests: progress watch, new requests, dispatch to the worker within the budget
  if (e.nav) {
    std::size_t made = 0;
    timed(Engine::kPathRequest, 0, [&] { made = e.nav->request_paths(world_, m.tick); });
    e.ops[Engine::kPathRequest].rows += made;
  }
  m.agents = world_.agents().size();
  m.state_hash = sim::state_hash(world_.agents(), m.tick);
  arrived_total_ += m.arrived;
  m.seconds = tick_clock.seconds();
  last_ = m;
  return last_;
}

std::string Simulation::explain() const {
  const Engine& e = *engine_;
  const TickPlan p = e.plan(world_, config_);
  const SteeringParams& s = config_.steering;
  std::ostringstream os;
  os << "TICK PLAN  rows=" << p.rows << " agents, " << world_.circles().size() << " circles, "
     << world_.polygons().size() << " polygons" << (config_.walls ? " + 4 walls" : "") << " ("
     << e.scene.point_count() << " charged points), " << world_.goals().size()
     << " goals; threads=" << config_.threads << "\n";
  os << "  0 apply_batch        buffered inserts, deletes, re-targets (" << world_.pending_changes()
     << " pending)\n";
  const NavigationParams& nv = config_.navigation;
  if (e.nav) {
    os << "  P path results       apply the routes due this tick (requested " << nv.latency
       << " tick" << (nv.latency == 1 ? "" : "s") << " earlier; waits only for a late worker)\n"
       << "       path service: Recast/Detour navigation mesh per radius class (radius rounded up "
          "to a multiple of "
       << num(nv.radius_step) << "), findPath + findStraightPath on a worker thread\n"
       << e.nav->describe_meshes();
  }
  os << "  1 Q1 attraction      per row: v_pref towards waypoint, (v_pref - v)/tau, tau="
     << num(s.tau);
  if (config_.nudge_after) os << "; sidestep after " << config_.nudge_after << " frozen ticks";
  os << "\n";
  if (e.nav)
    os << "       waypoints: advance when within "
       << (config_.waypoint_radius > 0 ? num(config_.waypoint_radius)
                                       : std::string("the agent's radius"))
       << (nv.skip_visible ? " or when the next one is in sight (Detour raycast" +
                                 (nv.sight_interval > 1
                                      ? ", every " + std::to_string(nv.sight_interval) + " ticks"
                                      : std::string()) +
                                 ")"
                           : std::string())
       << "\n";
  if (p.field)
    os << "  2 Q2 inner avoidance potential field " << kernel_name(s.potential.kernel) << "-"
       << metric_name(s.potential.metric) << " A=" << num(s.potential.A)
       << " k=" << num(s.potential.k) << " w_apf=" << num(s.w_apf)
       << "\n       access path: " << p.field->info.name << " (" << p.field->info.description
       << ")\n";
  else
    os << "  2 Q2 inner avoidance off (w_apf = 0)\n";
  if (p.ftc)
    os << "  3 Q3 outer avoidance first-to-collide, horizon=" << num(s.horizon)
       << " w_ftc=" << num(s.w_ftc) << "\n       access path: " << p.ftc->info.name << " ("
       << p.ftc->info.description << ")\n";
  else
    os << "  3 Q3 outer avoidance off (w_ftc = 0)\n";
  os << "  4 combine+integrate  sum effects; |a| <= max_accel; |v| <= max_speed; p += v dt, dt="
     << num(config_.dt) << "\n";
  os << "  5 "
     << (config_.backoff
             ? "backoff            freeze the collision set until empty; one full query, then"
               " probes of the agents frozen last"
             : "overlap count      backoff off: overlaps are only counted")
     << "\n       access path: " << p.collisions->info.name << " ("
     << p.collisions->info.description << ")";
  if (p.collisions_fallback)
    os << " instead of " << config_.access.collisions << ": agents overlap at the start";
  if (!p.collisions->info.exact) os << "; inexact: the zero-overlap invariant is not guaranteed";
  os << "\n";
  // A method that only finds the set (nn) serves once a tick starts with no overlapping agents.
  const TickPlan clean = e.plan(world_, config_, true, false);
  if (clean.collisions != p.collisions)
    os << "       then " << clean.collisions->info.name << " ("
       << clean.collisions->info.description
       << ") on ticks that start with no overlapping agents\n";
  os << "  6 commit             swap columns, waypoints, arrivals ("
     << (config_.arrival == ArrivalPolicy::remove ? "remove"
         : config_.arrival == ArrivalPolicy::idle ? "idle"
                                                  : "retarget")
     << "), state hash\n";
  if (e.nav)
    os << "  7 path requests      new goal or no progress for " << nv.replan_after
       << " ticks -> FIFO queue; <= " << nv.budget << " dispatched per tick, due " << nv.latency
       << " tick" << (nv.latency == 1 ? "" : "s") << " later\n";
  return os.str();
}

std::string Simulation::explain_analyze() const {
  const Engine& e = *engine_;
  static const char* names[] = {"apply_batch",
                                "path results",
                                "Q1 attraction",
                                "Q2 inner avoidance",
                                "Q3 outer avoidance",
                                "combine+integrate",
                                config_.backoff ? "backoff" : "overlap count",
                                "commit",
                                "path requests"};
  std::ostringstream os;
  char line[256];
  std::snprintf(line, sizeof line, "EXPLAIN ANALYZE  %llu ticks\n",
                static_cast<unsigned long long>(last_.tick));
  os << line;
  std::snprintf(line, sizeof line, "  %-20s %8s %12s %12s %12s\n", "operator", "loops", "rows",
                "total ms", "ms/loop");
  os << line;
  double total = 0;
  for (int op = 0; op < Engine::kOpCount; ++op) total += e.ops[op].seconds;
  for (int op = 0; op < Engine::kOpCount; ++op) {
    const OperatorStats& s = e.ops[op];
    if (!s.loops) continue;
    std::snprintf(line, sizeof line, "  %-20s %8llu %12llu %12.3f %12.4f\n", names[op],
                  static_cast<unsigned long long>(s.loops), static_cast<unsigned long long>(s.rows),
                  s.seconds * 1e3, s.seconds * 1e3 / static_cast<double>(s.loops));
    os << line;
    const QueryStats& q = s.query;
    if (q.pair_tests || q.nodes_visited || q.queue_pops) {
      std::snprintf(line, sizeof line,
                    "  %-20s pair tests %llu, nodes %llu, queue pushes %llu, pops %llu\n", "",
                    static_cast<unsigned long long>(q.pair_tests),
                    static_cast<unsigned long long>(q.nodes_visited),
                    static_cast<unsigned long long>(q.queue_pushes),
                    static_cast<unsigned long long>(q.queue_pops));
      os << line;
    }
    if (q.build_seconds > 0) {
      std::snprintf(line, sizeof line, "  %-20s index build %.3f ms, probes %.3f ms\n", "",
                    q.build_seconds * 1e3, q.query_seconds * 1e3);
      os << line;
    }
  }
  std::snprintf(line, sizeof line, "  %-20s %8s %12s %12.3f\n", "total", "", "", total * 1e3);
  os << line;
  if (e.nav) {
    const path::NavigationStats ns = e.nav->stats();
    const path::PathService::Stats ss = e.nav->service_stats();
    std::snprintf(
        line, sizeof line,
        "  path service: %llu requests (%llu re-plans), %llu dispatched, %llu superseded, %llu "
        "queued; "
        "%llu routes applied (%llu partial, %llu without a path)\n",
        static_cast<unsigned long long>(ns.requests), static_cast<unsigned long long>(ns.replans),
        static_cast<unsigned long long>(ns.dispatched),
        static_cast<unsigned long long>(ns.superseded), static_cast<unsigned long long>(ns.queued),
        static_cast<unsigned long long>(ns.applied), static_cast<unsigned long long>(ns.partial),
        static_cast<unsigned long long>(ns.failed));
    os << line;
    std::snprintf(line, sizeof line,
                  "  worker: %llu searches in %.3f ms; the tick waited for it %llu times, %.3f ms; "
                  "meshes built in %.3f ms\n",
                  static_cast<unsigned long long>(ss.jobs_done), ss.work_seconds * 1e3,
                  static_cast<unsigned long long>(ss.waits), ss.wait_seconds * 1e3,
                  e.nav->mesh_build_seconds() * 1e3);
    os << line;
  }
  os << "  access paths used (ticks):";
  for (const auto& [k, v] : e.method_ticks) os << " " << k << " x" << v;
  os << "\n";
  return os.str();
}

}  // namespace crowddb
