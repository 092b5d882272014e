// crowddb's orca tick against RVO2's doStep on the same agents, side by side in one run.
//
// Built only when the CMake option CROWDDB_RVO2_DIR names a checkout of RVO2
// (https://github.com/snape/RVO2; nothing of it is in this repository): docs/benchmarks.md says
// how. Both get identical agents (uniform without overlaps at a given density in a square,
// radius 0.25 m, preferred speed 1.3 m/s, four goals on the walls, round robin), identical
// parameters (neighbour distance 5 m, 10 neighbours, horizons 2 s and 0.5 s, dt 0.1 s) and the
// walls as obstacles. Steps are interleaved (crowddb, RVO2, crowddb, ...) so that load changes
// hit both alike; the medians and minima over `steps` steps are printed with the load average.
// crowddb's tick is the whole Simulation::step (goal stage, queries, LP, integrate, backoff,
// commit, stalemates); RVO2's step is setting the preferred velocities plus doStep. Both get
// `threads` threads: RVO2's OpenMP is set to that many here, whatever OMP_NUM_THREADS says
// (left unset, OpenMP took every core for RVO2 while crowddb had one). OpenMP's idle threads
// wait passively (OMP_WAIT_POLICY=passive, set here by running the program again with it unless
// the caller set it): spinning after each of RVO2's parallel regions, they took a core from
// crowddb's step that followed (2026-12-01, 2 * 10^4 agents on 2 threads: crowddb 17.1 ms with
// libgomp's default spin, 24.5 ms with "active", 14.3 ms with "passive"; RVO2's step 20.0-20.4 ms
// in all three).
//
//   rvo2_side_by_side [--agents 20000] [--threads 1] [--steps 60] [--density 0.5]
//                     [--model orca|orca-core] [--csv FILE]
//
// `--model orca-core` (bench/model_variant.hpp) times crowddb's orca without the three additions
// for crowds that RVO2 does not have (keeping to a side, the stream gap, the perturbation): the
// closer comparison of the two ORCAs; the default, `orca`, is what a user of crowddb gets. The CSV
// row (appended): agents, threads, steps, load before, crowddb median and min ms, RVO2 median and
// min ms, model.
#include <RVO.h>
#include <omp.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include "airport_scenario.hpp"
#include "bench_args.hpp"
#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "model_variant.hpp"

using namespace crowddb;
using Clock = std::chrono::steady_clock;

namespace {

double load_average() {
  std::ifstream f("/proc/loadavg");
  double l = -1;
  f >> l;
  return l;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0 : v[v.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  // libgomp reads its environment when it is loaded, before main: the policy needs a new start.
  if (std::getenv("OMP_WAIT_POLICY") == nullptr) {
    setenv("OMP_WAIT_POLICY", "passive", 1);
    execv("/proc/self/exe", argv);
    std::perror("rvo2_side_by_side: cannot run itself again with OMP_WAIT_POLICY=passive");
    return 1;
  }
  int agents = 20000, threads = 1, steps = 60;
  double density = 0.5;
  std::string csv, model = "orca";
  const bench::Usage usage{"rvo2_side_by_side",
                           "usage: rvo2_side_by_side [--agents N] [--threads N] [--steps N] "
                           "[--density PEOPLE_PER_M2] [--model orca|orca-core] [--csv FILE]\n"};
  for (int a = 1; a < argc; a += 2) {
    const std::string k = argv[a];
    if (bench::Usage::asked(k)) return usage.print();
    if (a + 1 >= argc) return usage.refuse("missing value after " + k);
    const std::string v = argv[a + 1];
    const auto count = [&](long long hi, int& out) {
      const auto n = bench::whole_number(v, 1, hi);
      if (n) out = static_cast<int>(*n);
      return n.has_value();
    };
    if (k == "--agents") {
      if (!count(100'000'000, agents))
        return usage.refuse("--agents takes 1 to 10^8, not '" + v + "'");
    } else if (k == "--threads") {
      if (!count(1024, threads)) return usage.refuse("--threads takes 1 to 1024, not '" + v + "'");
    } else if (k == "--steps") {
      if (!count(1'000'000, steps)) return usage.refuse("--steps takes 1 to 10^6, not '" + v + "'");
    } else if (k == "--density") {
      const auto d = bench::positive_number(v);
      if (!d) return usage.refuse("--density takes a number above 0, not '" + v + "'");
      density = *d;
    } else if (k == "--model") {
      if (v != "orca" && v != "orca-core")
        return usage.refuse("--model takes orca or orca-core, not '" + v + "'");
      model = v;
    } else if (k == "--csv") {
      csv = v;
    } else {
      return usage.refuse("unknown option " + k);
    }
  }
  const double side = bench::airport_side(static_cast<std::size_t>(agents), density);
  const std::string doc =
      bench::airport_scenario(static_cast<std::size_t>(agents), "orca", threads, density);
  Scenario sc = parse_scenario(doc, "side-by-side");
  bench::apply_variant(model, sc.config);
  const AgentTable& t = sc.world.agents();

  omp_set_num_threads(threads);
  RVO::RVOSimulator rvo;
  rvo.setTimeStep(0.1f);
  rvo.setAgentDefaults(5.0f, 10, 2.0f, 0.5f, 0.25f, 1.3f);
  std::vector<RVO::Vector2> goal;
  for (std::size_t i = 0; i < t.size(); ++i) {
    rvo.addAgent(RVO::Vector2(static_cast<float>(t.x[i]), static_cast<float>(t.y[i])));
    const Goal& g = sc.world.goals()[t.goal[i]];
    goal.emplace_back(static_cast<float>(g.x), static_cast<float>(g.y));
  }
  // The walls: the same four rectangles outside the bounds that crowddb uses (counter-clockwise).
  const auto s = static_cast<float>(side), w = s;
  const std::vector<std::vector<RVO::Vector2>> walls = {
      {{-w, -w}, {0, -w}, {0, s + w}, {-w, s + w}},
      {{s, -w}, {s + w, -w}, {s + w, s + w}, {s, s + w}},
      {{0, -w}, {s, -w}, {s, 0}, {0, 0}},
      {{0, s}, {s, s}, {s, s + w}, {0, s + w}}};
  for (const auto& poly : walls) rvo.addObstacle(poly);
  rvo.processObstacles();

  Simulation sim(std::move(sc.world), sc.config);
  std::vector<double> ours, theirs;
  const double load_before = load_average();
  for (int k = 0; k < steps; ++k) {
    auto a = Clock::now();
    sim.step();
    ours.push_back(std::chrono::duration<double>(Clock::now() - a).count());
    a = Clock::now();
    for (std::size_t i = 0; i < goal.size(); ++i) {
      const RVO::Vector2 d = goal[i] - rvo.getAgentPosition(i);
      const float l = RVO::abs(d);
      rvo.setAgentPrefVelocity(i, l > 0 ? d / l * std::min(1.3f, l / 0.1f) : RVO::Vector2());
    }
    rvo.doStep();
    theirs.push_back(std::chrono::duration<double>(Clock::now() - a).count());
  }
  const double load_after = load_average();
  const double mo = median(ours) * 1e3, mt = median(theirs) * 1e3;
  const double lo = *std::min_element(ours.begin(), ours.end()) * 1e3;
  const double lt = *std::min_element(theirs.begin(), theirs.end()) * 1e3;
  std::printf(
      "agents %d, threads %d (RVO2: %d OpenMP threads, OMP_WAIT_POLICY=%s), %d steps, load %.2f -> "
      "%.2f\n"
      "  crowddb %-9s  median %8.2f ms  min %8.2f ms\n"
      "  RVO2 doStep        median %8.2f ms  min %8.2f ms\n"
      "  ratio crowddb / RVO2: median %.2f, min %.2f\n",
      agents, threads, omp_get_max_threads(), std::getenv("OMP_WAIT_POLICY"), steps, load_before,
      load_after, model.c_str(), mo, lo, mt, lt, mo / mt, lo / lt);
  if (!csv.empty()) {
    std::ofstream f(csv, std::ios::app);
    f << agents << "," << threads << "," << steps << "," << load_before << "," << mo << "," << lo
      << "," << mt << "," << lt << "," << model << "\n";
  }
  return 0;
}
