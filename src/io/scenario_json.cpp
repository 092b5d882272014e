// Scenario files: JSON (nlohmann-json) -> World + SimConfig. The format is documented in
// docs/scenario-format.md. Every error names the file and the JSON pointer of the field (or the
// line and column of a syntax error); unknown keys and duplicate keys are errors, so a typo never
// silently falls back to a default.
#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <span>
#include <sstream>
#include <tuple>
#include <unordered_map>

#include "crowddb/scenario.hpp"
#include "io/scenario_doc.hpp"
#include "io/walkable_wkt.hpp"
#include "steer/model.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"
#include "world/nearest_point.hpp"
#include "world/obstacle_lookup.hpp"
#include "world/placement_grid.hpp"

namespace crowddb {
namespace {

std::string hex4(unsigned c) {
  const char* digits = "0123456789ABCDEF";
  return {digits[(c >> 12) & 15], digits[(c >> 8) & 15], digits[(c >> 4) & 15], digits[c & 15]};
}

using nlohmann::json;

// The document being read: its file name for messages and, for a document converted from another
// format, where its fields came from.
struct DocSource {
  std::string file;
  const io::Origins* origins = nullptr;

  // "file: /pointer" or, for a converted document, "file:LINE: <element>" of the nearest origin.
  std::string where(const std::string& pointer) const {
    if (origins) {
      for (std::string p = pointer; !p.empty(); p.resize(p.rfind('/'))) {
        const auto it = origins->find(p);
        if (it != origins->end())
          return it->second + " (converted: " + (pointer.empty() ? "/" : pointer) + ")";
      }
    }
    return file + ": " + (pointer.empty() ? "/" : pointer);
  }
};

// A JSON object being read: typed getters that know the object's pointer, and a check that
// every key was used.
class Node {
 public:
  Node(const json& j, std::string pointer, const DocSource* file)
      : j_(j), ptr_(std::move(pointer)), file_(file) {
    if (!j_.is_object()) fail("", "expected an object");
  }

  [[noreturn]] void fail(const std::string& key, const std::string& what) const {
    throw Error(Error::Kind::input,
                file_->where(key.empty() ? ptr_ : ptr_ + "/" + key) + ": " + what);
  }

  bool has(const std::string& key) const { return j_.contains(key); }

  const json& raw(const std::string& key) {
    const auto it = j_.find(key);
    if (it == j_.end()) fail(key, "missing");
    used_.insert(key);
    return *it;
  }

  double number(const std::string& key, std::optional<double> fallback = std::nullopt) {
    if (!has(key)) {
      if (!fallback) fail(key, "missing (a number is required)");
      return *fallback;
    }
    return number_of(raw(key), key);
  }

  double number_of(const json& v, const std::string& key) const {
    if (!v.is_number()) fail(key, "expected a number, got " + std::string(v.type_name()));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(key, "must be finite");
    return d;
  }

  double positive(const std::string& key, std::optional<double> fallback = std::nullopt) {
    const double v = number(key, fallback);
    if (!(v > 0)) fail(key, "must be > 0 (got " + fmt(v) + ")");
    return v;
  }

  double non_negative(const std::string& key, std::optional<double> fallback = std::nullopt) {
    const double v = number(key, fallback);
    if (!(v >= 0)) fail(key, "must be >= 0 (got " + fmt(v) + ")");
    return v;
  }

  // A number, "inf", or absent (-> fallback).
  double positive_or_inf(const std::string& key, double fallback) {
    if (!has(key)) return fallback;
    const json& v = raw(key);
    if (v.is_string() && v.get<std::string>() == "inf")
      return std::numeric_limits<double>::infinity();
    const double d = number_of(v, key);
    if (!(d > 0)) fail(key, "must be > 0 or \"inf\" (got " + fmt(d) + ")");
    return d;
  }

  uint64_t integer(const std::string& key, std::optional<uint64_t> fallback = std::nullopt,
                   uint64_t max = std::numeric_limits<uint64_t>::max()) {
    if (!has(key)) {
      if (!fallback) fail(key, "missing (a non-negative integer is required)");
      return *fallback;
    }
    const json& v = raw(key);
    if (!v.is_number_unsigned() && !(v.is_number_integer() && v.get<int64_t>() >= 0))
      fail(key, "expected a non-negative integer");
    const auto u = v.get<uint64_t>();
    if (u > max) fail(key, "must be at most " + std::to_string(max));
    return u;
  }

  bool boolean(const std::string& key, bool fallback) {
    if (!has(key)) return fallback;
    const json& v = raw(key);
    if (!v.is_boolean()) fail(key, "expected true or false");
    return v.get<bool>();
  }

  std::string string(const std::string& key, std::optional<std::string> fallback = std::nullopt) {
    if (!has(key)) {
      if (!fallback) fail(key, "missing (a string is required)");
      return *fallback;
    }
    const json& v = raw(key);
    if (!v.is_string()) fail(key, "expected a string");
    std::string text = v.get<std::string>();
    // "\u0000" and other control characters are valid JSON but would cut names short in C APIs
    // and SQLite output, or end up raw in messages: refuse them (tab and line breaks are fine).
    for (std::size_t i = 0; i < text.size(); ++i) {
      const auto c = static_cast<unsigned char>(text[i]);
      if ((c < 0x20 && c != '\t' && c != '\n' && c != '\r') || c == 0x7f)
        fail(key,
             "contains the control character U+" + hex4(c) + " at position " + std::to_string(i));
    }
    return text;
  }

  std::string choice(const std::string& key, std::initializer_list<const char*> options,
                     const char* fallback) {
    const std::string s = string(key, std::string(fallback));
    for (const char* o : options)
      if (s == o) return s;
    std::string list;
    for (const char* o : options) list += std::string(list.empty() ? "" : ", ") + o;
    fail(key, "'" + s + "' is not one of: " + list);
  }

  // [a, b, ...] of exactly `n` finite numbers.
  std::vector<double> numbers(const std::string& key, std::size_t n) {
    const json& v = raw(key);
    if (!v.is_array() || v.size() != n)
      fail(key, "expected an array of " + std::to_string(n) + " numbers");
    std::vector<double> out;
    for (std::size_t i = 0; i < n; ++i)
      out.push_back(number_of(v[i], key + "/" + std::to_string(i)));
    return out;
  }

  // A number (fixed value) or [lo, hi] (uniform in the range).
  std::pair<double, double> range(const std::string& key, std::pair<double, double> fallback) {
    if (!has(key)) return fallback;
    const json& v = raw(key);
    if (v.is_number()) {
      const double d = number_of(v, key);
      return {d, d};
    }
    if (!v.is_array() || v.size() != 2) fail(key, "expected a number or a [low, high] pair");
    const double lo = number_of(v[0], key + "/0"), hi = number_of(v[1], key + "/1");
    if (!(lo <= hi)) fail(key, "low must not exceed high");
    return {lo, hi};
  }

  std::vector<Vec2> points(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_array()) fail(key, "expected an array of [x, y] points");
    std::vector<Vec2> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      const std::string k = key + "/" + std::to_string(i);
      if (!v[i].is_array() || v[i].size() != 2) fail(k, "expected an [x, y] point");
      out.push_back({number_of(v[i][0], k + "/0"), number_of(v[i][1], k + "/1")});
    }
    return out;
  }

  const json& array(const std::string& key) {
    const json& v = raw(key);
    if (!v.is_array()) fail(key, "expected an array");
    return v;
  }

  Node child(const std::string& key) { return Node(raw(key), ptr_ + "/" + key, file_); }
  Node element(const json& arr, const std::string& key, std::size_t i) const {
    return Node(arr[i], ptr_ + "/" + key + "/" + std::to_string(i), file_);
  }

  // Every key must have been read: unknown keys are typos.
  void finish() const {
    for (const auto& item : j_.items())
      if (!used_.count(item.key())) fail(item.key(), "unknown key");
  }

  const std::string& pointer() const { return ptr_; }
  const std::string& file() const { return file_->file; }

  static std::string fmt(double v) {
    std::ostringstream os;
    os.precision(17);
    os << v;
    return os.str();
  }

 private:
  const json& j_;
  std::string ptr_;
  const DocSource* file_;
  std::set<std::string> used_;
};

// Line and column of a byte offset, for syntax errors.
std::string line_col(std::string_view text, std::size_t byte) {
  std::size_t line = 1, col = 1;
  for (std::size_t i = 0; i < byte && i < text.size(); ++i) {
    if (text[i] == '\n') {
      ++line;
      col = 1;
    } else {
      ++col;
    }
  }
  return std::to_string(line) + ":" + std::to_string(col);
}

// Overlapping spawned pairs are counted up to this many (a warning, not a list).
constexpr uint64_t kOverlapCountCap = 1'000'000;

struct Loader {
  Scenario& sc;
  std::map<std::string, uint32_t> goal_rows;
  std::vector<AgentSpec> agents;               // in insertion order
  std::vector<std::vector<Vec2>> routes;       // per agent (via points)
  std::unique_ptr<PlacementGrid> placed;       // every agent placed so far
  const io::WalkableArea* walkable = nullptr;  // the "walkable" WKT, if given
  std::size_t walkable_pieces = 0;             // polygons [0, walkable_pieces) are its blocked area
  std::vector<std::size_t> circle_src,
      polygon_src;  // /obstacles index of each circle / polygon row
  mutable std::shared_ptr<const ObstacleLookup> lookup;  // the world's, at the first question
  mutable std::vector<uint32_t> near;                    // its last answer
  // Agents from this row on were each placed clear of every agent before them, so no
  // overlapping pair reaches past it (warn_overlaps looks at the rows before it only).
  std::size_t may_overlap_end = 0;

  // Why a point is not walkable (a goal or an agent's centre), or empty when it is: outside the
  // walkable WKT area or the walled bounds, or strictly inside an obstacle.
  std::string outside_walkable(double x, double y) const {
    if (walkable && !walkable->covers(x, y)) return "lies outside the walkable area";
    const Bounds& b = sc.world.bounds();
    if (sc.config.walls && (x < b.xmin || x > b.xmax || y < b.ymin || y > b.ymax))
      return "lies outside the bounds (the walls)";
    const std::size_t circles = sc.world.circles().size();
    for (uint32_t k : obstacles_near(x, y, 0)) {
      if (k < circles) {
        const CircleObstacle& c = sc.world.circles()[k];
        if (std::hypot(c.x - x, c.y - y) < c.radius)
          return "lies inside obstacle /obstacles/" + std::to_string(circle_src[k]) +
                 ", outside the walkable area";
      } else if (const std::size_t p = k - circles; p >= walkable_pieces) {
        const auto& ring = sc.world.polygons()[p].vertices;
        if (lookup->polygon_holds(p, ring, x, y) && lookup->polygon_dist2(p, ring, x, y, 0) > 0)
          return "lies inside obstacle /obstacles/" +
                 std::to_string(polygon_src[p - walkable_pieces]) + ", outside the walkable area";
      }
    }
    return {};
  }

  bool blocked_by_obstacle(double x, double y, double r, double gap) const {
    const std::size_t circles = sc.world.circles().size();
    for (uint32_t k : obstacles_near(x, y, r + gap)) {
      if (k < circles) {
        const CircleObstacle& c = sc.world.circles()[k];
        if (discs_overlap(c.x - x, c.y - y, c.radius + r + gap)) return true;
      } else if (lookup->disc_overlaps_polygon(
                     k - circles, sc.world.polygons()[k - circles].vertices, x, y, r + gap)) {
        return true;
      }
    }
    return false;
  }

  // The obstacles (circles, then polygons, by row) that a disc of radius `reach` at (x, y) may
  // touch, in row order (world/obstacle_lookup.hpp). The world's lookup, taken at the first
  // question: the obstacles are all read by then (read_walkable, read_obstacles), and none come
  // after. (The walkable checks of the agents inserted use the same one.)
  const std::vector<uint32_t>& obstacles_near(double x, double y, double reach) const {
    if (!lookup) lookup = sc.world.obstacle_lookup();
    lookup->candidates(x, y, reach, near);
    return near;
  }

  uint32_t goal_named(Node& n, const std::string& key, const std::string& name) {
    auto it = goal_rows.find(name);
    if (it == goal_rows.end()) n.fail(key, "unknown goal '" + name + "'");
    return it->second;
  }

  // Explicit goals (rows 0.. of the goals table) must be walkable.
  void check_goals(Node& root) {
    if (!root.has("goals")) return;
    const json& arr = root.raw("goals");
    for (std::size_t i = 0; i < arr.size(); ++i) {
      const Goal& goal = sc.world.goals()[i];
      if (const std::string why = outside_walkable(goal.x, goal.y); !why.empty())
        root.element(arr, "goals", i)
            .fail("", "goal '" + goal.name + "' at (" + Node::fmt(goal.x) + ", " +
                          Node::fmt(goal.y) + ") " + why);
    }
  }

  // "walkable": a WKT POLYGON / MULTIPOLYGON (or {"wkt": ..., "charge": ...}). Its complement
  // within the bounds becomes polygon obstacles, so every query sees it as solid.
  void read_walkable(Node& root, const io::WalkableArea& area, double charge) {
    std::vector<std::vector<Vec2>> pieces;
    try {
      pieces = area.blocked_pieces(sc.world.bounds());
    } catch (const Error& e) {
      root.fail("walkable", e.what());
    }
    for (const auto& ring : pieces) {
      try {
        sc.world.add_obstacle(PolygonObstacle{ring, charge});
      } catch (const InvalidRow& e) {
        root.fail("walkable",
                  std::string("could not turn the blocked area into obstacles: ") + e.what());
      }
    }
    walkable = &area;
    walkable_pieces = sc.world.polygons().size();
  }

  // A polygon's point inside it: the centroid when inside, else the middle of the longest
  // horizontal chord through the centroid's height.
  static Vec2 point_inside(const std::vector<Vec2>& ring) {
    // Relative to the first vertex: far from the origin (UTM coordinates, 10^6 m) the products
    // of absolute coordinates lose the centroid's precision.
    const Vec2 o = ring[0];
    double a = 0, cx = 0, cy = 0;
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      const Vec2 p{ring[i].x - o.x, ring[i].y - o.y};
      const Vec2 q{ring[(i + 1) % n].x - o.x, ring[(i + 1) % n].y - o.y};
      const double c = p.x * q.y - q.x * p.y;
      a += c;
      cx += (p.x + q.x) * c;
      cy += (p.y + q.y) * c;
    }
    const Vec2 centroid{o.x + cx / (3 * a), o.y + cy / (3 * a)};
    if (point_in_polygon(ring, centroid.x, centroid.y)) return centroid;
    std::vector<double> xs;
    for (std::size_t i = 0, n = ring.size(); i < n; ++i) {
      const Vec2& p = ring[i];
      const Vec2& q = ring[(i + 1) % n];
      if ((p.y > centroid.y) != (q.y > centroid.y))
        xs.push_back(p.x + (centroid.y - p.y) * (q.x - p.x) / (q.y - p.y));
    }
    std::sort(xs.begin(), xs.end());
    Vec2 best = ring[0];
    double width = -1;
    for (std::size_t i = 0; i + 1 < xs.size(); i += 2)
      if (xs[i + 1] - xs[i] > width) {
        width = xs[i + 1] - xs[i];
        best = {(xs[i] + xs[i + 1]) / 2, centroid.y};
      }
    return best;
  }

  void read_goals(Node& root) {
    if (!root.has("goals")) return;
    const json& arr = root.array("goals");
    for (std::size_t i = 0; i < arr.size(); ++i) {
      Node g = root.element(arr, "goals", i);
      Goal goal;
      goal.name = g.string("name");
      goal.charge = g.number("charge", 1.0);
      if (g.has("wait") && g.raw("wait").is_object()) {
        Node w = g.child("wait");
        goal.wait_mean = w.positive("exponential");
        w.finish();
      } else {
        std::tie(goal.wait_min, goal.wait_max) = g.range("wait", {0.0, 0.0});
      }
      if (g.has("area")) {
        goal.area = g.points("area");
        if (g.has("arrival_radius"))
          g.fail("arrival_radius", "a goal with an area arrives inside the area: no radius");
        if (goal.area.size() < 3) g.fail("area", "a polygon needs at least 3 vertices");
        if (g.has("x") != g.has("y")) g.fail(g.has("x") ? "y" : "x", "missing (give both or none)");
        if (g.has("x")) {
          goal.x = g.number("x");
          goal.y = g.number("y");
        } else {
          std::vector<Vec2> ring = goal.area;
          if (ring.size() > 3 && ring.front().x == ring.back().x && ring.front().y == ring.back().y)
            ring.pop_back();
          if (std::abs(signed_area(ring)) > 0) {
            const Vec2 c = point_inside(ring);
            goal.x = c.x;
            goal.y = c.y;
          }
        }
      } else {
        goal.x = g.number("x");
        goal.y = g.number("y");
        goal.arrival_radius = g.positive("arrival_radius", 0.5);
      }
      g.finish();
      if (goal_rows.count(goal.name)) g.fail("name", "duplicate goal name '" + goal.name + "'");
      try {
        goal_rows[goal.name] = sc.world.add_goal(goal);
      } catch (const InvalidRow& e) {
        g.fail(e.field(), e.what());
      }
    }
  }

  // "goal": a name, or an array of names (a sequence: visited in order). Returns the first and
  // puts the rest in `then`.
  uint32_t goal_sequence(Node& n, const std::string& key, std::vector<uint32_t>& then) {
    const json& v = n.raw(key);
    if (v.is_string()) return goal_named(n, key, v.get<std::string>());
    if (!v.is_array() || v.empty())
      n.fail(key, "expected a goal name or a non-empty array of goal names (a sequence)");
    std::vector<uint32_t> rows;
    for (std::size_t k = 0; k < v.size(); ++k) {
      if (!v[k].is_string()) n.fail(key + "/" + std::to_string(k), "expected a goal name");
      rows.push_back(goal_named(n, key + "/" + std::to_string(k), v[k].get<std::string>()));
    }
    then.assign(rows.begin() + 1, rows.end());
    return rows.front();
  }

  // pref_speed and max_speed of an agent, a group or a source: pref_speed defaults to max_speed
  // when only that is given (scenarios written for the thesis's rule), else to 1.34 m/s
  // (Weidmann's free speed); max_speed defaults to the largest pref_speed.
  std::pair<std::pair<double, double>, double> speeds(Node& n) {
    std::pair<double, double> pref{1.34, 1.34};
    std::optional<double> max;
    if (n.has("max_speed")) max = n.positive("max_speed");
    if (n.has("pref_speed")) {
      pref = n.range("pref_speed", pref);
      if (!(pref.first > 0)) n.fail("pref_speed", "must be > 0");
    } else if (max) {
      pref = {*max, *max};
    }
    const double m = max ? *max : pref.second;
    if (m < pref.second)
      n.fail("max_speed",
             "must be >= pref_speed (" + Node::fmt(m) + " < " + Node::fmt(pref.second) + ")");
    return {pref, m};
  }

  void read_obstacles(Node& root) {
    if (!root.has("obstacles")) return;
    const json& arr = root.array("obstacles");
    for (std::size_t i = 0; i < arr.size(); ++i) {
      Node o = root.element(arr, "obstacles", i);
      const std::string type = o.choice("type", {"circle", "polygon"}, "");
      try {
        if (type == "circle") {
          CircleObstacle c;
          c.x = o.number("x");
          c.y = o.number("y");
          c.radius = o.positive("radius");
          c.charge = o.number("charge", 1.0);
          o.finish();
          sc.world.add_obstacle(c);
          circle_src.push_back(i);
        } else {
          PolygonObstacle p;
          p.vertices = o.points("vertices");
          p.charge = o.number("charge", 1.0);
          o.finish();
          sc.world.add_obstacle(std::move(p));
          polygon_src.push_back(i);
        }
      } catch (const InvalidRow& e) {
        o.fail(e.field(), e.what());
      }
    }
  }

  // Which agent of a group an error names ("agent 3 of 40"); count 0: an explicit agent. Spelled
  // out only on an error: at 10^6 agents the strings cost a tenth of a second.
  struct Who {
    uint64_t index = 0, count = 0;
    std::string str() const {
      return count == 0 ? "agent"
                        : "agent " + std::to_string(index + 1) + " of " + std::to_string(count);
    }
  };

  // `placed_clear`: the caller checked the agent against every agent before it (a uniform
  // placement), so it overlaps none of them.
  void add_agent(Node& n, AgentSpec spec, std::vector<Vec2> via, bool placed_clear, Who who) {
    try {
      World::validate_spec(spec, sc.world.goals().size());
    } catch (const InvalidRow& e) {
      n.fail(e.field(), e.what());
    }
    if (const std::string why = outside_walkable(spec.x, spec.y); !why.empty())
      n.fail("", who.str() + " at (" + Node::fmt(spec.x) + ", " + Node::fmt(spec.y) + ") " + why);
    agents.push_back(std::move(spec));
    routes.push_back(std::move(via));
    placed->add(agents.back().x, agents.back().y, agents.back().radius);
    if (!placed_clear) may_overlap_end = agents.size();
  }

  // Room for `more` agents, growing geometrically (many small groups must not reallocate for
  // every one).
  void reserve_agents(uint64_t more) {
    const std::size_t want = agents.size() + more;
    if (want <= agents.capacity()) return;
    const std::size_t cap = std::max(want, 2 * agents.capacity());
    agents.reserve(cap);
    routes.reserve(cap);
    placed->reserve(cap);
  }

  void read_agents(Node& root) {
    if (!root.has("agents")) return;
    const json& arr = root.array("agents");
    if (arr.size() > kMaxScenarioAgents)
      root.fail("agents", std::to_string(arr.size()) + " agents; a scenario places at most " +
                              std::to_string(kMaxScenarioAgents));
    for (std::size_t i = 0; i < arr.size(); ++i) {
      Node a = root.element(arr, "agents", i);
      AgentSpec s;
      s.x = a.number("x");
      s.y = a.number("y");
      s.vx = a.number("vx", 0.0);
      s.vy = a.number("vy", 0.0);
      s.radius = a.positive("radius", 0.25);
      const auto [pref, max] = speeds(a);
      if (pref.first != pref.second) a.fail("pref_speed", "expected a number");
      s.pref_speed = pref.first;
      s.max_speed = max;
      s.max_accel = a.positive_or_inf("max_accel", std::numeric_limits<double>::infinity());
      s.charge = a.number("charge", 1.0);
      s.goal = goal_sequence(a, "goal", s.then);
      std::vector<Vec2> via = a.has("via") ? a.points("via") : std::vector<Vec2>{};
      a.finish();
      add_agent(a, std::move(s), std::move(via), false, {});
    }
  }

  void read_groups(Node& root) {
    if (!root.has("groups")) return;
    const json& arr = root.array("groups");
    for (std::size_t gi = 0; gi < arr.size(); ++gi) {
      Node g = root.element(arr, "groups", gi);
      Rng rng = Rng::stream(sc.config.seed, gi);
      g.string("name", std::string());
      const uint64_t count = g.integer("count");
      if (count > kMaxScenarioAgents - std::min(kMaxScenarioAgents, agents.size()))
        g.fail("count", std::to_string(count) + " agents would make " +
                            std::to_string(agents.size() + count) + "; a scenario places at most " +
                            std::to_string(kMaxScenarioAgents) +
                            " at load time (explicit agents and groups together)");
      const auto radius = g.range("radius", {0.25, 0.25});
      if (!(radius.first > 0)) g.fail("radius", "must be > 0");
      const auto speed = g.range("speed", {0, 0});
      if (!(speed.first >= 0)) g.fail("speed", "must be >= 0");
      const std::string heading = g.choice("heading", {"random", "goal"}, "random");
      AgentSpec base;
      const auto [pref, max_speed] = speeds(g);
      base.max_speed = max_speed;
      base.max_accel = g.positive_or_inf("max_accel", std::numeric_limits<double>::infinity());
      base.charge = g.number("charge", 1.0);
      std::vector<Vec2> via = g.has("via") ? g.points("via") : std::vector<Vec2>{};

      // Goal assignment: one named goal (or sequence), or a rule over several.
      std::string assign = "single";
      std::vector<uint32_t> pool, then;
      std::optional<NearestPoint> nearest_goal;  // over the pool's goals, at the first "nearest"
      double own_radius = 0.5, own_charge = 1;   // antipodal and targets: each agent's own goal
      std::vector<Vec2> targets;
      if (g.has("goal") == g.has("goals")) g.fail("goal", "give exactly one of 'goal' and 'goals'");
      if (g.has("goal")) {
        pool.push_back(goal_sequence(g, "goal", then));
      } else {
        Node rule = g.child("goals");
        assign = rule.choice("assign", {"round_robin", "random", "nearest", "antipodal", "targets"},
                             "round_robin");
        if (assign == "antipodal" || assign == "targets") {
          own_radius = rule.positive("arrival_radius", 0.5);
          own_charge = rule.number("charge", 1.0);
          if (assign == "targets") {
            targets = rule.points("points");
            if (targets.size() != count)
              rule.fail("points", "expected one target per agent: " + std::to_string(count) +
                                      " points, got " + std::to_string(targets.size()));
          }
        } else if (rule.has("from")) {
          const json& names = rule.array("from");
          for (std::size_t k = 0; k < names.size(); ++k) {
            if (!names[k].is_string())
              rule.fail("from/" + std::to_string(k), "expected a goal name");
            pool.push_back(
                goal_named(rule, "from/" + std::to_string(k), names[k].get<std::string>()));
          }
        } else {
          for (uint32_t k = 0; k < sc.world.goals().size(); ++k) pool.push_back(k);
        }
        if (assign != "antipodal" && assign != "targets" && pool.empty())
          rule.fail("from", "no goals to assign");
        rule.finish();
      }
      if (g.has("then")) {
        const json& names = g.array("then");
        for (std::size_t k = 0; k < names.size(); ++k) {
          if (!names[k].is_string()) g.fail("then/" + std::to_string(k), "expected a goal name");
          then.push_back(goal_named(g, "then/" + std::to_string(k), names[k].get<std::string>()));
        }
      }
      base.then = then;

      Node pl = g.child("placement");
      const std::string type = pl.choice("type", {"uniform", "circle", "grid"}, "");
      std::vector<double> region;
      Vec2 centre{};
      double ring = 0, gap = 0;
      uint64_t attempts = 1000;
      std::pair<double, double> spacing{0, 0};
      if (type == "uniform" || type == "grid") {
        region = pl.numbers("region", 4);
        if (!(region[2] > region[0] && region[3] > region[1]))
          pl.fail("region", "needs x1 > x0 and y1 > y0");
      }
      if (type == "uniform") {
        gap = pl.non_negative("gap", 0.0);
        attempts = pl.integer("attempts", 1000, 1'000'000);
        if (attempts == 0) pl.fail("attempts", "must be >= 1");
      } else if (type == "circle") {
        const auto c = pl.numbers("center", 2);
        centre = {c[0], c[1]};
        ring = pl.positive("radius");
      } else {
        const json& sp = pl.raw("spacing");
        if (sp.is_number()) {
          spacing.first = spacing.second = pl.number_of(sp, "spacing");
        } else {
          const auto s2 = pl.numbers("spacing", 2);
          spacing = {s2[0], s2[1]};
        }
        if (!(spacing.first > 0 && spacing.second > 0)) pl.fail("spacing", "must be > 0");
      }
      pl.finish();
      if (assign == "antipodal" && type != "circle")
        g.fail("goals", "antipodal goals need a circle placement");
      g.finish();

      // Grid capacity is known up front.
      if (type == "grid") {
        const auto cols =
            static_cast<uint64_t>(std::floor((region[2] - region[0]) / spacing.first)) + 1;
        const auto rows =
            static_cast<uint64_t>(std::floor((region[3] - region[1]) / spacing.second)) + 1;
        if (cols * rows < count)
          pl.fail("spacing", "the grid holds " + std::to_string(cols * rows) +
                                 " agents, fewer than count " + std::to_string(count));
      }

      reserve_agents(count);
      for (uint64_t i = 0; i < count; ++i) {
        AgentSpec s = base;
        s.radius =
            radius.first == radius.second ? radius.first : rng.uniform(radius.first, radius.second);
        s.pref_speed =
            pref.first == pref.second ? pref.first : rng.uniform(pref.first, pref.second);
        // Position.
        if (type == "uniform") {
          bool ok = false;
          for (uint64_t a = 0; a < attempts && !ok; ++a) {
            s.x = rng.uniform(region[0] + s.radius,
                              std::max(region[0] + s.radius, region[2] - s.radius));
            s.y = rng.uniform(region[1] + s.radius,
                              std::max(region[1] + s.radius, region[3] - s.radius));
            ok = !placed->any_overlap(s.x, s.y, s.radius, gap) &&
                 !blocked_by_obstacle(s.x, s.y, s.radius, gap);
          }
          if (!ok)
            pl.fail("",
                    "could not place agent " + std::to_string(i + 1) + " of " +
                        std::to_string(count) + " without overlaps in " + std::to_string(attempts) +
                        " attempts (region too crowded: enlarge it, lower count, radius or gap)");
        } else if (type == "circle") {
          const double a =
              2 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(count);
          s.x = centre.x + ring * std::cos(a);
          s.y = centre.y + ring * std::sin(a);
        } else {
          const auto cols =
              static_cast<uint64_t>(std::floor((region[2] - region[0]) / spacing.first)) + 1;
          s.x = region[0] + static_cast<double>(i % cols) * spacing.first;
          s.y = region[1] + static_cast<double>(i / cols) * spacing.second;
        }
        // Goal.
        if (assign == "antipodal" || assign == "targets") {
          Goal goal;
          goal.name = g.pointer() + "#" + std::to_string(i);
          goal.x = assign == "antipodal" ? 2 * centre.x - s.x : targets[i].x;
          goal.y = assign == "antipodal" ? 2 * centre.y - s.y : targets[i].y;
          goal.arrival_radius = own_radius;
          goal.charge = own_charge;
          if (const std::string why = outside_walkable(goal.x, goal.y); !why.empty())
            g.fail(assign == "antipodal" ? "goals" : "goals/points/" + std::to_string(i),
                   "the " + std::string(assign == "antipodal" ? "antipodal goal" : "target") +
                       " of agent " + std::to_string(i + 1) + " at (" + Node::fmt(goal.x) + ", " +
                       Node::fmt(goal.y) + ") " + why);
          s.goal = sc.world.add_goal(goal);
        } else if (assign == "single" || assign == "round_robin") {
          s.goal = pool[i % pool.size()];
        } else if (assign == "random") {
          s.goal = pool[rng.below(pool.size())];
        } else {  // nearest: the first in the pool at the least distance (world/nearest_point.hpp)
          if (!nearest_goal) {
            std::vector<Vec2> at;
            at.reserve(pool.size());
            for (const uint32_t k : pool)
              at.push_back({sc.world.goals()[k].x, sc.world.goals()[k].y});
            nearest_goal.emplace(std::move(at));
          }
          if (const std::size_t k = nearest_goal->nearest(s.x, s.y); k != NearestPoint::kNone)
            s.goal = pool[k];
        }
        // Initial velocity.
        const double v =
            speed.first == speed.second ? speed.first : rng.uniform(speed.first, speed.second);
        double angle = rng.uniform(0, 2 * std::numbers::pi);
        if (heading == "goal") {
          const Goal& gl = sc.world.goals()[s.goal];
          if (gl.x != s.x || gl.y != s.y) angle = std::atan2(gl.y - s.y, gl.x - s.x);
        }
        s.vx = v * std::cos(angle);
        s.vy = v * std::sin(angle);
        add_agent(g, std::move(s), via, type == "uniform", {i, count});
      }
    }
  }

  // "sources": agents entering over time (World::sources, src/sim/sources.hpp).
  void read_sources(Node& root) {
    if (!root.has("sources")) return;
    const json& arr = root.array("sources");
    for (std::size_t si = 0; si < arr.size(); ++si) {
      Node n = root.element(arr, "sources", si);
      Source src;
      src.name = n.string("name", std::string());
      if (n.has("area") == n.has("polygon"))
        n.fail("area", "give exactly one of 'area' and 'polygon'");
      if (n.has("area")) {
        const auto b = n.numbers("area", 4);
        if (!(b[2] > b[0] && b[3] > b[1])) n.fail("area", "needs x1 > x0 and y1 > y0");
        src.area = {{b[0], b[1]}, {b[2], b[1]}, {b[2], b[3]}, {b[0], b[3]}};
      } else {
        src.area = n.points("polygon");
      }
      src.rate = n.positive("rate");
      src.count = n.integer("count", std::nullopt, 10'000'000);
      if (src.count == 0) n.fail("count", "must be >= 1");
      src.start = n.non_negative("start", 0.0);
      if (n.has("end")) {
        src.end = n.number("end");
        if (!(src.end > src.start)) n.fail("end", "must be later than start");
      }
      const auto radius = n.range("radius", {0.25, 0.25});
      if (!(radius.first > 0)) n.fail("radius", "must be > 0");
      src.agent.radius = radius.first;
      if (radius.second != radius.first) src.radius_max = radius.second;
      const auto [pref, max_speed] = speeds(n);
      src.agent.pref_speed = pref.first;
      if (pref.second != pref.first) src.pref_speed_max = pref.second;
      src.agent.max_speed = max_speed;
      src.agent.max_accel = n.positive_or_inf("max_accel", std::numeric_limits<double>::infinity());
      src.agent.charge = n.number("charge", 1.0);
      if (n.has("goal") == n.has("goals")) n.fail("goal", "give exactly one of 'goal' and 'goals'");
      if (n.has("goal")) {
        src.goals.push_back(goal_sequence(n, "goal", src.agent.then));
      } else {
        // Round robin over the listed goals.
        const json& names = n.array("goals");
        if (names.empty()) n.fail("goals", "expected at least one goal name");
        for (std::size_t k = 0; k < names.size(); ++k) {
          if (!names[k].is_string()) n.fail("goals/" + std::to_string(k), "expected a goal name");
          src.goals.push_back(
              goal_named(n, "goals/" + std::to_string(k), names[k].get<std::string>()));
        }
      }
      n.finish();
      for (const Vec2& v : src.area)
        if (const std::string why = outside_walkable(v.x, v.y); !why.empty() && sc.config.walls) {
          const Bounds& b = sc.world.bounds();
          if (v.x < b.xmin || v.x > b.xmax || v.y < b.ymin || v.y > b.ymax)
            n.fail(n.has("area") ? "area" : "polygon", "a corner lies outside the bounds");
        }
      try {
        sc.world.add_source(std::move(src));
      } catch (const InvalidRow& e) {
        n.fail(e.field(), e.what());
      }
    }
  }

  void warn_overlaps() {
    // A pair (i, j), i < j, with j placed clear of everyone before it cannot overlap, so both
    // lie before may_overlap_end: the same count and first pair as over every agent.
    const std::span<const AgentSpec> suspects(agents.data(), may_overlap_end);
    double rmax = 0;
    for (const AgentSpec& s : suspects) rmax = std::max(rmax, s.radius);
    PlacementGrid all(2 * rmax);
    all.reserve(suspects.size());
    for (const AgentSpec& s : suspects) all.add(s.x, s.y, s.radius);
    const PlacementGrid::PairCount pairs = all.count_pairs(kOverlapCountCap);
    if (pairs.found)
      sc.warnings.push_back(
          "agents spawned overlapping: " + std::string(pairs.capped ? "at least " : "") +
          std::to_string(pairs.count) + " pairs (first: agents " + std::to_string(pairs.first_i) +
          " and " + std::to_string(pairs.first_j) +
          " in spawn order); they are allowed to separate but not to overlap deeper");
    std::size_t blocked = 0, outside = 0;
    const Bounds& b = sc.world.bounds();
    for (const AgentSpec& s : agents) {
      blocked += blocked_by_obstacle(s.x, s.y, s.radius, 0);
      outside += s.x - s.radius < b.xmin || s.x + s.radius > b.xmax || s.y - s.radius < b.ymin ||
                 s.y + s.radius > b.ymax;
    }
    if (blocked)
      sc.warnings.push_back(std::to_string(blocked) + " agents spawned overlapping an obstacle");
    if (outside && sc.config.walls)
      sc.warnings.push_back(std::to_string(outside) + " agents spawned outside the bounds");
  }
};

// Keys of format 1 (abstract units, ticks, the thesis's weights at the top of "steering") that
// moved: a file that still uses them gets told where they went instead of "unknown key".
void reject_moved_keys(Node& n, std::initializer_list<std::pair<const char*, const char*>> moved) {
  for (const auto& [key, where] : moved)
    if (n.has(key))
      n.fail(key, std::string("no longer here: ") + where + " (docs/scenario-format.md)");
}

void read_steering(Node& root, SimConfig& cfg) {
  if (!root.has("steering")) return;
  Node s = root.child("steering");
  const char* thesis =
      "the thesis model's weights live in steering/thesis, with \"model\": \"thesis\"";
  reject_moved_keys(s, {{"tau", thesis},
                        {"w_apf", thesis},
                        {"w_ftc", thesis},
                        {"horizon", thesis},
                        {"obstacle_charges", thesis},
                        {"potential", thesis}});
  SteeringParams& p = cfg.steering;
  p.model = s.string("model", p.model);
  p.perturbation = s.non_negative("perturbation", p.perturbation);
  if (s.has("thesis")) {
    Node t = s.child("thesis");
    ThesisParams& th = p.thesis;
    th.tau = t.positive("tau", th.tau);
    th.w_apf = t.non_negative("w_apf", th.w_apf);
    th.w_ftc = t.non_negative("w_ftc", th.w_ftc);
    th.horizon = t.positive("horizon", th.horizon);
    th.obstacle_repulsion =
        t.choice("obstacle_repulsion", {"nearest", "charges"}, "nearest") == "charges"
            ? ThesisParams::ObstacleRepulsion::charges
            : ThesisParams::ObstacleRepulsion::nearest;
    th.obstacle_cutoff = t.positive("obstacle_cutoff", th.obstacle_cutoff);
    th.obstacle_charges =
        t.choice("obstacle_charges", {"boundary", "centres"}, "boundary") == "centres"
            ? ObstacleCharges::centres
            : ObstacleCharges::boundary;
    if (t.has("potential")) {
      Node pot = t.child("potential");
      PotentialSpec& ps = th.potential;
      ps.kernel = pot.choice("kernel", {"exp", "inv"}, "exp") == "inv" ? Kernel::inv : Kernel::exp;
      const std::string m = pot.choice("metric", {"l1", "l2", "radial"}, "l1");
      ps.metric = m == "l2" ? Metric::l2 : (m == "radial" ? Metric::radial : Metric::l1);
      ps.A = pot.number("A", ps.A);
      ps.k = pot.non_negative("k", ps.k);
      ps.radial_frames = static_cast<int>(pot.integer("frames", 2, 16));
      if (ps.radial_frames < 1) pot.fail("frames", "must be in 1..16");
      ps.inv_floor = pot.positive("inv_floor", ps.inv_floor);
      pot.finish();
    }
    t.finish();
  }
  if (s.has("orca")) {
    Node o = s.child("orca");
    OrcaParams& op = p.orca;
    op.neighbor_dist = o.positive("neighbor_dist", op.neighbor_dist);
    op.max_neighbors = static_cast<uint32_t>(o.integer("max_neighbors", op.max_neighbors, 1000));
    if (op.max_neighbors < 1) o.fail("max_neighbors", "must be >= 1");
    op.time_horizon = o.positive("time_horizon", op.time_horizon);
    op.time_horizon_obst = o.positive("time_horizon_obst", op.time_horizon_obst);
    op.first_share = o.positive("first_share", op.first_share);
    if (!(op.first_share < 1)) o.fail("first_share", "must be < 1");
    op.time_gap = o.non_negative("time_gap", op.time_gap);
    op.stream_gap = o.non_negative("stream_gap", op.stream_gap);
    op.max_retreat = o.non_negative("max_retreat", op.max_retreat);
    const std::string side = o.choice("pass_side", {"right", "left", "none"}, "right");
    op.pass_side = side == "right"  ? OrcaParams::PassSide::right
                   : side == "left" ? OrcaParams::PassSide::left
                                    : OrcaParams::PassSide::none;
    op.pass_look = o.non_negative("pass_look", op.pass_look);
    o.finish();
  }
  if (s.has("cfsm")) {
    Node c = s.child("cfsm");
    CfsmParams& cp = p.cfsm;
    cp.time_gap = c.positive("time_gap", cp.time_gap);
    cp.strength_neighbor = c.non_negative("strength_neighbor", cp.strength_neighbor);
    cp.range_neighbor = c.positive("range_neighbor", cp.range_neighbor);
    cp.strength_geometry = c.non_negative("strength_geometry", cp.strength_geometry);
    cp.range_geometry = c.positive("range_geometry", cp.range_geometry);
    cp.cutoff = c.positive("cutoff", cp.cutoff);
    c.finish();
  }
  s.finish();
  try {
    steer::find_model(p.model);
  } catch (const Error& e) {
    s.fail("model", e.what());
  }
}

}  // namespace

namespace io {

json parse_json_strict(std::string_view text, const std::string& source) {
  try {
    // Reject duplicate keys: nlohmann keeps the last one silently.
    std::vector<std::set<std::string>> keys;
    return json::parse(text, [&](int, json::parse_event_t event, json& parsed) {
      if (event == json::parse_event_t::object_start) keys.emplace_back();
      if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
      if (event == json::parse_event_t::key && !keys.empty() &&
          !keys.back().insert(parsed.get<std::string>()).second)
        throw Error(Error::Kind::input,
                    source + ": duplicate key \"" + parsed.get<std::string>() + "\"");
      return true;
    });
  } catch (const json::parse_error& e) {
    std::string what = e.what();
    const auto colon = what.rfind(": ");
    throw Error(Error::Kind::input,
                source + ":" + line_col(text, e.byte ? e.byte - 1 : 0) + ": malformed JSON: " +
                    (colon == std::string::npos ? what : what.substr(colon + 2)));
  } catch (const json::exception& e) {
    throw Error(Error::Kind::input, source + ": malformed JSON: " + e.what());
  }
}

Scenario parse_document(std::string_view text, const std::string& source, const Origins* origins) {
  Scenario sc;
  sc.source = source;
  sc.text = std::string(text);
  const json doc = parse_json_strict(text, source);

  const DocSource src{source, origins};
  Node root(doc, "", &src);
  sc.name = root.string("name", std::string());
  root.string("description", std::string());
  // The walkable area (WKT), if any: it may stand in for the bounds.
  std::optional<io::WalkableArea> walkable;
  double walkable_charge = 1;
  if (root.has("walkable")) {
    std::string wkt;
    std::string key = "walkable";
    if (root.raw("walkable").is_object()) {
      Node w = root.child("walkable");
      wkt = w.string("wkt");
      walkable_charge = w.number("charge", 1.0);
      w.finish();
      key = "walkable/wkt";
    } else {
      wkt = root.string("walkable");
    }
    try {
      walkable = io::WalkableArea::parse(wkt);
    } catch (const Error& e) {
      root.fail(key, e.what());
    }
  }
  try {
    if (root.has("bounds")) {
      const auto b = root.numbers("bounds", 4);
      sc.world.set_bounds({b[0], b[1], b[2], b[3]});
      if (walkable && !walkable->within(sc.world.bounds()))
        root.fail("walkable", "the walkable area extends outside the bounds");
    } else if (walkable) {
      sc.world.set_bounds(walkable->envelope());
    } else {
      root.fail(
          "bounds",
          "missing ([xmin, ymin, xmax, ymax] is required unless a \"walkable\" area is given)");
    }
  } catch (const InvalidRow& e) {
    root.fail("bounds", e.what());
  }
  SimConfig& cfg = sc.config;
  reject_moved_keys(root, {{"gridlock_ticks", "gridlock_time, in seconds"}});
  cfg.dt = root.positive("dt", cfg.dt);
  cfg.seed = root.integer("seed", 1);
  if (root.has("ticks") && root.has("duration"))
    root.fail("ticks", "give one of 'ticks' and 'duration', not both");
  if (root.has("ticks")) {
    sc.ticks = root.integer("ticks", 0, 1'000'000'000);
  } else {
    const double duration = root.non_negative("duration", 60.0);
    if (duration / cfg.dt > 1e9) root.fail("duration", "is over 10^9 ticks at this dt");
    sc.ticks = cfg.ticks_for(duration, 0);
  }
  sc.stop_when_all_arrived = root.boolean("stop_when_all_arrived", false);
  cfg.backoff = root.boolean("backoff", true);
  cfg.walls = root.boolean("walls", true);
  const std::string arrival = root.choice("arrival", {"remove", "idle", "retarget"}, "remove");
  cfg.arrival = arrival == "idle"
                    ? ArrivalPolicy::idle
                    : (arrival == "retarget" ? ArrivalPolicy::retarget : ArrivalPolicy::remove);
  cfg.threads = static_cast<int>(root.integer("threads", 1, 256));
  if (cfg.threads < 1) root.fail("threads", "must be >= 1");
  cfg.gridlock_time = root.positive("gridlock_time", cfg.gridlock_time);
  cfg.waypoint_radius = root.non_negative("waypoint_radius", 0.0);
  cfg.nudge_after = root.non_negative("nudge_after", cfg.nudge_after);
  read_steering(root, cfg);
  if (root.has("stall")) {
    Node st = root.child("stall");
    StallParams& sp = cfg.stall;
    sp.after = st.positive("after", sp.after);
    sp.progress = st.positive("progress", sp.progress);
    sp.resolve = st.boolean("resolve", sp.resolve);
    sp.yield_time = st.positive("yield_time", sp.yield_time);
    sp.head_on_yield_time = st.positive("head_on_yield_time", sp.head_on_yield_time);
    sp.sidestep_time = st.positive("sidestep_time", sp.sidestep_time);
    sp.reverse_after = st.non_negative("reverse_after", sp.reverse_after);
    sp.reverse_period = st.positive("reverse_period", sp.reverse_period);
    st.finish();
  }
  if (root.has("navigation")) {
    Node n = root.child("navigation");
    NavigationParams& nav = cfg.navigation;
    nav.enabled = n.boolean("enabled", true);
    nav.latency = n.non_negative("latency", nav.latency);
    nav.budget = static_cast<uint32_t>(n.integer("budget", nav.budget, 1u << 30));
    if (nav.budget < 1) n.fail("budget", "must be >= 1");
    nav.replan_after = n.non_negative("replan_after", nav.replan_after);
    nav.congestion_cost = n.non_negative("congestion_cost", nav.congestion_cost);
    nav.queue_flow = n.non_negative("queue_flow", nav.queue_flow);
    nav.radius_step = n.positive("radius_step", nav.radius_step);
    nav.cell_size = n.non_negative("cell_size", nav.cell_size);
    nav.clearance = n.non_negative("clearance", nav.clearance);
    nav.corner_push = n.non_negative("corner_push", nav.corner_push);
    nav.tile_size = static_cast<uint32_t>(n.integer("tile_size", nav.tile_size, 4096));
    if (nav.tile_size < 16) n.fail("tile_size", "must be in 16..4096");
    nav.skip_visible = n.boolean("skip_visible", nav.skip_visible);
    nav.sight_interval = n.non_negative("sight_interval", nav.sight_interval);
    n.finish();
  }
  if (root.has("access")) {
    Node a = root.child("access");
    cfg.access.ftc = a.string("ftc", "auto");
    cfg.access.field = a.string("field", "auto");
    cfg.access.collisions = a.string("collisions", "auto");
    cfg.access.neighbours = a.string("neighbours", "auto");
    cfg.access.edges = a.string("edges", "auto");
    cfg.access.row_order = a.choice("row_order", {"auto", "curve", "none"}, "auto");
    a.finish();
  }
  if (root.has("output")) {
    Node o = root.child("output");
    sc.output.path = o.string("path", std::string());
    sc.output.format = o.choice("format", {"sqlite", "csv"}, "sqlite") == "csv"
                           ? OutputSpec::Format::csv
                           : OutputSpec::Format::sqlite;
    sc.output.every = static_cast<uint32_t>(o.integer("every", 1, 1u << 30));
    if (sc.output.every == 0) o.fail("every", "must be >= 1");
    o.finish();
  }

  Loader loader{sc, {}, {}, {}, nullptr, nullptr, 0, {}, {}, nullptr, {}};
  if (walkable) loader.read_walkable(root, *walkable, walkable_charge);
  loader.read_goals(root);
  loader.read_obstacles(root);
  loader.check_goals(root);
  double rmax = 1;
  loader.placed = std::make_unique<PlacementGrid>(2 * rmax);
  // Cell size for the placement grid: twice the largest radius any agent may have.
  if (root.has("groups") && root.raw("groups").is_array())
    for (const json& g : root.raw("groups"))
      if (g.is_object() && g.contains("radius")) {
        const json& r = g["radius"];
        if (r.is_number()) rmax = std::max(rmax, r.get<double>());
        if (r.is_array() && r.size() == 2 && r[1].is_number())
          rmax = std::max(rmax, r[1].get<double>());
      }
  if (std::isfinite(rmax)) loader.placed = std::make_unique<PlacementGrid>(2 * rmax);
  loader.read_agents(root);
  loader.read_groups(root);
  loader.read_sources(root);
  root.finish();
  if ((!loader.agents.empty() || !sc.world.sources().empty()) && sc.world.goals().empty())
    root.fail("goals", "agents need at least one goal");
  if (cfg.navigation.enabled)
    for (const auto& via : loader.routes)
      if (!via.empty())
        root.fail("navigation",
                  "cannot be combined with \"via\" waypoints: the path service plans every route");
  loader.warn_overlaps();

  try {
    cfg.validate();
  } catch (const InvalidRow& e) {
    root.fail(e.field(), e.what());
  }
  sc.world.set_walls(sc.config.walls);  // the loader checked every agent against them already
  // Room for the sources' agents too, up to as many again: a table reserved for exactly the
  // loaded agents moves every column at the first agent a source lets in (10^6 agents with a
  // source: 0.65 s in the first tick's apply stage instead of 0.29), where growing would have
  // doubled it anyway. Untouched room costs address space, not memory.
  uint64_t from_sources = 0;
  for (const Source& entry : sc.world.sources())
    from_sources =
        entry.count > UINT64_MAX - from_sources ? UINT64_MAX : from_sources + entry.count;
  const std::size_t loaded = loader.agents.size();
  const uint64_t room = loaded + std::min<uint64_t>(from_sources, loaded);
  sc.world.reserve(static_cast<std::size_t>(std::min<uint64_t>(room, AgentId::kNoIndex)));
  // Applied a few thousand at a time: a change waiting in the world's batch takes 128 bytes, and
  // one batch of every agent would be 128 MB written and read once at 10^6 agents.
  constexpr std::size_t kInsertsPerBatch = 4096;
  for (std::size_t i = 0; i < loader.agents.size(); ++i) {
    sc.world.insert(loader.agents[i]);
    if ((i + 1) % kInsertsPerBatch == 0) sc.world.apply_pending();
  }
  sc.world.apply_pending();
  AgentTable& t = sc.world.agents_for_tick();
  for (std::size_t i = 0; i < loader.routes.size(); ++i)
    if (!loader.routes[i].empty()) {  // the rows without one have their goal's target already
      t.route[i] = std::move(loader.routes[i]);
      sc.world.refresh_target(i);
    }
  return sc;
}

}  // namespace io

Scenario parse_scenario(std::string_view text, const std::string& source) {
  return io::parse_document(text, source, nullptr);
}

}  // namespace crowddb
