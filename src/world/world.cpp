#include "crowddb/world.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "world/geometry.hpp"

namespace crowddb {
namespace {

std::string fmt(double v) {
  std::ostringstream os;
  os.precision(17);
  os << v;
  return os.str();
}

void require_finite(const char* field, double v) {
  if (!std::isfinite(v))
    throw InvalidRow(field, std::string(field) + " must be finite (got " + fmt(v) + ")");
}

void require_positive(const char* field, double v) {
  require_finite(field, v);
  if (!(v > 0)) throw InvalidRow(field, std::string(field) + " must be > 0 (got " + fmt(v) + ")");
}

}  // namespace

void World::validate_spec(const AgentSpec& s, std::size_t goal_count) {
  require_finite("x", s.x);
  require_finite("y", s.y);
  require_finite("vx", s.vx);
  require_finite("vy", s.vy);
  require_positive("radius", s.radius);
  require_positive("max_speed", s.max_speed);
  if (std::isnan(s.max_accel) || !(s.max_accel > 0))
    throw InvalidRow("max_accel",
                     "max_accel must be > 0 or infinite (got " + fmt(s.max_accel) + ")");
  require_finite("charge", s.charge);
  if (s.goal >= goal_count)
    throw InvalidRow("goal", "goal " + std::to_string(s.goal) + " does not exist (the world has " +
                                 std::to_string(goal_count) + " goals)");
}

uint32_t World::add_goal(const Goal& g) {
  require_finite("x", g.x);
  require_finite("y", g.y);
  require_finite("charge", g.charge);
  require_positive("arrival_radius", g.arrival_radius);
  goals_.push_back(g);
  return static_cast<uint32_t>(goals_.size() - 1);
}

uint32_t World::add_obstacle(const CircleObstacle& c) {
  require_finite("x", c.x);
  require_finite("y", c.y);
  require_positive("radius", c.radius);
  require_finite("charge", c.charge);
  circles_.push_back(c);
  return static_cast<uint32_t>(circles_.size() - 1);
}

uint32_t World::add_obstacle(PolygonObstacle p) {
  require_finite("charge", p.charge);
  if (p.vertices.size() < 3)
    throw InvalidRow("vertices", "a polygon needs at least 3 vertices (got " +
                                     std::to_string(p.vertices.size()) + ")");
  for (const Vec2& v : p.vertices) {
    require_finite("vertices", v.x);
    require_finite("vertices", v.y);
  }
  // An explicitly closed ring (last == first) is accepted and the duplicate dropped.
  if (p.vertices.size() > 3 && p.vertices.front().x == p.vertices.back().x &&
      p.vertices.front().y == p.vertices.back().y)
    p.vertices.pop_back();
  const double area = signed_area(p.vertices);
  if (area == 0) throw InvalidRow("vertices", "polygon has zero area");
  if (auto bad = first_self_intersection(p.vertices))
    throw InvalidRow("vertices", "polygon is not simple: edges " + std::to_string(bad->first) +
                                     " and " + std::to_string(bad->second) + " intersect");
  if (area < 0) std::reverse(p.vertices.begin(), p.vertices.end());
  polygons_.push_back(std::move(p));
  return static_cast<uint32_t>(polygons_.size() - 1);
}

void World::set_bounds(Bounds b) {
  require_finite("bounds", b.xmin);
  require_finite("bounds", b.ymin);
  require_finite("bounds", b.xmax);
  require_finite("bounds", b.ymax);
  if (!(b.xmax > b.xmin) || !(b.ymax > b.ymin))
    throw InvalidRow("bounds", "bounds must have xmax > xmin and ymax > ymin");
  bounds_ = b;
}

const World::Slot* World::live_slot(AgentId id) const {
  if (id.index >= slots_.size()) return nullptr;
  const Slot& s = slots_[id.index];
  if (s.generation != id.generation || s.doomed) return nullptr;
  if (s.row == kNoRow && !s.pending) return nullptr;
  return &s;
}

AgentId World::insert(const AgentSpec& spec) {
  validate_spec(spec, goals_.size());
  AgentId id;
  if (!free_slots_.empty()) {
    id.index = free_slots_.back();
    free_slots_.pop_back();
  } else {
    if (slots_.size() >= AgentId::kNoIndex) throw Error(Error::Kind::input, "too many agents");
    id.index = static_cast<uint32_t>(slots_.size());
    slots_.emplace_back();
  }
  Slot& s = slots_[id.index];
  s.pending = true;
  s.doomed = false;
  id.generation = s.generation;
  pending_.push_back({Change::Kind::insert, id, spec, 0});
  return id;
}

void World::erase(AgentId id) {
  Slot* s = const_cast<Slot*>(live_slot(id));
  if (!s)
    throw Error(Error::Kind::input,
                "erase: agent " + std::to_string(id.value()) + " does not exist");
  s->doomed = true;
  pending_.push_back({Change::Kind::erase, id, {}, 0});
}

void World::retarget(AgentId id, uint32_t goal) {
  if (!live_slot(id))
    throw Error(Error::Kind::input,
                "retarget: agent " + std::to_string(id.value()) + " does not exist");
  if (goal >= goals_.size())
    throw InvalidRow("goal", "goal " + std::to_string(goal) + " does not exist (the world has " +
                                 std::to_string(goals_.size()) + " goals)");
  pending_.push_back({Change::Kind::retarget, id, {}, goal});
}

std::optional<std::size_t> World::row_of(AgentId id) const {
  if (id.index >= slots_.size()) return std::nullopt;
  const Slot& s = slots_[id.index];
  if (s.generation != id.generation || s.row == kNoRow) return std::nullopt;
  return s.row;
}

void World::push_row(AgentId id, const AgentSpec& s) {
  AgentTable& t = agents_;
  t.x.push_back(s.x);
  t.y.push_back(s.y);
  t.vx.push_back(s.vx);
  t.vy.push_back(s.vy);
  t.radius.push_back(s.radius);
  t.max_speed.push_back(s.max_speed);
  t.max_accel.push_back(s.max_accel);
  t.charge.push_back(s.charge);
  t.target_x.push_back(goals_[s.goal].x);
  t.target_y.push_back(goals_[s.goal].y);
  t.goal.push_back(s.goal);
  t.state.push_back(AgentState::active);
  t.frozen_ticks.push_back(0);
  t.id.push_back(id.value());
  t.route.emplace_back();
  t.path_goal.push_back(AgentTable::kNoPath);
  t.path_ticket.push_back(0);
  t.path_best.push_back(INFINITY);
  t.path_stall.push_back(0);
  slots_[id.index].row = static_cast<uint32_t>(t.size() - 1);
  slots_[id.index].pending = false;
}

void World::remove_row(std::size_t row) {
  AgentTable& t = agents_;
  const std::size_t last = t.size() - 1;
  const AgentId dead = AgentId::from_value(t.id[row]);
  auto move_last = [&](auto& column) {
    if (row != last) column[row] = std::move(column[last]);
    column.pop_back();
  };
  move_last(t.x);
  move_last(t.y);
  move_last(t.vx);
  move_last(t.vy);
  move_last(t.radius);
  move_last(t.max_speed);
  move_last(t.max_accel);
  move_last(t.charge);
  move_last(t.target_x);
  move_last(t.target_y);
  move_last(t.goal);
  move_last(t.state);
  move_last(t.frozen_ticks);
  move_last(t.id);
  move_last(t.route);
  move_last(t.path_goal);
  move_last(t.path_ticket);
  move_last(t.path_best);
  move_last(t.path_stall);
  if (row != last) slots_[AgentId::from_value(t.id[row]).index].row = static_cast<uint32_t>(row);
  Slot& s = slots_[dead.index];
  s.row = kNoRow;
  s.pending = false;
  s.doomed = false;
  ++s.generation;
  free_slots_.push_back(dead.index);
}

void World::refresh_target(std::size_t row) {
  AgentTable& t = agents_;
  if (!t.route[row].empty()) {
    t.target_x[row] = t.route[row].front().x;
    t.target_y[row] = t.route[row].front().y;
  } else {
    const Goal& g = goals_[t.goal[row]];
    t.target_x[row] = g.x;
    t.target_y[row] = g.y;
  }
  t.path_best[row] = INFINITY;
  t.path_stall[row] = 0;
}

std::size_t World::apply_pending() {
  const std::size_t applied = pending_.size();
  for (Change& c : pending_) {
    switch (c.kind) {
      case Change::Kind::insert:
        push_row(c.id, c.spec);
        break;
      case Change::Kind::erase: {
        Slot& s = slots_[c.id.index];
        if (s.row != kNoRow) {
          remove_row(s.row);
        } else {  // inserted and erased within one batch: the insert was never applied
          s.pending = false;
          s.doomed = false;
          ++s.generation;
          free_slots_.push_back(c.id.index);
        }
        break;
      }
      case Change::Kind::retarget: {
        const auto row = row_of(c.id);
        if (!row) break;  // erased earlier in this batch
        agents_.goal[*row] = c.goal;
        agents_.route[*row].clear();
        agents_.path_goal[*row] = AgentTable::kNoPath;  // re-plan, even for the same goal
        if (agents_.state[*row] == AgentState::arrived) agents_.state[*row] = AgentState::active;
        refresh_target(*row);
        break;
      }
    }
  }
  pending_.clear();
  return applied;
}

void World::validate() const {
  const AgentTable& t = agents_;
  const std::size_t n = t.size();
  auto same = [&](std::size_t m, const char* name) {
    if (m != n) throw std::logic_error(std::string("column ") + name + " has the wrong length");
  };
  same(t.y.size(), "y");
  same(t.vx.size(), "vx");
  same(t.vy.size(), "vy");
  same(t.radius.size(), "radius");
  same(t.max_speed.size(), "max_speed");
  same(t.max_accel.size(), "max_accel");
  same(t.charge.size(), "charge");
  same(t.target_x.size(), "target_x");
  same(t.target_y.size(), "target_y");
  same(t.goal.size(), "goal");
  same(t.state.size(), "state");
  same(t.frozen_ticks.size(), "frozen_ticks");
  same(t.id.size(), "id");
  same(t.route.size(), "route");
  same(t.path_goal.size(), "path_goal");
  same(t.path_ticket.size(), "path_ticket");
  same(t.path_best.size(), "path_best");
  same(t.path_stall.size(), "path_stall");
  std::size_t live = 0;
  for (std::size_t r = 0; r < n; ++r) {
    const AgentId id = AgentId::from_value(t.id[r]);
    if (id.index >= slots_.size() || slots_[id.index].row != r ||
        slots_[id.index].generation != id.generation)
      throw std::logic_error("slot map does not point back at row " + std::to_string(r));
    if (t.goal[r] >= goals_.size())
      throw std::logic_error("row " + std::to_string(r) + " has a bad goal");
  }
  for (const Slot& s : slots_) live += s.row != kNoRow;
  if (live != n) throw std::logic_error("slot map and rows disagree on the agent count");
}

}  // namespace crowddb
