// E5 (thesis §4.2, DESIGN.md §7): potential-field performance, indexed vs naive.
//
// density x n = 1: n agents uniform on an n x n board (radius [1, 3], speed [0, 5]); circle
// obstacles at 125 agents : 3 (radius [5, 15]), one charged point at each centre (the thesis's
// model); A = 0.929328, k = 0.272194, exp-l1; potential and gradient for every agent. The
// index runs for every n up to 10^6; the naive nested loop while its predicted time (quadratic
// from the CPU time of the last size it ran) stays within about a minute (75 s). Where both ran,
// the index is checked against the naive answer with DESIGN.md §4's tolerance (all charges are
// positive here, so the naive potential is S_abs). Times are wall clock and process CPU time (the
// machine is shared: CPU time is the steadier figure; the load average is recorded per row).
#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <ctime>
#include <iomanip>
#include <ostream>
#include <sstream>

#include "crowddb/query.hpp"
#include "experiment/experiment.hpp"
#include "scenario/builders.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::experiment {
namespace {

struct Timing {
  double wall = 0, cpu = 0;
};

// Median wall and CPU time of `reps` runs of f (the result of the last run is kept in `out`).
template <class F>
Timing time_runs(int reps, FieldColumns& out, F f) {
  std::vector<double> wall, cpu;
  for (int r = 0; r < reps; ++r) {
    const std::clock_t c0 = std::clock();
    Stopwatch sw;
    out = f();
    wall.push_back(sw.seconds());
    cpu.push_back(static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC);
  }
  return {median(wall), median(cpu)};
}

double load1() {
  double l[3] = {0, 0, 0};
  return getloadavg(l, 3) > 0 ? l[0] : -1;
}

// max over rows and components of |index - naive| / tolerance (<= 1 means within DESIGN §4).
double error_over_tolerance(const FieldColumns& idx, const FieldColumns& naive,
                            const PotentialSpec& s, double cmax) {
  double worst = 0;
  for (std::size_t i = 0; i < naive.potential.size(); ++i) {
    const double tol = 1e-9 * std::abs(naive.potential[i]) + 1e-12 * s.A * cmax * cmax;
    worst = std::max(worst, std::abs(idx.potential[i] - naive.potential[i]) / tol);
    worst = std::max(worst, std::abs(idx.grad_x[i] - naive.grad_x[i]) / (s.k * tol));
    worst = std::max(worst, std::abs(idx.grad_y[i] - naive.grad_y[i]) / (s.k * tol));
  }
  return worst;
}

}  // namespace

void run_e5(const Options& opt) {
  const std::vector<std::size_t> sizes =
      opt.quick ? std::vector<std::size_t>{1000, 2000, 4000}
                : std::vector<std::size_t>{1000,  2000,  5000,   10000,  20000,  30000,  40000,
                                           50000, 70000, 100000, 200000, 500000, 1000000};
  // Predicted CPU seconds of one naive run: "what the naive path can do in about a minute".
  const double naive_budget = opt.quick ? 5.0 : 75.0;
  const int reps = 3;
  PotentialSpec spec;  // exp-l1, A = 0.929328, k = 0.272194

  const std::string header_cols[] = {"n",
                                     "board_side",
                                     "obstacles",
                                     "index_wall_s",
                                     "index_cpu_s",
                                     "naive_wall_s",
                                     "naive_cpu_s",
                                     "speedup_cpu",
                                     "max_err_over_tol",
                                     "load1"};
  CsvWriter csv(opt.out_dir / "e5.csv", header_cols);
  std::ostringstream table;
  table << "E5 potential field (exp-l1, density x n = 1, 125:3 obstacles), threads " << opt.threads
        << "\n"
        << machine_note(opt.threads) << "\n\n"
        << std::setw(9) << "n" << std::setw(12) << "index cpu" << std::setw(12) << "index wall"
        << std::setw(12) << "naive cpu" << std::setw(12) << "naive wall" << std::setw(10)
        << "speedup" << std::setw(12) << "err/tol" << std::setw(7) << "load"
        << "\n";

  double last_naive = 0;
  std::size_t last_naive_n = 0;
  for (std::size_t n : sizes) {
    const build::FieldWorld w = build::e5_world(n, opt.seed);
    const StaticScene scene(w.obstacles, {}, 1.0, ObstacleCharges::centres);
    const DiscView view = w.agents.view();
    FieldColumns idx, naive;
    const Timing ti = time_runs(
        reps, idx, [&] { return potential_field(view, scene, spec, "index", opt.threads); });
    const double predicted =
        last_naive_n
            ? last_naive * std::pow(static_cast<double>(n) / static_cast<double>(last_naive_n), 2)
            : 0;
    Timing tn{NAN, NAN};
    double err = NAN;
    if (predicted <= naive_budget) {
      tn = time_runs(predicted < 1 ? reps : 1, naive,
                     [&] { return potential_field(view, scene, spec, "naive", opt.threads); });
      last_naive = tn.cpu;  // CPU time: a shared machine's wall clock says little
      last_naive_n = n;
      err = error_over_tolerance(idx, naive, spec, 1.0);
    }
    const double l = load1();
    const double speedup = tn.cpu / ti.cpu;
    csv.row(std::vector<double>{static_cast<double>(n), static_cast<double>(n),
                                static_cast<double>(w.obstacles.size()), ti.wall, ti.cpu, tn.wall,
                                tn.cpu, speedup, err, l});
    std::ostringstream line;
    line << std::setw(9) << n << std::setprecision(4) << std::setw(12) << ti.cpu << std::setw(12)
         << ti.wall << std::setw(12) << tn.cpu << std::setw(12) << tn.wall << std::setw(10)
         << std::setprecision(4) << speedup << std::setw(12) << std::setprecision(3) << err
         << std::setw(7) << std::setprecision(3) << l << "\n";
    table << line.str();
    if (opt.log) *opt.log << "e5: " << line.str() << std::flush;
  }
  csv.close();
  {
    std::ofstream f(opt.out_dir / "e5.txt");
    f << table.str();
  }
  plot(opt.out_dir, "e5",
       "set terminal pngcairo size 900,620 font ',11'\n"
       "set output 'e5.png'\n"
       "set datafile separator ','\n"
       "set title 'E5: potential field, exp-l1, density x n = 1 (CPU seconds, log-log)'\n"
       "set logscale xy\n"
       "set xlabel 'agents n (board n x n)'\n"
       "set ylabel 'seconds per evaluation (potential + gradient, all agents)'\n"
       "set key top left\n"
       "set grid\n"
       "plot 'e5.csv' using 1:5 skip 1 with linespoints pt 7 title 'aggregate index', \\\n"
       "     'e5.csv' using 1:($7 == $7 ? $7 : 1/0) skip 1 with linespoints pt 5 title 'naive "
       "nested loop'\n");
}

}  // namespace crowddb::experiment
