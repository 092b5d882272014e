// The tick driver: runs the stages in their fixed order (stages.hpp, the steering model of
// src/steer/, backoff, stalemates), commits, and keeps the EXPLAIN ANALYZE counters.
#include "crowddb/simulation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>

#include "path/navigation.hpp"
#include "sim/moved_lists.hpp"
#include "sim/oplog.hpp"
#include "sim/row_order.hpp"
#include "sim/sources.hpp"
#include "sim/stages.hpp"
#include "sim/stalemate.hpp"
#include "steer/model.hpp"
#include "util/byte_codec.hpp"
#include "util/hash.hpp"
#include "util/rng.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb {
namespace {

constexpr std::size_t kCommitGrain = 1024;  // rows per chunk of the commit stage

void require(bool ok, const char* field, const std::string& what) {
  if (!ok) throw InvalidRow(field, std::string(field) + " " + what);
}

std::string num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

// Does the backoff try the steering model's neighbour lists (sim::lists_rule_out_overlaps)? Only
// with the collision method left to the planner: a method asked for by name (the naive oracle,
// say) answers every tick itself.
bool backoff_reads_model_lists(const SimConfig& cfg) {
  return cfg.access.collisions == "auto";
}

// Does the tick put the rows in curve order (AccessChoice::row_order)?
bool reorders(const SimConfig& cfg, std::size_t rows) {
  return cfg.access.row_order == "curve" ||
         (cfg.access.row_order == "auto" && rows >= sim::kReorderMinRows &&
          cfg.steering.model != "thesis");  // its field sums the charges in row order
}

// Rows i < n for which pred(i) holds, counted in chunks on every thread (a pass over every row
// on one thread was a millisecond a tick at 10^6 agents, the other thread idle meanwhile).
template <class Pred>
std::size_t count_rows(Executor& ex, std::size_t n, Pred pred) {
  constexpr std::size_t kGrain = 16384;
  std::vector<std::size_t> counts((n + kGrain - 1) / kGrain, 0);
  ex.for_each_chunk(n, kGrain, [&](std::size_t b, std::size_t e) {
    std::size_t c = 0;
    for (std::size_t i = b; i < e; ++i) c += pred(i) ? 1 : 0;
    counts[b / kGrain] = c;
  });
  std::size_t all = 0;
  for (std::size_t c : counts) all += c;
  return all;
}

}  // namespace

void SimConfig::validate() const {
  require(std::isfinite(dt) && dt > 0, "dt", "must be > 0");
  steer::find_model(steering.model);  // throws Error(usage) naming the models
  const ThesisParams& th = steering.thesis;
  require(std::isfinite(th.tau) && th.tau > 0, "steering/thesis/tau", "must be > 0");
  require(std::isfinite(th.w_apf) && th.w_apf >= 0, "steering/thesis/w_apf", "must be >= 0");
  require(std::isfinite(th.w_ftc) && th.w_ftc >= 0, "steering/thesis/w_ftc", "must be >= 0");
  require(std::isfinite(th.horizon) && th.horizon > 0, "steering/thesis/horizon", "must be > 0");
  require(std::isfinite(th.obstacle_cutoff) && th.obstacle_cutoff > 0,
          "steering/thesis/obstacle_cutoff", "must be > 0");
  const PotentialSpec& p = th.potential;
  require(std::isfinite(p.A), "steering/thesis/potential/A", "must be finite");
  require(std::isfinite(p.k) && p.k >= 0, "steering/thesis/potential/k", "must be >= 0");
  require(p.radial_frames >= 1 && p.radial_frames <= 16, "steering/thesis/potential/frames",
          "must be in 1..16");
  require(std::isfinite(p.inv_floor) && p.inv_floor > 0, "steering/thesis/potential/inv_floor",
          "must be > 0");
  const OrcaParams& o = steering.orca;
  require(std::isfinite(o.neighbor_dist) && o.neighbor_dist > 0, "steering/orca/neighbor_dist",
          "must be > 0");
  require(o.max_neighbors >= 1, "steering/orca/max_neighbors", "must be >= 1");
  require(std::isfinite(o.time_horizon) && o.time_horizon > 0, "steering/orca/time_horizon",
          "must be > 0");
  require(std::isfinite(o.time_horizon_obst) && o.time_horizon_obst > 0,
          "steering/orca/time_horizon_obst", "must be > 0");
  require(std::isfinite(o.first_share) && o.first_share > 0 && o.first_share < 1,
          "steering/orca/first_share", "must be in (0, 1)");
  require(std::isfinite(o.time_gap) && o.time_gap >= 0, "steering/orca/time_gap", "must be >= 0");
  require(std::isfinite(o.stream_gap) && o.stream_gap >= 0, "steering/orca/stream_gap",
          "must be >= 0");
  require(std::isfinite(o.max_retreat) && o.max_retreat >= 0, "steering/orca/max_retreat",
          "must be >= 0");
  require(std::isfinite(o.pass_look) && o.pass_look >= 0, "steering/orca/pass_look",
          "must be >= 0");
  const CfsmParams& c = steering.cfsm;
  require(std::isfinite(c.time_gap) && c.time_gap > 0, "steering/cfsm/time_gap", "must be > 0");
  require(std::isfinite(c.strength_neighbor) && c.strength_neighbor >= 0,
          "steering/cfsm/strength_neighbor", "must be >= 0");
  require(std::isfinite(c.range_neighbor) && c.range_neighbor > 0, "steering/cfsm/range_neighbor",
          "must be > 0");
  require(std::isfinite(c.strength_geometry) && c.strength_geometry >= 0,
          "steering/cfsm/strength_geometry", "must be >= 0");
  require(std::isfinite(c.range_geometry) && c.range_geometry > 0, "steering/cfsm/range_geometry",
          "must be > 0");
  require(std::isfinite(c.cutoff) && c.cutoff > 0, "steering/cfsm/cutoff", "must be > 0");
  require(std::isfinite(steering.perturbation) && steering.perturbation >= 0,
          "steering/perturbation", "must be >= 0");
  require(threads >= 1 && threads <= 256, "threads", "must be in 1..256");
  require(access.row_order == "auto" || access.row_order == "curve" || access.row_order == "none",
          "access/row_order", "must be \"auto\", \"curve\" or \"none\"");
  require(std::isfinite(gridlock_time) && gridlock_time > 0, "gridlock_time", "must be > 0");
  require(std::isfinite(nudge_after) && nudge_after >= 0, "nudge_after", "must be >= 0");
  require(std::isfinite(waypoint_radius) && waypoint_radius >= 0, "waypoint_radius",
          "must be >= 0");
  require(std::isfinite(stall.after) && stall.after > 0, "stall/after", "must be > 0");
  require(std::isfinite(stall.progress) && stall.progress > 0, "stall/progress", "must be > 0");
  require(std::isfinite(stall.yield_time) && stall.yield_time > 0, "stall/yield_time",
          "must be > 0");
  require(std::isfinite(stall.head_on_yield_time) && stall.head_on_yield_time > 0,
          "stall/head_on_yield_time", "must be > 0");
  require(std::isfinite(stall.sidestep_time) && stall.sidestep_time > 0, "stall/sidestep_time",
          "must be > 0");
  require(std::isfinite(stall.reverse_after) && stall.reverse_after >= 0, "stall/reverse_after",
          "must be >= 0");
  require(std::isfinite(stall.reverse_period) && stall.reverse_period > 0, "stall/reverse_period",
          "must be > 0");
  const NavigationParams& n = navigation;
  require(std::isfinite(n.latency) && n.latency >= 0, "navigation/latency", "must be >= 0");
  require(n.budget >= 1, "navigation/budget", "must be >= 1");
  require(std::isfinite(n.replan_after) && n.replan_after >= 0, "navigation/replan_after",
          "must be >= 0");
  require(std::isfinite(n.congestion_cost) && n.congestion_cost >= 0, "navigation/congestion_cost",
          "must be >= 0");
  require(std::isfinite(n.queue_flow) && n.queue_flow >= 0, "navigation/queue_flow",
          "must be >= 0");
  require(std::isfinite(n.radius_step) && n.radius_step > 0, "navigation/radius_step",
          "must be > 0");
  require(std::isfinite(n.cell_size) && n.cell_size >= 0, "navigation/cell_size", "must be >= 0");
  require(std::isfinite(n.clearance) && n.clearance >= 0, "navigation/clearance", "must be >= 0");
  require(std::isfinite(n.corner_push) && n.corner_push >= 0, "navigation/corner_push",
          "must be >= 0");
  require(n.tile_size >= 16 && n.tile_size <= 4096, "navigation/tile_size", "must be in 16..4096");
  require(std::isfinite(n.sight_interval) && n.sight_interval >= 0, "navigation/sight_interval",
          "must be >= 0");
  // Durations become tick counts: keep them representable.
  for (double d : {gridlock_time, nudge_after, stall.after, stall.yield_time,
                   stall.head_on_yield_time, stall.sidestep_time, stall.reverse_after,
                   stall.reverse_period, n.latency, n.replan_after, n.sight_interval})
    require(d / dt < 1e9, "dt", "is too small for the durations given (over 10^9 ticks)");
}

uint64_t SimConfig::ticks_for(double seconds, uint64_t min) const {
  // A hair of tolerance so that 0.3 s at dt 0.1 is 3 ticks, not 4.
  const double t = std::ceil(seconds / dt - 1e-9);
  const uint64_t n = t <= 0 ? 0 : static_cast<uint64_t>(t);
  return std::max(n, min);
}

// The collision-set access path chosen for one tick.
struct TickPlan {
  std::size_t rows = 0;
  const CollisionMethod* collisions = nullptr;
  bool collisions_fallback = false;  // the forced method does not apply to this tick (see plan())
};

struct Simulation::Engine {
  Engine(int threads, const World& w, uint64_t seed) : ex(threads), sources(w, seed) {}

  Executor ex;
  StaticScene scene;
  double scene_spacing = INFINITY;
  std::unique_ptr<steer::Model> model;
  sim::Preferred pref;
  sim::AimMemo aim;  // aim points, from the stalemate watch to the next goal stage
  sim::NextState next;
  // The reorder's order and what curve_order works in, kept from one reorder to the next.
  sim::CurveScratch curve;
  std::vector<uint32_t> order;
  std::vector<uint32_t> demand;  // active agents per goal row (arrival = idle only)
  sim::SourceEmitter sources;
  std::map<std::string, std::unique_ptr<CollisionPath>> collision_paths;
  std::unique_ptr<NeighbourPath> stall_path;
  std::unique_ptr<path::Navigation> nav;  // null: navigation off
  sim::OpLog log;
  // The agents are known to overlap nowhere at the start of the next tick: the last tick ended
  // (with backoff on) without an overlapping agent pair and no agent was inserted since. Only
  // then is a method that finds the collision set but not every pair (nn) exact for the
  // backoff: every overlap is new, so the set is all the freeze loop needs.
  bool start_clean = false;
  // The backoff's check on the model's neighbour lists (sim::lists_rule_out_overlaps) costs a
  // pass over the rows. Where it keeps failing (a dense queue: lists shorter than the tick's
  // moves) it waits 1, 2, 4, ... up to kListsWaitMost ticks before the next try. Which ticks try
  // changes the cost only, never a result.
  static constexpr uint32_t kListsWaitMost = 16;
  uint32_t lists_wait = 0, lists_left = 0;  // the current wait, and the ticks left of it

  // The collision access path for the next tick. A method forced by name that does not apply to
  // this tick (nn while agents still overlap from before, or radii that stopped being equal
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

  // The thesis model's charged points (obstacle_repulsion = charges) are spaced no wider than the
  // smallest agent radius (DESIGN.md §2); rebuild the scene when a smaller agent appears. Other
  // models and the nearest-geometry repulsion need no charged points.
  void refresh_scene(const World& w, const SimConfig& cfg) {
    const ThesisParams& th = cfg.steering.thesis;
    const bool charged = cfg.steering.model == "thesis" && th.w_apf > 0 &&
                         th.obstacle_repulsion == ThesisParams::ObstacleRepulsion::charges;
    double rmin = INFINITY;
    if (charged)
      for (double r : w.agents().radius) rmin = std::min(rmin, r);
    if (!std::isfinite(rmin)) rmin = 1;
    if (rmin >= scene_spacing) return;
    build_scene(w, cfg, rmin);
  }
  void build_scene(const World& w, const SimConfig& cfg, double spacing) {
    const ThesisParams& th = cfg.steering.thesis;
    const bool charged = cfg.steering.model == "thesis" && th.w_apf > 0 &&
                         th.obstacle_repulsion == ThesisParams::ObstacleRepulsion::charges;
    scene_spacing = spacing;
    scene = StaticScene({w.circles().begin(), w.circles().end()},
                        {w.polygons().begin(), w.polygons().end()}, scene_spacing,
                        charged ? th.obstacle_charges : ObstacleCharges::none,
                        cfg.walls ? &w.bounds() : nullptr);
  }

  // Arrivals that idle gather at their goal: an agent on its last goal also arrives when it
  // touches (a gap under kJoinGap) an agent already idle at that goal, so the group grows
  // outwards instead of the later ones pushing through it for ever. Likewise an agent reaches
  // any goal when it touches one waiting at it (a crowd round a booth). joined[i] says who.
  static constexpr double kJoinGap = 0.1;  // [m]
  std::vector<uint8_t> joined;
  std::vector<uint32_t> join_queries;
  NeighbourLists join_lists;
  std::unique_ptr<NeighbourPath> join_path;
  // `move`: the model's lists of the tick and the move since (sim/moved_lists.hpp).
  void join_idle_groups(const World& w, const SimConfig& cfg, QueryStats& stats,
                        const sim::TickMove* move) {
    const AgentTable& t = w.agents();
    joined.assign(t.size(), 0);
    const bool idle = cfg.arrival == ArrivalPolicy::idle;
    if (!idle && !w.any_goal_wait()) return;
    join_queries.clear();
    double rmax = 0;
    bool any_standing = false;
    for (std::size_t i = 0; i < t.size(); ++i) {
      rmax = std::max(rmax, t.radius[i]);
      any_standing = any_standing || standing(t.state[i]);
      if (!standing(t.state[i]) && t.route[i].empty() &&
          ((idle && t.then[i].empty()) || w.goals()[t.goal[i]].has_wait()))
        join_queries.push_back(static_cast<uint32_t>(i));
    }
    if (!any_standing || join_queries.empty()) return;
    if (!join_path) join_path = neighbour_method(cfg.access.neighbours, t.size()).make();
    sim::neighbours_after_move(t, move, join_queries, 2 * rmax + kJoinGap, 8, *join_path,
                               join_lists, ex, stats);
    for (std::size_t q = 0; q < join_queries.size(); ++q) {
      const uint32_t i = join_queries[q];
      for (uint32_t a = join_lists.offset[q]; a < join_lists.offset[q + 1]; ++a) {
        const uint32_t j = join_lists.row[a];
        if (!standing(t.state[j]) || t.goal[j] != t.goal[i]) continue;
        if (t.state[j] == AgentState::arrived && !t.then[i].empty()) continue;
        if (std::sqrt(join_lists.dist2[a]) - t.radius[i] - t.radius[j] < kJoinGap) {
          joined[i] = 1;
          break;
        }
      }
    }
  }

  steer::TickInput input(const World& w, const SimConfig& cfg, uint64_t tick) const {
    return {w.agents(), w.goals(), scene, cfg, pref.vx, pref.vy, pref.left, tick, start_clean};
  }
};

Simulation::Simulation(World world, SimConfig config)
    : world_(std::move(world)), config_(std::move(config)) {
  config_.validate();
  world_.set_walls(config_.walls);
  for (const Source& s : world_.sources())
    for (uint32_t g : s.goals)
      if (g >= world_.goals().size())
        throw InvalidRow("goal",
                         "a source names goal " + std::to_string(g) + ", which does not exist");
  engine_ = std::make_unique<Engine>(config_.threads, world_, config_.seed);
  world_.apply_pending();
  engine_->model = steer::find_model(config_.steering.model).make();
  engine_->refresh_scene(world_, config_);
  engine_->plan(world_, config_, true);  // reject unknown or unsupported methods now, not mid-run
  neighbour_method(config_.access.neighbours, 0);
  feature_method(config_.access.edges, 0);
  if (config_.steering.model == "thesis") {
    if (config_.access.ftc != "auto") find_ftc_method(config_.access.ftc);
    if (config_.access.field != "auto")
      find_field_method(config_.access.field, config_.steering.thesis.potential);
  }
  if (config_.navigation.enabled) {
    // Meshes for the radius classes present, and the first requests (tick 0: due at `latency`).
    engine_->nav = std::make_unique<path::Navigation>(world_, config_, engine_->ex);
    engine_->nav->request_paths(world_, 0);
  }
  last_.agents = world_.agents().size();
  for (AgentState st : world_.agents().state) last_.active += st != AgentState::arrived;
  last_.state_hash = sim::state_hash(world_.agents(), 0, &engine_->ex);
}

Simulation::~Simulation() = default;
Simulation::Simulation(Simulation&&) noexcept = default;
Simulation& Simulation::operator=(Simulation&&) noexcept = default;

uint64_t Simulation::state_hash() const {
  return sim::state_hash(world_.agents(), last_.tick, &engine_->ex);
}

namespace {

constexpr std::string_view kCheckpointMagic = "crowddb-checkpoint";
// 2: narrow meshes in the path service's state; 3: goal waits (the wait_until column); 4: the
// goal each agent left last (the left_goal column); 5: congestion costs of the path searches in
// flight; 6: the navigation's routes that fall short; 7: door cuts in the searches in flight;
// 8: the state hash in blocks and lanes (sim::state_hash).
constexpr uint32_t kCheckpointVersion = 9;

// What a checkpoint must agree on with the simulation it is restored into: the static tables
// and the settings that change what a tick computes (not the thread count).
uint64_t fingerprint(const World& w, const SimConfig& cfg) {
  StateHasher h;
  const Bounds& b = w.bounds();
  for (double v : {b.xmin, b.ymin, b.xmax, b.ymax, cfg.dt}) h.add(v);
  h.add(cfg.seed);
  for (char c : cfg.steering.model) h.add(static_cast<uint64_t>(c));
  h.add(static_cast<uint64_t>(cfg.backoff) | static_cast<uint64_t>(cfg.walls) << 1 |
        static_cast<uint64_t>(cfg.navigation.enabled) << 2 |
        static_cast<uint64_t>(cfg.arrival) << 3);
  h.add(w.goals().size());
  for (const Goal& g : w.goals()) {
    h.add(g.x);
    h.add(g.y);
    h.add(g.area.size());
  }
  h.add(w.circles().size());
  for (const CircleObstacle& c : w.circles()) {
    h.add(c.x);
    h.add(c.y);
    h.add(c.radius);
  }
  h.add(w.polygons().size());
  for (const PolygonObstacle& p : w.polygons()) h.add(p.vertices.size());
  h.add(w.sources().size());
  return h.digest();
}

template <class Io, class M>
void metrics_fields(Io&& io, M& m) {
  io(m.tick);
  io(m.time);
  for (auto* v : {&m.agents, &m.active, &m.entered, &m.arrived, &m.frozen, &m.freeze_iterations,
                  &m.overlapping_pairs, &m.obstacle_overlaps, &m.gridlocked, &m.gridlock_started,
                  &m.longest_frozen, &m.nudged, &m.stalled, &m.queueing, &m.stall_started,
                  &m.longest_stall, &m.yielding, &m.sidestepping, &m.making_way})
    io(*v);
  io(m.seconds);
  io(m.state_hash);
}

}  // namespace

std::string Simulation::save_state() const {
  ByteWriter out(kCheckpointMagic);
  write_state(out);
  return out.seal();
}

void Simulation::save_state(const std::function<void(std::string_view)>& sink) const {
  ByteWriter out(kCheckpointMagic);
  out.stream_to(sink);
  write_state(out);
  out.seal();
}

void Simulation::write_state(ByteWriter& out) const {
  const Engine& e = *engine_;
  out.u32(kCheckpointVersion);
  out.u64(fingerprint(world_, config_));
  world_.save_agents(out);
  metrics_fields(
      [&](const auto& v) {
        if constexpr (std::is_same_v<std::decay_t<decltype(v)>, double>)
          out.f64(v);
        else
          out.u64(static_cast<uint64_t>(v));
      },
      last_);
  out.u64(arrived_total_);
  out.u64(entered_total_);
  out.u8(e.start_clean);
  out.f64(e.scene_spacing);
  e.sources.save(out);
  out.u8(e.nav != nullptr);
  if (e.nav) e.nav->save(out);
  out.text(kCheckpointMagic);  // a trailer: the bytes ended where they should
}

void Simulation::restore_state(std::string_view bytes, const std::string& what) {
  Engine& e = *engine_;
  ByteReader in = ByteReader::open_sealed(bytes, kCheckpointMagic, "crowddb checkpoint", what);
  const uint32_t version = in.u32();
  if (version != kCheckpointVersion)
    in.fail("checkpoint version " + std::to_string(version) + ", this build reads version " +
            std::to_string(kCheckpointVersion));
  if (in.u64() != fingerprint(world_, config_))
    in.fail("the checkpoint is of another scenario or other settings");
  world_.restore_agents(in);
  TickMetrics m;
  metrics_fields(
      [&](auto& v) {
        using T = std::decay_t<decltype(v)>;
        if constexpr (std::is_same_v<T, double>)
          v = in.f64();
        else
          v = static_cast<T>(in.u64());
      },
      m);
  if (m.tick > (uint64_t{1} << 53)) in.fail("bad tick " + std::to_string(m.tick));
  last_ = m;
  arrived_total_ = in.u64();
  entered_total_ = in.u64();
  e.start_clean = in.u8() != 0;
  const double spacing = in.f64();
  if (!(spacing > 0)) in.fail("bad obstacle sampling");
  if (spacing != e.scene_spacing) e.build_scene(world_, config_, spacing);
  e.sources.restore(in, world_);
  const bool nav = in.u8() != 0;
  if (nav != (e.nav != nullptr)) in.fail("navigation is on in one and off in the other");
  if (e.nav) e.nav->restore(in, last_.tick, world_);
  if (in.text() != kCheckpointMagic || !in.at_end()) in.fail("trailing or damaged data");
  if (last_.state_hash != state_hash()) in.fail("the state does not match its hash");
}

std::size_t Simulation::waiting_to_enter() const {
  return engine_->sources.waiting(world_);
}

std::size_t Simulation::without_path() const {
  return engine_->nav ? engine_->nav->without_path(world_) : 0;
}

const TickMetrics& Simulation::step() {
  Engine& e = *engine_;
  const SimConfig& cfg = config_;
  sim::OpLog& log = e.log;
  Stopwatch tick_clock;
  TickMetrics m;
  m.tick = last_.tick + 1;
  m.time = static_cast<double>(m.tick) * cfg.dt;

  // 0. apply the buffered inserts, deletes and re-targets (and the sources' entries) as one batch
  std::size_t applied = 0;
  log.timed("apply_batch", world_.pending_changes(), [&] {
    if (!world_.sources().empty()) m.entered = e.sources.emit(world_, cfg, e.scene, m.tick);
    applied = world_.apply_pending();
  });
  if (applied)
    e.start_clean = false;  // an insert may overlap (erases and re-targets cannot, but are rare)
  if (e.nav) {
    std::size_t routes = 0;
    log.timed("path results", 0, [&] { routes = e.nav->apply_results(world_, m.tick); });
    log.at("path results").rows += routes;
  }
  if (reorders(cfg, world_.agents().size()) &&
      (m.tick - 1) % cfg.ticks_for(sim::kReorderInterval) == 0)
    log.timed("reorder rows", world_.agents().size(), [&] {
      // The table's columns on every thread, and beside them what the model and the grids keep
      // per row (they read only the order and their own state). Two threads at 2 * 10^4 rows:
      // 16 -> 13 ms per 100 ticks; the columns alone on every thread gained nothing.
      sim::curve_order(world_.agents(), &e.ex, e.curve, e.order);
      const std::vector<uint32_t>& order = e.order;
      e.ex.both([&] { world_.permute_rows(order, &e.ex); },
                [&] {
                  e.model->rows_permuted(order, &e.ex);
                  if (e.stall_path) e.stall_path->rows_permuted(order, &e.ex);
                  if (e.join_path) e.join_path->rows_permuted(order, &e.ex);
                });
    });
  e.refresh_scene(world_, cfg);
  const TickPlan plan = e.plan(world_, cfg);
  AgentTable& t = world_.agents_for_tick();
  const std::size_t n = t.size();
  e.pref.reset(n);
  e.next.resize(n);

  // 1. goal stage: preferred velocities
  if (cfg.arrival == ArrivalPolicy::idle || world_.any_goal_wait()) {
    e.demand.assign(world_.goals().size(), 0);
    for (std::size_t i = 0; i < n; ++i)
      if (!standing(t.state[i])) ++e.demand[t.goal[i]];
  } else {
    e.demand.clear();
  }
  const uint64_t nudge_ticks = cfg.nudge_after > 0 ? cfg.ticks_for(cfg.nudge_after) : 0;
  if (nudge_ticks)
    m.nudged += count_rows(e.ex, n, [&](std::size_t i) {
      return !standing(t.state[i]) && t.frozen_ticks[i] >= nudge_ticks;
    });
  log.timed("goal stage", n, [&] {
    e.aim.resize(n, world_.goals());
    sim::goal_stage(t, world_.goals(), cfg, m.tick, e.demand, e.pref, e.ex, e.nav.get(), &e.aim);
  });

  // 2. the steering model: one velocity per row
  e.model->velocities(e.input(world_, cfg, m.tick), e.next.vx, e.next.vy, e.ex, log);

  // 3. tentative positions
  log.timed("integrate", n, [&] { sim::integrate(t, e.next, cfg.dt, e.ex); });

  // 4. backoff (or, without it, just measure the overlaps)
  const std::string collisions_used =
      "collisions=" + plan.collisions->info.name +
      (plan.collisions_fallback ? " (instead of " + cfg.access.collisions + ")" : "");
  CollisionPath& cpath = [&]() -> CollisionPath& {
    auto& slot = e.collision_paths[plan.collisions->info.name];
    if (!slot) slot = plan.collisions->make();
    return *slot;
  }();
  sim::OverlapReport overlaps;
  const std::string backoff_name = cfg.backoff ? "backoff" : "overlap count";
  sim::OperatorStats& bop = log.at(backoff_name);
  log.timed(backoff_name, n, [&] {
    if (cfg.backoff) {
      const NearLists near =
          backoff_reads_model_lists(cfg) && e.lists_left == 0 ? e.model->near_lists() : NearLists{};
      e.lists_left -= e.lists_left > 0;
      overlaps =
          sim::backoff(t, e.next, e.scene, cpath, e.ex, bop.query, m.freeze_iterations, near);
      if (near.lists) {
        e.lists_wait = overlaps.agents_by_lists
                           ? 0
                           : std::min<uint32_t>(std::max<uint32_t>(2 * e.lists_wait, 1),
                                                Simulation::Engine::kListsWaitMost);
        e.lists_left = e.lists_wait;
      }
      bop.count("rounds (1: nothing to undo)", m.freeze_iterations);
    } else {
      overlaps = sim::find_overlaps(t, e.next, e.scene, cpath, e.ex, bop.query);
    }
  });
  log.used(overlaps.agents_by_lists ? std::string("collisions=model's neighbour lists")
                                    : collisions_used);
  m.overlapping_pairs = overlaps.agent_pairs;
  m.obstacle_overlaps = overlaps.obstacle_hits;
  e.start_clean = cfg.backoff && overlaps.agent_pairs == 0;

  // 5. commit: swap in the next state, advance waypoints, arrivals, goal sequences
  const uint64_t gridlock_ticks = cfg.ticks_for(cfg.gridlock_time);
  std::vector<uint64_t> lost_sight;  // ids of the walkers that lost sight of their targets
  sim::TickMove tick_move;
  log.timed("commit", n, [&] {
    t.x.swap(e.next.x);
    t.y.swap(e.next.y);
    t.vx.swap(e.next.vx);
    t.vy.swap(e.next.vy);
    // The model's lists of the tick and the move since (e.next holds the positions before now):
    // the idle groups' and the stalemate stage's searches are answered from them where they
    // must hold the answer (sim/moved_lists.hpp).
    const NearLists near = e.model->near_lists();
    tick_move = {near, e.next.x, e.next.y,
                 near.lists ? sim::largest_move(e.next.x, e.next.y, t.x, t.y, e.ex) : 0.0,
                 sim::RowRenumbering(n, {})};
    e.join_idle_groups(world_, cfg, log.at("commit").query, &tick_move);
    // Each row on its own (in chunks, on every thread: every write is to the row itself); the
    // counts and the rows leaving are gathered in row order afterwards.
    struct Part {
      std::size_t frozen = 0, gridlock_started = 0, longest_frozen = 0, gridlocked = 0, arrived = 0;
      std::vector<std::size_t> leaving;
      std::vector<uint64_t> lost_sight;  // ids (rows leave before the path requests)
    };
    std::vector<Part> parts((n + kCommitGrain - 1) / kCommitGrain);
    e.ex.for_each_chunk(n, kCommitGrain, [&](std::size_t begin, std::size_t end) {
      Part& c = parts[begin / kCommitGrain];
      // Done with goal t.goal[i] (reached, its wait over): on to the next goal of the sequence,
      // or the arrival policy.
      const auto done_with_goal = [&](std::size_t i) {
        if (world_.advance_goal(i)) return;  // an intermediate goal: on to the next one
        ++c.arrived;
        if (cfg.arrival == ArrivalPolicy::remove) {
          c.leaving.push_back(i);
        } else if (cfg.arrival == ArrivalPolicy::retarget && world_.goals().size() > 1) {
          // Another goal, from a stream keyed by seed, id and tick: thread- and
          // order-independent.
          Rng rng = Rng::stream(cfg.seed ^ (m.tick * 0x9e3779b97f4a7c15ull), t.id[i]);
          const auto others = static_cast<uint32_t>(world_.goals().size() - 1);
          const auto pick = static_cast<uint32_t>(rng.below(others));
          // (left_goal stays: out before in is for goal sequences, see sim::out_before_in)
          t.goal[i] = pick >= t.goal[i] ? pick + 1 : pick;
          t.route[i].clear();
          t.path_goal[i] = AgentTable::kNoPath;  // a new goal: re-plan
          t.progress_best[i] = INFINITY;
          t.stall_ticks[i] = 0;
          world_.refresh_target(i);
        } else {
          t.state[i] = AgentState::arrived;
          t.vx[i] = t.vy[i] = 0;
        }
      };
      for (std::size_t i = begin; i < end; ++i) {
        if (t.state[i] == AgentState::arrived) continue;
        if (t.state[i] == AgentState::waiting) {
          if (m.tick < t.wait_until[i]) continue;
          t.state[i] = AgentState::active;
          t.progress_best[i] = INFINITY;
          t.stall_ticks[i] = 0;
          done_with_goal(i);
          continue;
        }
        if (e.next.frozen[i]) {
          ++c.frozen;
          t.state[i] = AgentState::frozen;
          ++t.frozen_ticks[i];
          if (t.frozen_ticks[i] == gridlock_ticks) ++c.gridlock_started;
          c.longest_frozen = std::max<std::size_t>(c.longest_frozen, t.frozen_ticks[i]);
        } else {
          t.state[i] = AgentState::active;
          t.frozen_ticks[i] = 0;
        }
        if (t.frozen_ticks[i] >= gridlock_ticks) ++c.gridlocked;
        if (e.pref.skip[i] == sim::kLostSight) c.lost_sight.push_back(t.id[i]);
        if (e.pref.skip[i] == sim::kSkipWaypoint && !t.route[i].empty()) {  // saw the one after
          t.route[i].erase(t.route[i].begin());
          world_.refresh_target(i);
        }
        const double reach = cfg.waypoint_radius > 0 ? cfg.waypoint_radius : t.radius[i];
        while (!t.route[i].empty() &&
               length(t.route[i].front().x - t.x[i], t.route[i].front().y - t.y[i]) <= reach) {
          t.route[i].erase(t.route[i].begin());
          world_.refresh_target(i);
        }
        if (t.route[i].empty() && (world_.at_goal(i) || e.joined[i])) {
          const Goal& g = world_.goals()[t.goal[i]];
          if (g.has_wait()) {
            // Its wait, from a stream keyed by seed, id and tick (a visit of the agent).
            Rng rng = Rng::stream(cfg.seed ^ (m.tick * 0xbf58476d1ce4e5b9ull), t.id[i] ^ 0x3a17);
            const double wait =
                g.wait_mean > 0
                    ? std::min(-g.wait_mean * std::log1p(-rng.uniform()), Goal::kMaxWait)
                    : rng.uniform(g.wait_min, g.wait_max);
            if (wait > 0) {  // whole ticks, at least one
              t.state[i] = AgentState::waiting;
              t.frozen_ticks[i] = 0;
              t.stall_action[i] = StallAction::none;
              t.vx[i] = t.vy[i] = 0;
              t.wait_until[i] = m.tick + cfg.ticks_for(wait);
              continue;
            }
          }
          done_with_goal(i);
        }
      }
    });
    std::vector<std::size_t> leaving;
    for (const Part& c : parts) {
      m.frozen += c.frozen;
      m.gridlock_started += c.gridlock_started;
      m.longest_frozen = std::max(m.longest_frozen, c.longest_frozen);
      m.gridlocked += c.gridlocked;
      m.arrived += c.arrived;
      leaving.insert(leaving.end(), c.leaving.begin(), c.leaving.end());
      lost_sight.insert(lost_sight.end(), c.lost_sight.begin(), c.lost_sight.end());
    }
    tick_move.rows = sim::RowRenumbering(n, leaving);  // (the lists' rows, for the stalemates)
    world_.remove_rows(std::move(leaving));
  });

  // 6. stalemates: progress watch, then an action for each agent stalled without one
  std::vector<uint32_t> head_on;  // stalled where streams meet head-on (path requests avoid them)
  log.timed("stalemates", world_.agents().size(), [&] {
    if (!e.stall_path)
      e.stall_path = neighbour_method(cfg.access.neighbours, world_.agents().size()).make();
    e.aim.resize(world_.agents().size(), world_.goals());
    sim::OperatorStats& sop = log.at("stalemates");
    const sim::StallCounts sc =
        sim::stalemates(world_, cfg, m.tick, *e.stall_path, e.ex, sop.query, &e.aim, &tick_move);
    sop.count("rows looked at, blockers from the model's lists", sc.by_lists);
    m.stalled = sc.stalled;
    m.stall_started = sc.started;
    m.longest_stall = sc.longest;
    m.queueing = sc.queueing;
    m.yielding = sc.yielding;
    m.sidestepping = sc.sidestepping;
    m.making_way = sc.making_way;
    head_on = std::move(sc.head_on);
  });

  // 7. path requests: new requests, re-plans, dispatch to the worker within the budget
  if (e.nav) {
    std::size_t made = 0;
    log.timed("path requests", 0,
              [&] { made = e.nav->request_paths(world_, m.tick, head_on, lost_sight); });
    log.at("path requests").rows += made;
  }
  m.agents = world_.agents().size();
  const auto& state = world_.agents().state;
  m.active = count_rows(e.ex, state.size(),
                        [&](std::size_t i) { return state[i] != AgentState::arrived; });
  m.state_hash = sim::state_hash(world_.agents(), m.tick, &e.ex);
  arrived_total_ += m.arrived;
  entered_total_ += m.entered;
  m.seconds = tick_clock.seconds();
  last_ = m;
  return last_;
}

std::string Simulation::explain() const {
  const Engine& e = *engine_;
  const TickPlan p = e.plan(world_, config_);
  const SimConfig& cfg = config_;
  std::ostringstream os;
  os << "TICK PLAN  rows=" << p.rows << " agents, " << world_.circles().size() << " circles, "
     << world_.polygons().size() << " polygons" << (cfg.walls ? " + 4 walls" : "") << " ("
     << e.scene.feature_count() << " obstacle features, " << e.scene.point_count()
     << " charged points), " << world_.goals().size() << " goals, " << world_.sources().size()
     << " sources; model=" << cfg.steering.model << "; dt=" << num(cfg.dt)
     << " s; threads=" << cfg.threads << "\n";
  os << "  0 apply_batch        buffered inserts, deletes, re-targets (" << world_.pending_changes()
     << " pending)";
  if (!world_.sources().empty())
    os << "; sources let agents in at free spots (" << waiting_to_enter() << " still to enter)";
  if (reorders(cfg, world_.agents().size()))
    os << "; rows put in Z-curve order of their positions every " << num(sim::kReorderInterval)
       << " s (neighbours together in memory)";
  os << "\n";
  const NavigationParams& nv = cfg.navigation;
  const uint64_t latency = cfg.ticks_for(nv.latency);
  if (e.nav) {
    os << "  P path results       apply the routes due this tick (requested " << latency << " tick"
       << (latency == 1 ? "" : "s") << " earlier; waits only for a late worker)\n"
       << "       path service: Recast/Detour navigation mesh per radius class (radius rounded up "
          "to a multiple of "
       << num(nv.radius_step) << " m), findPath + "
       << (nv.corner_push > 0 ? "corners kept " + num(nv.corner_push) + " m in from the edges"
                              : std::string("findStraightPath"))
       << " on a worker thread\n"
       << e.nav->describe_meshes();
  }
  os << "  1 goal stage         per row: v_pref = pref_speed towards the waypoint (goal areas: "
        "their"
        " nearest point)";
  if (cfg.stall.resolve) os << "; stalemate actions (yield, sidestep)";
  if (cfg.nudge_after > 0) os << "; sidestep after " << num(cfg.nudge_after) << " s frozen";
  if (cfg.steering.perturbation > 0)
    os << "; seeded perturbation " << num(cfg.steering.perturbation) << " m/s";
  os << "\n";
  if (e.nav)
    os << "       waypoints: advance when within "
       << (cfg.waypoint_radius > 0 ? num(cfg.waypoint_radius) + " m"
                                   : std::string("the agent's radius"))
       << (nv.skip_visible ? " or when the next one is in sight (Detour raycast)" : "") << "\n";
  int step = 2;
  os << "       steering model " << cfg.steering.model << ": "
     << steer::find_model(cfg.steering.model).description << "\n";
  e.model->explain(os, e.input(world_, cfg, last_.tick + 1), step);
  os << "  " << step++ << " integrate          p' = p + v' dt\n";
  os << "  " << step++ << " ";
  if (!cfg.backoff) {
    os << "overlap count      backoff off: overlaps are only counted";
  } else {
    os << "backoff            freeze the collision set until empty; one full query, then probes"
          " of the agents frozen last";
    if (backoff_reads_model_lists(cfg))
      os << "; the query's agent half skipped on a tick the steering model's neighbour lists"
            " reach far enough to show no pair overlaps";
  }
  os << "\n       access path: " << p.collisions->info.name << " ("
     << p.collisions->info.description << ")";
  if (p.collisions_fallback)
    os << " instead of " << cfg.access.collisions << ": agents overlap at the start";
  if (!p.collisions->info.exact) os << "; inexact: the zero-overlap invariant is not guaranteed";
  os << "\n";
  // A method that only finds the set (nn) serves once a tick starts with no overlapping agents.
  const TickPlan clean = e.plan(world_, cfg, true, false);
  if (clean.collisions != p.collisions)
    os << "       then " << clean.collisions->info.name << " ("
       << clean.collisions->info.description
       << ") on ticks that start with no overlapping agents\n";
  os << "  " << step++ << " commit             swap columns, waypoints, arrivals ("
     << (cfg.arrival == ArrivalPolicy::remove ? "remove"
         : cfg.arrival == ArrivalPolicy::idle ? "idle"
                                              : "retarget")
     << "), goal sequences, state hash\n";
  os << "  " << step++ << " stalemates         progress watch: stalled after "
     << num(cfg.stall.after) << " s without getting " << num(cfg.stall.progress) << " m closer"
     << (cfg.stall.resolve ? "; resolve: yield by seeded priority, else sidestep" : "; resolve off")
     << "\n";
  if (e.nav) {
    os << "  " << step++ << " path requests      new goal";
    if (nv.replan_after > 0)
      os << ", or no progress for " << num(nv.replan_after) << " s, or an obstacle within "
         << num(sim::kLostSightLook) << " m towards a target farther than "
         << num(sim::kLostSightFar) << " m (walking slower than half its speed)";
    os << " -> FIFO queue; <= " << nv.budget << " dispatched per tick, due " << latency << " tick"
       << (latency == 1 ? "" : "s") << " later; congestion "
       << (nv.congestion_cost > 0
               ? "+" + num(nv.congestion_cost) + " m per agent stalled head-on in a polygon"
               : std::string("off"))
       << "; queues at doors "
       << (nv.queue_flow > 0 ? "(the first within " + num(path::kDoorLook) + " m, narrower than " +
                                   num(path::kDoorWidth) + " m) at " + num(nv.queue_flow) +
                                   " /(m s) per person ahead"
                             : std::string("off"))
       << "\n";
  }
  return os.str();
}

std::string Simulation::explain_analyze() const {
  const Engine& e = *engine_;
  std::ostringstream os;
  char line[512];
  std::snprintf(line, sizeof line, "EXPLAIN ANALYZE  %llu ticks (%.2f s simulated), model %s\n",
                static_cast<unsigned long long>(last_.tick), time(),
                config_.steering.model.c_str());
  os << line;
  std::snprintf(line, sizeof line, "  %-22s %8s %12s %12s %12s\n", "operator", "loops", "rows",
                "total ms", "ms/loop");
  os << line;
  double total = -e.log.overlap_seconds();
  for (const auto& [name, s] : e.log.entries()) total += s.seconds;
  for (const auto& [name, s] : e.log.entries()) {
    if (!s.loops) continue;
    std::snprintf(line, sizeof line, "  %-22s %8llu %12llu %12.3f %12.4f\n", name.c_str(),
                  static_cast<unsigned long long>(s.loops), static_cast<unsigned long long>(s.rows),
                  s.seconds * 1e3, s.seconds * 1e3 / static_cast<double>(s.loops));
    os << line;
    if (!s.beside.empty()) {
      std::snprintf(line, sizeof line, "  %-22s beside %s, on the same threads (times overlap)\n",
                    "", s.beside.c_str());
      os << line;
    }
    const QueryStats& q = s.query;
    if (q.pair_tests || q.nodes_visited || q.queue_pops) {
      std::snprintf(line, sizeof line,
                    "  %-22s pair tests %llu, nodes %llu, queue pushes %llu, pops %llu\n", "",
                    static_cast<unsigned long long>(q.pair_tests),
                    static_cast<unsigned long long>(q.nodes_visited),
                    static_cast<unsigned long long>(q.queue_pushes),
                    static_cast<unsigned long long>(q.queue_pops));
      os << line;
    }
    if (q.build_seconds > 0) {
      std::snprintf(line, sizeof line, "  %-22s index build %.3f ms, probes %.3f ms\n", "",
                    q.build_seconds * 1e3, q.query_seconds * 1e3);
      os << line;
    }
    if (!s.events_name.empty()) {
      std::snprintf(line, sizeof line, "  %-22s %s %llu (%.2f per loop, at most %llu)\n", "",
                    s.events_name.c_str(), static_cast<unsigned long long>(s.events),
                    static_cast<double>(s.events) / static_cast<double>(s.loops),
                    static_cast<unsigned long long>(s.events_max));
      os << line;
    }
  }
  std::snprintf(line, sizeof line, "  %-22s %8s %12s %12.3f\n", "total", "", "", total * 1e3);
  os << line;
  if (e.log.overlap_seconds() > 0) {
    std::snprintf(line, sizeof line,
                  "  (operators side by side overlapped by %.3f ms: counted once in the total)\n",
                  e.log.overlap_seconds() * 1e3);
    os << line;
  }
  if (e.nav) {
    const path::NavigationStats ns = e.nav->stats();
    const path::PathService::Stats ss = e.nav->service_stats();
    std::snprintf(
        line, sizeof line,
        "  path service: %llu requests (%llu re-plans), %llu dispatched, %llu superseded, %llu "
        "queued; "
        "%llu routes applied (%llu partial, %llu without a path); %llu searches on a narrow mesh, "
        "%llu of them reaching the goal; %llu searched round congestion, %llu of them with a "
        "queue at a door\n",
        static_cast<unsigned long long>(ns.requests), static_cast<unsigned long long>(ns.replans),
        static_cast<unsigned long long>(ns.dispatched),
        static_cast<unsigned long long>(ns.superseded), static_cast<unsigned long long>(ns.queued),
        static_cast<unsigned long long>(ns.applied), static_cast<unsigned long long>(ns.partial),
        static_cast<unsigned long long>(ns.failed), static_cast<unsigned long long>(ns.narrow),
        static_cast<unsigned long long>(ns.narrow_routes),
        static_cast<unsigned long long>(ns.costed),
        static_cast<unsigned long long>(ns.queue_costed));
    os << line;
    std::snprintf(line, sizeof line,
                  "  worker: %llu searches in %.3f ms; the tick waited for it %llu times, %.3f ms; "
                  "meshes built in %.3f ms\n",
                  static_cast<unsigned long long>(ss.jobs_done), ss.work_seconds * 1e3,
                  static_cast<unsigned long long>(ss.waits), ss.wait_seconds * 1e3,
                  e.nav->mesh_build_seconds() * 1e3);
    os << line;
  }
  std::snprintf(line, sizeof line,
                "  stalemates now: %zu stalled (longest %.1f s without progress), %zu yielding, "
                "%zu sidestepping, %zu making way\n",
                last_.stalled, static_cast<double>(last_.longest_stall) * config_.dt,
                last_.yielding, last_.sidestepping, last_.making_way);
  os << line;
  os << "  access paths used (ticks):";
  for (const auto& [k, v] : e.log.methods()) os << " " << k << " x" << v;
  os << "\n";
  return os.str();
}

}  // namespace crowddb
