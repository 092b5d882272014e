// Shared pieces of the first-to-collide experiments E1-E3 (thesis §4.1, DESIGN.md §7): the
// worlds, one timed run of the index or the naive loop, and the method variants compared.
#pragma once

#include <time.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "experiment/experiment.hpp"
#include "index/ftc_tree.hpp"
#include "query/naive_paths.hpp"
#include "scenario/builders.hpp"
#include "util/stopwatch.hpp"

namespace crowddb::experiment::ftc {

constexpr double kHorizon = 30;  // ticks (thesis: collisions after 30 ticks are ignored)
constexpr double kVmax = 50;     // |v| <= 50
constexpr double kArrival = 20;  // Big Crunch: everyone reaches the centre at t = 20
constexpr double kE1Density = 15000.0 / (640.0 * 480.0);  // agents per unit area at n = 15,000

// The E1 plane, 640 x 480, or a plane of the same aspect holding n agents at the E1 density.
inline build::Box e1_plane() {
  return {0, 0, 640, 480};
}
inline build::Box e1_density_plane(std::size_t n) {
  const double s = std::sqrt(static_cast<double>(n) / 15000.0);
  return {0, 0, 640 * s, 480 * s};
}

enum class World { uniform, crunch, perturbed };
inline const char* name(World w) {
  return w == World::uniform ? "uniform" : (w == World::crunch ? "crunch" : "perturbed");
}

// Radii [rmin, rmax]: E1's [1, 3], or "sparse" [0.1, 0.3] where collision times crowd towards
// the Big Crunch's arrival time (the regime in which a loose bound degrades).
struct Radii {
  const char* name;
  double rmin, rmax;
};
inline constexpr Radii kE1Radii{"e1", 1, 3};
inline constexpr Radii kSparseRadii{"sparse", 0.1, 0.3};

inline DiscTable make_world(World w, std::size_t n, build::Box box, Radii r, uint64_t seed) {
  switch (w) {
    case World::uniform:
      return build::uniform(n, box, kVmax, r.rmin, r.rmax, seed);
    case World::crunch:
      return build::big_crunch(n, box, kArrival, r.rmin, r.rmax, 0, seed);
    default:
      return build::big_crunch(n, box, kArrival, r.rmin, r.rmax, 1, seed);
  }
}

// The index as shipped, and the thesis's algorithm made exact: frustum bounds (velocity
// bounds), best-first from the root, one agent per leaf.
// Both built on every run (rebuild_every 1): the runs are independent random worlds, not ticks,
// and a tree refitted to another world would measure that world's tree.
inline FtcIndexOptions ours() {
  return {.rebuild_every = 1};
}
inline FtcIndexOptions thesis() {
  FtcIndexOptions o;
  o.leaf_size = 1;
  o.bound = FtcIndexOptions::Bound::frustum;
  o.slices = 1;
  o.order = FtcIndexOptions::Order::best_first;
  o.seed_own_leaf = false;
  o.overlap_join = false;  // its overlap phase searches the tree as well
  o.rebuild_every = 1;
  return o;
}

// The clock of the figures. Single-threaded runs (the default) use the CPU time of the calling
// thread, which a busy shared machine inflates far less than wall time (2 cores shared by a
// team: wall time here is mostly time spent waiting for a core); with more threads, wall time.
class RunClock {
 public:
  explicit RunClock(int threads) : cpu_(threads <= 1) { restart(); }
  void restart() { start_ = now(); }
  double seconds() const { return now() - start_; }
  const char* what() const { return cpu_ ? "CPU time of the (single) thread" : "wall time"; }

 private:
  double now() const {
    if (!cpu_) return wall_.seconds();
    timespec ts{};
    clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
  }
  bool cpu_;
  Stopwatch wall_;
  double start_ = 0;
};

// The experiments have no obstacles. One scene for all runs: the index keeps a reference to it
// (and to the table) until the next build.
inline const StaticScene& no_obstacles() {
  static const StaticScene none;
  return none;
}

struct Run {
  double build_s = 0, query_s = 0;  // RunClock
  double wall_s = 0;                // build + query, wall clock
  QueryStats stats;
};

inline Run run_index(FtcIndex& index, const DiscTable& t, Executor& ex, std::vector<FtcHit>& out) {
  out.assign(t.size(), FtcHit{});
  Run r;
  RunClock clock(ex.threads());
  Stopwatch wall;
  index.build(t.view(), no_obstacles(), kHorizon, &ex);
  r.build_s = clock.seconds();
  clock.restart();
  index.query_all(out, ex, r.stats);
  r.query_s = clock.seconds();
  r.wall_s = wall.seconds();
  return r;
}

inline double run_naive(const DiscTable& t, Executor& ex, std::vector<FtcHit>& out) {
  out.assign(t.size(), FtcHit{});
  FtcNaive naive;
  QueryStats st;
  RunClock clock(ex.threads());
  naive.run(t.view(), no_obstacles(), kHorizon, out, ex, st);
  return clock.seconds();
}

// Rows whose collider or time (bit for bit) differ.
inline std::size_t mismatches(const std::vector<FtcHit>& a, const std::vector<FtcHit>& b) {
  std::size_t bad = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (!(a[i].with == b[i].with) || std::memcmp(&a[i].time, &b[i].time, sizeof(double)) != 0)
      ++bad;
  return bad + (a.size() > b.size() ? a.size() - b.size() : b.size() - a.size());
}

// Naive runs at size n within a budget of pair tests (the nested loop is O(n^2)): at least
// `least`, at most `most`.
inline int naive_runs(std::size_t n, double budget_pairs, int least, int most) {
  const double nn = static_cast<double>(n) * static_cast<double>(n);
  const double r = std::floor(budget_pairs / std::max(nn, 1.0));
  return static_cast<int>(std::clamp(r, static_cast<double>(least), static_cast<double>(most)));
}

inline std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return buf;
}

// Writes NAME.txt (the command line and the machine note) and returns the note for the plots.
inline std::string write_run_note(const Options& opt, const std::string& name) {
  const std::string note = machine_note(opt.threads) + "; times: " + RunClock(opt.threads).what();
  std::ofstream txt(opt.out_dir / (name + ".txt"));
  txt << "crowddb experiment " << name << (opt.quick ? " --quick" : "") << " --seed " << opt.seed
      << "\n"
      << note << "\n";
  return note;
}

// A gnuplot series of the E2/E3 CSV files: the rows of (radii, world, method), x = n (column 4),
// y = column 6 with error bars of column 7 (low bars clipped by lowbar()).
inline std::string series(const std::string& csv, const std::string& radii,
                          const std::string& world, const std::string& method,
                          const std::string& style, const std::string& title) {
  const std::string sel = "(strcol(1) eq '" + radii + "' && strcol(2) eq '" + world +
                          "' && strcol(3) eq '" + method + "' ? ";
  return "'" + csv + "' using 4:" + sel + "$6 : NaN):" + sel + "lowbar($6, $6-$7) : NaN):" + sel +
         "$6+$7 : NaN) with yerrorlines " + style + " title \"" + title + "\"";
}

}  // namespace crowddb::experiment::ftc
