// The backoff invariant, checked by brute force after every tick (DESIGN.md §3.2): a pair of
// agents (or an agent and an obstacle) that overlaps at the end of a tick overlapped at its
// start, and no deeper. Starting from an overlap-free world, no tick ends with any overlap.
#pragma once

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "query/naive_paths.hpp"
#include "world/geometry.hpp"

namespace crowddb::test {

struct Snapshot {
  std::map<uint64_t, std::size_t> row;  // id -> index into x, y, r
  std::vector<double> x, y, r;
  static Snapshot of(const AgentTable& t) {
    Snapshot s;
    for (std::size_t i = 0; i < t.size(); ++i) {
      s.row[t.id[i]] = i;
      s.x.push_back(t.x[i]);
      s.y.push_back(t.y[i]);
      s.r.push_back(t.radius[i]);
    }
    return s;
  }
};

inline double polygon_depth(std::span<const Vec2> ring, double x, double y, double r) {
  const double d = std::sqrt(dist2_to_boundary(ring, x, y));
  return point_in_polygon(ring, x, y) ? r + d : r - d;
}

struct TickCheck {
  std::size_t pairs = 0, obstacle_hits = 0;      // overlaps at the end, by brute force
  std::size_t bad_pairs = 0, bad_obstacles = 0;  // new or deeper than at the start
};

// Brute-force check of one tick, from the state before it to the state after it.
inline TickCheck check_tick(const Snapshot& before, const AgentTable& t, const StaticScene& scene) {
  TickCheck c;
  const std::size_t n = t.size();
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 1; j < n; ++j) {
      const double dx = t.x[j] - t.x[i], dy = t.y[j] - t.y[i];
      if (!discs_overlap(dx, dy, t.radius[i] + t.radius[j])) continue;
      ++c.pairs;
      const auto a = before.row.find(t.id[i]), b = before.row.find(t.id[j]);
      if (a == before.row.end() || b == before.row.end()) continue;  // inserted this tick
      const double sx = before.x[b->second] - before.x[a->second],
                   sy = before.y[b->second] - before.y[a->second];
      const bool was = discs_overlap(sx, sy, t.radius[i] + t.radius[j]);
      if (!was || dx * dx + dy * dy < sx * sx + sy * sy) ++c.bad_pairs;
    }
  const DiscView d = DiscView::of(t);
  std::vector<std::pair<uint32_t, Collider>> hits;
  disc_obstacle_overlaps(d, scene, 0, n, hits);
  c.obstacle_hits = hits.size();
  for (const auto& [i, with] : hits) {
    const auto a = before.row.find(t.id[i]);
    if (a == before.row.end()) continue;
    const double x0 = before.x[a->second], y0 = before.y[a->second], r = t.radius[i];
    bool ok;
    if (with.kind == Collider::Kind::circle) {
      const CircleObstacle& o = scene.circles()[with.row];
      const double sx = o.x - x0, sy = o.y - y0, nx = o.x - t.x[i], ny = o.y - t.y[i];
      ok = discs_overlap(sx, sy, r + o.radius) && nx * nx + ny * ny >= sx * sx + sy * sy;
    } else {
      const auto& ring = scene.polygons()[with.row].vertices;
      const double was = polygon_depth(ring, x0, y0, r);
      ok = was > 0 && polygon_depth(ring, t.x[i], t.y[i], r) <= was;
    }
    if (!ok) ++c.bad_obstacles;
  }
  return c;
}

inline StaticScene scene_of(const World& w, const SimConfig& cfg) {
  return StaticScene({w.circles().begin(), w.circles().end()},
                     {w.polygons().begin(), w.polygons().end()}, 1e9, ObstacleCharges::centres,
                     cfg.walls ? &w.bounds() : nullptr);
}

struct RunResult {
  std::vector<uint64_t> hashes;  // per tick
  std::size_t ticks = 0, bad = 0, overlaps_at_end = 0, frozen_total = 0, iterations_max = 0;
  std::size_t metric_mismatch = 0;  // ticks whose overlap metrics differ from brute force
  std::size_t arrived = 0;
};

// Runs `ticks` ticks, checking every one by brute force when `check` (else only the hashes).
inline RunResult run_checked(Simulation& sim, uint64_t ticks, bool check = true) {
  RunResult r;
  const StaticScene scene = scene_of(sim.world(), sim.config());
  for (uint64_t k = 0; k < ticks; ++k) {
    const Snapshot before = Snapshot::of(sim.world().agents());
    const TickMetrics& m = sim.step();
    r.hashes.push_back(m.state_hash);
    r.frozen_total += m.frozen;
    r.iterations_max = std::max(r.iterations_max, m.freeze_iterations);
    ++r.ticks;
    if (!check) continue;
    const TickCheck c = check_tick(before, sim.world().agents(), scene);
    r.bad += c.bad_pairs + c.bad_obstacles;
    r.overlaps_at_end += c.pairs + c.obstacle_hits;
    r.metric_mismatch +=
        (c.pairs != m.overlapping_pairs) + (c.obstacle_hits != m.obstacle_overlaps);
  }
  r.arrived = sim.arrived_total();
  return r;
}

inline bool initially_overlap_free(const World& w, const SimConfig& cfg) {
  Snapshot s = Snapshot::of(w.agents());
  const TickCheck c = check_tick(s, w.agents(), scene_of(w, cfg));
  return c.pairs == 0 && c.obstacle_hits == 0;
}

// A shipped scenario, edited: `edit` changes the parsed JSON before the world is built.
template <class Edit>
Scenario load_edited(const std::string& name, Edit&& edit) {
  const std::string path = std::string(CROWDDB_SOURCE_DIR) + "/scenarios/" + name + ".json";
  std::ifstream f(path);
  std::stringstream ss;
  ss << f.rdbuf();
  nlohmann::json j = nlohmann::json::parse(ss.str());
  edit(j);
  j.erase("output");
  return parse_scenario(j.dump(), path);
}

}  // namespace crowddb::test
