#include "verify/verify.hpp"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <unordered_map>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "io/overrides.hpp"
#include "path/visibility_graph.hpp"
#include "util/stopwatch.hpp"
#include "world/geometry.hpp"

namespace crowddb::verify {

RunStats run_scenario(const std::string& json, const std::string& source, const std::string& model,
                      int threads, const std::vector<std::string>& overrides) {
  Scenario sc = overrides.empty() ? parse_scenario(json, source) : [&] {
    nlohmann::json doc = nlohmann::json::parse(json);
    io::apply_overrides(doc, overrides);
    return parse_scenario(doc.dump(), source);
  }();
  if (!model.empty()) sc.config.steering.model = model;
  sc.config.threads = threads;
  RunStats r;
  r.dt = sc.config.dt;
  r.duration = static_cast<double>(sc.ticks) * sc.config.dt;
  const World& w0 = sc.world;
  const AgentTable& t0 = w0.agents();
  r.agents = t0.size();
  // Shortest paths for each agent's disc to its first goal: to a disc goal's rim (its centre
  // minus the arrival radius), to the nearest point of a polygon goal.
  const path::DiscWorld dw = path::DiscWorld::of(w0, sc.config.walls);
  std::unordered_map<uint64_t, std::size_t> index;
  for (std::size_t i = 0; i < t0.size(); ++i) {
    index[t0.id[i]] = i;
    const Goal& g = w0.goals()[t0.goal[i]];
    double len;
    if (g.is_polygon()) {
      // To the area's interior point, less that point's distance to the area's boundary: exact
      // for a straight approach to a convex area, a lower bound otherwise (the nearest boundary
      // point itself may lie against a wall, where a disc cannot stand).
      len = path::shortest_path(dw, t0.radius[i], {t0.x[i], t0.y[i]}, {g.x, g.y}) -
            std::sqrt(dist2_to_boundary(g.area, g.x, g.y));
    } else {
      len = std::max(0.0, path::shortest_path(dw, t0.radius[i], {t0.x[i], t0.y[i]}, {g.x, g.y}) -
                              g.arrival_radius);
    }
    r.shortest.push_back(len);
    r.free_time.push_back(len / t0.pref_speed[i]);
    r.goal.push_back(t0.goal[i]);
    r.goal_name.push_back(g.name);
  }
  r.arrival.assign(r.agents, std::nan(""));
  r.walked.assign(r.agents, 0);
  std::vector<double> px(t0.x), py(t0.y);
  std::vector<uint8_t> seen(r.agents, 0);
  Simulation sim(std::move(sc.world), sc.config);
  for (uint64_t k = 1; k <= sc.ticks; ++k) {
    const TickMetrics& m = sim.step();
    r.max_pairs = std::max(r.max_pairs, m.overlapping_pairs);
    r.max_obstacle = std::max(r.max_obstacle, m.obstacle_overlaps);
    r.frozen += m.frozen;
    r.max_stall = std::max(r.max_stall, static_cast<double>(m.longest_stall) * r.dt);
    const AgentTable& t = sim.world().agents();
    std::fill(seen.begin(), seen.end(), 0);
    for (std::size_t row = 0; row < t.size(); ++row) {
      const auto it = index.find(t.id[row]);
      if (it == index.end()) continue;  // entered from a source
      const std::size_t i = it->second;
      seen[i] = 1;
      r.walked[i] += std::hypot(t.x[row] - px[i], t.y[row] - py[i]);
      px[i] = t.x[row];
      py[i] = t.y[row];
      if (t.state[row] == AgentState::arrived && std::isnan(r.arrival[i]))
        r.arrival[i] = static_cast<double>(k) * r.dt;
    }
    for (std::size_t i = 0; i < r.agents; ++i)
      if (!seen[i] && std::isnan(r.arrival[i])) r.arrival[i] = static_cast<double>(k) * r.dt;
  }
  r.stalled_at_end = sim.last_metrics().stalled;
  for (double a : r.arrival)
    if (!std::isnan(a)) {
      ++r.arrived;
      r.first_arrival = r.arrived == 1 ? a : std::min(r.first_arrival, a);
      r.last_arrival = std::max(r.last_arrival, a);
    }
  return r;
}

std::vector<Check> standard_checks(const RunStats& r, const Limits& l) {
  std::vector<Check> c;
  c.push_back(
      {"arrived / agents", static_cast<double>(r.arrived) / static_cast<double>(r.agents), 1, 1});
  c.push_back({"overlapping pairs (max)", static_cast<double>(r.max_pairs), 0, 0});
  c.push_back({"agent-obstacle overlaps (max)", static_cast<double>(r.max_obstacle), 0, 0});
  c.push_back({"longest stall [s]", r.max_stall, 0, l.max_stall});
  c.push_back({"stalled at the end", static_cast<double>(r.stalled_at_end), 0, 0});
  // Ratios per agent; NaN (a failed check) when an agent did not arrive or has no shortest path.
  auto ratios = [&](auto&& of) {
    double mean = 0, worst = 0;
    for (std::size_t i = 0; i < r.agents; ++i) {
      const double q = of(i);
      if (!std::isfinite(q)) return std::pair{std::nan(""), std::nan("")};
      mean += q / static_cast<double>(r.agents);
      worst = std::max(worst, q);
    }
    return std::pair{mean, worst};
  };
  auto over = [](double a, double b) { return std::isfinite(b) && b > 0 ? a / b : std::nan(""); };
  const auto time = ratios([&](std::size_t i) { return over(r.arrival[i], r.free_time[i]); });
  const auto path = ratios([&](std::size_t i) { return over(r.walked[i], r.shortest[i]); });
  if (l.time_mean > 0) c.push_back({"arrival / free-flow time (mean)", time.first, 0, l.time_mean});
  if (l.time_max > 0) c.push_back({"arrival / free-flow time (max)", time.second, 0, l.time_max});
  if (l.path_mean > 0) c.push_back({"walked / shortest path (mean)", path.first, 0, l.path_mean});
  if (l.path_max > 0) c.push_back({"walked / shortest path (max)", path.second, 0, l.path_max});
  return c;
}

CaseResult run_case(const Case& c, const std::string& model, int threads,
                    const std::vector<std::string>& overrides) {
  Stopwatch sw;
  std::vector<RunStats> runs;
  for (std::size_t k = 0; k < c.scenarios.size(); ++k)
    runs.push_back(run_scenario(c.scenarios[k], "verify/" + c.name + "#" + std::to_string(k), model,
                                threads, overrides));
  CaseResult res{c.name, c.family, model, c.evaluate(runs), 0};
  res.wall_seconds = sw.seconds();
  return res;
}

}  // namespace crowddb::verify
