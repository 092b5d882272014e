#include "path/navigation.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

namespace crowddb::path {
namespace {

// An agent progresses when it gets this much closer to its waypoint than ever before [radii].
constexpr double kProgress = 0.05;

}  // namespace

Navigation::Navigation(const World& world, const SimConfig& cfg, Executor& ex)
    : params_(cfg.navigation), geometry_(NavGeometry::of(world)), ex_(ex) {
  service_ = std::make_unique<PathService>();
  const AgentTable& t = world.agents();
  for (std::size_t i = 0; i < t.size(); ++i) mesh_for(t.radius[i]);
}

Navigation::~Navigation() {
  service_.reset();
}

int Navigation::class_of(double radius) const {
  // Rounded up, with a little slack so that a radius equal to a class boundary stays in it.
  return std::max(1, static_cast<int>(std::ceil(radius / params_.radius_step - 1e-9)));
}

double Navigation::class_radius(double radius) const {
  return class_of(radius) * params_.radius_step;
}

const NavMesh& Navigation::mesh_for(double radius) {
  const int k = class_of(radius);
  auto& slot = meshes_[k];
  if (!slot) {
    NavMeshParams p;
    p.radius = k * params_.radius_step + params_.clearance;
    // Auto: a quarter of the class radius, but at most 4096 cells along the world's longer side
    // (a 1 km world at 0.25: 16 M cells, seconds to build).
    const double side = std::max(geometry_.bounds.width(), geometry_.bounds.height());
    p.cell_size = params_.cell_size > 0 ? params_.cell_size
                                        : std::max(k * params_.radius_step / 4, side / 4096);
    p.tile_size = static_cast<int>(params_.tile_size);
    slot = NavMesh::build(geometry_, p, &ex_);
  }
  return *slot;
}

bool Navigation::visible(double radius, Vec2 from, Vec2 to) const {
  auto it = meshes_.find(class_of(radius));
  return it != meshes_.end() && it->second->visible(from, to);
}

void Navigation::trim_passed(World& world, std::size_t row) {
  AgentTable& t = world.agents_for_tick();
  auto& route = t.route[row];
  const Vec2 p{t.x[row], t.y[row]};
  const Goal& g = world.goals()[t.goal[row]];
  std::size_t drop = 0;
  while (drop < route.size()) {
    const Vec2 next = drop + 1 < route.size() ? route[drop + 1] : Vec2{g.x, g.y};
    ++stats_.sight_checks;
    if (!visible(t.radius[row], p, next)) break;
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
    if (r.result.status == PathStatus::no_start || r.result.status == PathStatus::no_goal) {
      ++stats_.failed;
      t.route[i].clear();  // no path: steer straight at the goal
    } else {
      stats_.partial += r.result.status == PathStatus::partial;
      t.route[i] = std::move(r.result.corners);
      if (params_.skip_visible) trim_passed(world, i);
    }
    world.refresh_target(i);
    ++applied;
  }
  return applied;
}

std::size_t Navigation::request_paths(World& world, uint64_t tick) {
  AgentTable& t = world.agents_for_tick();
  std::size_t made = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t.state[i] == AgentState::arrived) continue;  // idle at its goal
    // Progress watch: closer to the current waypoint than ever since it was set?
    const double d = std::hypot(t.target_x[i] - t.x[i], t.target_y[i] - t.y[i]);
    if (d < t.path_best[i] - kProgress * t.radius[i]) {
      t.path_best[i] = d;
      t.path_stall[i] = 0;
    } else {
      ++t.path_stall[i];
    }
    const bool stalled = params_.replan_after > 0 && t.path_stall[i] >= params_.replan_after;
    const bool new_goal = t.path_goal[i] != t.goal[i];
    if (!new_goal && !stalled) continue;
    if (stalled) {
      t.path_stall[i] = 0;
      t.path_best[i] = d;
      if (!new_goal && t.path_ticket[i] != 0) continue;  // a re-plan is on its way already
      ++stats_.replans;
    }
    t.path_goal[i] = t.goal[i];
    t.path_ticket[i] = ++next_ticket_;
    queue_.push_back({t.path_ticket[i], t.id[i]});
    ++stats_.requests;
    ++made;
  }
  // Dispatch the queue head within the budget, from the agents' current positions.
  std::vector<PathJob> jobs;
  while (!queue_.empty() && jobs.size() < params_.budget) {
    const Queued q = queue_.front();
    queue_.pop_front();
    const auto row = world.row_of(AgentId::from_value(q.agent));
    if (!row || t.path_ticket[*row] != q.ticket) {
      ++stats_.superseded;
      continue;
    }
    const std::size_t i = *row;
    const Goal& g = world.goals()[t.goal[i]];
    jobs.push_back({q.ticket, q.agent, &mesh_for(t.radius[i]), {t.x[i], t.y[i]}, {g.x, g.y}});
  }
  if (!jobs.empty()) {
    stats_.dispatched += jobs.size();
    service_->submit(tick + params_.latency, std::move(jobs));
  }
  return made;
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
    std::snprintf(line, sizeof line,
                  "       mesh r<=%g: cell %g, clearance %g, %d tile%s (%dx%d grid), %d polygons, "
                  "built in %.1f ms\n",
                  k * params_.radius_step, m->params().cell_size, m->clearance(), s.tiles,
                  s.tiles == 1 ? "" : "s", s.tiles_x, s.tiles_y, s.polygons, s.seconds * 1e3);
    os << line;
  }
  return os.str();
}

}  // namespace crowddb::path
