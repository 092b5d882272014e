#include "sim/stages.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <numbers>
#include <optional>

#include "path/navigation.hpp"
#include "sim/stalemate.hpp"
#include "util/hash.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"
#include "world/obstacle_lookup.hpp"

namespace crowddb::sim {
namespace {

constexpr std::size_t kGrain = 256;
// Rows per chunk of the integration where there are many (chunk_rows: fewer where there are not):
// two multiply-adds a row, so chunks of kGrain rows cost more to hand out than to run.
constexpr std::size_t kIntegrateGrain = 8192;

// Arrived or waiting at its goal: no steering for the goal, only making room at it.
bool idle(const AgentTable& t, std::size_t i) {
  return standing(t.state[i]);
}

// Does idle row i stand on (or touch) disc goal g?
bool on_disc(const AgentTable& t, const Goal& g, std::size_t i) {
  return length(g.x - t.x[i], g.y - t.y[i]) < g.arrival_radius + t.radius[i];
}

// The preferred velocity of idle row i stepping off disc goal g: away from its centre at half
// its preferred speed (on the centre itself, in a seeded direction of its own).
Vec2 step_off(const AgentTable& t, const Goal& g, const SimConfig& cfg, std::size_t i) {
  double dx = t.x[i] - g.x, dy = t.y[i] - g.y;
  double len = std::sqrt(dx * dx + dy * dy);
  if (len == 0) {
    Rng rng = Rng::stream(cfg.seed ^ 0x1d1e, t.id[i]);
    const double a = rng.uniform(0, 2 * std::numbers::pi);
    dx = std::cos(a);
    dy = std::sin(a);
    len = 1;
  }
  return {0.5 * t.pref_speed[i] * dx / len, 0.5 * t.pref_speed[i] * dy / len};
}

// The disc goals others still head for (demand > 0), for idle agents that stand in the way of
// one that is not their own: closer to its disc than the widest of those heading for it needs
// (Menge's formations put goals 0.3 m apart: the first to arrive stood where its neighbour had
// to stand, and the neighbour circled it for good). Rebuilt every tick while someone idles:
// O(agents + goals).
struct NeededDiscs {
  std::vector<uint32_t> goal;        // goal row of each disc
  std::vector<CircleObstacle> area;  // each disc grown by the widest radius heading for it
  std::optional<ObstacleLookup> lookup;

  NeededDiscs(const AgentTable& t, std::span<const Goal> goals, std::span<const uint32_t> demand) {
    if (demand.empty()) return;
    std::vector<double> widest(goals.size(), 0);
    bool anyone_idle = false;
    for (std::size_t i = 0; i < t.size(); ++i) {
      if (standing(t.state[i]))
        anyone_idle = true;
      else
        widest[t.goal[i]] = std::max(widest[t.goal[i]], t.radius[i]);
    }
    if (!anyone_idle) return;  // nobody to step off anything: no grid to build
    for (std::size_t g = 0; g < goals.size(); ++g)
      if (demand[g] > 0 && !goals[g].is_polygon()) {
        goal.push_back(static_cast<uint32_t>(g));
        area.push_back({goals[g].x, goals[g].y, goals[g].arrival_radius + widest[g], 0});
      }
    if (!area.empty()) lookup.emplace(area, std::span<const PolygonObstacle>{});
  }
};

}  // namespace

void Preferred::reset(std::size_t n) {
  // Sized only: goal_stage writes every entry of every row (clearing 25 bytes a row first was a
  // pass on one thread, 25 MB a tick at 10^6 agents).
  vx.resize(n);
  vy.resize(n);
  skip.resize(n);
  left.resize(n);
}

void NextState::resize(std::size_t n) {
  x.resize(n);
  y.resize(n);
  vx.resize(n);
  vy.resize(n);
  frozen.assign(n, 0);
}

void AimMemo::resize(std::size_t rows, std::span<const Goal> goals) {
  const bool areas =
      std::any_of(goals.begin(), goals.end(), [](const Goal& g) { return g.is_polygon(); });
  entries_.resize(areas ? rows : 0);
}

Vec2 AimMemo::target(std::span<const Goal> goals, uint32_t goal, double px, double py, double r,
                     std::size_t row) {
  const Goal& g = goals[goal];
  if (!g.is_polygon()) return {g.x, g.y};  // goal_target's answer for a point
  Entry& e = entries_[row];
  const auto bx = std::bit_cast<uint64_t>(px), by = std::bit_cast<uint64_t>(py),
             br = std::bit_cast<uint64_t>(r);
  if (e.goal != goal || e.x != bx || e.y != by || e.r != br)
    e = {goal, bx, by, br, goal_target(g, px, py, r)};
  return e.target;
}

Vec2 current_target(const AgentTable& t, std::span<const Goal> goals, std::size_t i, AimMemo* aim) {
  if (!t.route[i].empty()) return t.route[i].front();
  return aim ? aim->target(goals, t.goal[i], t.x[i], t.y[i], t.radius[i], i)
             : goal_target(goals[t.goal[i]], t.x[i], t.y[i], t.radius[i]);
}

double path_left(const AgentTable& t, std::span<const Goal> goals, std::size_t i, AimMemo* aim) {
  double x = t.x[i], y = t.y[i], len = 0;
  for (const Vec2& w : t.route[i]) {
    const double dx = w.x - x, dy = w.y - y;
    len += std::sqrt(dx * dx + dy * dy);
    x = w.x;
    y = w.y;
  }
  const Vec2 e = aim ? aim->target(goals, t.goal[i], x, y, t.radius[i], i)
                     : goal_target(goals[t.goal[i]], x, y, t.radius[i]);
  const double dx = e.x - x, dy = e.y - y;
  return len + std::sqrt(dx * dx + dy * dy);
}

namespace {
// Does walking row a leave the goal walking row b heads for, from nearer to it than b is?
bool lets_out(const AgentTable& t, std::span<const Goal> goals, std::size_t a, std::size_t b) {
  if (t.left_goal[a] != t.goal[b] || standing(t.state[a]) || standing(t.state[b])) return false;
  const Goal& g = goals[t.goal[b]];
  const double ax = t.x[a] - g.x, ay = t.y[a] - g.y, bx = t.x[b] - g.x, by = t.y[b] - g.y;
  return ax * ax + ay * ay < bx * bx + by * by;
}
}  // namespace

int out_before_in(const AgentTable& t, std::span<const Goal> goals, std::size_t i, std::size_t j) {
  const bool i_out = lets_out(t, goals, i, j), j_out = lets_out(t, goals, j, i);
  return i_out == j_out ? 0 : (i_out ? 1 : -1);
}

AheadInput ahead_input(const AgentTable& t, std::span<const Goal> goals, std::size_t i) {
  AheadInput h;
  h.x = t.x[i];
  h.y = t.y[i];
  h.goal = t.goal[i];
  h.left_goal = t.left_goal[i];
  const double dx = t.target_x[i] - t.x[i], dy = t.target_y[i] - t.y[i];
  const double to_target = std::sqrt(dx * dx + dy * dy);
  h.way_x = to_target > 0 ? dx / to_target : 0;
  h.way_y = to_target > 0 ? dy / to_target : 0;
  const Goal& g = goals[t.goal[i]];
  h.goal_x = g.x - t.x[i];
  h.goal_y = g.y - t.y[i];
  h.goal2 = h.goal_x * h.goal_x + h.goal_y * h.goal_y;
  return h;
}

void goal_stage(const AgentTable& t, std::span<const Goal> goals, const SimConfig& cfg,
                uint64_t tick, std::span<const uint32_t> demand, Preferred& pref, Executor& ex,
                const path::Navigation* nav, AimMemo* aims) {
  const double dt = cfg.dt;
  const bool sight = nav && cfg.navigation.skip_visible;
  const uint64_t sight_ticks = cfg.ticks_for(cfg.navigation.sight_interval);
  const bool lost_sight = nav && cfg.navigation.replan_after > 0;
  const uint64_t lost_ticks = cfg.ticks_for(kLostSightInterval);
  const uint64_t nudge_ticks = cfg.nudge_after > 0 ? cfg.ticks_for(cfg.nudge_after) : 0;
  const double noise = cfg.steering.perturbation;
  const NeededDiscs needed(t, goals, demand);
  ex.for_each_chunk(t.size(), kGrain, [&](std::size_t b, std::size_t e) {
    std::vector<uint32_t> near;  // candidates of NeededDiscs::lookup
    for (std::size_t i = b; i < e; ++i) {
      double px = 0, py = 0;  // preferred velocity
      pref.skip[i] = 0;
      pref.left[i] = INFINITY;  // (a walker's is set below)
      if (idle(t, i)) {
        const Goal& g = goals[t.goal[i]];
        if (making_way(t, i, tick)) {
          // Out of a stalled walker's way (sim/stalemate.hpp), at half its preferred speed.
          pref.vx[i] = 0.5 * t.pref_speed[i] * t.stall_dir_x[i];
          pref.vy[i] = 0.5 * t.pref_speed[i] * t.stall_dir_y[i];
          continue;
        }
        if (!demand.empty() && demand[t.goal[i]] > 0 && g.is_polygon()) {
          // An area others still head for: walk on into it, towards its inner point (where the
          // disc fits nearest to it), so that its edge stays free for those coming. Stepping off
          // the area instead put the first arrivals in the doorway the others came through
          // (Menge's maze example: 8 of 30 locked out for good).
          const Vec2 aim = goal_target(g, g.x, g.y, t.radius[i]);
          const double dx = aim.x - t.x[i], dy = aim.y - t.y[i];
          const double len = std::sqrt(dx * dx + dy * dy);
          if (len > t.radius[i]) {
            const double s = std::min(0.5 * t.pref_speed[i], len / dt);
            px = s * dx / len;
            py = s * dy / len;
          }
        } else if (!demand.empty() && demand[t.goal[i]] > 0 && on_disc(t, g, i)) {
          // Standing on (or touching) its goal's disc, which others still need: step off it.
          const Vec2 v = step_off(t, g, cfg, i);
          px = v.x;
          py = v.y;
        }
        if (px == 0 && py == 0 && needed.lookup) {
          // In the way of another goal's disc that others still need: step off the first one.
          needed.lookup->candidates(t.x[i], t.y[i], t.radius[i], near);
          for (uint32_t k : near) {
            const CircleObstacle& c = needed.area[k];
            if (needed.goal[k] == t.goal[i] ||
                !(length(c.x - t.x[i], c.y - t.y[i]) < c.radius + t.radius[i]))
              continue;
            const Vec2 v = step_off(t, goals[needed.goal[k]], cfg, i);
            px = v.x;
            py = v.y;
            break;
          }
        }
        pref.vx[i] = px;
        pref.vy[i] = py;
        continue;
      }
      Vec2 target = current_target(t, goals, i, aims);
      // path_left, without a second goal_target when the waypoint is the goal's own point.
      if (t.route[i].empty()) {
        const double dx = target.x - t.x[i], dy = target.y - t.y[i];
        pref.left[i] = std::sqrt(dx * dx + dy * dy);
      } else {
        pref.left[i] = path_left(t, goals, i, aims);
      }
      if (sight && !t.route[i].empty() && (tick + t.id[i]) % sight_ticks == 0) {
        // The waypoint after the current one: the next route point, or the goal.
        const auto& route = t.route[i];
        const Vec2 next = route.size() > 1
                              ? route[1]
                              : goal_target(goals[t.goal[i]], t.x[i], t.y[i], t.radius[i]);
        if (nav->visible(t.radius[i], t.id[i], {t.x[i], t.y[i]}, next)) {
          pref.skip[i] = kSkipWaypoint;
          target = next;
        }
      }
      if (lost_sight && !pref.skip[i] && (tick + t.id[i]) % lost_ticks == 0 && held_up(t, i)) {
        const double dx = target.x - t.x[i], dy = target.y - t.y[i];
        const double dist = std::sqrt(dx * dx + dy * dy);
        // (A target nearer than that is a corner at the obstacle itself, a door's post: the
        // search would give it again.)
        if (dist > kLostSightFar && nav->blocked_ahead(t.radius[i], t.id[i], {t.x[i], t.y[i]},
                                                       {t.x[i] + dx / dist * kLostSightLook,
                                                        t.y[i] + dy / dist * kLostSightLook}))
          pref.skip[i] = kLostSight;
      }
      const double dx = target.x - t.x[i], dy = target.y - t.y[i];
      const double dist = std::sqrt(dx * dx + dy * dy);
      if (dist > 0) {
        const double s = std::min(t.pref_speed[i], dist / dt);
        px = s * dx / dist;
        py = s * dy / dist;
      }
      if (t.stall_action[i] != StallAction::none && tick < t.stall_until[i]) {
        const double s = t.pref_speed[i] * (t.stall_action[i] == StallAction::sidestep ? 1.0 : 0.5);
        px = s * t.stall_dir_x[i];
        py = s * t.stall_dir_y[i];
      }
      if (nudge_ticks > 0 && t.frozen_ticks[i] >= nudge_ticks) {
        Rng rng = Rng::stream(cfg.seed ^ (tick * 0xd6e8feb86659fd93ull), t.id[i]);
        const double turn =
            rng.uniform(std::numbers::pi / 4, std::numbers::pi / 2) * (rng.below(2) ? 1 : -1);
        const double c = std::cos(turn), s = std::sin(turn);
        const double rx = c * px - s * py, ry = s * px + c * py;
        px = rx;
        py = ry;
      }
      if (noise > 0) {
        Rng rng = Rng::stream(cfg.seed ^ (tick * 0x94d049bb133111ebull), t.id[i] ^ 0xa11ce);
        double ux, uy;
        rng.direction(ux, uy);
        px += noise * ux;
        py += noise * uy;
      }
      pref.vx[i] = px;
      pref.vy[i] = py;
    }
  });
}

void integrate(const AgentTable& t, NextState& next, double dt, Executor& ex) {
  const std::size_t grain = chunk_rows(t.size(), kIntegrateGrain);
  ex.for_each_chunk(t.size(), grain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      next.x[i] = t.x[i] + next.vx[i] * dt;
      next.y[i] = t.y[i] + next.vy[i] * dt;
    }
  });
}

uint64_t state_hash(const AgentTable& t, uint64_t tick, Executor* ex) {
  const std::size_t n = t.size();
  const std::size_t blocks = (n + kHashBlock - 1) / kHashBlock;
  std::vector<uint64_t> digest(blocks);
  auto add_row = [&](StateHasher& h, std::size_t i) {
    h.add(t.id[i]);
    h.add(t.x[i]);
    h.add(t.y[i]);
    h.add(t.vx[i]);
    h.add(t.vy[i]);
    h.add(static_cast<uint64_t>(t.state[i]));
  };
  static_assert(kHashLanes == 4 && kHashBlock % kHashLanes == 0);
  auto hash_blocks = [&](std::size_t b, std::size_t e) {
    // The lanes as four locals (an array indexed by row kept them in memory); b is a multiple of
    // the lane count, so row i goes to lane i mod 4.
    StateHasher l0, l1, l2, l3;
    std::size_t i = b;
    for (; i + 4 <= e; i += 4) {
      add_row(l0, i);
      add_row(l1, i + 1);
      add_row(l2, i + 2);
      add_row(l3, i + 3);
    }
    if (i < e) add_row(l0, i++);
    if (i < e) add_row(l1, i++);
    if (i < e) add_row(l2, i++);
    StateHasher block;
    for (const StateHasher* h : {&l0, &l1, &l2, &l3}) block.add(h->digest());
    digest[b / kHashBlock] = block.digest();
  };
  if (ex)
    ex->for_each_chunk(n, kHashBlock, hash_blocks);
  else
    for (std::size_t b = 0; b < n; b += kHashBlock) hash_blocks(b, std::min(n, b + kHashBlock));
  StateHasher h;
  h.add(tick);
  h.add(static_cast<uint64_t>(n));
  for (const uint64_t d : digest) h.add(d);
  return h.digest();
}

}  // namespace crowddb::sim
