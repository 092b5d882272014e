// The backoff stage: classification of overlaps, the incremental freeze loop, and the plain loop
// it is tested against. See stages.hpp for the contract.
#include <algorithm>
#include <atomic>
#include <cmath>

#include "index/collisions_grid.hpp"
#include "index/obstacle_index.hpp"
#include "query/naive_paths.hpp"
#include "query/scene_polygons.hpp"
#include "sim/stages.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb::sim {
namespace {

// Penetration depth of a disc into polygon p (> 0: overlapping).
double polygon_depth(const StaticScene& scene, std::size_t p, double x, double y, double r) {
  const double d = std::sqrt(scene_polygon_dist2(scene, p, x, y, std::abs(r)));
  return scene_polygon_holds(scene, p, x, y) ? r + d : r - d;
}

DiscView next_view(const AgentTable& t, const NextState& next) {
  return {t.size(),       next.x.data(),   next.y.data(),   next.vx.data(),
          next.vy.data(), t.radius.data(), t.charge.data(), t.id.data()};
}

void freeze(const AgentTable& t, NextState& next, uint32_t i) {
  // Back to the start-of-tick position with zero velocity. The frozen set only grows and an
  // all-frozen world is the previous (valid) state, so the loop ends.
  next.frozen[i] = 1;
  next.x[i] = t.x[i];
  next.y[i] = t.y[i];
  next.vx[i] = 0;
  next.vy[i] = 0;
}

// Overlaps of single discs against the current (next-state) positions of all agents, for the
// probes of the freeze loop. Agents frozen after the grid was built sit elsewhere now: their
// grid entries are skipped and they are checked one by one until there are enough of them to
// rebuild. Small probe batches on small tables skip the grid altogether.
//
// The grid is the one the tick's collision query built over the same discs, when it lends one
// (CollisionPath::disc_grid): the rows frozen since count as moved. A grid of its own is built
// only without it (the model's neighbour lists answered the query, or its method keeps no grid),
// or once enough rows have moved. The moved rows get a small grid of their own once there are
// more than a batch of them (rebuilt each round, over their columns): every probe scanned them
// all, and a jam freezes hundreds a tick (the thesis model at airport-20k: ~740 over 4 rounds,
// ~380,000 tests a tick).
class OverlapProbe {
 public:
  // A lent grid is used only when it indexes as many rows as the view (else: built on demand).
  OverlapProbe(const DiscView& view, const index::DiscGrid* lent)
      : view_(view),
        grid_(lent != nullptr && lent->usable() && lent->rows() == view.n ? lent : nullptr),
        built_(grid_ != nullptr),
        stale_(view.n, 0) {}

  void prepare(std::size_t probes) {
    if (built_ || probes * view_.n <= kBruteWork) return;
    build();
  }
  void moved(std::span<const uint32_t> rows) {
    if (!built_) return;
    for (uint32_t r : rows)
      if (!stale_[r]) {
        stale_[r] = 1;
        moved_.push_back(r);
        moved_x_.push_back(view_.x[r]);  // where it is now, and stays: frozen once, for good
        moved_y_.push_back(view_.y[r]);
        moved_r_.push_back(view_.radius[r]);
      }
    if (moved_.size() > std::max<std::size_t>(64, view_.n / 8)) {
      build();
      for (uint32_t r : moved_) stale_[r] = 0;
      moved_.clear();
      moved_x_.clear();
      moved_y_.clear();
      moved_r_.clear();
    }
    moved_in_grid_ = false;
    if (moved_.size() > kMovedBatch) {
      DiscView mv;
      mv.n = moved_.size();
      mv.x = moved_x_.data();
      mv.y = moved_y_.data();
      mv.radius = moved_r_.data();
      moved_grid_.build(mv);
      moved_in_grid_ = moved_grid_.usable();
    }
  }
  bool moved_in_grid() const { return moved_in_grid_; }
  template <class F>
  void for_each_overlap(uint32_t a, F&& fn) const {
    const double x = view_.x[a], y = view_.y[a], r = view_.radius[a];
    auto test = [&](uint32_t b) {
      if (b != a && discs_overlap(view_.x[b] - x, view_.y[b] - y, r + view_.radius[b])) fn(b);
    };
    if (!built_) {
      for (std::size_t b = 0; b < view_.n; ++b) test(static_cast<uint32_t>(b));
      return;
    }
    grid_->for_each_overlap(x, y, r, [&](uint32_t b) {
      if (!stale_[b] && b != a) fn(b);
    });
    // The moved rows: through their grid, or (a batch or fewer) from their own columns without
    // branches.
    if (moved_in_grid_) {
      moved_grid_.for_each_overlap(x, y, r, [&](uint32_t u) {
        if (moved_[u] != a) fn(moved_[u]);
      });
      return;
    }
    const std::size_t m = moved_.size();
    const double *mx = moved_x_.data(), *my = moved_y_.data(), *mr = moved_r_.data();
    for (std::size_t u0 = 0; u0 < m; u0 += kMovedBatch) {
      const std::size_t u1 = std::min(m, u0 + kMovedBatch);
      uint32_t hit[kMovedBatch];
      uint32_t h = 0;
      for (std::size_t u = u0; u < u1; ++u) {
        hit[h] = static_cast<uint32_t>(u);
        h += static_cast<uint32_t>(discs_overlap(mx[u] - x, my[u] - y, r + mr[u]));
      }
      for (uint32_t k = 0; k < h; ++k)
        if (moved_[hit[k]] != a) fn(moved_[hit[k]]);
    }
  }

 private:
  static constexpr std::size_t kBruteWork = 1 << 16;  // pair tests below which a scan is cheaper
  static constexpr std::size_t kMovedBatch = 64;
  void build() {
    own_.build(view_);
    grid_ = &own_;
    built_ = own_.usable();
  }
  DiscView view_;
  const index::DiscGrid* grid_;
  index::DiscGrid own_;
  bool built_;
  std::vector<uint8_t> stale_;
  std::vector<uint32_t> moved_;
  std::vector<double> moved_x_, moved_y_, moved_r_;  // their columns, as moved_ lists them
  index::DiscGrid moved_grid_;  // over those columns (its rows: places in moved_)
  bool moved_in_grid_ = false;  // moved_grid_ holds all of moved_ (false: scan them)
};

}  // namespace

bool pair_violates(const AgentTable& t, const NextState& next, uint32_t i, uint32_t j) {
  const double sx = t.x[j] - t.x[i], sy = t.y[j] - t.y[i];
  const double nx = next.x[j] - next.x[i], ny = next.y[j] - next.y[i];
  return !(discs_overlap(sx, sy, t.radius[i] + t.radius[j]) &&
           nx * nx + ny * ny >= sx * sx + sy * sy);
}

bool obstacle_violates(const AgentTable& t, const NextState& next, const StaticScene& scene,
                       uint32_t i, Collider with) {
  const double r_i = t.radius[i];
  if (with.kind == Collider::Kind::circle) {
    const CircleObstacle& c = scene.circles()[with.row];
    const double sx = c.x - t.x[i], sy = c.y - t.y[i], nx = c.x - next.x[i], ny = c.y - next.y[i];
    return !(discs_overlap(sx, sy, r_i + c.radius) && nx * nx + ny * ny >= sx * sx + sy * sy);
  }
  const double before = polygon_depth(scene, with.row, t.x[i], t.y[i], r_i);
  return !(before > 0 && polygon_depth(scene, with.row, next.x[i], next.y[i], r_i) <= before);
}

namespace {

OverlapReport classify(const AgentTable& t, const NextState& next, const StaticScene& scene,
                       const CollisionPairs& pairs) {
  OverlapReport r;
  r.agent_pairs = pairs.agents.size();
  r.obstacle_hits = pairs.obstacles.size();
  for (auto [i, j] : pairs.agents)
    if (pair_violates(t, next, i, j)) {
      r.violators.push_back(i);
      r.violators.push_back(j);
    }
  for (const auto& [i, with] : pairs.obstacles)
    if (obstacle_violates(t, next, scene, i, with)) r.violators.push_back(i);
  std::sort(r.violators.begin(), r.violators.end());
  r.violators.erase(std::unique(r.violators.begin(), r.violators.end()), r.violators.end());
  return r;
}

}  // namespace

OverlapReport find_overlaps(const AgentTable& t, const NextState& next, const StaticScene& scene,
                            CollisionPath& path, Executor& ex, QueryStats& stats) {
  CollisionPairs pairs;
  path.run(next_view(t, next), scene, pairs, ex, stats);
  return classify(t, next, scene, pairs);
}

OverlapReport backoff_reference(const AgentTable& t, NextState& next, const StaticScene& scene,
                                CollisionPath& path, Executor& ex, QueryStats& stats,
                                std::size_t& iterations) {
  iterations = 0;
  for (;;) {
    OverlapReport r = find_overlaps(t, next, scene, path, ex, stats);
    ++iterations;
    bool froze = false;
    for (uint32_t i : r.violators)
      if (!next.frozen[i]) {
        freeze(t, next, i);
        froze = true;
      }
    if (!froze) return r;
  }
}

// Newly frozen agents per chunk of a round's probes.
constexpr std::size_t kProbeGrain = 64;

// Rows whose lists fall short, at most (their pairs among each other are tested one by one).
constexpr std::size_t kShortMost = 256;

// Obstacles (walls included) beyond which the final count of the moved rows' obstacle hits goes
// through an index rather than the naive test per row.
constexpr std::size_t kObstaclesForAnIndex = 32;

bool lists_rule_out_overlaps(const AgentTable& t, const NextState& next, const NearLists& near,
                             Executor& ex) {
  const std::size_t n = t.size();
  if (!near.lists || near.lists->queries() != n || n == 0) return false;
  // Raw columns: through the captured vectors every load re-read their data pointers.
  const double *x = t.x.data(), *y = t.y.data(), *r = t.radius.data();
  const double *nx = next.x.data(), *ny = next.y.data();
  const uint32_t *offset = near.lists->offset.data(), *row = near.lists->row.data();
  // The largest move and radius, per chunk, then folded (a maximum: the same in any order).
  // Every row is given the largest move as its own (D_i <= D_max): no square root per row, and
  // a bound hardly looser where everyone walks.
  constexpr std::size_t kCheckGrain = 4096;  // rows per chunk where there are many
  const std::size_t grain = chunk_rows(n, kCheckGrain);
  const std::size_t chunks = (n + grain - 1) / grain;
  std::vector<double> part_move2(chunks, 0), part_radius(chunks, 0);
  std::vector<uint8_t> shown(chunks, 1);
  ex.for_each_chunk(n, grain, [&](std::size_t b, std::size_t e) {
    double m2 = 0, rm = 0;
    bool finite = true;
    for (std::size_t i = b; i < e; ++i) {
      const double dx = nx[i] - x[i], dy = ny[i] - y[i], d2 = dx * dx + dy * dy;
      finite = finite && std::isfinite(d2) && std::isfinite(r[i]);
      m2 = std::max(m2, d2);
      rm = std::max(rm, r[i]);
    }
    part_move2[b / grain] = m2;
    part_radius[b / grain] = rm;
    shown[b / grain] = finite;
  });
  double move2_max = 0, radius_max = 0;
  for (std::size_t c = 0; c < chunks; ++c) {
    if (!shown[c]) return false;  // a position or radius that is not finite
    move2_max = std::max(move2_max, part_move2[c]);
    radius_max = std::max(radius_max, part_radius[c]);
  }
  // Distances come from differences of doubles, each within a few ulps of the true one: a
  // relative 1e-9 on the bound keeps it conservative.
  const double skin = radius_max + 2 * std::sqrt(move2_max);
  const double range2 = near.range * near.range;
  const uint32_t k = near.k;
  // Once a chunk fails the answer is no, whichever: the chunks not yet begun are skipped.
  std::atomic<bool> failed{false};
  std::vector<std::vector<uint32_t>> part_short(chunks);
  ex.for_each_chunk(n, grain, [&](std::size_t b, std::size_t e) {
    bool ok = !failed.load(std::memory_order_relaxed);
    std::vector<uint32_t>& short_rows = part_short[b / grain];
    for (std::size_t i = b; i < e && ok; ++i) {
      const double need = (r[i] + skin) * (1 + 1e-9);
      const double need2 = need * need;
      const uint32_t lo = offset[i], hi = offset[i + 1];
      const double xi = x[i], yi = y[i];
      auto dist2 = [&](uint32_t j) {  // as the lists rank them (steer::dist2_of)
        const double dx = x[j] - xi, dy = y[j] - yi;
        return dx * dx + dy * dy;
      };
      // Everyone strictly closer than the list's bound is in it (NearLists).
      const double bound2 = k > 0 && hi - lo >= k ? dist2(row[hi - 1]) : range2;
      if (!(bound2 >= need2)) {
        short_rows.push_back(static_cast<uint32_t>(i));
        ok = short_rows.size() <= kShortMost;
        continue;
      }
      // Nearest first: the pairs near enough to overlap come first. Tested from both sides: a
      // row whose list falls short has its pairs tested from the other side only.
      for (uint32_t a = lo; a < hi && ok; ++a) {
        const uint32_t j = row[a];
        if (!(dist2(j) < need2)) break;
        ok = !discs_overlap(nx[j] - nx[i], ny[j] - ny[i], r[i] + r[j]);
      }
    }
    if (!ok) failed.store(true, std::memory_order_relaxed);
  });
  if (failed.load()) return false;
  // A pair of two short-listed rows may be in neither list: every such pair is tested.
  std::vector<uint32_t> short_rows;
  for (const auto& part : part_short) short_rows.insert(short_rows.end(), part.begin(), part.end());
  if (short_rows.size() > kShortMost) return false;
  for (std::size_t a = 0; a < short_rows.size(); ++a)
    for (std::size_t b = a + 1; b < short_rows.size(); ++b) {
      const uint32_t i = short_rows[a], j = short_rows[b];
      if (discs_overlap(nx[j] - nx[i], ny[j] - ny[i], r[i] + r[j])) return false;
    }
  return true;
}

OverlapReport backoff(const AgentTable& t, NextState& next, const StaticScene& scene,
                      CollisionPath& path, Executor& ex, QueryStats& stats, std::size_t& iterations,
                      const NearLists& near) {
  const DiscView view = next_view(t, next);
  CollisionPairs first;
  const bool by_lists = lists_rule_out_overlaps(t, next, near, ex);
  if (by_lists) {
    // No agent pair: only the obstacle half of the query is left.
    if (!scene.empty()) {
      Stopwatch sw;
      index::ObstacleIndex obstacles;
      obstacles.build(scene, index::Frame::of(view));
      stats.build_seconds += sw.seconds();
      sw.restart();
      obstacles.overlaps(view, first.obstacles, stats.pair_tests, ex);
      stats.query_seconds += sw.seconds();
    }
    stats.rows += view.n;
  } else {
    path.run(view, scene, first, ex, stats);
  }
  iterations = 1;
  OverlapReport report = classify(t, next, scene, first);
  report.agents_by_lists = by_lists;
  if (report.violators.empty()) return report;

  // stamp[i]: the iteration that froze i (0: never). Agents already frozen on entry keep 0 and
  // are treated as unmoved: the loop only tracks what it moves itself.
  std::vector<uint32_t> stamp(t.size(), 0);
  std::vector<uint32_t> newly;
  for (uint32_t i : report.violators)
    if (!next.frozen[i]) {
      freeze(t, next, i);
      stamp[i] = 1;
      newly.push_back(i);
    }
  // Pairs found by probes, with the stamp of the probing agent: such a pair still holds at the
  // end iff its other agent did not move later (never frozen, or frozen no later).
  struct Found {
    uint32_t a, b, k;
  };
  std::vector<Found> found;
  OverlapProbe probe(view, by_lists ? nullptr : path.disc_grid());
  std::vector<uint32_t> next_new;
  // A round's probes only read (positions, stamps, frozen flags change between rounds), so they
  // run in chunks on every thread, each with lists of its own, joined in chunk order.
  std::vector<std::vector<Found>> chunk_found;
  std::vector<std::vector<uint32_t>> chunk_new;
  uint32_t k = 1, moved_grid_rounds = 0;
  while (!newly.empty()) {
    ++iterations;
    probe.moved(newly);  // only matters when the grid was built before they were frozen
    probe.prepare(newly.size());
    moved_grid_rounds += probe.moved_in_grid();
    const std::size_t chunks = (newly.size() + kProbeGrain - 1) / kProbeGrain;
    chunk_found.resize(std::max(chunk_found.size(), chunks));
    chunk_new.resize(std::max(chunk_new.size(), chunks));
    ex.for_each_chunk(newly.size(), kProbeGrain, [&](std::size_t b0, std::size_t e0) {
      std::vector<Found>& fd = chunk_found[b0 / kProbeGrain];
      std::vector<uint32_t>& nn = chunk_new[b0 / kProbeGrain];
      fd.clear();
      nn.clear();
      for (std::size_t u = b0; u < e0; ++u) {
        const uint32_t a = newly[u];
        probe.for_each_overlap(a, [&](uint32_t b) {
          if (stamp[b] == k && b < a) return;  // frozen together: found from b's side
          fd.push_back({a, b, k});
          if (!next.frozen[b] && pair_violates(t, next, std::min(a, b), std::max(a, b)))
            nn.push_back(b);
        });
      }
    });
    next_new.clear();
    for (std::size_t c = 0; c < chunks; ++c) {
      found.insert(found.end(), chunk_found[c].begin(), chunk_found[c].end());
      next_new.insert(next_new.end(), chunk_new[c].begin(), chunk_new[c].end());
    }
    std::sort(next_new.begin(), next_new.end());
    next_new.erase(std::unique(next_new.begin(), next_new.end()), next_new.end());
    ++k;
    for (uint32_t b : next_new) {
      freeze(t, next, b);
      stamp[b] = k;
    }
    newly.swap(next_new);
    stats.rows += newly.size();
  }

  // Final overlaps: pairs of the first query whose agents both stayed, plus the probe pairs that
  // still hold; obstacle hits of agents that stayed, plus those of the moved agents where they are.
  report = {};
  report.agents_by_lists = by_lists;
  report.moved_grid_rounds = moved_grid_rounds;
  for (auto [i, j] : first.agents) report.agent_pairs += stamp[i] == 0 && stamp[j] == 0;
  for (const Found& f : found) report.agent_pairs += stamp[f.b] == 0 || stamp[f.b] <= f.k;
  for (const auto& hit : first.obstacles) report.obstacle_hits += stamp[hit.first] == 0;
  if (!scene.empty()) {
    // Where the moved rows times the obstacles outweigh the rows and obstacles, through an
    // obstacle index over where everyone stands now (its frame is a pass over every row; the
    // naive test per moved row cost moved rows x obstacles: 10^3 among SteerSuite's 5,000
    // boxes, 5·10^6 tests a tick); the same hits either way.
    std::vector<std::pair<uint32_t, Collider>> hits;
    const auto moved = static_cast<std::size_t>(
        std::count_if(stamp.begin(), stamp.end(), [](auto s) { return s != 0; }));
    const std::size_t m = scene.circles().size() + scene.polygons().size();
    if (m > kObstaclesForAnIndex && moved * m > 2 * (t.size() + m)) {
      index::ObstacleIndex obstacles;
      obstacles.build(scene, index::Frame::of(view));
      uint64_t tests = 0;
      for (std::size_t i = 0; i < t.size(); ++i)
        if (stamp[i]) obstacles.overlaps(view, i, i + 1, hits, tests);
    } else if (moved > 0) {
      for (std::size_t i = 0; i < t.size(); ++i)
        if (stamp[i]) disc_obstacle_overlaps(view, scene, i, i + 1, hits);
    }
    report.obstacle_hits += hits.size();
  }
  return report;
}

}  // namespace crowddb::sim
