// Model "cfsm": the collision-free speed model (Tordeux, Chraibi, Seyfried 2016), JuPedSim's
// default. A first-order model: no inertia, the velocity is set each tick.
//
//   neighbours   every agent within `cutoff` (NeighbourPath, k = 0) that no obstacle edge hides
//   obstacles    obstacle features within `cutoff` (FeaturePath)
//   direction    e = unit(e0 + sum_j a exp((l - d_ij) / D) n_ji + sum_walls a_w exp((r - d_iw) /
//                D_w) n_wi), e0 the unit preferred direction, l = r_i + r_j, n_ji from j to i
//   speed        v = min(max(s / T, 0), v0), s the spacing to the nearest neighbour ahead within
//                the corridor of width 2 l along e (distance of centres minus l), v0 = |v_pref|
//
// When the repulsions cancel the preferred direction exactly, the agent keeps its heading (the
// direction of its current velocity) and, standing still, its preferred direction.
//
// Contact clipping (ours): the headway rule only looks at neighbours inside the corridor ahead,
// so a turned direction can run a disc into a neighbour beside it or into a wall, which JuPedSim
// reports as a model violation and our backoff would freeze (two people in a 0.7 m corridor froze
// for good). So the speed along e is also capped so that the move closes at most half of the gap
// to any visible neighbour and all but a micrometre of the gap to any obstacle feature within one
// tick. Both agents of a pair keep to their half, so no move of the model overlaps.
#include <cmath>
#include <map>

#include "plan/access_path.hpp"
#include "steer/model.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::steer {
namespace {

constexpr uint32_t kCorridorBatch = 32;  // neighbours filtered at once for the corridor ahead

// Do segments [a, b] and [c, d] intersect (touching counts)?
bool segments_cross(double ax, double ay, double bx, double by, const Vec2& c, const Vec2& d) {
  auto orient = [](double px, double py, double qx, double qy, double rx, double ry) {
    const double v = (qx - px) * (ry - py) - (qy - py) * (rx - px);
    return (v > 0) - (v < 0);
  };
  auto on = [](double px, double py, double qx, double qy, double rx, double ry) {
    return std::min(px, qx) <= rx && rx <= std::max(px, qx) && std::min(py, qy) <= ry &&
           ry <= std::max(py, qy);
  };
  const int o1 = orient(ax, ay, bx, by, c.x, c.y), o2 = orient(ax, ay, bx, by, d.x, d.y);
  const int o3 = orient(c.x, c.y, d.x, d.y, ax, ay), o4 = orient(c.x, c.y, d.x, d.y, bx, by);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && on(ax, ay, bx, by, c.x, c.y)) || (o2 == 0 && on(ax, ay, bx, by, d.x, d.y)) ||
         (o3 == 0 && on(c.x, c.y, d.x, d.y, ax, ay)) || (o4 == 0 && on(c.x, c.y, d.x, d.y, bx, by));
}

class CfsmModel final : public Model {
 public:
  void velocities(const TickInput& in, std::span<double> vx, std::span<double> vy, Executor& ex,
                  sim::OpLog& log) override {
    const AgentTable& t = in.agents;
    const CfsmParams& p = in.cfg.steering.cfsm;
    const std::size_t n = t.size();
    const DiscView view = DiscView::of(t);
    near_ = {};  // until this call's lists are in
    const NeighbourMethod& nm = neighbour_method(in.cfg.access.neighbours, n);
    log.used("neighbours=" + nm.info.name);
    auto& neighbours = neighbour_paths_[nm.info.name];
    if (!neighbours) neighbours = nm.make();
    const bool obstacles = in.scene.feature_count() > 0;
    const FeatureMethod* fm =
        obstacles ? &feature_method(in.cfg.access.edges, in.scene.feature_count()) : nullptr;
    if (fm) log.used("edges=" + fm->info.name);
    // The two queries do not read each other's answers: side by side on the same threads
    // (Executor::both), so that neither's one-thread parts leave the other thread idle. Each is
    // timed on its own (EXPLAIN ANALYZE); their times overlap.
    sim::OperatorStats neighbour_op, obstacle_op;
    Stopwatch side_by_side;
    ex.both(
        [&] {
          Stopwatch sw;
          nb_.with_dist2 = false;  // recomputed where needed (dist2_of)
          neighbours->run(view, {}, p.cutoff, 0, nb_, ex, neighbour_op.query);
          near_ = {&nb_, p.cutoff, 0};
          neighbour_op.seconds = sw.seconds();
        },
        [&] {
          Stopwatch sw;
          if (obstacles) {
            reach_.assign(n, p.cutoff);
            auto& path = feature_paths_[fm->info.name];
            if (!path) path = fm->make();
            path->run(view, reach_, in.scene, features_, ex, obstacle_op.query);
          } else {
            features_.offset.assign(n + 1, 0);
            features_.feature.clear();
            features_.dist2.clear();
          }
          obstacle_op.seconds = sw.seconds();
        });
    // Only the times booked below count towards the overlap (no obstacles: none booked).
    log.side_by_side(neighbour_op.seconds + (obstacles ? obstacle_op.seconds : 0),
                     side_by_side.seconds());
    log.book("CFSM neighbours", n, neighbour_op.seconds).query += neighbour_op.query;
    if (obstacles) {
      sim::OperatorStats& op = log.book("CFSM obstacles", n, obstacle_op.seconds);
      op.query += obstacle_op.query;
      if (ex.threads() > 1) op.beside = "CFSM neighbours";
    }
    log.timed("CFSM rule", n, [&] {
      ex.for_each_chunk(n, kGrain, [&](std::size_t b, std::size_t e) {
        for (std::size_t i = b; i < e; ++i) rule(in, i, vx[i], vy[i]);
      });
    });
  }

  void explain(std::ostream& os, const TickInput& in, int& step) const override {
    const CfsmParams& p = in.cfg.steering.cfsm;
    const std::size_t n = in.agents.size();
    const NeighbourMethod& nm = neighbour_method(in.cfg.access.neighbours, n);
    os << "  " << step++ << " CFSM neighbours    every agent within " << explain_number(p.cutoff)
       << " m (" << n << " rows)\n       access path: " << nm.info.name << " ("
       << nm.info.description << ")\n";
    if (in.scene.feature_count() > 0) {
      const FeatureMethod& fm = feature_method(in.cfg.access.edges, in.scene.feature_count());
      os << "  " << step++ << " CFSM obstacles     obstacle features within "
         << explain_number(p.cutoff) << " m\n       access path: " << fm.info.name << " ("
         << fm.info.description << ")\n";
    }
    os << "  " << step++ << " CFSM rule          direction from exponential repulsion (a="
       << explain_number(p.strength_neighbor) << ", D=" << explain_number(p.range_neighbor)
       << " m; walls a=" << explain_number(p.strength_geometry)
       << ", D=" << explain_number(p.range_geometry)
       << " m); speed min(max(s/T, 0), v0), T=" << explain_number(p.time_gap) << " s\n";
  }

  NearLists near_lists() const override { return near_; }

 private:
  // Is the segment from agent i to agent j blocked by one of i's nearby obstacle edges?
  bool hidden(const TickInput& in, std::size_t i, std::size_t j) const {
    const AgentTable& t = in.agents;
    const StaticScene& scene = in.scene;
    for (uint32_t a = features_.offset[i]; a < features_.offset[i + 1]; ++a) {
      const std::size_t f = features_.feature[a];
      if (f < scene.circles().size()) {
        // A circle hides j when the segment passes through it.
        const CircleObstacle& c = scene.circles()[f];
        const Vec2 p0{t.x[i], t.y[i]}, p1{t.x[j], t.y[j]};
        const double ex = p1.x - p0.x, ey = p1.y - p0.y, len2 = ex * ex + ey * ey;
        double s = len2 > 0 ? ((c.x - p0.x) * ex + (c.y - p0.y) * ey) / len2 : 0;
        s = s < 0 ? 0 : (s > 1 ? 1 : s);
        const double dx = p0.x + s * ex - c.x, dy = p0.y + s * ey - c.y;
        if (dx * dx + dy * dy < c.radius * c.radius) return true;
        continue;
      }
      const StaticScene::Edge& e = scene.edge(f);
      if (segments_cross(t.x[i], t.y[i], t.x[j], t.y[j], e.a, e.b)) return true;
    }
    return false;
  }

  void rule(const TickInput& in, std::size_t i, double& out_x, double& out_y) const {
    const AgentTable& t = in.agents;
    const CfsmParams& p = in.cfg.steering.cfsm;
    const double x = t.x[i], y = t.y[i], r = t.radius[i];
    const double px = in.pref_vx[i], py = in.pref_vy[i];
    const double v0 = std::sqrt(px * px + py * py);
    double e0x = 0, e0y = 0;
    if (v0 > 0) {
      e0x = px / v0;
      e0y = py / v0;
    }
    double dx = e0x, dy = e0y;
    const uint32_t lo = nb_.offset[i], hi = nb_.offset[i + 1];
    for (uint32_t a = lo; a < hi; ++a) {
      const uint32_t j = nb_.row[a];
      const double d = std::sqrt(dist2_of(t, i, j));
      if (d == 0 || hidden(in, i, j)) continue;
      const double s = p.strength_neighbor * std::exp((r + t.radius[j] - d) / p.range_neighbor);
      dx += s * (x - t.x[j]) / d;
      dy += s * (y - t.y[j]) / d;
    }
    for (uint32_t a = features_.offset[i]; a < features_.offset[i + 1]; ++a) {
      const std::size_t f = features_.feature[a];
      const Vec2 c = feature_closest(in.scene, f, x, y);
      const double wx = x - c.x, wy = y - c.y, d = std::sqrt(wx * wx + wy * wy);
      if (d == 0) continue;
      const double s = p.strength_geometry * std::exp((r - d) / p.range_geometry);
      dx += s * wx / d;
      dy += s * wy / d;
    }
    double len = std::sqrt(dx * dx + dy * dy);
    if (len == 0) {  // balanced: keep the heading
      dx = t.vx[i];
      dy = t.vy[i];
      len = std::sqrt(dx * dx + dy * dy);
      if (len == 0) {
        dx = e0x;
        dy = e0y;
        len = v0 > 0 ? 1 : 0;
      }
      if (len == 0) {
        out_x = out_y = 0;
        return;
      }
    }
    dx /= len;
    dy /= len;
    // Spacing to the nearest neighbour ahead in the corridor of width 2 l along e.
    // In batches: first the neighbours in the corridor ahead, without branches (whether one is
    // behind is a coin toss to the predictor), then their spacings in list order. (The tests as
    // ints: & on them is meant.)
    double spacing = INFINITY;
    for (uint32_t a0 = lo; a0 < hi; a0 += kCorridorBatch) {
      const uint32_t a1 = a0 + std::min(kCorridorBatch, hi - a0);
      uint32_t ahead[kCorridorBatch];
      uint32_t m = 0;
      for (uint32_t a = a0; a < a1; ++a) {
        const uint32_t j = nb_.row[a];
        const double rx = t.x[j] - x, ry = t.y[j] - y;
        ahead[m] = j;
        m += static_cast<uint32_t>(int{!(rx * dx + ry * dy < 0)} &                          // ahead
                                   int{!(std::abs(ry * dx - rx * dy) > r + t.radius[j])});  // in it
      }
      for (uint32_t u = 0; u < m; ++u) {
        const uint32_t j = ahead[u];
        if (hidden(in, i, j)) continue;
        spacing = std::min(spacing, std::sqrt(dist2_of(t, i, j)) - (r + t.radius[j]));
      }
    }
    double speed = std::min(std::max(spacing / p.time_gap, 0.0), v0);
    // Contact clipping: at most half the gap to a neighbour, all of it to an obstacle, per tick.
    const double dt = in.cfg.dt;
    for (uint32_t a = lo; a < hi && speed > 0; ++a) {
      const uint32_t j = nb_.row[a];
      const double d = std::sqrt(dist2_of(t, i, j));
      if (d == 0) continue;
      const double along = ((t.x[j] - x) * dx + (t.y[j] - y) * dy) / d;  // e . n_ij
      // Only towards j (along > 0); picked by mask, not by a jump (a coin toss, as above).
      const double gap = std::max(0.0, d - r - t.radius[j] - kSkin);
      speed = std::min(speed, pick(!(along <= 0), 0.5 * gap / (dt * along), INFINITY));
    }
    for (uint32_t a = features_.offset[i]; a < features_.offset[i + 1] && speed > 0; ++a) {
      const Vec2 c = feature_closest(in.scene, features_.feature[a], x, y);
      const double wx = c.x - x, wy = c.y - y, d = std::sqrt(wx * wx + wy * wy);
      if (d == 0) {
        speed = 0;
        break;
      }
      const double along = (wx * dx + wy * dy) / d;
      if (along <= 0) continue;
      speed = std::min(speed, std::max(0.0, d - r - kSkin) / (dt * along));
    }
    out_x = dx * speed;
    out_y = dy * speed;
  }

  NeighbourLists nb_;
  NearLists near_;  // nb_ with what it was asked, once this tick's query ran
  FeatureLists features_;
  std::vector<double> reach_;
  std::map<std::string, std::unique_ptr<NeighbourPath>> neighbour_paths_;
  std::map<std::string, std::unique_ptr<FeaturePath>> feature_paths_;
};

}  // namespace

std::unique_ptr<Model> make_cfsm_model() {
  return std::make_unique<CfsmModel>();
}

}  // namespace crowddb::steer
