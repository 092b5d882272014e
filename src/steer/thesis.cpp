// Model "thesis": the thesis's steering rule (DESIGN.md §3.1), kept for its experiments.
//
//   Q1 attraction        c_goal (v_pref - v) / tau
//   Q2 inner avoidance   -w_apf grad of the potential field over the other agents; obstacles
//                        either by their nearest geometry within a cut-off (default) or by the
//                        thesis's charged points in the field
//   Q3 outer avoidance   w_ftc (1 - t*/T) along the line of centres at the first collision
//   combine              sum, |a| <= max_accel, v' = v + a dt, |v'| <= max_speed
//
// Why the nearest geometry: a wall sampled into hundreds of charged points sums to a field whose
// local minima trap agents that have a path (an agent in a serpentine stopped 1.8 m from the
// nearest wall for 970 s). One repulsion per obstacle feature, from its nearest point along its
// normal, cannot add up to a pocket in front of a straight wall.
#include <algorithm>
#include <cmath>
#include <map>

#include "plan/access_path.hpp"
#include "query/scene_polygons.hpp"
#include "steer/model.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb::steer {
namespace {

constexpr std::size_t kThesisGrain = 256;

const char* kernel_name(Kernel k) {
  return k == Kernel::exp ? "exp" : "inv";
}
const char* metric_name(Metric m) {
  return m == Metric::l1 ? "l1" : (m == Metric::l2 ? "l2" : "radial");
}

// |dK/dd| of the potential's kernel at distance d (the inv kernel's floor as in DESIGN.md §4).
double kernel_slope(const PotentialSpec& s, double d) {
  if (s.kernel == Kernel::exp) return s.k * std::exp(-s.k * d);
  const double f = std::max(d, s.inv_floor);
  return d < s.inv_floor ? 0.0 : 1.0 / (f * f);
}

class ThesisModel final : public Model {
 public:
  void velocities(const TickInput& in, std::span<double> vx, std::span<double> vy, Executor& ex,
                  sim::OpLog& log) override {
    const AgentTable& t = in.agents;
    const ThesisParams& p = in.cfg.steering.thesis;
    const std::size_t n = t.size();
    const DiscView view = DiscView::of(t);
    for (auto* c : {&ax_, &ay_, &fx_, &fy_, &ox_, &oy_, &qx_, &qy_}) c->assign(n, 0.0);

    log.timed("Q1 attraction", n, [&] { attraction(in, ex); });
    // Q2 and Q3 read the table and write columns of their own: they run beside each other on the
    // same threads (Executor::both), so that neither's one-thread parts (the field's serial
    // passes and its two sweeps, which occupy two threads at most; the tree's top levels) leave
    // a thread idle. Each is timed on its own (EXPLAIN ANALYZE); side by side, their times
    // overlap.
    const FieldMethod* field = p.w_apf > 0 ? &field_method(in) : nullptr;
    const FeatureMethod* edges =
        field && p.obstacle_repulsion == ThesisParams::ObstacleRepulsion::nearest &&
                in.scene.feature_count() > 0
            ? &feature_method(in.cfg.access.edges, in.scene.feature_count())
            : nullptr;
    const FtcMethod* ftc = p.w_ftc > 0 ? &ftc_method(in) : nullptr;
    if (field) log.used("field=" + field->info.name);
    if (edges) log.used("edges=" + edges->info.name);
    if (ftc) log.used("ftc=" + ftc->info.name);
    sim::OperatorStats field_op, edges_op, ftc_op;
    bool hinted = false;  // the first-to-collide method took the hint that nothing overlaps
    Stopwatch side_by_side;
    ex.both(
        [&] {
          if (field) {
            Stopwatch sw;
            path(field_paths_, *field).run(view, in.scene, p.potential, field_, ex, field_op.query);
            ex.for_each_chunk(n, kThesisGrain, [&](std::size_t b, std::size_t e) {
              for (std::size_t i = b; i < e; ++i) {
                fx_[i] = -p.w_apf * field_.grad_x[i];
                fy_[i] = -p.w_apf * field_.grad_y[i];
              }
            });
            field_op.seconds = sw.seconds();
          }
          if (edges) {
            Stopwatch sw;
            nearest_obstacles(in, view, *edges, ex, edges_op.query);
            edges_op.seconds = sw.seconds();
          }
        },
        [&] {
          if (!ftc) return;
          Stopwatch sw;
          hits_.assign(n, FtcHit{});
          FtcPath& f = path(ftc_paths_, *ftc);
          // On a tick that starts without overlaps the index skips its overlaps-first pass (cost
          // only: the answers are the same).
          hinted = f.assume_no_overlaps(in.no_overlaps) && in.no_overlaps;
          f.run(view, in.scene, p.horizon, hits_, ex, ftc_op.query);
          outer(in, ex);
          ftc_op.seconds = sw.seconds();
        });
    log.side_by_side(field_op.seconds + edges_op.seconds + ftc_op.seconds, side_by_side.seconds());
    const bool beside = ftc && field && ex.threads() > 1;
    if (field) {
      sim::OperatorStats& op = log.book("Q2 inner avoidance", n, field_op.seconds);
      op.query += field_op.query;
      if (beside) op.beside = "Q3 outer avoidance";
    }
    if (edges) {
      sim::OperatorStats& op = log.book("Q2 obstacles", n, edges_op.seconds);
      op.query += edges_op.query;
      if (beside) op.beside = "Q3 outer avoidance";
    }
    if (ftc) {
      sim::OperatorStats& op = log.book("Q3 outer avoidance", n, ftc_op.seconds);
      op.query += ftc_op.query;
      op.count("ticks with no overlap pass (none at the start)", hinted ? 1 : 0);
    }
    log.timed("combine", n, [&] { combine(in, vx, vy, ex); });
  }

  void explain(std::ostream& os, const TickInput& in, int& step) const override {
    const ThesisParams& p = in.cfg.steering.thesis;
    const std::size_t n = in.agents.size();
    os << "  " << step++
       << " Q1 attraction      c_goal (v_pref - v) / tau, tau=" << explain_number(p.tau) << " s\n";
    if (p.w_apf > 0) {
      const FieldMethod& m = field_method(in);
      os << "  " << step++ << " Q2 inner avoidance potential field "
         << kernel_name(p.potential.kernel) << "-" << metric_name(p.potential.metric)
         << " A=" << explain_number(p.potential.A) << " k=" << explain_number(p.potential.k)
         << " w_apf=" << explain_number(p.w_apf) << " over the other agents"
         << (p.obstacle_repulsion == ThesisParams::ObstacleRepulsion::charges
                 ? " and the obstacles' charged points"
                 : "")
         << "\n       access path: " << m.info.name << " (" << m.info.description << ")\n";
      if (p.obstacle_repulsion == ThesisParams::ObstacleRepulsion::nearest) {
        const FeatureMethod& fm = feature_method(in.cfg.access.edges, in.scene.feature_count());
        os << "       obstacles: the nearest obstacle feature within "
           << explain_number(p.obstacle_cutoff)
           << " m pushes along its normal with the kernel's slope\n       access path: "
           << fm.info.name << " (" << fm.info.description << ")\n";
      }
    } else {
      os << "  " << step++ << " Q2 inner avoidance off (w_apf = 0)\n";
    }
    if (p.w_ftc > 0) {
      const FtcMethod& m = ftc_method(in);
      os << "  " << step++
         << " Q3 outer avoidance first-to-collide, horizon=" << explain_number(p.horizon)
         << " s w_ftc=" << explain_number(p.w_ftc) << "\n       access path: " << m.info.name
         << " (" << m.info.description << ")\n";
    } else {
      os << "  " << step++ << " Q3 outer avoidance off (w_ftc = 0)\n";
    }
    os << "  " << step++
       << " combine            sum effects; |a| <= max_accel; v' = v + a dt; |v'| <= max_speed ("
       << n << " rows)\n";
  }

 private:
  const FieldMethod& field_method(const TickInput& in) const {
    const PotentialSpec& s = in.cfg.steering.thesis.potential;
    const std::size_t rows = in.agents.size();
    return in.cfg.access.field == "auto" ? choose_field_method(rows, s)
                                         : find_field_method(in.cfg.access.field, s);
  }
  const FtcMethod& ftc_method(const TickInput& in) const {
    return in.cfg.access.ftc == "auto" ? choose_ftc_method(in.agents.size())
                                       : find_ftc_method(in.cfg.access.ftc);
  }
  template <class Map, class Method>
  static typename Map::mapped_type::element_type& path(Map& map, const Method& m) {
    auto& slot = map[m.info.name];
    if (!slot) slot = m.make();
    return *slot;
  }

  void attraction(const TickInput& in, Executor& ex) {
    const AgentTable& t = in.agents;
    const double tau = in.cfg.steering.thesis.tau;
    ex.for_each_chunk(t.size(), kThesisGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        if (standing(t.state[i])) continue;
        const double c = in.goals[t.goal[i]].charge;
        ax_[i] = c * (in.pref_vx[i] - t.vx[i]) / tau;
        ay_[i] = c * (in.pref_vy[i] - t.vy[i]) / tau;
      }
    });
  }

  // The nearest obstacle feature within the cut-off pushes agent i away along the line from its
  // nearest point: w_apf A c_i c_obstacle |K'(d)|, d the distance of centre and nearest point.
  void nearest_obstacles(const TickInput& in, const DiscView& view, const FeatureMethod& fm,
                         Executor& ex, QueryStats& qs) {
    const AgentTable& t = in.agents;
    const ThesisParams& p = in.cfg.steering.thesis;
    reach_.assign(t.size(), p.obstacle_cutoff);
    auto& fpath = feature_paths_[fm.info.name];
    if (!fpath) fpath = fm.make();
    fpath->run(view, reach_, in.scene, features_, ex, qs);
    const std::size_t circles = in.scene.circles().size();
    ex.for_each_chunk(t.size(), kThesisGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const uint32_t lo = features_.offset[i], hi = features_.offset[i + 1];
        if (lo == hi) continue;
        uint32_t best = lo;  // nearest, the lower feature number on ties (lists are ascending)
        for (uint32_t a = lo + 1; a < hi; ++a)
          if (features_.dist2[a] < features_.dist2[best]) best = a;
        const std::size_t f = features_.feature[best];
        const Vec2 c = feature_closest(in.scene, f, t.x[i], t.y[i]);
        double nx = t.x[i] - c.x, ny = t.y[i] - c.y;
        const double d = std::sqrt(nx * nx + ny * ny);
        if (d == 0) continue;  // on the boundary: the backoff keeps it out
        nx /= d;
        ny /= d;
        const double charge = f < circles ? in.scene.circles()[f].charge
                                          : in.scene.polygons()[in.scene.edge_of(f).first].charge;
        const double s =
            p.w_apf * p.potential.A * t.charge[i] * charge * kernel_slope(p.potential, d);
        ox_[i] = s * nx;
        oy_[i] = s * ny;
      }
    });
  }

  // Q3: push away from the first collider along the line of centres predicted at the collision
  // time, scaled by (1 - t/T); the perpendicular of the relative velocity when that line is zero.
  void outer(const TickInput& in, Executor& ex) {
    const AgentTable& t = in.agents;
    const StaticScene& scene = in.scene;
    const double w = in.cfg.steering.thesis.w_ftc, horizon = in.cfg.steering.thesis.horizon;
    ex.for_each_chunk(t.size(), kThesisGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        const FtcHit& h = hits_[i];
        if (h.with.kind == Collider::Kind::none || standing(t.state[i])) continue;
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
            // Touching at t*: within about a radius of the boundary (exact at any distance).
            scene_polygon_dist2(scene, h.with.row, ax, ay, 2 * t.radius[i], &c);
            bx = c.x;
            by = c.y;
            break;
          }
        }
        double nx = ax - bx, ny = ay - by;
        double len = std::sqrt(nx * nx + ny * ny);
        if (len == 0) {  // centres coincide at t*: counter-clockwise of the relative velocity
          nx = -(t.vy[i] - bvy);
          ny = t.vx[i] - bvx;
          len = std::sqrt(nx * nx + ny * ny);
          if (len == 0) continue;
        }
        const double s = w * (1 - ts / horizon) / len;
        qx_[i] = s * nx;
        qy_[i] = s * ny;
      }
    });
  }

  void combine(const TickInput& in, std::span<double> vxo, std::span<double> vyo, Executor& ex) {
    const AgentTable& t = in.agents;
    const double dt = in.cfg.dt;
    ex.for_each_chunk(t.size(), kThesisGrain, [&](std::size_t b, std::size_t e) {
      for (std::size_t i = b; i < e; ++i) {
        if (standing(t.state[i])) {
          // Idle: still, unless the goal stage moves it off a goal area others need.
          vxo[i] = in.pref_vx[i];
          vyo[i] = in.pref_vy[i];
          continue;
        }
        double ax = ax_[i] + fx_[i] + ox_[i] + qx_[i];
        double ay = ay_[i] + fy_[i] + oy_[i] + qy_[i];
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
        vxo[i] = vx;
        vyo[i] = vy;
      }
    });
  }

  std::vector<double> ax_, ay_;  // Q1 [m/s^2]
  std::vector<double> fx_, fy_;  // Q2 field
  std::vector<double> ox_, oy_;  // Q2 nearest obstacle
  std::vector<double> qx_, qy_;  // Q3
  FieldColumns field_;
  std::vector<FtcHit> hits_;
  std::vector<double> reach_;
  FeatureLists features_;
  std::map<std::string, std::unique_ptr<FtcPath>> ftc_paths_;
  std::map<std::string, std::unique_ptr<FieldPath>> field_paths_;
  std::map<std::string, std::unique_ptr<FeaturePath>> feature_paths_;
};

}  // namespace

std::unique_ptr<Model> make_thesis_model() {
  return std::make_unique<ThesisModel>();
}

}  // namespace crowddb::steer
