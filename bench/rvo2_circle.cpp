// A circle swap, or a four-way crossing, run by crowddb's default orca and by RVO2 on the same
// agents, side by side: who gets everyone home, how fast the knot in the middle dissolves, and
// how far discs overlap.
//
// Built with rvo2_side_by_side, only when CROWDDB_RVO2_DIR names a checkout of RVO2 (nothing of
// it is in this repository). Both scenes: radius 0.25 m, 1.34 m/s (also the top speed), ORCA's
// neighbour distance 5 m, 10 neighbours, horizons 2 s and 0.5 s, dt 0.1 s. crowddb runs the
// scenario with its defaults otherwise (contact planes, backoff, the behaviour rules,
// stalemates); RVO2 gets the same start positions and goals, its preferred velocity towards the
// goal at 1.34 m/s (slower within the last tick's step) plus a perturbation of at most 10^-4 m/s
// as in its examples (crowddb's own is 10^-4 m/s too). Overlapping pairs are counted from the
// positions of both every `--sample` seconds (all pairs: keep `agents` to a few thousand).
// Measures the crowds, not the speed: one thread each.
//   - `--scene circle` (default): `agents` people evenly spaced on a circle of `radius` metres,
//     each heading for the point opposite (RVO2's Circle example in metres, tick_speed's ring-1k
//     by default); arrival within 0.3 m, arrived people stand.
//   - `--scene fourway`: four blocks of `agents` people each (placed uniformly, 0.1 m apart, at
//     about 1.5 per m^2, 12 m wide) at the four sides of an open square, each block bound for
//     the goal area (1 m deep, 12 m wide) on the opposite side: two head-on counter-flows
//     crossing each other. crowddb steers for the nearest point of the area where the disc
//     fits; RVO2 for the same point as at the start (straight across). Arrived people leave
//     (crowddb removes them; RVO2's are moved far away). "near" counts those within 6 m of the
//     square's centre.
//
// `--seed` seeds both perturbations (crowddb's scenario seed, RVO2's stream) and the fourway's
// placement.
//
//   rvo2_circle [--scene circle|fourway] [--agents 1000 (fourway: 200 a block)] [--radius 100]
//               [--seconds 600] [--sample 2] [--seed 7]
#include <RVO.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include "bench_args.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"

using namespace crowddb;

namespace {

struct Tally {
  std::size_t arrived = 0, centre = 0;  // arrived so far; within 10 m of the centre now
  std::size_t overlaps = 0;             // overlapping pairs now (at a sample)
  double deepest = 0;                   // [m] deepest overlap now
};

// Pairs of discs of radius r closer than 2 r, from positions (x, y).
void count_overlaps(const std::vector<double>& x, const std::vector<double>& y, double r,
                    Tally& t) {
  t.overlaps = 0;
  t.deepest = 0;
  for (std::size_t i = 0; i < x.size(); ++i)
    for (std::size_t j = i + 1; j < x.size(); ++j) {
      const double d = std::hypot(x[j] - x[i], y[j] - y[i]);
      if (d < 2 * r) {
        ++t.overlaps;
        t.deepest = std::max(t.deepest, 2 * r - d);
      }
    }
}

std::size_t near_centre(const std::vector<double>& x, const std::vector<double>& y, double cx,
                        double cy, double within) {
  std::size_t c = 0;
  for (std::size_t i = 0; i < x.size(); ++i) c += std::hypot(x[i] - cx, y[i] - cy) < within;
  return c;
}

// The four-way crossing's scenario: blocks of `per_block` at the sides of a square, goal areas
// opposite (see the top).
std::string fourway_doc(int per_block, unsigned seed, double& side) {
  const double depth = per_block / 18.0;  // 12 m wide at 1.5 per m^2
  side = 2 * depth + 18;
  const double c = side / 2, lo = c - 6, hi = c + 6, far = side - 1;
  char doc[4096];
  std::snprintf(doc, sizeof doc, R"({"bounds": [0, 0, %.17g, %.17g], "dt": 0.1, "seed": %u,
    "threads": 1, "steering": {"model": "orca", "orca": {"neighbor_dist": 5, "max_neighbors": 10,
    "time_horizon": 2, "time_horizon_obst": 0.5}}, "arrival": "remove",
    "goals": [{"name": "E", "area": [[%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g]]},
              {"name": "W", "area": [[0, %.17g], [1, %.17g], [1, %.17g], [0, %.17g]]},
              {"name": "N", "area": [[%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g], [%.17g, %.17g]]},
              {"name": "S", "area": [[%.17g, 0], [%.17g, 0], [%.17g, 1], [%.17g, 1]]}],
    "groups": [
      {"count": %d, "placement": {"type": "uniform", "region": [1, %.17g, %.17g, %.17g], "gap": 0.1},
       "radius": 0.25, "pref_speed": 1.34, "goal": "E"},
      {"count": %d, "placement": {"type": "uniform", "region": [%.17g, %.17g, %.17g, %.17g], "gap": 0.1},
       "radius": 0.25, "pref_speed": 1.34, "goal": "W"},
      {"count": %d, "placement": {"type": "uniform", "region": [%.17g, 1, %.17g, %.17g], "gap": 0.1},
       "radius": 0.25, "pref_speed": 1.34, "goal": "N"},
      {"count": %d, "placement": {"type": "uniform", "region": [%.17g, %.17g, %.17g, %.17g], "gap": 0.1},
       "radius": 0.25, "pref_speed": 1.34, "goal": "S"}]})",
                side, side, seed,                      //
                far, lo, side, lo, side, hi, far, hi,  // E
                lo, lo, hi, hi,                        // W
                lo, far, hi, far, hi, side, lo, side,  // N
                lo, hi, hi, lo,                        // S
                per_block, lo, 1 + depth, hi,          // eastbound
                per_block, far - depth, lo, far, hi,   // westbound
                per_block, lo, hi, 1 + depth,          // northbound
                per_block, lo, far - depth, hi, far);  // southbound
  return doc;
}

}  // namespace

int main(int argc, char** argv) {
  std::string scene = "circle";
  int agents = -1;
  double radius = 100, seconds = 600, sample = 2;
  unsigned seed = 7;
  const bench::Usage usage{
      "rvo2_circle",
      "usage: rvo2_circle [--scene circle|fourway] [--agents N] [--radius M] [--seconds S] "
      "[--sample S] [--seed N]\n"};
  for (int a = 1; a < argc; a += 2) {
    const std::string k = argv[a];
    if (bench::Usage::asked(k)) return usage.print();
    if (a + 1 >= argc) return usage.refuse("missing value after " + k);
    const std::string v = argv[a + 1];
    const auto number = [&](double& out) {
      const auto d = bench::positive_number(v);
      if (d) out = *d;
      return d.has_value();
    };
    if (k == "--scene") {
      scene = v;
    } else if (k == "--agents") {
      const auto n = bench::whole_number(v, 1, 1'000'000);
      if (!n) return usage.refuse("--agents takes a count, not '" + v + "'");
      agents = static_cast<int>(*n);
    } else if (k == "--radius" || k == "--seconds" || k == "--sample") {
      if (!number(k == "--radius" ? radius : k == "--seconds" ? seconds : sample))
        return usage.refuse(k + " takes a number above 0, not '" + v + "'");
    } else if (k == "--seed") {
      const auto n = bench::whole_number(v, 0, 4'294'967'295);
      if (!n) return usage.refuse("--seed takes 0 to 2^32 - 1, not '" + v + "'");
      seed = static_cast<unsigned>(*n);
    } else {
      return usage.refuse("unknown option " + k);
    }
  }
  const bool fourway = scene == "fourway";
  if (agents < 0) agents = fourway ? 200 : 1000;
  if ((scene != "circle" && !fourway) || agents < (fourway ? 1 : 2) ||
      agents > (fourway ? 2000 : 20000) || !(radius > 0) || !(seconds > 0) || !(sample >= 0.1)) {
    std::fprintf(stderr,
                 "rvo2_circle: --scene circle or fourway, --agents 2..20000 (fourway: 1..2000 a "
                 "block), --radius and --seconds positive, --sample at least one tick (0.1 s)\n");
    return 2;
  }
  std::string doc;
  double cx = 0, cy = 0, near = 10, free_walk = 2 * radius / 1.34;
  if (fourway) {
    double side = 0;
    doc = fourway_doc(agents, seed, side);
    cx = cy = side / 2;
    near = 6;
    free_walk = (side - 2) / 1.34;  // the farthest: from the block's back to the far side
  } else {
    const double side = radius + 10;
    char buf[1024];
    std::snprintf(buf, sizeof buf, R"({"bounds": [%.17g, %.17g, %.17g, %.17g], "dt": 0.1,
      "seed": %u, "threads": 1, "steering": {"model": "orca", "orca": {"neighbor_dist": 5,
      "max_neighbors": 10, "time_horizon": 2, "time_horizon_obst": 0.5}}, "arrival": "idle",
      "groups": [{"count": %d, "placement": {"type": "circle", "center": [0, 0], "radius": %.17g},
                  "radius": 0.25, "pref_speed": 1.34,
                  "goals": {"assign": "antipodal", "arrival_radius": 0.3}}]})",
                  -side, -side, side, side, seed, agents, radius);
    doc = buf;
  }
  Scenario sc = parse_scenario(doc, "rvo2-" + scene);
  const AgentTable& t0 = sc.world.agents();
  const std::size_t n = t0.size();

  omp_set_num_threads(1);
  RVO::RVOSimulator rvo;
  rvo.setTimeStep(0.1f);
  rvo.setAgentDefaults(5.0f, 10, 2.0f, 0.5f, 0.25f, 1.34f);
  // Per agent: the point steered for, and (four-way) the goal area's box, entering which counts.
  std::vector<RVO::Vector2> goal;
  struct Box {
    double x0, y0, x1, y1;
  };
  std::vector<Box> box;
  for (std::size_t i = 0; i < n; ++i) {
    rvo.addAgent(RVO::Vector2(static_cast<float>(t0.x[i]), static_cast<float>(t0.y[i])));
    const Goal& g = sc.world.goals()[t0.goal[i]];
    if (!fourway) {
      goal.emplace_back(static_cast<float>(g.x), static_cast<float>(g.y));
      continue;
    }
    Box b{INFINITY, INFINITY, -INFINITY, -INFINITY};
    for (const Vec2& v : g.area) {
      b.x0 = std::min(b.x0, v.x);
      b.y0 = std::min(b.y0, v.y);
      b.x1 = std::max(b.x1, v.x);
      b.y1 = std::max(b.y1, v.y);
    }
    box.push_back(b);
    goal.emplace_back(static_cast<float>(std::clamp(t0.x[i], b.x0 + 0.5, b.x1 - 0.5)),
                      static_cast<float>(std::clamp(t0.y[i], b.y0 + 0.5, b.y1 - 0.5)));
  }
  std::vector<char> rvo_home(n, 0);
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> angle(0, 2 * static_cast<float>(M_PI)), small(0, 1e-4f);

  Simulation sim(std::move(sc.world), sc.config);
  const auto ticks = static_cast<long>(std::llround(seconds / 0.1));
  const auto every = std::max<long>(1, std::lround(sample / 0.1));
  Tally ours, theirs, ours_max, theirs_max;
  double ours_last = -1, theirs_last = -1;
  std::vector<double> x, y;
  char near_label[32];
  std::snprintf(near_label, sizeof near_label, "r < %g m", near);
  std::printf("%8s | %25s | %25s\n", "", "crowddb orca", "RVO2");
  std::printf("%8s | %8s %8s %7s | %8s %8s %7s\n", "time [s]", "arrived", near_label, "overlap",
              "arrived", near_label, "overlap");
  for (long k = 1; k <= ticks; ++k) {
    if (ours.arrived < n) {
      ours.arrived += sim.step().arrived;
      if (ours.arrived == n) ours_last = static_cast<double>(k) * 0.1;
    }
    if (theirs.arrived < n) {
      for (std::size_t i = 0; i < n; ++i) {
        const RVO::Vector2 d = goal[i] - rvo.getAgentPosition(i);
        const float l = RVO::abs(d);
        const float a = angle(rng), s = small(rng);
        rvo.setAgentPrefVelocity(i, (l > 0 ? d / l * std::min(1.34f, l / 0.1f) : RVO::Vector2()) +
                                        s * RVO::Vector2(std::cos(a), std::sin(a)));
      }
      rvo.doStep();
      for (std::size_t i = 0; i < n; ++i) {
        if (rvo_home[i]) continue;
        const RVO::Vector2 p = rvo.getAgentPosition(i);
        const bool home = fourway ? p.x() >= box[i].x0 && p.x() <= box[i].x1 &&
                                        p.y() >= box[i].y0 && p.y() <= box[i].y1
                                  : RVO::absSq(goal[i] - p) < 0.3f * 0.3f;
        if (!home) continue;
        rvo_home[i] = 1;
        if (++theirs.arrived == n) theirs_last = static_cast<double>(k) * 0.1;
        if (fourway) {  // leaves: far away, apart from everyone who left before
          goal[i] = RVO::Vector2(1e5f + 3.0f * static_cast<float>(i), 1e5f);
          rvo.setAgentPosition(i, goal[i]);
        }
      }
    }
    if (k % every != 0 && k != ticks) continue;
    const AgentTable& t = sim.world().agents();
    x.assign(t.x.begin(), t.x.end());
    y.assign(t.y.begin(), t.y.end());
    count_overlaps(x, y, 0.25, ours);
    ours.centre = near_centre(x, y, cx, cy, near);
    x.clear();
    y.clear();
    for (std::size_t i = 0; i < n; ++i) {
      if (fourway && rvo_home[i]) continue;
      x.push_back(rvo.getAgentPosition(i).x());
      y.push_back(rvo.getAgentPosition(i).y());
    }
    count_overlaps(x, y, 0.25, theirs);
    theirs.centre = near_centre(x, y, cx, cy, near);
    for (auto [now, most] : {std::pair{&ours, &ours_max}, std::pair{&theirs, &theirs_max}}) {
      most->overlaps = std::max(most->overlaps, now->overlaps);
      most->deepest = std::max(most->deepest, now->deepest);
    }
    if (k % std::max<long>(every, fourway ? 100 : 300) == 0 || k == ticks)
      std::printf("%8.0f | %8zu %8zu %7zu | %8zu %8zu %7zu\n", static_cast<double>(k) * 0.1,
                  ours.arrived, ours.centre, ours.overlaps, theirs.arrived, theirs.centre,
                  theirs.overlaps);
    if (ours.arrived == n && theirs.arrived == n) break;
  }
  if (fourway)
    std::printf(
        "%zu people in four blocks of %d crossing a square (the farthest's free walk %.1f s):\n", n,
        agents, free_walk);
  else
    std::printf("%d people on a circle of radius %g m (free walk %.1f s):\n", agents, radius,
                free_walk);
  const auto line = [&](const char* who, const Tally& now, const Tally& most, double last) {
    char when[32] = "never";
    if (last >= 0) std::snprintf(when, sizeof when, "%.1f s", last);
    std::printf(
        "  %-13s %zu of %zu home, the last at %s; overlapping pairs at most %zu (sampled "
        "every %g s), deepest %.3f m\n",
        who, now.arrived, n, when, most.overlaps, static_cast<double>(every) * 0.1, most.deepest);
  };
  line("crowddb orca:", ours, ours_max, ours_last);
  line("RVO2:", theirs, theirs_max, theirs_last);
  return 0;
}
