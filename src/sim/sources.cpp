#include "sim/sources.hpp"

#include <algorithm>
#include <cmath>
#include <optional>

#include "query/naive_paths.hpp"
#include "query/scene_polygons.hpp"
#include "util/byte_codec.hpp"
#include "world/geometry.hpp"
#include "world/placement_grid.hpp"

namespace crowddb::sim {

uint64_t source_total(const Source& s) {
  if (!std::isfinite(s.end)) return s.count;
  // Agents k with start + k / rate < end.
  const double span = (s.end - s.start) * s.rate;
  const double k = std::ceil(span);
  return std::min<uint64_t>(s.count, k >= 1.8e19 ? s.count : static_cast<uint64_t>(k));
}

SourceEmitter::SourceEmitter(const World& world, uint64_t seed, FreeSpots free_spots)
    : naive_(free_spots == FreeSpots::naive) {
  for (std::size_t i = 0; i < world.sources().size(); ++i)
    state_.push_back({0, Rng::stream(seed ^ 0x50a7ce5ull, i)});
}

void SourceEmitter::save(ByteWriter& out) const {
  out.u64(state_.size());
  for (const State& st : state_) {
    out.u64(st.entered);
    for (uint64_t w : st.rng.state()) out.u64(w);
  }
}

void SourceEmitter::restore(ByteReader& in, const World& world) {
  if (in.u64() != state_.size()) in.fail("the number of sources differs from the scenario's");
  for (std::size_t i = 0; i < state_.size(); ++i) {
    const uint64_t entered = in.u64();
    if (entered > source_total(world.sources()[i]))
      in.fail("source " + std::to_string(i) + " let in more agents than it has");
    std::array<uint64_t, 4> rng;
    for (uint64_t& w : rng) w = in.u64();
    state_[i].entered = entered;
    state_[i].rng.set_state(rng);
  }
}

bool SourceEmitter::touches_an_obstacle(const StaticScene& scene, const AgentSpec& a) {
  const std::size_t circles = scene.circles().size(), count = circles + scene.polygons().size();
  const auto hits = [&](std::size_t k) {
    if (k < circles) return disc_hits_circle(scene.circles()[k], a.x, a.y, a.radius);
    return naive_ ? disc_hits_polygon(scene.polygons()[k - circles],
                                      scene.polygon_boxes()[k - circles], a.x, a.y, a.radius)
                  : scene_disc_hits_polygon(scene, k - circles, a.x, a.y, a.radius);
  };
  if (naive_ || count <= kObstaclesForALookup) {
    for (std::size_t k = 0; k < count; ++k)
      if (hits(k)) return true;
    return false;
  }
  // Among many obstacles, those whose box holds the disc (grown by a micrometre against the
  // rounding of the box's and the disc's bounds): the same answer as the loop over all.
  if (!lookup_ || lookup_obstacles_ != count) {
    // Candidates only: the scene's own edge grids answer the tests (query/scene_polygons.hpp).
    lookup_.emplace(scene.circles(), scene.polygons(), ObstacleLookup::EdgeGrids::skip);
    lookup_obstacles_ = count;
  }
  lookup_->candidates(a.x, a.y, a.radius + 1e-6, near_obstacles_);
  for (const uint32_t k : near_obstacles_)
    if (hits(k)) return true;
  return false;
}

std::size_t SourceEmitter::waiting(const World& world) const {
  std::size_t n = 0;
  for (std::size_t i = 0; i < state_.size(); ++i)
    n += source_total(world.sources()[i]) - state_[i].entered;
  return n;
}

std::size_t SourceEmitter::emit(World& world, const SimConfig& cfg, const StaticScene& scene,
                                uint64_t tick) {
  const double now = static_cast<double>(tick - 1) * cfg.dt;
  const AgentTable& t = world.agents();
  std::size_t made = 0;
  // Discs entering this tick, for the free-spot test beside the table's rows.
  std::vector<double> nx, ny, nr;
  double table_rmax = -1;  // (computed once, when a source has someone due)
  for (std::size_t si = 0; si < state_.size(); ++si) {
    const Source& src = world.sources()[si];
    State& st = state_[si];
    const uint64_t total = source_total(src);
    if (st.entered >= total || now < src.start) continue;
    // Due so far: agents k with start + k / rate <= now.
    const double k = std::floor((now - src.start) * src.rate * (1 + 1e-12)) + 1;
    const uint64_t due = std::min<uint64_t>(total, k >= 1.8e19 ? total : static_cast<uint64_t>(k));
    if (st.entered >= due) continue;
    const auto [x0, y0, x1, y1] = ring_box(src.area);
    const double rmax = std::max(src.agent.radius, src.radius_max);
    if (table_rmax < 0) {
      table_rmax = 0;
      for (double r : t.radius) table_rmax = std::max(table_rmax, r);
    }
    // The discs a new agent may touch: the rows near the area and those entered this tick,
    // tested one by one until that has cost kScansBeforeGrid passes over them, then through a
    // placement grid built over them. (Always one by one, a source over a crowd was quadratic:
    // 3.5·10^6 agents into a square holding 2·10^6 had not entered after ten minutes; always
    // through a grid, one agent a tick into that square cost 1.2 s a tick to build it.) The grid's
    // test is the loop's, so the same spots are taken; FreeSpots::naive (the tests' oracle)
    // never builds it.
    const double grow = rmax + table_rmax;
    std::vector<uint32_t> near;
    for (std::size_t i = 0; i < t.size(); ++i)
      if (t.x[i] >= x0 - grow && t.x[i] <= x1 + grow && t.y[i] >= y0 - grow && t.y[i] <= y1 + grow)
        near.push_back(static_cast<uint32_t>(i));
    std::optional<PlacementGrid> grid;
    uint64_t tested = 0;  // discs tested one by one
    const auto touches_a_disc = [&](const AgentSpec& a) {
      const std::size_t discs = near.size() + nx.size();
      if (!grid && !naive_ && tested > kScansBeforeGrid * discs) {
        grid.emplace(2 * std::max(rmax, table_rmax));
        ++grids_built_;
        grid->reserve(discs);
        for (uint32_t j : near) grid->add(t.x[j], t.y[j], t.radius[j]);
        for (std::size_t j = 0; j < nx.size(); ++j) grid->add(nx[j], ny[j], nr[j]);
      }
      if (grid) return grid->any_overlap(a.x, a.y, a.radius, 0);
      tested += discs;
      for (uint32_t j : near)
        if (discs_overlap(t.x[j] - a.x, t.y[j] - a.y, t.radius[j] + a.radius)) return true;
      for (std::size_t j = 0; j < nx.size(); ++j)
        if (discs_overlap(nx[j] - a.x, ny[j] - a.y, nr[j] + a.radius)) return true;
      return false;
    };
    while (st.entered < due) {
      AgentSpec a = src.agent;
      if (src.radius_max > 0) a.radius = st.rng.uniform(src.agent.radius, src.radius_max);
      if (src.pref_speed_max > 0)
        a.pref_speed = st.rng.uniform(src.agent.pref_speed, src.pref_speed_max);
      a.goal = src.goals[st.entered % src.goals.size()];
      bool placed = false;
      for (int tries = 0; tries < kTries && !placed; ++tries) {
        a.x = st.rng.uniform(x0, x1);
        a.y = st.rng.uniform(y0, y1);
        if (!point_in_polygon(src.area, a.x, a.y)) continue;
        placed = !touches_a_disc(a) && !touches_an_obstacle(scene, a);
      }
      if (!placed) break;  // the area is full: try again next tick
      world.insert(a);
      if (grid) grid->add(a.x, a.y, a.radius);
      nx.push_back(a.x);
      ny.push_back(a.y);
      nr.push_back(a.radius);
      ++st.entered;
      ++made;
    }
  }
  return made;
}

}  // namespace crowddb::sim
