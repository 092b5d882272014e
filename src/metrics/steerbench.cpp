#include "metrics/steerbench.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <unordered_map>

#include "crowddb/error.hpp"
#include "util/byte_codec.hpp"
#include "util/executor.hpp"
#include "world/geometry.hpp"
#include "world/obstacle_lookup.hpp"

namespace crowddb::metrics {
namespace {

constexpr double kCollision = 0.001;  // [m] SteerSuite's COLLISION_EPSILON
// Obstacles beyond which the collision count looks only at those near each agent.
constexpr std::size_t kObstaclesForALookup = 16;

uint64_t cell_key(int64_t cx, int64_t cy) {
  return (static_cast<uint64_t>(cx) << 32) ^ static_cast<uint64_t>(cy & 0xffffffff);
}

}  // namespace

void SteerBench::open_score(uint64_t id) {
  if (where_.size() >= kClosed - 1)
    throw Error(Error::Kind::input, "steerbench: more than 2^31 - 2 agents measured in one run");
  known_.at(id) = static_cast<uint32_t>(where_.size());
  where_.push_back(kNoSlot);
}

uint32_t SteerBench::open_track(Track tr) {
  tr.live = true;
  uint32_t slot;
  if (!free_slots_.empty()) {
    slot = free_slots_.back();
    free_slots_.pop_back();
    tracks_[slot] = tr;
  } else {
    slot = static_cast<uint32_t>(tracks_.size());
    tracks_.push_back(tr);
  }
  where_[tr.order] = slot;
  return slot;
}

uint32_t SteerBench::open_agent(uint64_t id, double x, double y) {
  open_score(id);
  Track tr{x, y};
  tr.id = id;
  tr.seen = static_cast<uint32_t>(tick_);
  tr.order = static_cast<uint32_t>(where_.size() - 1);
  return open_track(tr);
}

AgentScore SteerBench::score_at(uint32_t where) const {
  if (where & kClosed) return closed_[where & ~kClosed];
  const Track& tr = tracks_[where];
  return {.id = tr.id,
          .collisions = tr.collisions,
          .time = tr.time,
          .path_length = tr.path_length,
          .energy = tr.energy,
          .acceleration = tr.acceleration,
          .arrived = false};
}

const std::vector<AgentScore>& SteerBench::scores() const {
  scores_.clear();
  scores_.reserve(where_.size());
  for_each_score([&](const AgentScore& a) { scores_.push_back(a); });
  return scores_;
}

void SteerBench::close_track(uint32_t slot) {
  Track& tr = tracks_[slot];
  AgentScore a = score_at(slot);
  a.arrived = true;
  where_[tr.order] = kClosed | static_cast<uint32_t>(closed_.size());
  closed_.push_back(a);
  tr.live = false;
  free_slots_.push_back(slot);
}

void SteerBench::start(const World& world) {
  tick_ = 0;
  const AgentTable& t = world.agents();
  // Exactly, and without the copies of a doubling vector.
  where_.reserve(where_.size() + t.size());
  tracks_.reserve(tracks_.size() + t.size());
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t.state[i] == AgentState::arrived) continue;
    open_agent(t.id[i], t.x[i], t.y[i]);
  }
}

void SteerBench::add_tick(Track& tr, double x, double y) const {
  tr.seen = static_cast<uint32_t>(tick_);
  const double dx = x - tr.x, dy = y - tr.y;
  const double vx = dx / dt_, vy = dy / dt_;
  tr.time += dt_;
  tr.path_length += std::sqrt(dx * dx + dy * dy);
  tr.energy += 0.5 * (vx * vx + vy * vy);
  if (tr.has_v) {
    const double ax = vx - tr.vx, ay = vy - tr.vy;
    tr.acceleration += std::sqrt(ax * ax + ay * ay) / dt_;
  }
  tr.x = x;
  tr.y = y;
  tr.vx = vx;
  tr.vy = vy;
  tr.has_v = true;
}

void SteerBench::tick(const World& world, const TickMetrics& m, Executor* ex) {
  ++tick_;
  const AgentTable& t = world.agents();
  const std::size_t n = t.size();
  row_slot_.resize(n, kNoSlot);
  // 1. On every thread, each row that did not arrive adds the tick to its agent's live track:
  // the one its slot holds, or, when the slot no longer does (the table reordered its rows), the
  // one its id finds (a lookup that only reads, and a row writes only its own slot). A live
  // track is one agent's, so one row's. New agents and arrivals are marked for 2.
  pending_.resize(n);
  const std::size_t chunks = (n + kTickGrain - 1) / kTickGrain;
  std::vector<std::size_t> chunk_seen(chunks, 0), chunk_moved(chunks, 0);
  const auto own_tracks = [&](std::size_t b, std::size_t e) {
    std::size_t seen = 0, moved = 0;
    for (std::size_t i = b; i < e; ++i) {
      uint32_t slot = row_slot_[i];
      pending_[i] = 0;
      if (!holds(slot, t.id[i])) {
        const uint32_t order = known_.find(t.id[i]);
        if (order == kUnknown) {  // new in the table: opened in 2
          pending_[i] = 1;
          continue;
        }
        ++moved;
        slot = where_[order] & kClosed ? kNoSlot : where_[order];
        row_slot_[i] = slot;
      }
      if (slot == kNoSlot) continue;  // measured before and closed on arrival: stays closed
      if (t.state[i] == AgentState::arrived) {
        pending_[i] = 1;  // arrived in this tick: closed in 2, the tick not counted
        continue;
      }
      add_tick(tracks_[slot], t.x[i], t.y[i]);
      ++seen;
    }
    chunk_seen[b / kTickGrain] = seen;
    chunk_moved[b / kTickGrain] = moved;
  };
  if (ex && ex->threads() > 1)
    ex->for_each_chunk(n, kTickGrain, own_tracks);
  else
    for (std::size_t b = 0; b < n; b += kTickGrain) own_tracks(b, std::min(n, b + kTickGrain));
  std::size_t seen = 0;   // live tracks seen this tick
  std::size_t moved = 0;  // rows whose track had to be looked up
  for (std::size_t c = 0; c < chunks; ++c) {
    seen += chunk_seen[c];
    moved += chunk_moved[c];
  }
  // 2. The others in row order, on one thread: arrivals close their tracks (1 found them),
  // new agents open theirs.
  for (std::size_t i = 0; i < n; ++i) {
    if (!pending_[i]) continue;
    const uint32_t slot = row_slot_[i];
    if (holds(slot, t.id[i])) {  // arrived in this tick: the tick is not counted
      close_track(slot);
      row_slot_[i] = kNoSlot;
      continue;
    }
    // New in the table (a source, an insert): measured from here on.
    ++moved;
    if (t.state[i] == AgentState::arrived) {
      row_slot_[i] = kNoSlot;
    } else {
      row_slot_[i] = open_agent(t.id[i], t.x[i], t.y[i]);
      ++seen;
    }
  }
  // Agents no longer in the table left it on arrival (or were deleted): their tracks were not
  // seen. (Every live track is seen at most once, so when the count says all were, no slot
  // needs a look.)
  if (seen != tracks_.size() - free_slots_.size())
    for (uint32_t slot = 0; slot < tracks_.size(); ++slot)
      if (tracks_[slot].live && tracks_[slot].seen != static_cast<uint32_t>(tick_))
        close_track(slot);
  if (moved > n / 8) lay_out_in_row_order(t);
  if (m.overlapping_pairs > 0 || m.obstacle_overlaps > 0 || !open_pairs_.empty() ||
      !open_obstacles_.empty())
    collisions(world);
}

void SteerBench::lay_out_in_row_order(const AgentTable& t) {
  // Each live track's new slot: its row's place among the rows holding live tracks; then the
  // free slots. (After the tick's loop every live track is held by exactly one row.)
  constexpr uint32_t kUnset = UINT32_MAX;
  std::vector<uint32_t> dest(tracks_.size(), kUnset);
  uint32_t next = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    uint32_t& slot = row_slot_[i];
    if (slot == kNoSlot) continue;
    const Track& tr = tracks_[slot];
    if (!tr.live || tr.id != t.id[i] || dest[slot] != kUnset) {  // closed this tick (arrived)
      slot = kNoSlot;
      continue;
    }
    dest[slot] = next;
    slot = next++;
  }
  const uint32_t live = next;
  for (uint32_t& d : dest)
    if (d == kUnset) d = next++;
  // Cycle by cycle: each track swapped straight into its place.
  for (uint32_t s = 0; s < tracks_.size(); ++s)
    while (dest[s] != s) {
      const uint32_t d = dest[s];
      std::swap(tracks_[s], tracks_[d]);
      std::swap(dest[s], dest[d]);
    }
  tracks_.resize(live);
  for (uint32_t s = 0; s < live; ++s) where_[tracks_[s].order] = s;
  free_slots_.clear();
}

void SteerBench::collisions(const World& world) {
  const AgentTable& t = world.agents();
  std::vector<std::size_t> rows;
  double rmax = 0;
  for (std::size_t i = 0; i < t.size(); ++i)
    if (t.state[i] != AgentState::arrived) {
      rows.push_back(i);
      rmax = std::max(rmax, t.radius[i]);
    }
  std::set<std::pair<uint64_t, uint64_t>> pairs;
  std::set<std::pair<uint64_t, int64_t>> obstacles;
  // Among more than a few obstacles, each agent is tested against those near it only.
  const std::size_t obstacle_count = world.circles().size() + world.polygons().size();
  const bool by_lookup = obstacle_count > kObstaclesForALookup;
  // The world's (built once, shared with its walkable checks and the scenario reader).
  const std::shared_ptr<const ObstacleLookup> lookup =
      by_lookup ? world.obstacle_lookup() : nullptr;
  std::vector<uint32_t> near(by_lookup ? 0 : obstacle_count);
  std::iota(near.begin(), near.end(), 0u);
  if (!rows.empty()) {
    const double cell = std::max(2 * rmax, 1e-6);
    std::unordered_map<uint64_t, std::vector<std::size_t>> grid;
    for (std::size_t i : rows)
      grid[cell_key(static_cast<int64_t>(std::floor(t.x[i] / cell)),
                    static_cast<int64_t>(std::floor(t.y[i] / cell)))]
          .push_back(i);
    for (std::size_t i : rows) {
      const auto cx = static_cast<int64_t>(std::floor(t.x[i] / cell));
      const auto cy = static_cast<int64_t>(std::floor(t.y[i] / cell));
      for (int64_t gx = cx - 1; gx <= cx + 1; ++gx)
        for (int64_t gy = cy - 1; gy <= cy + 1; ++gy) {
          const auto it = grid.find(cell_key(gx, gy));
          if (it == grid.end()) continue;
          for (std::size_t j : it->second) {
            if (t.id[j] <= t.id[i]) continue;
            const double d = std::hypot(t.x[j] - t.x[i], t.y[j] - t.y[i]);
            if (t.radius[i] + t.radius[j] - d > kCollision) pairs.insert({t.id[i], t.id[j]});
          }
        }
      const double x = t.x[i], y = t.y[i], r = t.radius[i];
      // A penetration over 1 mm puts the centre that far inside the obstacle's box grown by r:
      // the lookup's candidates hold every such obstacle (tested as before, one by one, they cost
      // agents x obstacles a tick while any overlap lasts).
      const auto circles = world.circles();
      const auto polys = world.polygons();
      if (by_lookup) lookup->candidates(x, y, r, near);
      for (const uint32_t k : near) {
        if (k < circles.size()) {
          if (r + circles[k].radius - std::hypot(circles[k].x - x, circles[k].y - y) > kCollision)
            obstacles.insert({t.id[i], static_cast<int64_t>(k)});
          continue;
        }
        // Through the lookup's edge grid where there is one: the distance is exact up to r, and
        // beyond it the penetration is negative either way.
        const std::size_t p = k - circles.size();
        const auto& v = polys[p].vertices;
        const double pen =
            by_lookup ? (lookup->polygon_holds(p, v, x, y)
                             ? r
                             : r - std::sqrt(lookup->polygon_dist2(p, v, x, y, std::abs(r))))
                      : (point_in_polygon(v, x, y) ? r : r - std::sqrt(dist2_to_boundary(v, x, y)));
        if (pen > kCollision) obstacles.insert({t.id[i], static_cast<int64_t>(k)});
      }
      if (walls_) {
        const Bounds& b = world.bounds();
        const double gaps[4] = {x - b.xmin, b.xmax - x, y - b.ymin, b.ymax - y};
        for (int k = 0; k < 4; ++k)
          if (r - gaps[k] > kCollision) obstacles.insert({t.id[i], -1 - k});
      }
    }
  }
  auto count = [&](uint64_t id) {
    const uint32_t order = known_.find(id);
    if (order == kUnknown || where_[order] & kClosed) return;
    uint32_t& c = tracks_[where_[order]].collisions;
    c += c < UINT32_MAX;  // (an episode takes two ticks at least: 2^32 of them are out of reach)
  };
  for (const auto& p : pairs)
    if (!open_pairs_.count(p)) {
      count(p.first);
      count(p.second);
    }
  for (const auto& o : obstacles)
    if (!open_obstacles_.count(o)) count(o.first);
  open_pairs_ = std::move(pairs);
  open_obstacles_ = std::move(obstacles);
}

SteerBenchTotals SteerBench::totals() const {
  SteerBenchTotals s;
  s.agents = where_.size();
  if (where_.empty()) return s;
  double c = 0, tm = 0, e = 0, a = 0, p = 0;
  for_each_score([&](const AgentScore& x) {
    s.collisions += x.collisions;
    c += static_cast<double>(x.collisions);
    tm += x.time;
    e += x.energy;
    a += x.acceleration;
    p += x.path_length;
  });
  const double n = static_cast<double>(where_.size());
  s.avg_collisions = c / n;
  s.avg_time = tm / n;
  s.avg_energy = e / n;
  s.avg_acceleration = a / n;
  s.avg_path = p / n;
  s.composite01 = 50 * s.avg_collisions + s.avg_time + s.avg_energy;
  s.composite02 = s.composite01 + s.avg_acceleration;
  return s;
}

void SteerBench::save(ByteWriter& out) const {
  out.u64(tick_);
  out.u64(where_.size());
  for_each_score([&](const AgentScore& a) {
    out.u64(a.id);
    out.u64(a.collisions);
    for (double v : {a.time, a.path_length, a.energy, a.acceleration}) out.f64(v);
    out.u8(a.arrived);
  });
  // In id order, so equal states save equal bytes (the layout of the slots does not show).
  std::vector<std::pair<uint64_t, uint32_t>> live;  // id, slot
  for (uint32_t slot = 0; slot < tracks_.size(); ++slot)
    if (tracks_[slot].live) live.push_back({tracks_[slot].id, slot});
  std::sort(live.begin(), live.end());
  out.u64(live.size());
  for (const auto& [id, slot] : live) {
    const Track& tr = tracks_[slot];
    out.u64(id);
    out.u64(tr.order);
    for (double v : {tr.x, tr.y, tr.vx, tr.vy}) out.f64(v);
    out.u8(tr.has_v);
    // The tick it was seen, whole: the latest tick up to now with those low 32 bits (a live
    // track was seen in the last tick).
    out.u64(tick_ - static_cast<uint32_t>(static_cast<uint32_t>(tick_) - tr.seen));
  }
  std::vector<uint64_t> known;
  known.reserve(where_.size());
  for_each_score([&](const AgentScore& a) { known.push_back(a.id); });
  std::sort(known.begin(), known.end());
  out.vec(known);
  out.u64(open_pairs_.size());
  for (const auto& [a, b] : open_pairs_) {
    out.u64(a);
    out.u64(b);
  }
  out.u64(open_obstacles_.size());
  for (const auto& [a, o] : open_obstacles_) {
    out.u64(a);
    out.u64(static_cast<uint64_t>(o));
  }
}

void SteerBench::restore(ByteReader& in) {
  tick_ = in.u64();
  const uint64_t count = in.count(49);
  if (count >= kClosed - 1) in.fail("steerbench: too many scores");
  // Every score as saved (in order of appearance); the live ones become tracks below, the
  // others closed scores.
  std::vector<AgentScore> all(count);
  known_.clear();
  for (std::size_t k = 0; k < all.size(); ++k) {
    AgentScore& a = all[k];
    a.id = in.u64();
    a.collisions = in.u64();
    for (double* v : {&a.time, &a.path_length, &a.energy, &a.acceleration}) *v = in.f64();
    a.arrived = in.u8() != 0;
    if (known_.find(a.id) != kUnknown) in.fail("steerbench: an agent scored twice");
    known_.at(a.id) = static_cast<uint32_t>(k);
  }
  where_.assign(count, kNoSlot);
  closed_.clear();
  scores_.clear();
  tracks_.clear();
  free_slots_.clear();
  row_slot_.clear();
  for (uint64_t k = 0, n = in.count(57); k < n; ++k) {
    const uint64_t id = in.u64();
    Track tr{};
    tr.id = id;
    const uint64_t order = in.u64();
    if (order >= all.size() || all[order].id != id)
      in.fail("steerbench: a track without its score");
    tr.order = static_cast<uint32_t>(order);
    for (double* v : {&tr.x, &tr.y, &tr.vx, &tr.vy}) *v = in.f64();
    tr.has_v = in.u8() != 0;
    tr.seen = static_cast<uint32_t>(in.u64());
    const AgentScore& s = all[order];
    if (s.arrived) in.fail("steerbench: a track of an agent that arrived");
    if (s.collisions > UINT32_MAX) in.fail("steerbench: more collisions than a track counts");
    tr.collisions = static_cast<uint32_t>(s.collisions);
    tr.time = s.time;
    tr.path_length = s.path_length;
    tr.energy = s.energy;
    tr.acceleration = s.acceleration;
    if (where_[order] != kNoSlot) in.fail("steerbench: a track twice");
    open_track(tr);
  }
  for (std::size_t k = 0; k < all.size(); ++k) {
    if (where_[k] != kNoSlot) continue;
    where_[k] = kClosed | static_cast<uint32_t>(closed_.size());
    closed_.push_back(all[k]);
  }
  // The ids measured so far: those of the scores (the index above), written for the record.
  std::vector<uint64_t> known;
  in.vec(known);
  std::vector<uint64_t> ids;
  ids.reserve(all.size());
  for (const AgentScore& a : all) ids.push_back(a.id);
  std::sort(ids.begin(), ids.end());
  if (known != ids) in.fail("steerbench: the ids measured are not those scored");
  open_pairs_.clear();
  for (uint64_t k = 0, n = in.count(16); k < n; ++k) {
    const uint64_t a = in.u64();
    open_pairs_.insert({a, in.u64()});
  }
  open_obstacles_.clear();
  for (uint64_t k = 0, n = in.count(16); k < n; ++k) {
    const uint64_t a = in.u64();
    open_obstacles_.insert({a, static_cast<int64_t>(in.u64())});
  }
}

}  // namespace crowddb::metrics
