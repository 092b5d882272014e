// The public, stand-alone entry points of the steering queries: look the method up in the
// registry, run it once on a private executor.
#include "crowddb/query.hpp"

#include <algorithm>

#include "plan/access_path.hpp"
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

}  // namespace

std::vector<FtcHit> first_to_collide(const DiscView& discs, const StaticScene& scene,
                                     double horizon, std::string_view method, int threads,
                                     QueryStats* stats) {
  const FtcMethod& m = method == "auto" ? choose_ftc_method(discs.n) : find_ftc_method(method);
  auto path = m.make();
  Executor ex(threads);
  QueryStats local;
  std::vector<FtcHit> out(discs.n);
  path->run(discs, scene, horizon, out, ex, local);
  if (stats) *stats += local;
  return out;
}

FieldColumns potential_field(const DiscView& discs, const StaticScene& scene,
                             const PotentialSpec& spec, std::string_view method, int threads,
                             QueryStats* stats) {
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

std::vector<uint32_t> collision_set(const DiscView& discs, const StaticScene& scene,
                                    std::string_view method, int threads, QueryStats* stats) {
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
