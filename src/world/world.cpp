#include "crowddb/world.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <sstream>
#include <stdexcept>
#include <type_traits>

#include "util/byte_codec.hpp"
#include "util/executor.hpp"
#include "world/geometry.hpp"
#include "world/obstacle_lookup.hpp"

namespace crowddb {
namespace {

constexpr std::size_t kKeptPending = 4096;  // changes whose room a batch keeps for the next

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

// Within +-kMaxCoordinate (positions, radii, speeds: beyond it grid cells and radius classes
// overflow their integers).
void require_within(const char* field, double v) {
  require_finite(field, v);
  if (std::abs(v) > kMaxCoordinate)
    throw InvalidRow(field, std::string(field) + " must lie within +-1e9 (got " + fmt(v) + ")");
}

std::string missing_goal(uint32_t g, std::size_t goal_count) {
  return "goal " + std::to_string(g) + " does not exist (the world has " +
         std::to_string(goal_count) + " goals)";
}

// A simple polygon ring: finite, >= 3 vertices, no repeated closing vertex, non-zero area, no
// self-intersection; turned counter-clockwise.
void normalize_ring(std::vector<Vec2>& ring, const char* field) {
  if (ring.size() > 3 && ring.front().x == ring.back().x && ring.front().y == ring.back().y)
    ring.pop_back();
  if (ring.size() < 3)
    throw InvalidRow(field, std::string("a polygon needs at least 3 vertices (got ") +
                                std::to_string(ring.size()) + ")");
  for (const Vec2& v : ring) {
    require_finite(field, v.x);
    require_finite(field, v.y);
  }
  const double area = signed_area(ring);
  if (area == 0) throw InvalidRow(field, "polygon has zero area");
  if (auto bad = first_self_intersection(ring))
    throw InvalidRow(field, bad->named
                                ? "polygon is not simple: edges " + std::to_string(bad->first) +
                                      " and " + std::to_string(bad->second) + " intersect"
                                : "polygon is not simple: it crosses or touches itself");
  if (area < 0) std::reverse(ring.begin(), ring.end());
}

}  // namespace

void World::validate_spec(const AgentSpec& s, std::size_t goal_count) {
  require_within("x", s.x);
  require_within("y", s.y);
  require_within("vx", s.vx);
  require_within("vy", s.vy);
  require_positive("radius", s.radius);
  require_within("radius", s.radius);
  require_positive("pref_speed", s.pref_speed);
  require_positive("max_speed", s.max_speed);
  require_within("max_speed", s.max_speed);
  if (s.max_speed < s.pref_speed)
    throw InvalidRow("max_speed", "max_speed must be >= pref_speed (got " + fmt(s.max_speed) +
                                      " < " + fmt(s.pref_speed) + ")");
  if (std::isnan(s.max_accel) || !(s.max_accel > 0))
    throw InvalidRow("max_accel",
                     "max_accel must be > 0 or infinite (got " + fmt(s.max_accel) + ")");
  require_finite("charge", s.charge);
  for (uint32_t g : s.then)
    if (g >= goal_count) throw InvalidRow("goal", missing_goal(g, goal_count));
  if (s.goal >= goal_count) throw InvalidRow("goal", missing_goal(s.goal, goal_count));
}

std::optional<uint32_t> World::goal_named(std::string_view name) const {
  const auto it = goal_rows_.find(std::string(name));
  if (it == goal_rows_.end()) return std::nullopt;
  return it->second;
}

uint32_t World::add_goal(Goal g) {
  require_finite("x", g.x);
  require_finite("y", g.y);
  require_finite("charge", g.charge);
  require_positive("arrival_radius", g.arrival_radius);
  if (!(g.wait_mean >= 0 && g.wait_mean <= Goal::kMaxWait))
    throw InvalidRow("wait", "the exponential wait's mean must be in [0, " + fmt(Goal::kMaxWait) +
                                 "] s (got " + fmt(g.wait_mean) + ")");
  if (g.wait_mean > 0 && g.wait_max > 0)
    throw InvalidRow("wait", "give a uniform range or an exponential mean, not both");
  if (!(g.wait_min >= 0 && g.wait_min <= g.wait_max && g.wait_max <= Goal::kMaxWait))
    throw InvalidRow("wait", "the wait must be a range 0 <= low <= high <= " + fmt(Goal::kMaxWait) +
                                 " s (got [" + fmt(g.wait_min) + ", " + fmt(g.wait_max) + "])");
  if (goal_named(g.name)) throw InvalidRow("name", "duplicate goal name '" + g.name + "'");
  if (g.is_polygon()) {
    normalize_ring(g.area, "area");
    if (!point_in_polygon(g.area, g.x, g.y) && dist2_to_boundary(g.area, g.x, g.y) > 0)
      throw InvalidRow(
          "x", "the goal's point (" + fmt(g.x) + ", " + fmt(g.y) + ") lies outside its area");
  }
  g.inward_normals = convex_inward_normals(g.area);
  any_goal_wait_ = any_goal_wait_ || g.has_wait();
  const auto row = static_cast<uint32_t>(goals_.size());
  goal_rows_.emplace(g.name, row);
  goals_.push_back(std::move(g));
  return row;
}

uint32_t World::add_source(Source src) {
  normalize_ring(src.area, "area");
  if (!std::isfinite(src.rate) || !(src.rate > 0))
    throw InvalidRow("rate", "rate must be > 0 agents per second (got " + fmt(src.rate) + ")");
  if (src.count == 0) throw InvalidRow("count", "count must be >= 1");
  if (!std::isfinite(src.start) || src.start < 0)
    throw InvalidRow("start", "start must be >= 0 s (got " + fmt(src.start) + ")");
  if (std::isnan(src.end) || !(src.end > src.start))
    throw InvalidRow("end", "end must be later than start (got " + fmt(src.end) + ")");
  if (src.goals.empty()) src.goals.push_back(src.agent.goal);
  for (uint32_t g : src.goals) {
    src.agent.goal = g;
    validate_spec(src.agent, goals_.size());
  }
  src.agent.goal = src.goals.front();
  if (src.radius_max != 0 && !(src.radius_max >= src.agent.radius))
    throw InvalidRow("radius", "the radius range must have low <= high");
  if (src.pref_speed_max != 0 &&
      !(src.pref_speed_max >= src.agent.pref_speed && src.pref_speed_max <= src.agent.max_speed))
    throw InvalidRow("pref_speed", "the pref_speed range must have low <= high <= max_speed");
  sources_.push_back(std::move(src));
  return static_cast<uint32_t>(sources_.size() - 1);
}

uint32_t World::add_obstacle(const CircleObstacle& c) {
  require_finite("x", c.x);
  require_finite("y", c.y);
  require_positive("radius", c.radius);
  require_finite("charge", c.charge);
  circles_.push_back(c);
  lookup_.reset();
  return static_cast<uint32_t>(circles_.size() - 1);
}

uint32_t World::add_obstacle(PolygonObstacle p) {
  require_finite("charge", p.charge);
  normalize_ring(p.vertices, "vertices");
  polygons_.push_back(std::move(p));
  lookup_.reset();
  return static_cast<uint32_t>(polygons_.size() - 1);
}

void World::set_bounds(Bounds b) {
  require_finite("bounds", b.xmin);
  require_finite("bounds", b.ymin);
  require_finite("bounds", b.xmax);
  require_finite("bounds", b.ymax);
  if (!(b.xmax > b.xmin) || !(b.ymax > b.ymin))
    throw InvalidRow("bounds", "bounds must have xmax > xmin and ymax > ymin");
  for (double v : {b.xmin, b.ymin, b.xmax, b.ymax})
    if (std::abs(v) > kMaxCoordinate) {
      std::ostringstream os;
      os << "coordinates must lie within +-1e9 m (got " << v << ")";
      throw InvalidRow("bounds", os.str());
    }
  bounds_ = b;
  has_bounds_ = true;
}

void World::set_walls(bool walls) {
  walls_ = walls;
  if (!walls) return;
  try {
    for (std::size_t i = 0; i < agents_.size(); ++i) check_walkable(agents_.x[i], agents_.y[i]);
    for (const Change& c : pending_)
      if (c.kind == Change::Kind::insert) check_walkable(c.spec.x, c.spec.y);
  } catch (const InvalidRow&) {
    walls_ = false;
    throw;
  }
}

void World::check_walkable(double x, double y) const {
  const auto at = [&] { return "the agent at (" + fmt(x) + ", " + fmt(y) + ") lies "; };
  const Bounds& b = bounds_;
  if (walls_ && has_bounds_ && !(x >= b.xmin && x <= b.xmax && y >= b.ymin && y <= b.ymax))
    throw InvalidRow("x", at() + "outside the bounds [" + fmt(b.xmin) + ", " + fmt(b.xmax) +
                              "] x [" + fmt(b.ymin) + ", " + fmt(b.ymax) + "] (the walls)");
  if (circles_.empty() && polygons_.empty()) return;
  const ObstacleLookup& lookup = *obstacle_lookup();  // (held by lookup_: no copy per insert)
  thread_local std::vector<uint32_t> near;
  lookup.candidates(x, y, 0, near);
  for (const uint32_t k : near) {  // circles, then polygons, by row: the first hit as a scan's
    if (k < circles_.size()) {
      if (std::hypot(circles_[k].x - x, circles_[k].y - y) < circles_[k].radius)
        throw InvalidRow("x", at() + "inside circle obstacle " + std::to_string(k));
      continue;
    }
    const std::size_t p = k - circles_.size();
    const auto& ring = polygons_[p].vertices;
    if (lookup.polygon_holds(p, ring, x, y) && lookup.polygon_dist2(p, ring, x, y, 0) > 0)
      throw InvalidRow("x", at() + "inside polygon obstacle " + std::to_string(p));
  }
}

std::shared_ptr<const ObstacleLookup> World::obstacle_lookup() const {
  if (!lookup_) lookup_ = std::make_shared<const ObstacleLookup>(circles_, polygons_);
  return lookup_;
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
  check_walkable(spec.x, spec.y);
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
  t.pref_speed.push_back(s.pref_speed);
  t.max_speed.push_back(s.max_speed);
  t.max_accel.push_back(s.max_accel);
  t.charge.push_back(s.charge);
  const Vec2 target = goal_target(goals_[s.goal], s.x, s.y, s.radius);
  t.target_x.push_back(target.x);
  t.target_y.push_back(target.y);
  t.goal.push_back(s.goal);
  t.state.push_back(AgentState::active);
  t.frozen_ticks.push_back(0);
  t.progress_best.push_back(INFINITY);
  t.stall_ticks.push_back(0);
  t.id.push_back(id.value());
  t.route.emplace_back();
  t.then.push_back(s.then);
  t.left_goal.push_back(AgentTable::kNoGoal);
  t.stall_action.push_back(StallAction::none);
  t.stall_until.push_back(0);
  t.stall_dir_x.push_back(0);
  t.stall_dir_y.push_back(0);
  t.path_goal.push_back(AgentTable::kNoPath);
  t.path_ticket.push_back(0);
  t.replan_ticks.push_back(0);
  t.wait_until.push_back(0);
  slots_[id.index].row = static_cast<uint32_t>(t.size() - 1);
  slots_[id.index].pending = false;
}

namespace {

// Every column of the agents table, for the row moves (remove_row, permute_rows). A new column
// goes here and into columns() (checkpoints); the assertion catches one forgotten.
// Rows per chunk of permute_rows's gather.
constexpr std::size_t kPermuteGrain = 8192;

template <class F>
void each_member(F&& f) {
  f(&AgentTable::x);
  f(&AgentTable::y);
  f(&AgentTable::vx);
  f(&AgentTable::vy);
  f(&AgentTable::radius);
  f(&AgentTable::pref_speed);
  f(&AgentTable::max_speed);
  f(&AgentTable::max_accel);
  f(&AgentTable::charge);
  f(&AgentTable::target_x);
  f(&AgentTable::target_y);
  f(&AgentTable::goal);
  f(&AgentTable::state);
  f(&AgentTable::frozen_ticks);
  f(&AgentTable::progress_best);
  f(&AgentTable::stall_ticks);
  f(&AgentTable::id);
  f(&AgentTable::route);
  f(&AgentTable::then);
  f(&AgentTable::left_goal);
  f(&AgentTable::stall_action);
  f(&AgentTable::stall_until);
  f(&AgentTable::stall_dir_x);
  f(&AgentTable::stall_dir_y);
  f(&AgentTable::path_goal);
  f(&AgentTable::path_ticket);
  f(&AgentTable::replan_ticks);
  f(&AgentTable::wait_until);
}

template <class F>
void each_column(AgentTable& t, F&& f) {
  each_member([&](auto m) { f(t.*m); });
}

static_assert(sizeof(AgentTable) == 28 * sizeof(std::vector<double>));

// Does every row of the column hold the same value, bit for bit (a column of lists: is every list
// empty)? Then it reads the same in any order of the rows, and permute_rows leaves it as it is.
template <class T>
bool same_in_every_row(const std::vector<T>& column) {
  if constexpr (std::is_trivially_copyable_v<T>) {
    return std::all_of(column.begin(), column.end(),
                       [&](const T& v) { return std::memcmp(&v, column.data(), sizeof(T)) == 0; });
  } else {
    return std::all_of(column.begin(), column.end(), [](const T& v) { return v.empty(); });
  }
}

}  // namespace

void World::permute_rows(std::span<const uint32_t> order, Executor* ex) {
  AgentTable& t = agents_;
  const std::size_t n = t.size();
  if (order.size() != n) throw std::invalid_argument("permute_rows: not one entry per row");
  std::vector<uint8_t> seen(n, 0);
  for (uint32_t r : order) {
    if (r >= n || seen[r]) throw std::invalid_argument("permute_rows: not a permutation");
    seen[r] = 1;
  }
  // Column by column, each into a new one in one pass; with `ex`, the columns on its threads
  // (each task owns its column; distinct old rows, a permutation). A column that holds one value
  // in every row is not moved: most of them where everyone is alike and nobody is held up (the
  // radii, speeds, routes, goal sequences and stalemate actions of an airport crowd).
  std::vector<std::function<void()>> gather;
  each_column(t, [&](auto& column) {
    gather.push_back([&column, order, n] {
      if (same_in_every_row(column)) return;
      std::remove_reference_t<decltype(column)> out;
      out.reserve(std::max(n, column.capacity()));  // room kept for the agents yet to come
      for (uint32_t r : order) out.push_back(std::move(column[r]));
      column.swap(out);
    });
  });
  const auto run = [&](std::size_t count, std::size_t grain, const auto& body) {
    if (ex)
      ex->for_each_chunk(count, grain, body);
    else
      body(0, count);
  };
  run(gather.size(), 1, [&](std::size_t b, std::size_t e) {
    for (std::size_t c = b; c < e; ++c) gather[c]();
  });
  run(n, kPermuteGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t r = b; r < e; ++r)
      slots_[AgentId::from_value(t.id[r]).index].row = static_cast<uint32_t>(r);
  });
}

void World::reserve(std::size_t agents) {
  if (agents > AgentId::kNoIndex)
    throw Error(Error::Kind::usage, "reserve: " + std::to_string(agents) +
                                        " agents; a world holds at most " +
                                        std::to_string(AgentId::kNoIndex));
  each_column(agents_, [&](auto& column) { column.reserve(agents); });
  slots_.reserve(agents);
  // (Not beyond one batch's kept room: apply_pending gives a larger one back at once.)
  pending_.reserve(std::min(agents - std::min(agents, agents_.size()), kKeptPending));
}

void World::remove_rows(std::vector<std::size_t> rows) {
  // Descending rows: each swap-remove moves in a row that is staying (or already handled).
  std::sort(rows.begin(), rows.end(), std::greater<>());
  for (std::size_t row : rows) remove_row(row);
  // insert() takes the last free slot first: the lowest of these.
  std::sort(free_slots_.end() - static_cast<std::ptrdiff_t>(rows.size()), free_slots_.end(),
            std::greater<>());
}

void World::remove_row(std::size_t row) {
  AgentTable& t = agents_;
  const std::size_t last = t.size() - 1;
  const AgentId dead = AgentId::from_value(t.id[row]);
  auto move_last = [&](auto& column) {
    if (row != last) column[row] = std::move(column[last]);
    column.pop_back();
  };
  each_column(t, move_last);
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
    const Vec2 p = goal_target(goals_[t.goal[row]], t.x[row], t.y[row], t.radius[row]);
    t.target_x[row] = p.x;
    t.target_y[row] = p.y;
  }
  // A new route gets its time to work before the next re-plan. The progress watch measures the
  // path left to the goal, so it carries on (a new route is no progress by itself).
  t.replan_ticks[row] = 0;
}

bool World::advance_goal(std::size_t row) {
  AgentTable& t = agents_;
  if (t.then[row].empty()) return false;
  t.left_goal[row] = t.goal[row];
  t.goal[row] = t.then[row].front();
  t.then[row].erase(t.then[row].begin());
  t.route[row].clear();
  t.path_goal[row] = AgentTable::kNoPath;  // a new goal: re-plan
  t.progress_best[row] = INFINITY;         // and a new reference for the progress watch
  t.stall_ticks[row] = 0;
  refresh_target(row);
  return true;
}

bool World::at_goal(std::size_t row) const {
  return inside_goal(goals_[agents_.goal[row]], agents_.x[row], agents_.y[row]);
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
        if (standing(agents_.state[*row])) agents_.left_goal[*row] = agents_.goal[*row];
        agents_.goal[*row] = c.goal;
        agents_.then[*row].clear();
        agents_.route[*row].clear();
        agents_.path_goal[*row] = AgentTable::kNoPath;  // re-plan, even for the same goal
        agents_.progress_best[*row] = INFINITY;
        agents_.stall_ticks[*row] = 0;
        if (standing(agents_.state[*row])) agents_.state[*row] = AgentState::active;
        refresh_target(*row);
        break;
      }
    }
  }
  // A big batch (a scenario's agents, loaded at once: 128 bytes each, 134 MB at 10^6) gives its
  // memory back; the tick's own small batches keep theirs.
  if (pending_.capacity() > kKeptPending)
    std::vector<Change>().swap(pending_);
  else
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
  same(t.pref_speed.size(), "pref_speed");
  same(t.max_speed.size(), "max_speed");
  same(t.max_accel.size(), "max_accel");
  same(t.charge.size(), "charge");
  same(t.target_x.size(), "target_x");
  same(t.target_y.size(), "target_y");
  same(t.goal.size(), "goal");
  same(t.state.size(), "state");
  same(t.frozen_ticks.size(), "frozen_ticks");
  same(t.progress_best.size(), "progress_best");
  same(t.stall_ticks.size(), "stall_ticks");
  same(t.id.size(), "id");
  same(t.route.size(), "route");
  same(t.then.size(), "then");
  same(t.left_goal.size(), "left_goal");
  same(t.stall_action.size(), "stall_action");
  same(t.stall_until.size(), "stall_until");
  same(t.stall_dir_x.size(), "stall_dir_x");
  same(t.stall_dir_y.size(), "stall_dir_y");
  same(t.path_goal.size(), "path_goal");
  same(t.path_ticket.size(), "path_ticket");
  same(t.replan_ticks.size(), "replan_ticks");
  same(t.wait_until.size(), "wait_until");
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

// ---- checkpoints ----

namespace {

template <class T>
void save_nested(ByteWriter& out, const std::vector<std::vector<T>>& v) {
  out.u64(v.size());
  for (const auto& inner : v) {
    if constexpr (std::is_same_v<T, Vec2>) {
      out.u64(inner.size());
      for (const Vec2& p : inner) {
        out.f64(p.x);
        out.f64(p.y);
      }
    } else {
      out.vec(inner);
    }
  }
}

template <class T>
void restore_nested(ByteReader& in, std::vector<std::vector<T>>& v) {
  v.resize(in.count(8));
  for (auto& inner : v) {
    if constexpr (std::is_same_v<T, Vec2>) {
      inner.resize(in.count(16));
      for (Vec2& p : inner) {
        p.x = in.f64();
        p.y = in.f64();
      }
    } else {
      in.vec(inner);
    }
  }
}

// Every column, in one order for saving and restoring.
template <class Io, class Table>
void columns(Io& io, Table& t) {
  io.vec(t.x);
  io.vec(t.y);
  io.vec(t.vx);
  io.vec(t.vy);
  io.vec(t.radius);
  io.vec(t.pref_speed);
  io.vec(t.max_speed);
  io.vec(t.max_accel);
  io.vec(t.charge);
  io.vec(t.target_x);
  io.vec(t.target_y);
  io.vec(t.goal);
  io.vec(t.state);
  io.vec(t.frozen_ticks);
  io.vec(t.progress_best);
  io.vec(t.stall_ticks);
  io.vec(t.id);
  io.vec(t.stall_action);
  io.vec(t.stall_until);
  io.vec(t.stall_dir_x);
  io.vec(t.stall_dir_y);
  io.vec(t.path_goal);
  io.vec(t.path_ticket);
  io.vec(t.replan_ticks);
  io.vec(t.wait_until);
  io.vec(t.left_goal);
}

}  // namespace

void World::save_agents(ByteWriter& out) const {
  if (!pending_.empty())
    throw Error(Error::Kind::usage,
                "checkpoint: agent changes are buffered; save before changing agents or after a "
                "step applied them");
  columns(out, agents_);
  save_nested(out, agents_.route);
  save_nested(out, agents_.then);
  out.u64(slots_.size());
  for (const Slot& s : slots_) {
    out.u32(s.generation);
    out.u32(s.row);
  }
  out.vec(free_slots_);
}

void World::restore_agents(ByteReader& in) {
  AgentTable t;
  columns(in, t);
  restore_nested(in, t.route);
  restore_nested(in, t.then);
  std::vector<Slot> slots(in.count(8));
  for (Slot& s : slots) {
    s.generation = in.u32();
    s.row = in.u32();
  }
  std::vector<uint32_t> free_slots;
  in.vec(free_slots);
  // The data must make a table this world could have reached: check before taking it.
  const auto bad = [&](const std::string& why) { in.fail("agents table: " + why); };
  World trial;  // column lengths, slot map and goal rows, by the world's own invariants
  trial.goals_ = goals_;
  trial.goal_rows_ = goal_rows_;
  trial.agents_ = std::move(t);
  trial.slots_ = std::move(slots);
  try {
    trial.validate();
  } catch (const std::logic_error& e) {
    bad(e.what());
  }
  const AgentTable& a = trial.agents_;
  for (std::size_t r = 0; r < a.size(); ++r) {
    const std::string row = "row " + std::to_string(r);
    if (static_cast<uint8_t>(a.state[r]) > static_cast<uint8_t>(AgentState::waiting))
      bad(row + ": bad state");
    if (static_cast<uint8_t>(a.stall_action[r]) > 3) bad(row + ": bad stall action");
    AgentSpec spec;  // the rules an inserted agent obeys
    spec.x = a.x[r];
    spec.y = a.y[r];
    spec.vx = a.vx[r];
    spec.vy = a.vy[r];
    spec.radius = a.radius[r];
    spec.pref_speed = a.pref_speed[r];
    spec.max_speed = a.max_speed[r];
    spec.max_accel = a.max_accel[r];
    spec.charge = a.charge[r];
    spec.goal = a.goal[r];
    spec.then = a.then[r];
    try {
      validate_spec(spec, goals_.size());
    } catch (const InvalidRow& e) {
      bad(row + ": " + e.what());
    }
    if (!std::isfinite(a.target_x[r]) || !std::isfinite(a.target_y[r]))
      bad(row + ": waypoint not finite");
    for (const Vec2& p : a.route[r])
      if (!(std::abs(p.x) <= kMaxCoordinate && std::abs(p.y) <= kMaxCoordinate))
        bad(row + ": a route point lies beyond +-1e9");
    if (a.path_goal[r] != AgentTable::kNoPath && a.path_goal[r] >= goals_.size())
      bad(row + ": bad planned goal");
    if (a.left_goal[r] != AgentTable::kNoGoal && a.left_goal[r] >= goals_.size())
      bad(row + ": bad goal left");
  }
  std::vector<uint8_t> seen(trial.slots_.size(), 0);
  for (uint32_t f : free_slots) {
    if (f >= trial.slots_.size() || trial.slots_[f].row != kNoRow || seen[f])
      bad("free slot " + std::to_string(f) + " is not a free slot");
    seen[f] = 1;
  }
  agents_ = std::move(trial.agents_);
  slots_ = std::move(trial.slots_);
  free_slots_ = std::move(free_slots);
  pending_.clear();
}

}  // namespace crowddb
