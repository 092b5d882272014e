#include "sim/stalemate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/stages.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"

namespace crowddb::sim {
namespace {

constexpr double kBlockGap = 0.6;  // [m] a blocker's disc is this close to the agent's, or less
constexpr double kFreeWalk = 0.5;  // walking at half the preferred speed towards the target
constexpr double kOpposed = -0.5;  // cos 120 degrees: directions further apart head at each other
constexpr std::size_t kWatchGrain = 256;  // rows per chunk of the progress watch
constexpr std::size_t kLookGrain = 64;    // looked-at rows per chunk of blockers and actions
constexpr std::size_t kPlaceTable = 16;   // a table of places from 1 looked-at row in 16 on

uint64_t priority(uint64_t seed, uint64_t id) {
  uint64_t s = seed ^ (id * 0x9e3779b97f4a7c15ull);
  return splitmix64(s);
}

// Unit direction from row i to its current target (0, 0 when on it).
Vec2 heading(const AgentTable& t, std::span<const Goal> goals, std::size_t i) {
  return unit_towards(t.x[i], t.y[i], current_target(t, goals, i));
}

// Following each stalled agent's blocker while the blocker is stalled too gives chains that end
// either in a cycle of agents blocking each other or in a blocker that is not stalled (or in
// nobody: walls). jammed[q] says the chain of looked_at[q] ends in people going its way or
// across: a cycle of which no two neighbours head at each other (an arch in front of a door),
// or a last blocker not heading at the chain's end. Such a jam clears only if the people behind
// it give way, so its yields go first in orca (StallAction::yield_ahead). Not so at the front
// of two streams meeting head-on, where pushing the other block back is what ends the standoff
// (measured: dense head-on counter-flow lost two thirds of its arrivals when every yield went
// first), nor against walls. One pass over the chains: O(looked_at).
std::vector<uint8_t> jammed_ahead(const AgentTable& t, std::span<const Goal> goals,
                                  std::span<const uint32_t> looked_at,
                                  std::span<const int64_t> blocker, std::span<const int64_t> bpos,
                                  std::span<const uint8_t> queueing, std::span<const Vec2> dir) {
  const std::size_t m = looked_at.size();
  std::vector<int64_t> next(m, -1);
  for (std::size_t q = 0; q < m; ++q) {
    if (queueing[q] || blocker[q] < 0) continue;
    const int64_t p = bpos[q];
    if (p >= 0 && !queueing[static_cast<std::size_t>(p)]) next[q] = p;
  }
  enum : uint8_t { kUnseen, kOnPath, kDone };
  std::vector<uint8_t> seen(m, kUnseen), jammed(m, 0);
  std::vector<std::size_t> path;
  for (std::size_t q0 = 0; q0 < m; ++q0) {
    if (seen[q0] != kUnseen) continue;
    path.clear();
    int64_t q = static_cast<int64_t>(q0);
    while (q >= 0 && seen[static_cast<std::size_t>(q)] == kUnseen) {
      seen[static_cast<std::size_t>(q)] = kOnPath;
      path.push_back(static_cast<std::size_t>(q));
      q = next[static_cast<std::size_t>(q)];
    }
    uint8_t verdict = 0;
    if (q < 0) {  // ends in a blocker that is not stalled, or in nobody in front (walls)
      const std::size_t u = path.back();
      if (blocker[u] >= 0) {
        const Vec2 db = heading(t, goals, static_cast<std::size_t>(blocker[u]));
        verdict = dir[u].x * db.x + dir[u].y * db.y > kOpposed;
      }
    } else if (q >= 0 && seen[static_cast<std::size_t>(q)] == kDone) {
      verdict = jammed[static_cast<std::size_t>(q)];
    } else if (q >= 0) {  // a new cycle: from q round to q
      verdict = 1;
      std::size_t u = static_cast<std::size_t>(q);
      do {
        const std::size_t v = static_cast<std::size_t>(next[u]);
        if (dir[u].x * dir[v].x + dir[u].y * dir[v].y <= kOpposed) verdict = 0;
        u = v;
      } while (u != static_cast<std::size_t>(q));
    }
    for (std::size_t u : path) {
      seen[u] = kDone;
      jammed[u] = verdict;
    }
  }
  return jammed;
}

}  // namespace

std::vector<uint8_t> queue_members(std::span<const uint8_t> same_way,
                                   std::span<const uint8_t> moves, std::span<const int64_t> next) {
  const std::size_t m = same_way.size();
  enum : uint8_t { kUnseen, kOnPath, kDone };
  std::vector<uint8_t> seen(m, kUnseen), member(m, 0);
  std::vector<std::size_t> path;
  for (std::size_t q0 = 0; q0 < m; ++q0) {
    if (seen[q0] != kUnseen) continue;
    // Follow the same-way blockers that are looked at and do not move, until the chain ends.
    path.clear();
    int64_t q = static_cast<int64_t>(q0);
    uint8_t verdict = 0;
    while (true) {
      const auto u = static_cast<std::size_t>(q);
      if (seen[u] == kDone) {
        verdict = member[u];
        break;
      }
      if (seen[u] == kOnPath || !same_way[u]) break;  // a cycle, or not walking its blocker's way
      if (moves[u] || next[u] < 0) {                  // the head of a queue: it moves
        verdict = 1;
        path.push_back(u);
        break;
      }
      seen[u] = kOnPath;
      path.push_back(u);
      q = next[u];
    }
    for (std::size_t u : path) {
      seen[u] = kDone;
      member[u] = verdict;
    }
    if (seen[q0] != kDone) {  // q0 itself ended the walk (not its blocker's way)
      seen[q0] = kDone;
      member[q0] = 0;
    }
  }
  return member;
}

std::vector<uint8_t> queue_members_naive(std::span<const uint8_t> same_way,
                                         std::span<const uint8_t> moves,
                                         std::span<const int64_t> next) {
  const std::size_t m = same_way.size();
  std::vector<uint8_t> member(m, 0);
  for (bool changed = true; changed;) {
    changed = false;
    for (std::size_t q = 0; q < m; ++q) {
      if (member[q] || !same_way[q]) continue;
      if (moves[q] || next[q] < 0 || member[static_cast<std::size_t>(next[q])]) {
        member[q] = 1;
        changed = true;
      }
    }
  }
  return member;
}

StallCounts stalemates(World& world, const SimConfig& cfg, uint64_t tick, NeighbourPath& path,
                       Executor& ex, QueryStats& stats, AimMemo* aim, const TickMove* move) {
  AgentTable& t = world.agents_for_tick();
  const auto goals = world.goals();
  const uint64_t after = cfg.ticks_for(cfg.stall.after);
  const uint64_t reverse_after = cfg.ticks_for(cfg.stall.reverse_after, 0);
  const uint64_t reverse_period = cfg.ticks_for(cfg.stall.reverse_period);
  StallCounts c;
  // 1. progress watch: each row on its own (in chunks, on every thread), then the stalled rows
  // collected in row order, so the result does not depend on the thread count.
  std::vector<uint8_t> look(t.size(), 0);
  std::vector<double> chunk_rmax((t.size() + kWatchGrain - 1) / kWatchGrain, 0);
  ex.for_each_chunk(t.size(), kWatchGrain, [&](std::size_t b, std::size_t e) {
    double rm = 0;  // the chunk's, written once at its end (the entries share cache lines)
    for (std::size_t i = b; i < e; ++i) {
      rm = std::max(rm, t.radius[i]);
      if (standing(t.state[i])) {
        t.stall_ticks[i] = 0;
        // (Making way for a walker lasts its time: standing is what it is done from.)
        if (!making_way(t, i, tick)) t.stall_action[i] = StallAction::none;
        continue;
      }
      const double d = path_left(t, goals, i, aim);
      if (!std::isfinite(t.progress_best[i])) {
        t.progress_best[i] = d;  // a new goal: this tick is the reference
      } else if (d < t.progress_best[i] - cfg.stall.progress) {
        t.progress_best[i] = d;
        t.stall_ticks[i] = 0;
        t.replan_ticks[i] = 0;
        t.stall_action[i] = StallAction::none;  // unstuck
      } else {
        ++t.stall_ticks[i];
        ++t.replan_ticks[i];
      }
      // A sidestep is followed by `after` of walking on before the next action: the agent
      // heads for its target again and gets the same time as anyone to make progress. Acting
      // again at once chained sidesteps into a random walk for as long as its best distance
      // stayed out of reach (Menge's formationNavigation: one pushed off its spot at the
      // start wandered 280 s with stall.after 2 s).
      if (t.stall_action[i] != StallAction::none &&
          tick >= t.stall_until[i] + (t.stall_action[i] == StallAction::sidestep ? after : 0))
        t.stall_action[i] = StallAction::none;
      look[i] = t.stall_ticks[i] >= after;
    }
    chunk_rmax[b / kWatchGrain] = rm;
  });
  std::vector<uint32_t> looked_at;  // in row order
  for (std::size_t i = 0; i < t.size(); ++i)
    if (look[i]) looked_at.push_back(static_cast<uint32_t>(i));
  double rmax = 0;
  for (double r : chunk_rmax) rmax = std::max(rmax, r);
  if (looked_at.empty()) return c;
  // 2. blockers, queueing
  NeighbourLists nb;
  nb.with_dist2 = false;  // (the gaps below are computed from the positions)
  const double block_range = 2 * rmax + kBlockGap;
  constexpr uint32_t kBlockers = 6;
  // From the model's lists where they are sure to hold the answer (at airport-20k nearly all of
  // the ~500 rows looked at a tick), a few left (the densest spots) by a scan of every row each,
  // more by the query (on every thread, however few rows: the grid's build over every row and the
  // searches), whose grid over every row for a few searches was most of this step's cost and did
  // not speed up on two threads.
  const AnsweredBy by =
      neighbours_after_move(t, move, looked_at, block_range, kBlockers, path, nb, ex, stats);
  c.by_lists = by.lists;
  c.by_scan = by.scan;
  c.by_query = by.query;
  std::vector<int64_t> blocker(looked_at.size(), -1);
  std::vector<Vec2> dir(looked_at.size());
  std::vector<uint8_t> same_way(looked_at.size(), 0), queueing(looked_at.size(), 0);
  std::vector<int64_t> bpos(looked_at.size(), -1);  // the blocker's place in looked_at, or -1
  // Where a row is in looked_at (sorted), -1 if not looked at: a table of every row when many
  // are looked at (a dense jam: the searches were a tenth of the stage), else a search (a few
  // among 10^6 rows need no table of 10^6 entries).
  std::vector<int32_t> place;
  if (looked_at.size() >= t.size() / kPlaceTable) {
    place.assign(t.size(), -1);
    for (std::size_t q = 0; q < looked_at.size(); ++q)
      place[looked_at[q]] = static_cast<int32_t>(q);
  }
  auto pos = [&](std::size_t j) -> int64_t {
    if (!place.empty()) return place[j];
    const auto it = std::lower_bound(looked_at.begin(), looked_at.end(), j);
    return it != looked_at.end() && *it == j ? it - looked_at.begin() : -1;
  };
  // Each looked-at row on its own (in chunks, on every thread).
  ex.for_each_chunk(looked_at.size(), kLookGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t q = b; q < e; ++q) {
      const uint32_t i = looked_at[q];
      dir[q] = heading(t, goals, i);
      for (uint32_t j : nb.rows_of(q)) {
        const double rx = t.x[j] - t.x[i], ry = t.y[j] - t.y[i];
        const double gap = std::sqrt(rx * rx + ry * ry) - t.radius[i] - t.radius[j];
        if (gap < kBlockGap && rx * dir[q].x + ry * dir[q].y > 0) {
          blocker[q] = j;
          break;
        }
      }
      if (blocker[q] < 0) continue;
      const auto j = static_cast<std::size_t>(blocker[q]);
      const Vec2 dj = heading(t, goals, j);
      // Someone idle heads a queue only at i's own goal: idle on another goal (arrivals of
      // the other stream) or anywhere else, it is an obstacle that does not move away by itself.
      same_way[q] = t.goal[j] == t.goal[i] ||
                    (!standing(t.state[j]) && dj.x * dir[q].x + dj.y * dir[q].y >= kSameWay);
      bpos[q] = pos(j);
    }
  });
  // A queue ends in someone who moves: an agent waits in one when its same-way blocker is
  // progressing (not looked at) or waits in one itself. Chains resolve outwards from a moving
  // head; a cycle of mutual blockers (people arching in a door) never does: it is a stalemate.
  {
    std::vector<uint8_t> moves(looked_at.size(), 0);
    for (std::size_t q = 0; q < looked_at.size(); ++q)
      moves[q] =
          same_way[q] && (standing(t.state[static_cast<std::size_t>(blocker[q])]) || bpos[q] < 0);
    queueing = queue_members(same_way, moves, bpos);
  }
  // Waiting in a queue is no stalemate: no action, and the clock is held at the threshold (so
  // a queueing agent never passes for a moving head, and should it become a stalled head, its
  // stall is counted from then).
  for (std::size_t q = 0; q < looked_at.size(); ++q)
    if (queueing[q]) {
      t.stall_action[looked_at[q]] = StallAction::none;
      t.stall_ticks[looked_at[q]] = static_cast<uint32_t>(after);
      ++c.queueing;
    }
  for (std::size_t q = 0; q < looked_at.size(); ++q) {
    if (queueing[q]) continue;
    const uint32_t i = looked_at[q];
    ++c.stalled;
    if (t.stall_ticks[i] == after + 1) ++c.started;
    c.longest = std::max<std::size_t>(c.longest, t.stall_ticks[i]);
  }
  if (!cfg.stall.resolve) return c;
  const std::vector<uint8_t> jammed =
      jammed_ahead(t, goals, looked_at, blocker, bpos, queueing, dir);
  for (std::size_t q = 0; q < looked_at.size(); ++q)
    if (!queueing[q] && !jammed[q]) c.head_on.push_back(looked_at[q]);
  // 3. actions for the stalled ones that have none running: each row's own columns only, read
  // from the others what this loop does not write (in chunks, on every thread; counts summed in
  // chunk order).
  // Per looked-at row: a standing blocker asked to make way (applied after the parallel loop, in
  // row order: the blocker's columns are not the row's own).
  std::vector<int64_t> make_way(looked_at.size(), -1);
  auto act = [&](std::size_t q, std::size_t& yields, std::size_t& sidesteps) {
    const uint32_t i = looked_at[q];
    if (queueing[q] || t.stall_action[i] != StallAction::none) return;
    const double dx = dir[q].x, dy = dir[q].y;
    if (dx == 0 && dy == 0) return;
    // Nobody in front and walking towards the target: it is making its way back to where it
    // was pushed from (a counter-stream carried it backwards), not stuck; a sidestep would only
    // slow it down.
    if (blocker[q] < 0 && t.vx[i] * dx + t.vy[i] * dy >= kFreeWalk * t.pref_speed[i]) return;
    const auto j = static_cast<std::size_t>(blocker[q]);
    const bool blocker_stalled = blocker[q] >= 0 && t.stall_ticks[j] >= after &&
                                 !(bpos[q] >= 0 && queueing[static_cast<std::size_t>(bpos[q])]);
    // As in orca's right of way: out before in (sim::out_before_in), then, of two bound for
    // different goals the same way, the one ahead (sim::ahead), then the one with less of its
    // path left (at a clogged door: the one nearest to getting through); ties by the seeded rank.
    const double li = path_left(t, goals, i), lj = blocker_stalled ? path_left(t, goals, j) : 0;
    const int out = blocker_stalled ? out_before_in(t, goals, i, j) : 0;
    bool i_ahead = false;
    const bool by_place = blocker_stalled && out == 0 &&
                          ahead(ahead_input(t, goals, i), ahead_input(t, goals, j), i_ahead);
    bool j_first =
        out != 0 ? out < 0
        : by_place
            ? !i_ahead
            : lj < li || (lj == li && priority(cfg.seed, t.id[j]) > priority(cfg.seed, t.id[i]));
    // Taking turns: a pair both stalled for reverse_after swaps the order in every other period
    // (the same for both of them: it depends on the pair and the tick only).
    if (blocker_stalled && reverse_after > 0 && t.stall_ticks[i] >= reverse_after &&
        t.stall_ticks[j] >= reverse_after && (tick / reverse_period) % 2 == 1)
      j_first = !j_first;
    if (blocker_stalled && j_first) {
      // Yield: back away from the blocker and to the side it is not on.
      const double rx = t.x[i] - t.x[j], ry = t.y[i] - t.y[j];
      const double rl = std::max(std::sqrt(rx * rx + ry * ry), 1e-12);
      const bool left = dx * (-ry) - dy * (-rx) > 0;  // blocker to the left of the heading
      const double sx = left ? dy : -dy, sy = left ? -dx : dx;
      double yx = rx / rl + sx, yy = ry / rl + sy;
      const double yl = std::sqrt(yx * yx + yy * yy);
      if (yl > 0) {
        yx /= yl;
        yy /= yl;
      } else {
        yx = sx;
        yy = sy;
      }
      t.stall_action[i] = jammed[q] ? StallAction::yield_ahead : StallAction::yield;
      t.stall_dir_x[i] = yx;
      t.stall_dir_y[i] = yy;
      t.stall_until[i] =
          tick + cfg.ticks_for(jammed[q] ? cfg.stall.yield_time : cfg.stall.head_on_yield_time);
      ++yields;
    } else if (blocker_stalled) {
      return;  // the blocker yields to this one
    } else {
      if (blocker[q] >= 0 && t.state[j] == AgentState::arrived && t.goal[j] != t.goal[i])
        make_way[q] = blocker[q];
      Rng rng = Rng::stream(cfg.seed ^ (tick * 0xbf58476d1ce4e5b9ull), t.id[i]);
      const double turn =
          rng.uniform(std::numbers::pi / 4, std::numbers::pi / 2) * (rng.below(2) ? 1 : -1);
      const double cs = std::cos(turn), sn = std::sin(turn);
      t.stall_action[i] = StallAction::sidestep;
      t.stall_dir_x[i] = cs * dx - sn * dy;
      t.stall_dir_y[i] = sn * dx + cs * dy;
      t.stall_until[i] = tick + cfg.ticks_for(cfg.stall.sidestep_time);
      ++sidesteps;
    }
  };
  const std::size_t chunks = (looked_at.size() + kLookGrain - 1) / kLookGrain;
  std::vector<std::size_t> yields(chunks, 0), sidesteps(chunks, 0);
  ex.for_each_chunk(looked_at.size(), kLookGrain, [&](std::size_t b, std::size_t e) {
    std::size_t yielded = 0, sidestepped = 0;  // written once (the entries share cache lines)
    for (std::size_t q = b; q < e; ++q) act(q, yielded, sidestepped);
    yields[b / kLookGrain] = yielded;
    sidesteps[b / kLookGrain] = sidestepped;
  });
  for (std::size_t k = 0; k < chunks; ++k) {
    c.yielding += yields[k];
    c.sidestepping += sidesteps[k];
  }
  // Standing blockers step aside, off the walker's line to the side they stand on, for
  // yield_time (the first walker to ask, in row order, sets the direction).
  for (std::size_t q = 0; q < looked_at.size(); ++q) {
    if (make_way[q] < 0) continue;
    const auto j = static_cast<std::size_t>(make_way[q]);
    if (making_way(t, j, tick)) continue;
    const uint32_t i = looked_at[q];
    const double dx = dir[q].x, dy = dir[q].y;
    const double side = dx * (t.y[j] - t.y[i]) - dy * (t.x[j] - t.x[i]);
    const bool left = side > 0 || (side == 0 && (t.id[j] & 1));
    t.stall_action[j] = StallAction::make_way;
    t.stall_dir_x[j] = left ? -dy : dy;
    t.stall_dir_y[j] = left ? dx : -dx;
    t.stall_until[j] = tick + cfg.ticks_for(cfg.stall.yield_time);
    ++c.making_way;
  }
  return c;
}

}  // namespace crowddb::sim
