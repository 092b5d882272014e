// The public, stand-alone entry points of the steering queries: look the method up in the
// registry, run it once on a private executor.
#include "crowddb/query.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "crowddb/error.hpp"
#include "plan/access_path.hpp"
#include "util/plain_number.hpp"
#include "util/stopwatch.hpp"

namespace crowddb {

QueryStats& QueryStats::operator+=(const QueryStats& o) {
  rows += o.rows;
  pair_tests += o.pair_tests;
  nodes_visited += o.nodes_visited;
  queue_pushes += o.queue_pushes;
  queue_pops += o.queue_pops;
  build_seconds += o.build_seconds;
  query_seconds += o.query_seconds;
  return *this;
}

namespace {

CollisionQueryShape shape_of(const DiscView& d) {
  CollisionQueryShape s;
  s.rows = d.n;
  s.equal_radii = std::all_of(d.radius, d.radius + d.n, [&](double r) { return r == d.radius[0]; });
  return s;
}

[[noreturn]] void out_of_range(std::string_view query, const std::string& what, double v,
                               double limit) {
  std::ostringstream os;
  const std::string l = plain_number(limit);
  os << query << ": " << what << " = " << v << " is outside [-" << l << ", " << l
     << "] (larger values could overflow the exact pair arithmetic)";
  throw Error(Error::Kind::input, os.str());
}

// The input rules of first-to-collide and the collision set (query.hpp, kMaxQuerySpeed).
void check_inputs(std::string_view query, const DiscView& d, const StaticScene& scene) {
  const auto row = [&](std::size_t i, const char* field) {
    return "agent " + (d.id ? "id " + std::to_string(d.id[i]) : "row " + std::to_string(i)) + " " +
           field;
  };
  for (std::size_t i = 0; i < d.n; ++i) {
    if (!(std::abs(d.x[i]) <= kMaxCoordinate))
      out_of_range(query, row(i, "x"), d.x[i], kMaxCoordinate);
    if (!(std::abs(d.y[i]) <= kMaxCoordinate))
      out_of_range(query, row(i, "y"), d.y[i], kMaxCoordinate);
    if (!(std::abs(d.vx[i]) <= kMaxQuerySpeed))
      out_of_range(query, row(i, "vx"), d.vx[i], kMaxQuerySpeed);
    if (!(std::abs(d.vy[i]) <= kMaxQuerySpeed))
      out_of_range(query, row(i, "vy"), d.vy[i], kMaxQuerySpeed);
    if (!(d.radius[i] > 0 && d.radius[i] <= kMaxCoordinate))
      throw Error(Error::Kind::input, std::string(query) + ": " + row(i, "radius") +
                                          " must be > 0 and <= 1e9 (got " +
                                          std::to_string(d.radius[i]) + ")");
  }
  // Walls (rows >= wall_begin) lie up to three world widths out, by construction within range.
  const auto circles = scene.circles();
  for (std::size_t i = 0; i < circles.size(); ++i) {
    const std::string at = "obstacle circle " + std::to_string(i);
    if (!(std::abs(circles[i].x) <= kMaxCoordinate))
      out_of_range(query, at + " x", circles[i].x, kMaxCoordinate);
    if (!(std::abs(circles[i].y) <= kMaxCoordinate))
      out_of_range(query, at + " y", circles[i].y, kMaxCoordinate);
    if (!(std::abs(circles[i].radius) <= kMaxCoordinate))
      out_of_range(query, at + " radius", circles[i].radius, kMaxCoordinate);
  }
  const auto polygons = scene.polygons();
  for (std::size_t p = 0; p < scene.wall_begin(); ++p)
    for (const Vec2& v : polygons[p].vertices)
      if (!(std::abs(v.x) <= kMaxCoordinate && std::abs(v.y) <= kMaxCoordinate))
        out_of_range(query, "obstacle polygon " + std::to_string(p) + " vertex",
                     std::abs(v.x) > std::abs(v.y) || !std::isfinite(v.x) ? v.x : v.y,
                     kMaxCoordinate);
}

}  // namespace

std::vector<FtcHit> first_to_collide(const DiscView& discs, const StaticScene& scene,
                                     double horizon, std::string_view method, int threads,
                                     QueryStats* stats) {
  check_inputs("first-to-collide", discs, scene);
  if (!(horizon >= 0 && horizon <= kMaxQueryHorizon)) {
    std::ostringstream os;
    os << "first-to-collide: horizon must be >= 0 and <= 1e9 ticks (got " << horizon << ")";
    throw Error(Error::Kind::input, os.str());
  }
  const FtcMethod& m = method == "auto" ? choose_ftc_method(discs.n) : find_ftc_method(method);
  auto path = m.make();
  Executor ex(threads);
  QueryStats local;
  std::vector<FtcHit> out(discs.n);
  path->run(discs, scene, horizon, out, ex, local);
  if (stats) *stats += local;
  return out;
}

namespace {

// Rejects specs no method can evaluate (Error(usage) naming the field).
void check_spec(const PotentialSpec& s) {
  const auto bad = [](const std::string& field, const std::string& why) {
    throw Error(Error::Kind::usage, "potential spec: " + field + " " + why);
  };
  if (!std::isfinite(s.A)) bad("A", "must be finite");
  if (!std::isfinite(s.k)) bad("k", "must be finite");
  if (s.radial_frames < 1 || s.radial_frames > 16) bad("radial_frames", "must be in [1, 16]");
  if (s.kernel == Kernel::inv && !(s.inv_floor > 0 && std::isfinite(s.inv_floor)))
    bad("inv_floor", "must be finite and > 0");
  if (s.finite_difference && !(s.fd_step > 0 && std::isfinite(s.fd_step)))
    bad("fd_step", "must be finite and > 0");
}

}  // namespace

FieldColumns potential_field(const DiscView& discs, const StaticScene& scene,
                             const PotentialSpec& spec, std::string_view method, int threads,
                             QueryStats* stats) {
  check_spec(spec);
  const FieldMethod& m =
      method == "auto" ? choose_field_method(discs.n, spec) : find_field_method(method, spec);
  auto path = m.make();
  Executor ex(threads);
  QueryStats local;
  FieldColumns out;
  path->run(discs, scene, spec, out, ex, local);
  if (stats) *stats += local;
  return out;
}

FieldColumns field_at(std::span<const Vec2> points, const DiscView& sources,
                      const StaticScene& scene, const PotentialSpec& spec, std::string_view method,
                      int threads, QueryStats* stats) {
  check_spec(spec);
  for (std::size_t i = 0; i < points.size(); ++i)
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y))
      throw Error(Error::Kind::input, "field_at: point " + std::to_string(i) + " is not finite");
  const std::size_t rows = points.size() + sources.n;
  const FieldMethod& m =
      method == "auto" ? choose_field_method(rows, spec) : find_field_method(method, spec);
  auto path = m.make();
  Executor ex(threads);
  QueryStats local;
  FieldColumns out;
  path->probe(points, sources, scene, spec, out, ex, local);
  if (stats) *stats += local;
  return out;
}

std::vector<uint32_t> collision_set(const DiscView& discs, const StaticScene& scene,
                                    std::string_view method, int threads, QueryStats* stats) {
  check_inputs("collision set", discs, scene);
  const CollisionQueryShape shape = shape_of(discs);
  const CollisionMethod& m =
      method == "auto" ? choose_collision_method(shape) : find_collision_method(method, shape);
  auto path = m.make();
  Executor ex(threads);
  QueryStats local;
  CollisionPairs pairs;
  path->run(discs, scene, pairs, ex, local);
  if (stats) *stats += local;
  std::vector<uint32_t> rows;
  rows.reserve(2 * pairs.agents.size() + pairs.obstacles.size());
  for (auto [i, j] : pairs.agents) {
    rows.push_back(i);
    rows.push_back(j);
  }
  for (const auto& hit : pairs.obstacles) rows.push_back(hit.first);
  std::sort(rows.begin(), rows.end());
  rows.erase(std::unique(rows.begin(), rows.end()), rows.end());
  return rows;
}

NeighbourLists neighbours(const DiscView& discs, double range, uint32_t k,
                          std::span<const uint32_t> queries, std::string_view method, int threads,
                          QueryStats* stats) {
  if (!(range > 0) || !std::isfinite(range))
    throw Error(Error::Kind::usage, "neighbours: range must be finite and > 0");
  for (uint32_t q : queries)
    if (q >= discs.n)
      throw Error(Error::Kind::usage, "neighbours: query row " + std::to_string(q) +
                                          " does not exist (" + std::to_string(discs.n) + " rows)");
  const NeighbourMethod& m = neighbour_method(method, discs.n);
  auto path = m.make();
  Executor ex(threads);
  QueryStats local;
  NeighbourLists out;
  path->run(discs, queries, range, k, out, ex, local);
  if (stats) *stats += local;
  return out;
}

FeatureLists obstacle_features(const DiscView& points, std::span<const double> reach,
                               const StaticScene& scene, std::string_view method, int threads,
                               QueryStats* stats) {
  if (reach.size() != points.n)
    throw Error(Error::Kind::usage, "obstacle_features: one reach per point is needed");
  for (double r : reach)
    if (!(r >= 0) || !std::isfinite(r))
      throw Error(Error::Kind::usage, "obstacle_features: every reach must be finite and >= 0");
  const FeatureMethod& m = feature_method(method, scene.feature_count());
  auto path = m.make();
  Executor ex(threads);
  QueryStats local;
  FeatureLists out;
  path->run(points, reach, scene, out, ex, local);
  if (stats) *stats += local;
  return out;
}

std::vector<std::string> neighbour_methods() {
  std::vector<std::string> names;
  for (const auto& m : neighbour_registry()) names.push_back(m.info.name);
  return names;
}
std::vector<std::string> feature_methods() {
  std::vector<std::string> names;
  for (const auto& m : feature_registry()) names.push_back(m.info.name);
  return names;
}

std::vector<std::string> ftc_methods() {
  std::vector<std::string> names;
  for (const auto& m : ftc_registry()) names.push_back(m.info.name);
  return names;
}
std::vector<std::string> field_methods() {
  std::vector<std::string> names;
  for (const auto& m : field_registry()) names.push_back(m.info.name);
  return names;
}
std::vector<std::string> collision_methods() {
  std::vector<std::string> names;
  for (const auto& m : collision_registry()) names.push_back(m.info.name);
  return names;
}

}  // namespace crowddb
