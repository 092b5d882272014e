// E1 — first-to-collide scaling (thesis §4.1, Figure 4.1; DESIGN.md §7).
//
// Plane 640 x 480, positions uniform, velocity uniform in the disc |v| <= 50, radius uniform in
// [1, 3], horizon 30 ticks; n = 1,000 ... 15,000, 200 runs (fresh worlds) per n. Per run: index
// build time, time of the queries of all agents, and (on fewer runs at large n: the nested loop
// is O(n^2); the CSV says how many) the naive time; every naive run is also checked against the
// index, row by row. A second table keeps the E1 density while the plane grows, up to 10^6.
//
// Output: e1.csv, e1_density.csv, e1.png, e1_density.png (+ the .gp scripts), e1.txt (machine).
#include <fstream>
#include <ostream>

#include "experiment/experiment.hpp"
#include "experiment/ftc_runs.hpp"
#include "util/executor.hpp"

namespace crowddb::experiment {

void run_e1(const Options& opt) {
  using namespace ftc;
  const bool quick = opt.quick;
  std::vector<std::size_t> sizes;
  if (quick)
    sizes = {500, 1000, 2000};
  else
    for (std::size_t n = 1000; n <= 15000; n += 1000) sizes.push_back(n);
  const int runs = quick ? 3 : 200;
  // Naive: at most `runs`, at least 3 (1 when quick), within ~6e8 pair tests per n.
  const double budget = quick ? 1e7 : 6e8;
  const int naive_least = quick ? 1 : 3;

  Executor ex(opt.threads);
  FtcIndex index(ours());
  std::vector<FtcHit> got, want;

  const std::vector<std::string> head = {"n",
                                         "runs",
                                         "build_ms",
                                         "build_2sd_ms",
                                         "query_ms",
                                         "query_2sd_ms",
                                         "total_ms",
                                         "total_2sd_ms",
                                         "naive_runs",
                                         "naive_ms",
                                         "naive_2sd_ms",
                                         "speedup",
                                         "nodes_per_query",
                                         "pops_per_query",
                                         "pairs_per_query",
                                         "mismatches",
                                         "wall_total_ms"};
  CsvWriter csv(opt.out_dir / "e1.csv", head);
  for (std::size_t n : sizes) {
    const int nruns = std::min(runs, naive_runs(n, budget, naive_least, runs));
    std::vector<double> b, q, tot, nv, wall;
    QueryStats st;
    std::size_t bad = 0;
    run_index(index, make_world(World::uniform, n, e1_plane(), kE1Radii, opt.seed), ex,
              got);  // warm-up
    for (int r = 0; r < runs; ++r) {
      const DiscTable t =
          make_world(World::uniform, n, e1_plane(), kE1Radii, opt.seed * 1000003 + n * 7919 + r);
      const Run x = run_index(index, t, ex, got);
      b.push_back(x.build_s * 1e3);
      q.push_back(x.query_s * 1e3);
      tot.push_back((x.build_s + x.query_s) * 1e3);
      wall.push_back(x.wall_s * 1e3);
      st += x.stats;
      if (r < nruns) {
        nv.push_back(run_naive(t, ex, want) * 1e3);
        bad += mismatches(got, want);
      }
    }
    const MeanSd mb = mean_sd(b), mq = mean_sd(q), mt = mean_sd(tot), mn = mean_sd(nv);
    const double queries = static_cast<double>(st.rows);
    csv.row(std::vector<double>{
        static_cast<double>(n), static_cast<double>(runs), mb.mean, 2 * mb.sd, mq.mean, 2 * mq.sd,
        mt.mean, 2 * mt.sd, static_cast<double>(nruns), mn.mean, 2 * mn.sd, mn.mean / mt.mean,
        static_cast<double>(st.nodes_visited) / queries,
        static_cast<double>(st.queue_pops) / queries, static_cast<double>(st.pair_tests) / queries,
        static_cast<double>(bad), mean_sd(wall).mean});
    if (opt.log)
      *opt.log << "e1: n=" << n << " index " << fmt(mt.mean) << " ms (build " << fmt(mb.mean)
               << ", query " << fmt(mq.mean) << "), naive " << fmt(mn.mean) << " ms over " << nruns
               << " runs, mismatches " << bad << "\n";
  }
  csv.close();

  // The same density on a growing plane, up to a million agents (index only).
  std::vector<std::size_t> dsizes = quick ? std::vector<std::size_t>{1000, 4000}
                                          : std::vector<std::size_t>{1000, 15000, 100000, 1000000};
  const std::vector<std::string> dhead = {"n",
                                          "plane_w",
                                          "plane_h",
                                          "runs",
                                          "build_ms",
                                          "build_2sd_ms",
                                          "query_ms",
                                          "query_2sd_ms",
                                          "total_ms",
                                          "total_2sd_ms",
                                          "nodes_per_query",
                                          "pops_per_query",
                                          "pairs_per_query"};
  CsvWriter dcsv(opt.out_dir / "e1_density.csv", dhead);
  for (std::size_t n : dsizes) {
    const int druns = quick ? 2 : (n <= 15000 ? 50 : (n <= 100000 ? 10 : 5));
    const build::Box box = e1_density_plane(n);
    std::vector<double> b, q, tot;
    QueryStats st;
    for (int r = 0; r < druns; ++r) {
      const DiscTable t =
          make_world(World::uniform, n, box, kE1Radii, opt.seed * 1000003 + n * 7919 + r);
      const Run x = run_index(index, t, ex, got);
      b.push_back(x.build_s * 1e3);
      q.push_back(x.query_s * 1e3);
      tot.push_back((x.build_s + x.query_s) * 1e3);
      st += x.stats;
    }
    const MeanSd mb = mean_sd(b), mq = mean_sd(q), mt = mean_sd(tot);
    const double queries = static_cast<double>(st.rows);
    dcsv.row(std::vector<double>{
        static_cast<double>(n), box.xmax, box.ymax, static_cast<double>(druns), mb.mean, 2 * mb.sd,
        mq.mean, 2 * mq.sd, mt.mean, 2 * mt.sd, static_cast<double>(st.nodes_visited) / queries,
        static_cast<double>(st.queue_pops) / queries,
        static_cast<double>(st.pair_tests) / queries});
    if (opt.log)
      *opt.log << "e1 density: n=" << n << " index " << fmt(mt.mean) << " ms (build "
               << fmt(mb.mean) << ", query " << fmt(mq.mean) << ")\n";
  }
  dcsv.close();

  const std::string note = ftc::write_run_note(opt, "e1");
  plot(
      opt.out_dir, "e1",
      "set terminal pngcairo size 1500,620 font ',11'\n"
      "set output 'e1.png'\n"
      "set datafile separator ','\n"
      "set datafile columnheaders\n"
      "set multiplot layout 1,2 title \"E1 first-to-collide: uniform positions on 640 x 480, |v| "
      "<= 50, "
      "radius in [1, 3], horizon 30; mean ± 2σ over runs\\n" +
          note +
          "\"\n"
          "set grid\n"
          "set key top left\n"
          "set xlabel 'agents n'\n"
          "set ylabel 'time per tick [ms]'\n"
          "set title 'kinetic k-d tree, single thread (" +
          std::to_string(runs) +
          " runs per n)'\n"
          "plot 'e1.csv' using 1:3:($3-$4):($3+$4) with yerrorlines lw 2 title 'build', \\\n"
          "     '' using 1:5:($5-$6):($5+$6) with yerrorlines lw 2 title 'query (all agents)', \\\n"
          "     '' using 1:7:($7-$8):($7+$8) with yerrorlines lw 2 title 'build + query'\n"
          "set logscale y\n"
          "set title 'index vs naive (log; low bars clipped at mean/10; naive runs: e1.csv)'\n"
          "lowbar(m, x) = x > m / 10 ? x : m / 10\n"
          "plot 'e1.csv' using 1:7:(lowbar($7, $7-$8)):($7+$8) with yerrorlines lw 2 title 'index: "
          "build + query', \\\n"
          "     '' using 1:10:(lowbar($10, $10-$11)):($10+$11) with yerrorlines lw 2 title "
          "'naive'\n"
          "unset multiplot\n");
  plot(opt.out_dir, "e1_density",
       "set terminal pngcairo size 1000,620 font ',11'\n"
       "set output 'e1_density.png'\n"
       "set datafile separator ','\n"
       "set datafile columnheaders\n"
       "set title \"E1 density (15,000 agents per 640 x 480) on a growing plane: mean ± 2σ\\n" +
           note +
           "\"\n"
           "set grid\n"
           "set key top left\n"
           "set logscale xy\n"
           "set xlabel 'agents n'\n"
           "set ylabel 'time per tick [ms]'\n"
           "lowbar(m, x) = x > m / 10 ? x : m / 10\n"
           "plot 'e1_density.csv' using 1:5:(lowbar($5, $5-$6)):($5+$6) with yerrorlines lw 2 "
           "title 'build', \\\n"
           "     '' using 1:7:(lowbar($7, $7-$8)):($7+$8) with yerrorlines lw 2 title 'query (all "
           "agents)', \\\n"
           "     '' using 1:9:(lowbar($9, $9-$10)):($9+$10) with yerrorlines lw 2 title 'build + "
           "query'\n");
}

}  // namespace crowddb::experiment
