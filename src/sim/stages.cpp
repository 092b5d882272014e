#include "sim/stages.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>

#include "path/navigation.hpp"
#include "util/hash.hpp"
#include "util/rng.hpp"
#include "world/geometry.hpp"

namespace crowddb::sim {
namespace {

constexpr std::size_t kGrain = 256;

bool idle(const AgentTable& t, std::size_t i) {
  return t.state[i] == AgentState::arrived;
}

}  // namespace

void Effects::reset(std::size_t n) {
  for (auto* c : {&attract_x, &attract_y, &apf_x, &apf_y, &ftc_x, &ftc_y}) c->assign(n, 0.0);
  skip.assign(n, 0);
}

void NextState::resize(std::size_t n) {
  x.resize(n);
  y.resize(n);
  vx.resize(n);
  vy.resize(n);
  frozen.assign(n, 0);
}

void attraction(const AgentTable& t, std::span<const Goal> goals, const SimConfig& cfg,
                uint64_t tick, Effects& fx, Executor& ex, const path::Navigation* nav) {
  const double tau = cfg.steering.tau, dt = cfg.dt;
  const bool sight = nav && cfg.navigation.skip_visible;
  ex.for_each_chunk(t.size(), kGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (idle(t, i)) continue;
      double tx = t.target_x[i], ty = t.target_y[i];
      if (sight && !t.route[i].empty() && (tick + t.id[i]) % cfg.navigation.sight_interval == 0) {
        // The waypoint after the current one: the next route point, or the goal.
        const auto& route = t.route[i];
        const Goal& g = goals[t.goal[i]];
        const Vec2 next = route.size() > 1 ? route[1] : Vec2{g.x, g.y};
        if (nav->visible(t.radius[i], {t.x[i], t.y[i]}, next)) {
          fx.skip[i] = 1;
          tx = next.x;
          ty = next.y;
        }
      }
      const double dx = tx - t.x[i], dy = ty - t.y[i];
      const double dist = std::sqrt(dx * dx + dy * dy);
      double px = 0, py = 0;  // preferred velocity
      if (dist > 0) {
        const double s = std::min(t.max_speed[i], dist / dt);
        px = s * dx / dist;
        py = s * dy / dist;
      }
      if (cfg.nudge_after > 0 && t.frozen_ticks[i] >= cfg.nudge_after) {
        Rng rng = Rng::stream(cfg.seed ^ (tick * 0xd6e8feb86659fd93ull), t.id[i]);
        const double turn =
            rng.uniform(std::numbers::pi / 4, std::numbers::pi / 2) * (rng.below(2) ? 1 : -1);
        const double c = std::cos(turn), s = std::sin(turn);
        const double rx = c * px - s * py, ry = s * px + c * py;
        px = rx;
        py = ry;
      }
      const double c = goals[t.goal[i]].charge;
      fx.attract_x[i] = c * (px - t.vx[i]) / tau;
      fx.attract_y[i] = c * (py - t.vy[i]) / tau;
    }
  });
}

void inner_avoidance(const FieldColumns& field, const SimConfig& cfg, Effects& fx, Executor& ex) {
  const double w = cfg.steering.w_apf;
  ex.for_each_chunk(field.grad_x.size(), kGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      fx.apf_x[i] = -w * field.grad_x[i];
      fx.apf_y[i] = -w * field.grad_y[i];
    }
  });
}

void outer_avoidance(const AgentTable& t, const StaticScene& scene, std::span<const FtcHit> hits,
                     const SimConfig& cfg, Effects& fx, Executor& ex) {
  const double w = cfg.steering.w_ftc, horizon = cfg.steering.horizon;
  ex.for_each_chunk(t.size(), kGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      const FtcHit& h = hits[i];
      if (h.with.kind == Collider::Kind::none || idle(t, i)) continue;
      const double ts = h.time;
      const double ax = t.x[i] + t.vx[i] * ts, ay = t.y[i] + t.vy[i] * ts;  // a at t*
      double bx, by, bvx = 0, bvy = 0;                                      // b at t*
      switch (h.with.kind) {
        case Collider::Kind::agent:
          bvx = t.vx[h.with.row];
          bvy = t.vy[h.with.row];
          bx = t.x[h.with.row] + bvx * ts;
          by = t.y[h.with.row] + bvy * ts;
          break;
        case Collider::Kind::circle:
          bx = scene.circles()[h.with.row].x;
          by = scene.circles()[h.with.row].y;
          break;
        case Collider::Kind::polygon:
        default: {
          Vec2 c{};
          dist2_to_boundary(scene.polygons()[h.with.row].vertices, ax, ay, &c);
          bx = c.x;
          by = c.y;
          break;
        }
      }
      double nx = ax - bx, ny = ay - by;
      double len = std::sqrt(nx * nx + ny * ny);
      if (len ==
          0) {  // centres coincide at t*: sidestep, counter-clockwise of the relative velocity
        nx = -(t.vy[i] - bvy);
        ny = t.vx[i] - bvx;
        len = std::sqrt(nx * nx + ny * ny);
        if (len == 0) continue;
      }
      const double s = w * (1 - ts / horizon) / len;
      fx.ftc_x[i] = s * nx;
      fx.ftc_y[i] = s * ny;
    }
  });
}

void combine_integrate(const AgentTable& t, const Effects& fx, const SimConfig& cfg,
                       NextState& next, Executor& ex) {
  const double dt = cfg.dt;
  ex.for_each_chunk(t.size(), kGrain, [&](std::size_t b, std::size_t e) {
    for (std::size_t i = b; i < e; ++i) {
      if (idle(t, i)) {
        next.x[i] = t.x[i];
        next.y[i] = t.y[i];
        next.vx[i] = 0;
        next.vy[i] = 0;
        continue;
      }
      double ax = fx.attract_x[i] + fx.apf_x[i] + fx.ftc_x[i];
      double ay = fx.attract_y[i] + fx.apf_y[i] + fx.ftc_y[i];
      const double a = std::sqrt(ax * ax + ay * ay);
      if (a > t.max_accel[i]) {
        ax *= t.max_accel[i] / a;
        ay *= t.max_accel[i] / a;
      }
      double vx = t.vx[i] + ax * dt, vy = t.vy[i] + ay * dt;
      const double v = std::sqrt(vx * vx + vy * vy);
      if (v > t.max_speed[i]) {
        vx *= t.max_speed[i] / v;
        vy *= t.max_speed[i] / v;
      }
      next.vx[i] = vx;
      next.vy[i] = vy;
      next.x[i] = t.x[i] + vx * dt;
      next.y[i] = t.y[i] + vy * dt;
    }
  });
}

uint64_t state_hash(const AgentTable& t, uint64_t tick) {
  StateHasher h;
  h.add(tick);
  h.add(static_cast<uint64_t>(t.size()));
  for (std::size_t i = 0; i < t.size(); ++i) {
    h.add(t.id[i]);
    h.add(t.x[i]);
    h.add(t.y[i]);
    h.add(t.vx[i]);
    h.add(t.vy[i]);
    h.add(static_cast<uint64_t>(t.state[i]));
  }
  return h.digest();
}

}  // namespace crowddb::sim
