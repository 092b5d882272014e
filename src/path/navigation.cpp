#include "path/navigation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "util/byte_codec.hpp"
#include "world/geometry.hpp"

namespace crowddb::path {
namespace {

constexpr double kNarrowStep = 0.01;  // [m] narrow meshes are per radius to the centimetre
// Searches dispatched with congestion costs per tick, at most: each may be an A* over a large
// mesh (SteerSuite's scenarioSpace: 5,000 agents re-planning across a forest of 5,000 boxes,
// where without a bound the path worker took 4.5 times as long); the rest plan as before.
constexpr std::size_t kCostedPerTick = 8;
// blocked_ahead: how far to look for the mesh's nearest point, and how far off it is off it.
constexpr double kBlockedReach = 2;  // [m]
constexpr double kOnMesh = 1e-3;     // [m] (the mesh is in floats)

// Where row i walks now: the unit vector to its waypoint (World::refresh_target's).
Vec2 heading(const AgentTable& t, std::size_t i) {
  return unit_towards(t.x[i], t.y[i], {t.target_x[i], t.target_y[i]});
}

}  // namespace

Navigation::Navigation(const World& world, const SimConfig& cfg, Executor& ex)
    : params_(cfg.navigation),
      latency_ticks_(cfg.ticks_for(cfg.navigation.latency)),
      replan_ticks_(cfg.navigation.replan_after > 0 ? cfg.ticks_for(cfg.navigation.replan_after)
                                                    : 0),
      geometry_(NavGeometry::of(world)),
      ex_(ex) {
  service_ = std::make_unique<PathService>();
  const AgentTable& t = world.agents();
  for (std::size_t i = 0; i < t.size(); ++i) mesh_for(t.radius[i]);
}

Navigation::~Navigation() {
  service_.reset();
}

int Navigation::class_of(double radius) const {
  // Rounded up, with a little slack so that a radius equal to a class boundary stays in it.
  // (Clamped in double: a radius of 1e9 m at a step of 0.01 m would overflow an int.)
  const double k = std::ceil(radius / params_.radius_step - 1e-9);
  return k >= 1e9 ? 1'000'000'000 : std::max(1, static_cast<int>(k));
}

double Navigation::class_radius(double radius) const {
  return class_of(radius) * params_.radius_step;
}

const NavMesh& Navigation::mesh_for(double radius) {
  return mesh_of_class(class_of(radius));
}

const NavMesh& Navigation::mesh_of_class(int k) {
  auto& slot = meshes_[k];
  if (!slot) {
    const int c = std::abs(k);
    // Cells: at most 4096 x 4096 over the world's area (a long, thin world, such as a queue of
    // passengers 1 km long before a 30 m aircraft, keeps its fine cells).
    const double side = std::sqrt(geometry_.bounds.width() * geometry_.bounds.height());
    NavMeshParams p;
    p.tile_size = static_cast<int>(params_.tile_size);
    if (k > 0) {
      p.radius = c * params_.radius_step + params_.clearance;
      // Opt-in: corners beyond the class radius from the walls where there is room (people 1 m
      // wide aiming at a door's posts wedge there: SteerSuite's bottleneck-evacuation). By at
      // most an eighth of a portal from either end: everyone aiming at the middle of a narrow
      // exit slows it more (RiMEA 9's 1 m exits).
      p.corner_push = params_.corner_push;
      p.push_share = 0.125;
      // Auto: a quarter of the class radius (a 1 km square world at 0.25: 16 M cells, seconds
      // to build).
      p.cell_size = params_.cell_size > 0 ? params_.cell_size
                                          : std::max(c * params_.radius_step / 4, side / 4096);
    } else {
      // Narrow: for the agent's own radius r (to the centimetre, not its class), an eighth of it
      // per cell, eroded by r less two cells, cells marked only when their centre is within half
      // a cell of an obstacle. Its polygons then keep about r from the walls (the erosion's
      // extra cell and the rounding give back what the two cells took), and a door is on it
      // from 1.9-2.3 r wide, as the cells fall (tests/path/navmesh_test.cpp).
      const double r = c * kNarrowStep;
      p.cell_size = std::max(r / 8, side / 4096);
      if (params_.cell_size > 0) p.cell_size = std::min(p.cell_size, params_.cell_size);
      p.radius = std::max(r - 2 * p.cell_size, r / 2);
      p.touch = 0.5;
      // Its corners lie about r from the walls, the disc's edge on them: move them out by up to
      // r more, into the middle of a door barely wider than the disc (aiming at a door's post, a
      // crowd wedges at it: SteerSuite's bottleneck-evacuation-2, 100 -> 40-64 of 100).
      p.corner_push = r;
    }
    slot = NavMesh::build(geometry_, p, &ex_);
  }
  return *slot;
}

bool Navigation::is_narrow(const NavMesh* m) const {
  for (const auto& [k, mesh] : meshes_)
    if (mesh.get() == m) return k < 0;
  return false;
}

// The search did not find the goal from where the agent stands: no path, or the start or goal
// moved onto the mesh by more than the clearance and two cells of rounding allow.
bool Navigation::off_mesh(const PathResult& r, const NavMesh& m) const {
  return r.status != PathStatus::ok || r.snap > m.clearance() + 2 * m.params().cell_size;
}

int Navigation::narrow_key(double radius) const {
  const double k = std::ceil(radius / kNarrowStep - 1e-9);
  return k >= 1e9 ? -1'000'000'000 : -std::max(1, static_cast<int>(k));
}

const NavMesh* Navigation::mesh_of_agent(double radius, uint64_t agent) const {
  auto it = meshes_.find(narrow_routes_.count(agent) ? narrow_key(radius) : class_of(radius));
  return it != meshes_.end() ? it->second.get() : nullptr;
}

bool Navigation::visible(double radius, uint64_t agent, Vec2 from, Vec2 to) const {
  const NavMesh* m = mesh_of_agent(radius, agent);
  return m && m->visible(from, to);
}

bool Navigation::blocked_ahead(double radius, uint64_t agent, Vec2 from, Vec2 to) const {
  // Not for those whose last route ends short of the goal (walled in, or no path: a search ends
  // there again, and they stand pressed against its end), nor for those on a narrow mesh's route
  // (its passages are barely wider than the agent, a ray through one is blocked as often as not,
  // and one squeezing into an aircraft's aisle was re-planned at its entrance every second and
  // never got in).
  if (short_routes_.count(agent) || narrow_routes_.count(agent)) return false;
  const NavMesh* mesh = mesh_of_agent(radius, agent);
  if (!mesh) return false;
  const NavMesh& m = *mesh;
  const std::optional<Vec2> on = m.nearest(from, kBlockedReach);
  if (!on) return false;
  const double nx = from.x - on->x, ny = from.y - on->y, n2 = nx * nx + ny * ny;
  if (n2 > kOnMesh * kOnMesh) {  // off the mesh: does the way lead into what lies beyond its edge?
    const double ux = to.x - from.x, uy = to.y - from.y;
    const double dot = ux * nx + uy * ny;
    if (!(dot > 0 && dot * dot >= 0.25 * (ux * ux + uy * uy) * n2)) return false;
  }
  return !m.visible(from, to);
}

std::size_t Navigation::without_path(const World& world) const {
  const AgentTable& t = world.agents();
  std::size_t n = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    n += !standing(t.state[i]) && short_routes_.count(t.id[i]) > 0;
  return n;
}

void Navigation::trim_passed(World& world, std::size_t row) {
  AgentTable& t = world.agents_for_tick();
  auto& route = t.route[row];
  const Vec2 p{t.x[row], t.y[row]};
  const Vec2 goal = goal_target(world.goals()[t.goal[row]], p.x, p.y, t.radius[row]);
  std::size_t drop = 0;
  while (drop < route.size()) {
    const Vec2 next = drop + 1 < route.size() ? route[drop + 1] : goal;
    ++stats_.sight_checks;
    if (!visible(t.radius[row], t.id[row], p, next)) break;
    ++drop;
  }
  route.erase(route.begin(), route.begin() + static_cast<std::ptrdiff_t>(drop));
}

std::size_t Navigation::apply_results(World& world, uint64_t tick) {
  std::size_t applied = 0;
  AgentTable& t = world.agents_for_tick();
  for (PathReply& r : service_->collect(tick)) {
    const auto row = world.row_of(AgentId::from_value(r.agent));
    if (!row || t.path_ticket[*row] != r.ticket) {
      ++stats_.superseded;
      continue;
    }
    const std::size_t i = *row;
    t.path_ticket[i] = 0;
    ++stats_.applied;
    const bool narrow = is_narrow(r.mesh);
    if (narrow) {
      // Taken only when it reaches the goal; otherwise the class mesh's route stays.
      if (off_mesh(r.result, *r.mesh)) continue;
      ++stats_.narrow_routes;
      narrow_routes_.insert(r.agent);
      short_routes_.erase(r.agent);
      t.route[i] = std::move(r.result.corners);
      if (params_.skip_visible) trim_passed(world, i);
    } else {
      narrow_routes_.erase(r.agent);
      if (off_mesh(r.result, *r.mesh)) {
        // Repeat the search on the narrow mesh (queued like any request, due latency later).
        t.path_ticket[i] = ++next_ticket_;
        queue_.push_back({t.path_ticket[i], r.agent, true});
      }
      if (r.result.status == PathStatus::ok)
        short_routes_.erase(r.agent);
      else
        short_routes_.insert(r.agent);
      if (r.result.status == PathStatus::no_start || r.result.status == PathStatus::no_goal) {
        ++stats_.failed;
        t.route[i].clear();  // no path: steer straight at the goal
      } else {
        stats_.partial += r.result.status == PathStatus::partial;
        t.route[i] = std::move(r.result.corners);
        if (params_.skip_visible) trim_passed(world, i);
      }
    }
    world.refresh_target(i);
    // A new route changes the path-left measure of the progress watch (the first route of a
    // serpentine is 2.5 times the straight line it replaces): it gets a new reference; its clock
    // runs on.
    t.progress_best[i] = INFINITY;
    ++applied;
  }
  forget_departed(world);
  return applied;
}

void Navigation::forget_departed(const World& world) {
  // Swept when the two sets hold more than twice the agents there are (plus a margin): each sweep
  // removes at least half of what it looks at, and the condition depends on the state alone, so a
  // resumed run sweeps where the uninterrupted one did.
  const std::size_t live = world.agents().size();
  if (short_routes_.size() + narrow_routes_.size() <= 2 * live + 64) return;
  for (std::set<uint64_t>* s : {&short_routes_, &narrow_routes_})
    std::erase_if(*s, [&](uint64_t id) { return !world.contains(AgentId::from_value(id)); });
}

std::size_t Navigation::request_paths(World& world, uint64_t tick,
                                      const std::vector<uint32_t>& head_on,
                                      const std::vector<uint64_t>& lost_sight) {
  AgentTable& t = world.agents_for_tick();
  std::size_t made = 0;
  std::vector<uint8_t> lost;  // per row, when anyone lost sight (blocked_ahead)
  if (!lost_sight.empty()) {
    lost.assign(t.size(), 0);
    for (uint64_t id : lost_sight)
      if (const auto row = world.row_of(AgentId::from_value(id))) lost[*row] = 1;
  }
  // Requests are numbered and queued in agent id order, not row order: who is served first
  // within the budget must not depend on where a row happens to sit (src/sim/row_order.hpp).
  struct Due {
    uint64_t id;
    std::size_t row;
    bool narrow;
  };
  std::vector<Due> due;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (standing(t.state[i])) continue;  // idle or waiting at its goal
    // The progress watch (stalemate.cpp) counts the ticks without progress since the last request;
    // the goal stage saw some lose sight of their targets (sim::goal_stage).
    const bool stalled =
        (replan_ticks_ > 0 && t.replan_ticks[i] >= replan_ticks_) || (!lost.empty() && lost[i]);
    const bool new_goal = t.path_goal[i] != t.goal[i];
    if (!new_goal && !stalled) continue;
    if (stalled) {
      t.replan_ticks[i] = 0;
      if (!new_goal && t.path_ticket[i] != 0) continue;  // a re-plan is on its way already
      ++stats_.replans;
    }
    t.path_goal[i] = t.goal[i];
    // A re-plan for the same goal searches where the route came from: an agent on a narrow
    // route keeps to the narrow mesh (the class mesh has no way there).
    due.push_back({t.id[i], i, !new_goal && narrow_routes_.count(t.id[i]) > 0});
  }
  std::sort(due.begin(), due.end(), [](const Due& a, const Due& b) { return a.id < b.id; });
  for (const Due& d : due) {
    t.path_ticket[d.row] = ++next_ticket_;
    queue_.push_back({t.path_ticket[d.row], d.id, d.narrow});
    ++stats_.requests;
    ++made;
  }
  // Dispatch the queue head within the budget, from the agents' current positions.
  std::vector<PathJob> jobs;
  std::vector<std::size_t> rows;  // each job's row
  while (!queue_.empty() && jobs.size() < params_.budget) {
    const Queued q = queue_.front();
    queue_.pop_front();
    const auto row = world.row_of(AgentId::from_value(q.agent));
    if (!row || t.path_ticket[*row] != q.ticket) {
      ++stats_.superseded;
      continue;
    }
    const std::size_t i = *row;
    const Vec2 goal = goal_target(world.goals()[t.goal[i]], t.x[i], t.y[i], t.radius[i]);
    const int k = q.narrow ? narrow_key(t.radius[i]) : class_of(t.radius[i]);
    stats_.narrow += q.narrow;
    jobs.push_back({q.ticket, q.agent, &mesh_of_class(k), {t.x[i], t.y[i]}, goal, nullptr, k});
    rows.push_back(i);
  }
  // Costs, job by job while fewer than kCostedPerTick have some: congestion, then queues at
  // doors. Each job adds at most one to the count, so the next (kCostedPerTick - costed) jobs
  // are all costed whatever the others find: their door searches (the expensive part) run at
  // once on every thread, each with scratch of its own, and the results are taken in job order,
  // as one job after another would.
  std::vector<std::size_t> stalled;  // rows, in row order (only counted, so the order is moot)
  std::map<const NavMesh*, std::vector<StalledAt>> located;  // this tick's, per mesh
  std::vector<std::size_t> slow;  // slow walkers: found once, for the first search that needs them
  bool slow_ready = false;
  if (params_.congestion_cost > 0)
    for (uint32_t i : head_on)
      if (i < t.size() && !standing(t.state[i])) stalled.push_back(i);
  std::size_t costed = 0;
  std::vector<std::vector<DoorCut>> cuts;
  std::vector<std::size_t> door_jobs;
  for (std::size_t next = 0; next < jobs.size() && costed < kCostedPerTick;) {
    const std::size_t end = std::min(jobs.size(), next + (kCostedPerTick - costed));
    door_jobs.clear();
    for (std::size_t j = next; j < end; ++j) {
      const std::size_t i = rows[j];
      if (!stalled.empty()) {
        auto [it, fresh] = located.try_emplace(jobs[j].mesh);
        if (fresh) it->second = locate(world, *jobs[j].mesh, stalled);
        jobs[j].costs = congestion(it->second, heading(t, i));
      }
      // (Only for those held up themselves: one walking freely is not in a queue yet; a new one
      // standing at its source is.)
      if (params_.queue_flow > 0 && held_up(t, i)) {
        if (!slow_ready) {
          slow = slow_walkers(t);
          slow_ready = true;
        }
        if (!slow.empty()) door_jobs.push_back(j);
      }
    }
    cuts.assign(door_jobs.size(), {});
    while (door_scratch_.size() < door_jobs.size())
      door_scratch_.push_back(std::make_unique<DoorScratch>());
    ex_.for_each_chunk(door_jobs.size(), 1, [&](std::size_t b, std::size_t e) {
      for (std::size_t u = b; u < e; ++u) {
        const PathJob& job = jobs[door_jobs[u]];
        cuts[u] = queues_ahead(t, *job.mesh, rows[door_jobs[u]], job.goal, slow, job.costs.get(),
                               *door_scratch_[u]);
      }
    });
    for (std::size_t u = 0; u < door_jobs.size(); ++u) {
      if (cuts[u].empty()) continue;
      PathJob& job = jobs[door_jobs[u]];
      auto pc = std::make_shared<PolygonCosts>(job.costs ? *job.costs : PolygonCosts{});
      pc->cuts = std::move(cuts[u]);
      job.costs = std::move(pc);
      ++stats_.queue_costed;
    }
    for (std::size_t j = next; j < end; ++j) {
      costed += jobs[j].costs != nullptr;
      stats_.costed += jobs[j].costs != nullptr;
    }
    next = end;
  }
  if (!jobs.empty()) {
    stats_.dispatched += jobs.size();
    service_->submit(tick + latency_ticks_, std::move(jobs));
  }
  return made;
}

std::vector<std::size_t> Navigation::slow_walkers(const AgentTable& t) {
  std::vector<std::size_t> out;
  for (std::size_t j = 0; j < t.size(); ++j)
    if (!standing(t.state[j]) && held_up(t, j)) out.push_back(j);
  return out;
}

std::vector<DoorCut> Navigation::queues_ahead(const AgentTable& t, const NavMesh& m, std::size_t i,
                                              Vec2 goal, const std::vector<std::size_t>& slow,
                                              const PolygonCosts* base,
                                              DoorScratch& scratch) const {
  auto& finder = scratch.finders[&m];
  auto& context = scratch.contexts[&m];
  if (!context) context = std::make_unique<NavMesh::Context>(m);
  // (A bounded search: a door within kDoorLook is found by a few hundred nodes; a search
  // over a large mesh to a far goal took milliseconds: SteerSuite's scenarioSpace, 5,000 agents
  // among 5,000 boxes, spent 45 ms a tick on them. Beyond the bound the route is Detour's partial
  // one, towards the goal.)
  if (!finder) finder = std::make_unique<PathFinder>(m, kDoorSearchNodes);
  const Vec2 at{t.x[i], t.y[i]};
  // The people queued at a door for row i: slow, bound for its goal, on its side of the door,
  // nearer to the door's middle than row i and heading towards it.
  const auto queued = [&](const DoorCut& cut) {
    const double ex = cut.b.x - cut.a.x, ey = cut.b.y - cut.a.y;
    const double mx = 0.5 * (cut.a.x + cut.b.x), my = 0.5 * (cut.a.y + cut.b.y);
    const auto side = [&](double x, double y) {
      return ex * (y - cut.a.y) - ey * (x - cut.a.x) >= 0;
    };
    const bool mine = side(at.x, at.y);
    const double reach2 = (at.x - mx) * (at.x - mx) + (at.y - my) * (at.y - my);
    std::size_t n = 0;
    for (std::size_t j : slow) {
      if (j == i || t.goal[j] != t.goal[i] || side(t.x[j], t.y[j]) != mine) continue;
      const double dx = mx - t.x[j], dy = my - t.y[j];
      if (!(dx * dx + dy * dy < reach2)) continue;
      const Vec2 h = heading(t, j);
      n += h.x * dx + h.y * dy > 0;
    }
    return n;
  };
  // Detour's route, and the first door on it with its queue; then the way the search takes
  // with that door's queue charged, and the first door on that one (another door's queue), and
  // so on, until a way's first door is charged already or has nobody queued.
  PolygonCosts costs = base ? *base : PolygonCosts{};  // (base has no cuts: congestion only)
  for (int round = 0; round < kDoorRounds; ++round) {
    const PathResult r = finder->find(at, goal, costs.empty() ? nullptr : &costs);
    if (r.status == PathStatus::no_start || r.status == PathStatus::no_goal) break;
    std::vector<Vec2> way{at};
    way.insert(way.end(), r.corners.begin(), r.corners.end());
    way.push_back(r.end);
    std::optional<DoorCut> cut = m.first_narrows(way, kDoorLook, kDoorWidth, context.get());
    if (!cut) break;
    const Vec2 mid{0.5 * (cut->a.x + cut->b.x), 0.5 * (cut->a.y + cut->b.y)};
    const bool known = std::any_of(costs.cuts.begin(), costs.cuts.end(), [&](const DoorCut& c) {
      return std::hypot(0.5 * (c.a.x + c.b.x) - mid.x, 0.5 * (c.a.y + c.b.y) - mid.y) < kSameDoor;
    });
    if (known) break;
    const std::size_t ahead = queued(*cut);
    if (ahead == 0) break;
    const double width = std::hypot(cut->b.x - cut->a.x, cut->b.y - cut->a.y) + 2 * m.clearance();
    cut->cost = static_cast<double>(ahead) / (params_.queue_flow * width) * t.pref_speed[i];
    costs.cuts.push_back(*cut);
  }
  return std::move(costs.cuts);
}

std::vector<Navigation::StalledAt> Navigation::locate(const World& world, const NavMesh& m,
                                                      const std::vector<std::size_t>& stalled) {
  const AgentTable& t = world.agents();
  // An agent pressed against a wall stands up to about the mesh's clearance off it.
  const double reach = m.clearance() + 2 * m.params().cell_size;
  std::vector<StalledAt> out;
  for (std::size_t i : stalled)
    if (const uint32_t ref = m.polygon_at({t.x[i], t.y[i]}, reach))
      out.push_back({ref, heading(t, i)});
  return out;
}

std::shared_ptr<const PolygonCosts> Navigation::congestion(const std::vector<StalledAt>& stalled,
                                                           Vec2 dir) const {
  // Stalled people walking one's own way (within 60 degrees: an arch at the door one heads for
  // too) are followed, not walked round: they go where one goes.
  constexpr double kSameWay = 0.5;
  std::map<uint32_t, uint64_t> count;
  for (const StalledAt& s : stalled)
    if (s.dir.x * dir.x + s.dir.y * dir.y < kSameWay) ++count[s.ref];
  if (count.empty()) return nullptr;
  auto c = std::make_shared<PolygonCosts>();
  c->entries.reserve(count.size());
  for (const auto& [ref, n] : count)
    c->entries.emplace_back(ref, static_cast<double>(n) * params_.congestion_cost);
  return c;
}

void Navigation::save(ByteWriter& out) const {
  out.u64(next_ticket_);
  for (uint64_t v : {stats_.requests, stats_.replans, stats_.dispatched, stats_.superseded,
                     stats_.applied, stats_.failed, stats_.partial, stats_.sight_checks,
                     stats_.narrow, stats_.narrow_routes, stats_.costed, stats_.queue_costed})
    out.u64(v);
  out.u64(queue_.size());
  for (const Queued& q : queue_) {
    out.u64(q.ticket);
    out.u64(q.agent);
    out.u8(q.narrow ? 1 : 0);
  }
  for (const std::set<uint64_t>* s : {&narrow_routes_, &short_routes_}) {
    out.u64(s->size());
    for (uint64_t a : *s) out.u64(a);
  }
  const auto batches = service_->pending_jobs();
  out.u64(batches.size());
  for (const auto& [due, jobs] : batches) {
    out.u64(due);
    out.u64(jobs.size());
    for (const PathJob& j : jobs) {
      out.u64(j.ticket);
      out.u64(j.agent);
      out.u32(static_cast<uint32_t>(j.key));  // -class for a narrow mesh (two's complement)
      for (double v : {j.start.x, j.start.y, j.goal.x, j.goal.y}) out.f64(v);
      out.u64(j.costs ? j.costs->entries.size() : 0);
      if (j.costs)
        for (const auto& [ref, cost] : j.costs->entries) {
          out.u32(ref);
          out.f64(cost);
        }
      out.u64(j.costs ? j.costs->cuts.size() : 0);
      if (j.costs)
        for (const DoorCut& c : j.costs->cuts)
          for (double v : {c.a.x, c.a.y, c.b.x, c.b.y, c.cost}) out.f64(v);
    }
  }
}

void Navigation::restore(ByteReader& in, uint64_t tick, const World& world) {
  const AgentTable& t = world.agents();
  next_ticket_ = in.u64();
  for (uint64_t* v : {&stats_.requests, &stats_.replans, &stats_.dispatched, &stats_.superseded,
                      &stats_.applied, &stats_.failed, &stats_.partial, &stats_.sight_checks,
                      &stats_.narrow, &stats_.narrow_routes, &stats_.costed, &stats_.queue_costed})
    *v = in.u64();
  queue_.resize(in.count(17));
  for (Queued& q : queue_) {
    q.ticket = in.u64();
    q.agent = in.u64();
    const uint8_t narrow = in.u8();
    if (narrow > 1) in.fail("a queued path request with a bad mesh flag");
    q.narrow = narrow == 1;
  }
  for (std::set<uint64_t>* s : {&narrow_routes_, &short_routes_}) {
    s->clear();
    const uint64_t routes = in.count(8);
    for (uint64_t k = 0; k < routes; ++k) s->insert(in.u64());
  }
  // The searches the constructor dispatched are not this run's: start a fresh service.
  service_ = std::make_unique<PathService>();
  const uint64_t batches = in.count(16);
  uint64_t last_due = 0;
  for (uint64_t b = 0; b < batches; ++b) {
    const uint64_t due = in.u64();
    // Dispatched at some tick <= `tick` and not collected yet: due in (tick, tick + latency].
    if (due < last_due || due <= tick || due - tick > latency_ticks_)
      in.fail("path searches due at tick " + std::to_string(due) + " after tick " +
              std::to_string(tick));
    last_due = due;
    std::vector<PathJob> jobs(in.count(60));
    for (PathJob& j : jobs) {
      j.ticket = in.u64();
      j.agent = in.u64();
      const auto k = static_cast<int32_t>(in.u32());
      // A class is a multiple of radius_step no larger than the world is wide (negative: a
      // narrow mesh, centimetres).
      const double side = std::max(geometry_.bounds.width(), geometry_.bounds.height());
      const int32_t c = k < 0 ? (k == INT32_MIN ? 0 : -k) : k;
      if (c < 1 || c * (k < 0 ? kNarrowStep : params_.radius_step) > side)
        in.fail("bad radius class " + std::to_string(k));
      j.key = k;
      // Its agent takes the reply only if it is still here and has not asked again since.
      const auto row = world.row_of(AgentId::from_value(j.agent));
      if (row && t.path_ticket[*row] == j.ticket) {
        const double r = t.radius[*row];
        if (k != (k < 0 ? narrow_key(r) : class_of(r)))
          in.fail("a path search on mesh class " + std::to_string(k) + ", not its agent's");
        j.mesh = &mesh_of_class(k);
      }
      j.start = {in.f64(), in.f64()};
      j.goal = {in.f64(), in.f64()};
      if (!std::isfinite(j.start.x) || !std::isfinite(j.start.y) || !std::isfinite(j.goal.x) ||
          !std::isfinite(j.goal.y))
        in.fail("a path search with a point that is not finite");
      const uint64_t entries = in.count(12);
      auto pc = std::make_shared<PolygonCosts>();
      if (entries > 0) {
        pc->entries.resize(entries);
        for (std::size_t e = 0; e < pc->entries.size(); ++e) {
          auto& [ref, cost] = pc->entries[e];
          ref = in.u32();
          cost = in.f64();
          if ((j.mesh && !j.mesh->valid_polygon(ref)) || (e > 0 && ref <= pc->entries[e - 1].first))
            in.fail("a path search's congestion with a bad or unsorted polygon ref");
          if (!std::isfinite(cost) || cost < 0)
            in.fail("a path search's congestion with a cost that is not finite and >= 0");
        }
      }
      pc->cuts.resize(in.count(40));
      for (DoorCut& cut : pc->cuts) {
        for (double* v : {&cut.a.x, &cut.a.y, &cut.b.x, &cut.b.y, &cut.cost}) *v = in.f64();
        if (!std::isfinite(cut.a.x) || !std::isfinite(cut.a.y) || !std::isfinite(cut.b.x) ||
            !std::isfinite(cut.b.y) || !std::isfinite(cut.cost) || cut.cost < 0)
          in.fail("a path search's door cut that is not finite, or costs less than 0");
      }
      if (!pc->empty()) j.costs = std::move(pc);
    }
    service_->submit(due, std::move(jobs));
  }
}

NavigationStats Navigation::stats() const {
  NavigationStats s = stats_;
  s.queued = queue_.size();
  return s;
}

double Navigation::mesh_build_seconds() const {
  double s = 0;
  for (const auto& [k, m] : meshes_) s += m->stats().seconds;
  return s;
}

std::string Navigation::describe_meshes() const {
  std::ostringstream os;
  for (const auto& [k, m] : meshes_) {
    const NavMeshStats& s = m->stats();
    char line[256];
    std::snprintf(
        line, sizeof line,
        "       mesh r<=%g%s: cell %g, clearance %g, %d tile%s (%dx%d grid), %d polygons, "
        "built in %.1f ms\n",
        k < 0 ? -k * kNarrowStep : k * params_.radius_step, k < 0 ? " (narrow)" : "",
        m->params().cell_size, m->clearance(), s.tiles, s.tiles == 1 ? "" : "s", s.tiles_x,
        s.tiles_y, s.polygons, s.seconds * 1e3);
    os << line;
  }
  return os.str();
}

}  // namespace crowddb::path
