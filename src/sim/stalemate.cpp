#include "sim/stalemate.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "sim/stages.hpp"
#include "util/rng.hpp"

namespace crowddb::sim {
namespace {

constexpr double kBlockGap = 0.6;  // [m] a blocker's disc is this close to the agent's, or less

uint64_t priority(uint64_t seed, uint64_t id) {
  uint64_t s = seed ^ (id * 0x9e3779b97f4a7c15ull);
  return splitmix64(s);
}

}  // namespace

StallCounts watch_progress(World& world, const SimConfig& cfg) {
  AgentTable& t = world.agents_for_tick();
  const uint64_t after = cfg.ticks_for(cfg.stall.after);
  StallCounts c;
  for (std::size_t i = 0; i < t.size(); ++i) {
    if (t.state[i] == AgentState::arrived) {
      t.stall_ticks[i] = 0;
      t.stall_action[i] = StallAction::none;
      continue;
    }
    const double d = distance_to_target(t, world.goals(), i);
    if (!std::isfinite(t.progress_best[i])) {
      t.progress_best[i] = d;  // a new target (or path): this tick is the reference
    } else if (d < t.progress_best[i] - cfg.stall.progress) {
      t.progress_best[i] = d;
      t.stall_ticks[i] = 0;
      t.replan_ticks[i] = 0;
      t.stall_action[i] = StallAction::none;  // unstuck
    } else {
      ++t.stall_ticks[i];
      ++t.replan_ticks[i];
    }
    if (t.stall_ticks[i] >= after) ++c.stalled;
    if (t.stall_ticks[i] == after) ++c.started;
    c.longest = std::max<std::size_t>(c.longest, t.stall_ticks[i]);
  }
  return c;
}

void resolve_stalemates(World& world, const SimConfig& cfg, uint64_t tick, NeighbourPath& path,
                        Executor& ex, QueryStats& stats, StallCounts& counts) {
  AgentTable& t = world.agents_for_tick();
  const uint64_t after = cfg.ticks_for(cfg.stall.after);
  std::vector<uint32_t> deciding;
  double rmax = 0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    rmax = std::max(rmax, t.radius[i]);
    if (t.stall_action[i] != StallAction::none && tick >= t.stall_until[i])
      t.stall_action[i] = StallAction::none;
    if (t.state[i] != AgentState::arrived && t.stall_ticks[i] >= after &&
        t.stall_action[i] == StallAction::none)
      deciding.push_back(static_cast<uint32_t>(i));
  }
  if (deciding.empty()) return;
  NeighbourLists nb;
  path.run(DiscView::of(t), deciding, 2 * rmax + kBlockGap, 6, nb, ex, stats);
  for (std::size_t q = 0; q < deciding.size(); ++q) {
    const uint32_t i = deciding[q];
    const Vec2 target = current_target(t, world.goals(), i);
    double dx = target.x - t.x[i], dy = target.y - t.y[i];
    const double dl = std::sqrt(dx * dx + dy * dy);
    if (dl == 0) continue;
    dx /= dl;
    dy /= dl;
    int64_t blocker = -1;
    for (uint32_t j : nb.rows_of(q)) {
      const double rx = t.x[j] - t.x[i], ry = t.y[j] - t.y[i];
      const double gap = std::sqrt(rx * rx + ry * ry) - t.radius[i] - t.radius[j];
      if (gap < kBlockGap && rx * dx + ry * dy > 0) {
        blocker = j;
        break;
      }
    }
    const auto j = static_cast<std::size_t>(blocker);
    const bool blocker_stalled =
        blocker >= 0 && t.state[j] != AgentState::arrived && t.stall_ticks[j] >= after;
    if (blocker_stalled && priority(cfg.seed, t.id[j]) > priority(cfg.seed, t.id[i])) {
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
      t.stall_action[i] = StallAction::yield;
      t.stall_dir_x[i] = yx;
      t.stall_dir_y[i] = yy;
      t.stall_until[i] = tick + cfg.ticks_for(cfg.stall.yield_time);
      ++counts.yielding;
    } else if (blocker_stalled) {
      continue;  // the blocker yields to this one
    } else {
      Rng rng = Rng::stream(cfg.seed ^ (tick * 0xbf58476d1ce4e5b9ull), t.id[i]);
      const double turn =
          rng.uniform(std::numbers::pi / 4, std::numbers::pi / 2) * (rng.below(2) ? 1 : -1);
      const double c = std::cos(turn), s = std::sin(turn);
      t.stall_action[i] = StallAction::sidestep;
      t.stall_dir_x[i] = c * dx - s * dy;
      t.stall_dir_y[i] = s * dx + c * dy;
      t.stall_until[i] = tick + cfg.ticks_for(cfg.stall.sidestep_time);
      ++counts.sidestepping;
    }
  }
}

}  // namespace crowddb::sim
