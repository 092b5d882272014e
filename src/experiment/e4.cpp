// E4 (thesis §4.2, DESIGN.md §7): collision quality of the six potential functions.
//
// The thesis's airport: 1000 agents, radius uniform in [1, 3], start speed uniform in [0, 5]
// (random heading), 24 large static obstacles, 12 goals on the walls assigned round-robin like
// airport gates; 100 ticks; no backoff. The board side varies from large to small, giving the
// x-axis density x n = n^2 / side^2 (1000 agents on 250 x 250 is 16). y-axis: agent-agent pairs
// overlapping after a tick, averaged over the ticks of a run; mean ± 2σ over seeds.
//
// Choices the thesis leaves open, fixed here and printed with the results:
//  - the layout is the shipped airport scenario scaled to the board: a 6 x 4 grid of pillars
//    (radius drawn per seed in [12, 20] x side/500), three gates per wall (arrival radius 12);
//    agents start without overlaps (uniform placement with rejection), so every overlap counted
//    is one the steering failed to avoid; agents that reach their gate walk on to another one
//    (arrival "retarget"), so the density stays constant for the whole run;
//  - steering: attraction (tau 2) plus the potential field only (w_apf 30, as the airport
//    scenario; first-to-collide switched off so the potential function alone is measured),
//    max speed 5, max acceleration 1;
//  - the thesis's field model: each obstacle is one charged point at its centre, and the board
//    has no walls (the bounds sampled into charged points would outnumber the agents 5 to 1 on
//    the largest board and make the naive inv kernels the whole cost of the experiment);
//  - exp kernels use the thesis's A = 0.929328, k = 0.272194 (A e^{-kx} fitted to 1/x); inv
//    kernels use A = 1 (the 1/x they approximate), distance floor 0.1; radial uses 2 frames.
#include <cmath>
#include <iomanip>
#include <nlohmann/json.hpp>
#include <ostream>
#include <sstream>

#include "crowddb/scenario.hpp"
#include "crowddb/simulation.hpp"
#include "experiment/experiment.hpp"
#include "util/rng.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::experiment {
namespace {

struct Function {
  const char* name;
  const char* kernel;
  const char* metric;
};
constexpr Function kFunctions[] = {
    {"exp-l1", "exp", "l1"}, {"exp-l2", "exp", "l2"}, {"exp-radial", "exp", "radial"},
    {"inv-l1", "inv", "l1"}, {"inv-l2", "inv", "l2"}, {"inv-radial", "inv", "radial"}};

std::string airport_json(std::size_t agents, double side, const Function& f, uint64_t seed,
                         uint64_t ticks) {
  using nlohmann::json;
  const double s = side / 500;
  Rng rng = Rng::stream(seed, 4);
  json goals = json::array();
  const char* walls[] = {"E", "N", "S", "W"};
  for (int w = 0; w < 4; ++w)
    for (int i = 1; i <= 3; ++i) {
      const double along = side * i / 4, inset = 4;
      double x = along, y = along;
      if (w == 0) x = side - inset;
      if (w == 1) y = side - inset;
      if (w == 2) y = inset;
      if (w == 3) x = inset;
      goals.push_back({{"name", std::string(walls[w]) + std::to_string(i)},
                       {"x", x},
                       {"y", y},
                       {"arrival_radius", 12}});
    }
  json obstacles = json::array();
  for (int j = 0; j < 4; ++j)
    for (int i = 0; i < 6; ++i)
      obstacles.push_back({{"type", "circle"},
                           {"x", (60 + 76 * i) * s},
                           {"y", (95 + 103 * j) * s},
                           {"radius", rng.uniform(12, 20) * s}});
  const bool exp = std::string(f.kernel) == "exp";
  json potential = {{"kernel", f.kernel}, {"metric", f.metric}, {"A", exp ? 0.929328 : 1.0},
                    {"k", 0.272194},      {"frames", 2},        {"inv_floor", 0.1}};
  json doc = {
      {"name", "e4-airport"},
      {"bounds", {0, 0, side, side}},
      {"seed", seed},
      {"ticks", ticks},
      {"goals", goals},
      {"obstacles", obstacles},
      {"groups",
       {{{"name", "travellers"},
         {"count", agents},
         {"placement",
          {{"type", "uniform"}, {"region", {8, 8, side - 8, side - 8}}, {"attempts", 100000}}},
         {"radius", {1, 3}},
         {"speed", {0, 5}},
         {"heading", "random"},
         {"max_speed", 5},
         {"max_accel", 1},
         {"goals", {{"assign", "round_robin"}}}}}},
      // The thesis's rule in its own units (a tick is a second), obstacles as charged centres.
      {"dt", 1},
      {"steering",
       {{"model", "thesis"},
        {"perturbation", 0},
        {"thesis",
         {{"tau", 2},
          {"w_apf", 30.0},
          {"w_ftc", 0.0},
          {"horizon", 30},
          {"obstacle_repulsion", "charges"},
          {"obstacle_charges", "centres"},
          {"potential", potential}}}}},
      {"stall", {{"resolve", false}}},
      {"walls", false},
      {"backoff", false},
      {"arrival", "retarget"},
  };
  return doc.dump();
}

}  // namespace

void run_e4(const Options& opt) {
  const std::size_t agents = opt.quick ? 200 : 1000;
  const uint64_t ticks = opt.quick ? 10 : 100;
  const int seeds = opt.quick ? 2 : 5;
  const std::vector<double> dn =
      opt.quick ? std::vector<double>{0.5, 2} : std::vector<double>{0.5, 1, 2, 4, 8, 16};

  const std::string run_cols[] = {"density_n", "board_side",     "function",
                                  "seed",      "pairs_per_tick", "obstacle_overlaps_per_tick",
                                  "seconds"};
  CsvWriter runs(opt.out_dir / "e4_runs.csv", run_cols);
  std::vector<std::string> cols = {"density_n", "board_side"};
  for (const Function& f : kFunctions) {
    cols.push_back(std::string(f.name) + "_mean");
    cols.push_back(std::string(f.name) + "_2sd");
  }
  CsvWriter summary(opt.out_dir / "e4.csv", cols);
  std::ostringstream table;
  table << "E4 overlapping agent pairs per tick (mean ± 2 sd over " << seeds << " seeds), "
        << agents << " agents, " << ticks << " ticks, no backoff\n"
        << machine_note(opt.threads) << "\n\n"
        << std::setw(8) << "dens*n" << std::setw(8) << "side";
  for (const Function& f : kFunctions) table << std::setw(20) << f.name;
  table << "\n";

  for (double d : dn) {
    const double side = static_cast<double>(agents) / std::sqrt(d);
    std::vector<double> row = {d, side};
    std::ostringstream line;
    line << std::setw(8) << d << std::setw(8) << std::setprecision(4) << side;
    for (const Function& f : kFunctions) {
      std::vector<double> per_seed;
      for (int s = 0; s < seeds; ++s) {
        const uint64_t seed = opt.seed * 1000 + static_cast<uint64_t>(s);
        Scenario sc = parse_scenario(airport_json(agents, side, f, seed, ticks), "e4");
        sc.config.threads = opt.threads;
        Simulation sim(std::move(sc.world), sc.config);
        Stopwatch sw;
        double pairs = 0, obstacle = 0;
        for (uint64_t t = 0; t < ticks; ++t) {
          const TickMetrics& m = sim.step();
          pairs += static_cast<double>(m.overlapping_pairs);
          obstacle += static_cast<double>(m.obstacle_overlaps);
        }
        const double tk = static_cast<double>(ticks);
        per_seed.push_back(pairs / tk);
        runs.row(std::vector<std::string>{std::to_string(d), std::to_string(side), f.name,
                                          std::to_string(seed), std::to_string(pairs / tk),
                                          std::to_string(obstacle / tk),
                                          std::to_string(sw.seconds())});
      }
      const MeanSd ms = mean_sd(per_seed);
      row.push_back(ms.mean);
      row.push_back(2 * ms.sd);
      std::ostringstream cell;
      cell << std::fixed << std::setprecision(1) << ms.mean << " ± " << 2 * ms.sd;
      line << std::setw(20) << cell.str();
      if (opt.log)
        *opt.log << "e4: density*n " << d << " " << f.name << " " << cell.str() << "\n"
                 << std::flush;
    }
    summary.row(row);
    table << line.str() << "\n";
  }
  runs.close();
  summary.close();
  {
    std::ofstream f(opt.out_dir / "e4.txt");
    f << table.str();
  }
  // Six series with error bars, nudged sideways (x is logarithmic) so the bars stay readable.
  std::string script =
      "set terminal pngcairo size 1000,650 font ',11'\n"
      "set output 'e4.png'\n"
      "set datafile separator ','\n"
      "set title 'E4: overlapping agent pairs per tick (mean ± 2σ over seeds), no backoff'\n"
      "set logscale x 2\n"
      "set xlabel 'density × n (agents² / board area)'\n"
      "set ylabel 'overlapping pairs per tick'\n"
      "set key top left\n"
      "set grid\n"
      "plot ";
  for (int i = 0; i < 6; ++i) {
    const double nudge = std::pow(1.04, i - 2.5);
    std::ostringstream one;
    one << (i ? ", \\\n     " : "") << "'e4.csv' using ($1*" << nudge << "):" << 3 + 2 * i << ":"
        << 4 + 2 * i << " skip 1 with yerrorlines pt " << 5 + i << " title '" << kFunctions[i].name
        << "'";
    script += one.str();
  }
  plot(opt.out_dir, "e4", script + "\n");
}

}  // namespace crowddb::experiment
