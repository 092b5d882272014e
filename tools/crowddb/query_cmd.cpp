// `crowddb query ftc|field|collisions`: one steering query over CSV tables (DESIGN.md §9).
#include <algorithm>
#include <limits>
#include <numeric>

#include "cli_checks.hpp"
#include "commands.hpp"
#include "crowddb/query.hpp"
#include "io/csv_tables.hpp"

namespace crowddb::cli {
namespace {

struct Common {
  std::string agents, obstacles, method = "auto", out = "-";
  int threads = 1;
};

void add_common(CLI::App* sub, Common& c, bool method_required = false) {
  sub->add_option("--agents", c.agents, "agents CSV: id,x,y,vx,vy,radius[,charge]")->required();
  sub->add_option("--obstacles", c.obstacles, "obstacles CSV: x,y,radius[,charge] (named o<row>)");
  auto* m = sub->add_option("--method", c.method,
                            "access path: auto, naive or an index (see --help of run)");
  if (method_required) m->required();
  sub->add_option("--threads", c.threads, "threads (the answer does not depend on it)")
      ->check(cli_checks::whole(1, 256));
  sub->add_option("--out", c.out, "output file ('-' for stdout)");
}

struct Inputs {
  DiscTable agents;
  StaticScene scene;
  std::vector<std::size_t> by_id;  // rows in id order
};

Inputs load(const Common& c, ObstacleCharges charges) {
  Inputs in;
  in.agents = io::read_agents_csv(c.agents);
  std::vector<CircleObstacle> circles;
  if (!c.obstacles.empty()) circles = io::read_obstacles_csv(c.obstacles);
  double rmin = std::numeric_limits<double>::infinity();
  for (double r : in.agents.radius) rmin = std::min(rmin, r);
  in.scene = StaticScene(std::move(circles), {}, std::isfinite(rmin) ? rmin : 1.0, charges);
  in.by_id.resize(in.agents.size());
  std::iota(in.by_id.begin(), in.by_id.end(), std::size_t{0});
  std::sort(in.by_id.begin(), in.by_id.end(),
            [&](auto a, auto b) { return in.agents.id[a] < in.agents.id[b]; });
  return in;
}

}  // namespace

void add_query_commands(CLI::App& app, Action& action) {
  auto* query = app.add_subcommand("query", "run one steering query over CSV tables");
  query->require_subcommand(1);

  // ---- first-to-collide
  auto* ftc = query->add_subcommand(
      "ftc", "first agent or obstacle each agent collides with (CSV id,first_id,time)");
  static Common fc;
  static double horizon = 30;
  add_common(ftc, fc);
  ftc->add_option("--horizon", horizon, "look-ahead T in ticks; collisions after T are ignored")
      ->required()
      ->check(cli_checks::finite(0, kMaxQueryHorizon));
  ftc->callback([&action] {
    action = [] {
      Inputs in = load(fc, ObstacleCharges::centres);
      const auto hits =
          first_to_collide(in.agents.view(), in.scene, horizon, fc.method, fc.threads);
      std::string text = "id,first_id,time\n";
      for (std::size_t row : in.by_id) {
        const FtcHit& h = hits[row];
        text += std::to_string(in.agents.id[row]) + ",";
        switch (h.with.kind) {
          case Collider::Kind::none:
            text += "-1,\n";
            continue;
          case Collider::Kind::agent:
            text += std::to_string(in.agents.id[h.with.row]);
            break;
          case Collider::Kind::circle:
          case Collider::Kind::polygon:
            text += "o" + std::to_string(h.with.row);
            break;
        }
        text += "," + format_number(h.time) + "\n";
      }
      write_output(fc.out, text);
      return 0;
    };
  });

  // ---- potential field
  auto* field = query->add_subcommand(
      "field", "potential and gradient at every agent (CSV id,potential,grad_x,grad_y)");
  static Common pc;
  static std::string kernel = "exp", metric = "l1";
  static PotentialSpec spec;
  static double floor_value = 0;
  add_common(field, pc);
  field->add_option("--kernel", kernel, "exp (A e^{-k d}) or inv (A / d)")
      ->check(CLI::IsMember({"exp", "inv"}));
  field->add_option("--metric", metric, "distance: l1, l2 or radial")
      ->check(CLI::IsMember({"l1", "l2", "radial"}));
  field->add_option("--A", spec.A, "kernel scale A")->capture_default_str();
  field->add_option("--k", spec.k, "exp kernel rate k")->capture_default_str();
  field->add_option("--frames", spec.radial_frames, "rotated frames of the radial metric")
      ->check(cli_checks::whole(1, 16))
      ->capture_default_str();
  field
      ->add_option("--floor", floor_value,
                   "inv kernel: distance floor (default: a tenth of the smallest radius)")
      ->check(cli_checks::positive());
  static double fd_step = 0;
  field
      ->add_option("--fd-step", fd_step,
                   "gradient by the thesis's forward finite differences with this step instead of "
                   "analytically")
      ->check(cli_checks::positive());
  field->callback([&action] {
    action = [] {
      Inputs in = load(pc, ObstacleCharges::centres);
      spec.kernel = kernel == "inv" ? Kernel::inv : Kernel::exp;
      spec.metric =
          metric == "l2" ? Metric::l2 : (metric == "radial" ? Metric::radial : Metric::l1);
      if (!std::isfinite(spec.A) || !std::isfinite(spec.k))
        throw Error(Error::Kind::usage, "--A and --k must be finite numbers");
      double rmin = std::numeric_limits<double>::infinity();
      for (double r : in.agents.radius) rmin = std::min(rmin, r);
      spec.inv_floor = floor_value > 0 ? floor_value : (std::isfinite(rmin) ? rmin / 10 : 0.1);
      spec.finite_difference = fd_step > 0;
      if (fd_step > 0) spec.fd_step = fd_step;
      const FieldColumns f =
          potential_field(in.agents.view(), in.scene, spec, pc.method, pc.threads);
      std::string text = "id,potential,grad_x,grad_y\n";
      for (std::size_t row : in.by_id)
        text += std::to_string(in.agents.id[row]) + "," + format_number(f.potential[row]) + "," +
                format_number(f.grad_x[row]) + "," + format_number(f.grad_y[row]) + "\n";
      write_output(pc.out, text);
      return 0;
    };
  });

  // ---- collision set
  auto* col = query->add_subcommand("collisions",
                                    "ids of agents that overlap another agent or an obstacle");
  static Common cc;
  add_common(col, cc);
  col->callback([&action] {
    action = [] {
      Inputs in = load(cc, ObstacleCharges::centres);
      const auto rows = collision_set(in.agents.view(), in.scene, cc.method, cc.threads);
      std::vector<uint64_t> ids;
      for (uint32_t r : rows) ids.push_back(in.agents.id[r]);
      std::sort(ids.begin(), ids.end());
      std::string text;
      for (uint64_t id : ids) text += std::to_string(id) + "\n";
      write_output(cc.out, text);
      return 0;
    };
  });
}

}  // namespace crowddb::cli
